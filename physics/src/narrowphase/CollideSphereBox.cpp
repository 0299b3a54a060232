#include "narrowphase/CollideSphereBox.h"

namespace cairn::physics
{

bool CollideSphereBox(const SphereShape& inA, const Transform& inTransformA, const BoxShape& inB,
                      const Transform& inTransformB, const CollideSettings& inSettings,
                      ContactManifold& outManifold)
{
    const float radius = inA.GetRadius();
    const Vec3& extent = inB.GetHalfExtent();
    const Vec3 center = inTransformB.InverseTransformPoint(inTransformA.mPosition);
    const Vec3 clamped = center.cwiseMax(-extent).cwiseMin(extent);
    const Vec3 delta = center - clamped;
    const float distSq = delta.squaredNorm();
    const float reach = radius + inSettings.mMaxSeparation;
    if (distSq > reach * reach) return false;

    Vec3 localNormal; // From the sphere (A) towards the box (B), box space
    Vec3 onBox;
    float penetration;
    if (distSq > 1.0e-12f)
    {
        const float dist = std::sqrt(distSq);
        localNormal = -delta / dist;
        onBox = clamped;
        penetration = radius - dist;
    }
    else
    {
        // Centre inside (or on) the box: leave through the nearest face
        const Vec3 toFace = extent - center.cwiseAbs();
        int axis = 0;
        toFace.minCoeff(&axis);
        const float side = center[axis] < 0.0f ? -1.0f : 1.0f;
        localNormal = Vec3::Zero();
        localNormal[axis] = -side;
        onBox = center;
        onBox[axis] = side * extent[axis];
        penetration = radius + toFace[axis];
    }

    const Vec3 n = inTransformB.RotateVector(localNormal);
    outManifold.mNormal = n;
    outManifold.mNumPoints = 1;
    ContactPoint& p = outManifold.mPoints[0];
    p.mPositionOnB = inTransformB * onBox;
    p.mPositionOnA = inTransformA.mPosition + n * radius;
    p.mPenetration = penetration;
    return true;
}

} // namespace cairn::physics
