#pragma once

// A static triangle mesh with its own bounding-volume tree. Has no volume: only static or kinematic bodies
// may use it. Immutable: safe to share between threads.
//
// Internal edges: at creation every edge shared by two triangles whose dihedral angle is flat or concave
// (within cActiveEdgeCosThreshold) is marked inactive (Triangle::mActiveEdges). The narrow phase replaces a
// contact normal that comes from an inactive edge or vertex by the triangle's face normal, so a body sliding
// or rolling across a flat mesh does not catch on the seams between triangles.

#include "cairn/physics/math/Result.h"
#include "cairn/physics/shapes/Shape.h"

#include <array>
#include <span>

namespace cairn::physics
{

class TriangleMeshShape final : public Shape
{
public:
    /// Edges between triangles whose normals' dot product exceeds this are inactive (about 2.6 degrees).
    static constexpr float cActiveEdgeCosThreshold = 0.999f;

    /// Builds the mesh. Fails on NaN/infinite vertices, out-of-range indices, no triangles, or when every
    /// triangle is degenerate (zero area); degenerate triangles among good ones are dropped.
    static Result<std::shared_ptr<const TriangleMeshShape>>
    Create(std::span<const Vec3> inVertices, std::span<const std::array<uint32_t, 3>> inTriangles);

    size_t GetTriangleCount() const;

    AABB GetLocalBounds() const override;
    MassProperties GetMassProperties(float inDensity) const override; ///< Zero mass: no volume
    void VisitTriangles(const AABB& inLocalBox, TriangleVisitor inVisitor) const override;

    struct Impl;
    explicit TriangleMeshShape(std::unique_ptr<Impl> inImpl); ///< Use Create()
    ~TriangleMeshShape() override;

private:
    bool CastCheckedRay(const RayCast& inLocalRay, RayHit& ioHit) const override; ///< Two-sided

    std::unique_ptr<Impl> mImpl; ///< Vertices, triangles with edge flags, BVH nodes
};

} // namespace cairn::physics
