#pragma once

// A box centred on its local origin, aligned with the local axes. Immutable: safe to share between threads.

#include "cairn/physics/math/Result.h"
#include "cairn/physics/shapes/Shape.h"

namespace cairn::physics
{

class BoxShape final : public ConvexShape
{
public:
    /// Fails unless every half extent is finite and > 0.
    static Result<std::shared_ptr<const BoxShape>> Create(const Vec3& inHalfExtent);

    const Vec3& GetHalfExtent() const { return mHalfExtent; }

    AABB GetLocalBounds() const override;
    MassProperties GetMassProperties(float inDensity) const override;
    void VisitTriangles(const AABB& inLocalBox, TriangleVisitor inVisitor) const override;
    Vec3 GetSupport(const Vec3& inDirection) const override;
    void GetSupportingFace(const Vec3& inDirection, SupportingFace& outFace) const override;

    explicit BoxShape(const Vec3& inHalfExtent); ///< Use Create(), which validates

private:
    bool CastCheckedRay(const RayCast& inLocalRay, RayHit& ioHit) const override;

    Vec3 mHalfExtent; ///< Metres, each > 0
};

} // namespace cairn::physics
