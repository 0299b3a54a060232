#pragma once

// A capsule along the local Y axis: the points within mRadius of the segment from (0, -h, 0) to (0, h, 0).
// Immutable: safe to share between threads.

#include "cairn/physics/math/Result.h"
#include "cairn/physics/shapes/Shape.h"

namespace cairn::physics
{

class CapsuleShape final : public ConvexShape
{
public:
    /// inHalfHeight is half the length of the inner segment (>= 0); inRadius > 0; both finite.
    static Result<std::shared_ptr<const CapsuleShape>> Create(float inHalfHeight, float inRadius);

    float GetHalfHeight() const { return mHalfHeight; }
    float GetRadius() const { return mRadius; }

    AABB GetLocalBounds() const override;
    /// The box of the inner segment's two ends grown by the radius: tight at every rotation.
    AABB GetWorldBounds(const Transform& inTransform) const override;
    MassProperties GetMassProperties(float inDensity) const override;
    void VisitTriangles(const AABB& inLocalBox, TriangleVisitor inVisitor) const override;
    Vec3 GetSupport(const Vec3& inDirection) const override;
    /// Two points (the segment pushed out by the radius) when inDirection is nearly perpendicular to the
    /// axis, otherwise the single support point.
    void GetSupportingFace(const Vec3& inDirection, SupportingFace& outFace) const override;

    CapsuleShape(float inHalfHeight, float inRadius); ///< Use Create(), which validates

private:
    bool CastCheckedRay(const RayCast& inLocalRay, RayHit& ioHit) const override;

    float mHalfHeight; ///< Half the inner segment length, >= 0
    float mRadius;     ///< > 0
};

} // namespace cairn::physics
