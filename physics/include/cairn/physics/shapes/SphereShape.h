#pragma once

// A sphere centred on its local origin. Immutable after creation: safe to share between threads.

#include "cairn/physics/math/Result.h"
#include "cairn/physics/shapes/Shape.h"

namespace cairn::physics
{

class SphereShape final : public ConvexShape
{
public:
    /// Fails for a radius that is not finite and > 0.
    static Result<std::shared_ptr<const SphereShape>> Create(float inRadius);

    float GetRadius() const { return mRadius; }

    AABB GetLocalBounds() const override;
    /// The centre grown by the radius: a sphere's box does not turn with it.
    AABB GetWorldBounds(const Transform& inTransform) const override;
    MassProperties GetMassProperties(float inDensity) const override;
    void VisitTriangles(const AABB& inLocalBox, TriangleVisitor inVisitor) const override;
    Vec3 GetSupport(const Vec3& inDirection) const override;

    explicit SphereShape(float inRadius); ///< Use Create(), which validates

private:
    bool CastCheckedRay(const RayCast& inLocalRay, RayHit& ioHit) const override;

    float mRadius; ///< Metres, > 0
};

} // namespace cairn::physics
