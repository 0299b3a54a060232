#include "narrowphase/ConvexSupport.h"

#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/CapsuleShape.h"
#include "cairn/physics/shapes/SphereShape.h"

namespace cairn::physics
{

ConvexSupport ConvexSupport::FromShape(const ConvexShape& inShape, const Transform& inTransform)
{
    ConvexSupport s;
    s.mCenter = inTransform.mPosition;
    switch (inShape.GetType())
    {
    case ShapeType::Sphere:
        s.mKind = Kind::Points;
        s.mNumPoints = 1;
        s.mPoints[0] = inTransform.mPosition;
        s.mRadius = static_cast<const SphereShape&>(inShape).GetRadius();
        break;
    case ShapeType::Capsule:
    {
        const auto& capsule = static_cast<const CapsuleShape&>(inShape);
        const Vec3 axis = inTransform.RotateVector(Vec3(0.0f, capsule.GetHalfHeight(), 0.0f));
        s.mKind = Kind::Points;
        s.mNumPoints = 2;
        s.mPoints[0] = inTransform.mPosition - axis;
        s.mPoints[1] = inTransform.mPosition + axis;
        s.mRadius = capsule.GetRadius();
        break;
    }
    case ShapeType::Box:
        s.mKind = Kind::Box;
        s.mRotation = inTransform.mRotation.toRotationMatrix();
        s.mHalfExtent = static_cast<const BoxShape&>(inShape).GetHalfExtent();
        break;
    default:
        s.mKind = Kind::Shape;
        s.mRotation = inTransform.mRotation.toRotationMatrix();
        s.mShape = &inShape;
        s.mTranslation = inTransform.mPosition;
        // The local origin need not be inside a hull: the centre of its bounds is a better first guess
        s.mCenter = inTransform * inShape.GetLocalBounds().Center();
        break;
    }
    return s;
}

ConvexSupport ConvexSupport::FromTriangle(const Vec3& inV0, const Vec3& inV1, const Vec3& inV2)
{
    ConvexSupport s;
    s.mKind = Kind::Points;
    s.mNumPoints = 3;
    s.mPoints[0] = inV0;
    s.mPoints[1] = inV1;
    s.mPoints[2] = inV2;
    s.mCenter = (inV0 + inV1 + inV2) / 3.0f;
    return s;
}

Vec3 ConvexSupport::GetCoreSupport(const Vec3& inDirection) const
{
    switch (mKind)
    {
    case Kind::Points:
    {
        int best = 0;
        float bestDot = mPoints[0].dot(inDirection);
        for (int i = 1; i < mNumPoints; ++i)
        {
            const float d = mPoints[i].dot(inDirection);
            if (d > bestDot)
            {
                bestDot = d;
                best = i;
            }
        }
        return mPoints[best];
    }
    case Kind::Box:
    {
        const Vec3 local = mRotation.transpose() * inDirection;
        const Vec3 corner(local.x() >= 0.0f ? mHalfExtent.x() : -mHalfExtent.x(),
                          local.y() >= 0.0f ? mHalfExtent.y() : -mHalfExtent.y(),
                          local.z() >= 0.0f ? mHalfExtent.z() : -mHalfExtent.z());
        return mCenter + mRotation * corner;
    }
    case Kind::Shape:
        break;
    }
    // mCenter is the bounds centre for generic shapes, so rebuild the translation from the rotation instead
    return mRotation * mShape->GetSupport(mRotation.transpose() * inDirection) + mTranslation;
}

} // namespace cairn::physics
