#pragma once

// A compound: sub-shapes at local transforms. Sub-shapes may be any shape except another compound's cycle
// (shapes are immutable, so cycles cannot be built). SubShapeID of a compound hit = the child's index.
// Immutable: safe to share between threads.

#include "cairn/physics/math/Result.h"
#include "cairn/physics/shapes/Shape.h"

#include <span>

namespace cairn
{

class CompoundShape final : public Shape
{
public:
    struct SubShape
    {
        ShapeRef mShape;           ///< Never null
        Transform mLocalTransform; ///< Child space to compound space
    };

    /// Fails for no children, a null child, or a non-finite / non-unit transform.
    static Result<std::shared_ptr<const CompoundShape>> Create(std::vector<SubShape> inSubShapes);

    std::span<const SubShape> GetSubShapes() const { return mSubShapes; }

    AABB GetLocalBounds() const override;
    AABB GetWorldBounds(const Transform& inTransform) const override;
    MassProperties GetMassProperties(float inDensity) const override; ///< Sum of children (parallel axis)
    bool CastRay(const RayCast& inLocalRay, RayHit& ioHit) const override;
    void VisitTriangles(const AABB& inLocalBox, TriangleVisitor inVisitor) const override;

    explicit CompoundShape(std::vector<SubShape> inSubShapes); ///< Use Create()

private:
    std::vector<SubShape> mSubShapes;
    AABB mBounds;
};

} // namespace cairn
