#pragma once

// A convex hull built from a point cloud (quickhull). Immutable: safe to share between threads.

#include "cairn/physics/math/Result.h"
#include "cairn/physics/shapes/Shape.h"

#include <span>

namespace cairn::physics
{

class ConvexHullShape final : public ConvexShape
{
public:
    /// One planar face of the hull: vertex indices counter-clockwise seen from outside.
    struct Face
    {
        Vec3 mNormal;                   ///< Outward unit normal
        float mPlaneConstant;           ///< dot(mNormal, p) == mPlaneConstant for points p on the face
        std::vector<uint32_t> mIndices; ///< Into GetVertices(); coplanar triangles are merged into one face
    };

    /// The most points Create takes. The build grows faster than the point count (some 6 s for 40,000
    /// points on a sphere), and a game's hulls have tens to hundreds: reduce a larger cloud first.
    static constexpr size_t cMaxInputPoints = 16384;

    /// Builds the hull of inPoints. Fails with DegenerateShape for fewer than 4 points, coincident,
    /// collinear or coplanar input (no volume), and with InvalidArgument for NaN/infinite points or more
    /// than cMaxInputPoints. Points inside the hull are dropped.
    static Result<std::shared_ptr<const ConvexHullShape>> Create(std::span<const Vec3> inPoints);

    const std::vector<Vec3>& GetVertices() const { return mVertices; }
    const std::vector<Face>& GetFaces() const { return mFaces; }

    AABB GetLocalBounds() const override;
    MassProperties GetMassProperties(float inDensity) const override;
    void VisitTriangles(const AABB& inLocalBox, TriangleVisitor inVisitor) const override;
    Vec3 GetSupport(const Vec3& inDirection) const override;
    void GetSupportingFace(const Vec3& inDirection, SupportingFace& outFace) const override;

    ConvexHullShape(std::vector<Vec3> inVertices, std::vector<Face> inFaces); ///< Use Create()

private:
    bool CastCheckedRay(const RayCast& inLocalRay, RayHit& ioHit) const override;

    std::vector<Vec3> mVertices; ///< Hull vertices only
    std::vector<Face> mFaces;    ///< Planar faces, merged
    AABB mBounds;                ///< Local bounds of mVertices
};

} // namespace cairn::physics
