#pragma once

// A compound: sub-shapes at local transforms. Sub-shapes may be any shape except another compound's cycle
// (shapes are immutable, so cycles cannot be built). SubShapeID of a compound's ray hit or triangle = the
// child's index. A contact manifold's SubShapeID also keeps the child's own id (a mesh child's triangle), see
// MakeManifoldSubShapeID: it keys the contact cache, and every triangle's manifold needs a key of its own.
// Immutable: safe to share between threads.

#include "cairn/physics/math/Result.h"
#include "cairn/physics/shapes/Shape.h"

#include <span>

namespace cairn::physics
{

class CompoundShape final : public Shape
{
public:
    struct SubShape
    {
        ShapeRef mShape;           ///< Never null
        Transform mLocalTransform; ///< Child space to compound space
    };

    /// The most compounds nested in one another, this one included. Every query and collision walks a nested
    /// compound by recursion, a few stack frames a level: a bound keeps that within any thread's stack (a
    /// job thread's too); real assets nest a handful of levels.
    static constexpr uint32_t cMaxDepth = 32;

    /// Fails for no children, a null child, a non-finite / non-unit transform, or nesting deeper than
    /// cMaxDepth.
    static Result<std::shared_ptr<const CompoundShape>> Create(std::vector<SubShape> inSubShapes);

    std::span<const SubShape> GetSubShapes() const { return mSubShapes; }
    /// 1 for a compound of other shapes; one more than its deepest compound child otherwise.
    uint32_t GetDepth() const { return mDepth; }

    /// The id of a manifold of child inChild (of inNumChildren) whose own id is inChildSubShape: the child
    /// index in the low bits (as many as inNumChildren needs), the child's id above them. An id too large to
    /// fit is mixed in instead (still distinct from the others in practice, no longer decodable).
    static SubShapeID MakeManifoldSubShapeID(uint32_t inChild, size_t inNumChildren,
                                             SubShapeID inChildSubShape);
    /// The child index of an id made by MakeManifoldSubShapeID (when it fitted).
    static uint32_t GetManifoldChild(SubShapeID inID, size_t inNumChildren);

    AABB GetLocalBounds() const override;
    AABB GetWorldBounds(const Transform& inTransform) const override;
    MassProperties GetMassProperties(float inDensity) const override; ///< Sum of children (parallel axis)
    void VisitTriangles(const AABB& inLocalBox, TriangleVisitor inVisitor) const override;

    explicit CompoundShape(std::vector<SubShape> inSubShapes); ///< Use Create()

private:
    bool CastCheckedRay(const RayCast& inLocalRay, RayHit& ioHit) const override;

    std::vector<SubShape> mSubShapes;
    AABB mBounds;
    uint32_t mDepth = 1;
};

} // namespace cairn::physics
