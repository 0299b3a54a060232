#include "cairn/physics/shapes/SphereShape.h"

#include "cairn/physics/shapes/CapsuleShape.h"
#include "shapes/RayQuadratic.h"

#include <string>

namespace cairn::physics
{

Result<std::shared_ptr<const SphereShape>> SphereShape::Create(float inRadius)
{
    if (!std::isfinite(inRadius) || inRadius > cMaxWorldCoordinate)
        return MakeError(ErrorCode::InvalidArgument,
                         "SphereShape: radius must be finite and <= cMaxWorldCoordinate");
    if (!(inRadius > 0.0f))
        return MakeError(ErrorCode::DegenerateShape,
                         "SphereShape: radius must be > 0, got " + std::to_string(inRadius));
    return std::shared_ptr<const SphereShape>(std::make_shared<SphereShape>(inRadius));
}

SphereShape::SphereShape(float inRadius) : ConvexShape(ShapeType::Sphere), mRadius(inRadius) {}

AABB SphereShape::GetLocalBounds() const
{
    return AABB::FromCenterExtent(Vec3::Zero(), Vec3::Constant(mRadius));
}

AABB SphereShape::GetWorldBounds(const Transform& inTransform) const
{
    // The turned local box of a sphere is up to sqrt(3) times as wide as the sphere: every pair search and
    // query around it would find bodies it cannot touch
    return AABB::FromCenterExtent(inTransform.mPosition, Vec3::Constant(mRadius));
}

MassProperties SphereShape::GetMassProperties(float inDensity) const
{
    MassProperties props;
    props.mMass = inDensity * (4.0f / 3.0f) * cPi * mRadius * mRadius * mRadius;
    props.mInertia = Mat3::Identity() * (0.4f * props.mMass * mRadius * mRadius);
    return props;
}

bool SphereShape::CastCheckedRay(const RayCast& inLocalRay, RayHit& ioHit) const
{
    const Vec3& o = inLocalRay.mOrigin;
    const Vec3& d = inLocalRay.mDirection;
    const float c = o.squaredNorm() - mRadius * mRadius;
    if (c <= 0.0f) return ShapeHelpers::ReportStartInside(inLocalRay, ioHit);

    // |o + t d|^2 = r^2  ->  a t^2 + 2 b t + c = 0
    const float a = d.squaredNorm();
    const float b = o.dot(d);
    if (!(a > 0.0f) || b >= 0.0f) return false; // Not moving, or moving away from the centre while outside
    const float disc = RayQuadratic::Discriminant(o, d, a, b, mRadius);
    if (disc < 0.0f) return false;
    const float t = RayQuadratic::Entry(b, c, disc);
    if (!(t >= 0.0f && t <= 1.0f && t < ioHit.mFraction)) return false;
    ioHit.mFraction = t;
    ioHit.mNormal = ShapeHelpers::SafeNormalized(o + t * d, -d.normalized());
    ioHit.mSubShape = 0;
    return true;
}

void SphereShape::VisitTriangles(const AABB& inLocalBox, TriangleVisitor inVisitor) const
{
    // A capsule without an inner segment is this sphere: reuse its tessellation
    const CapsuleShape asCapsule(0.0f, mRadius);
    asCapsule.VisitTriangles(inLocalBox, inVisitor);
}

Vec3 SphereShape::GetSupport(const Vec3& inDirection) const
{
    return mRadius * ShapeHelpers::SafeNormalized(inDirection, Vec3::UnitX());
}

} // namespace cairn::physics
