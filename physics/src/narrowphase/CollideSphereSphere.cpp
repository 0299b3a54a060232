#include "narrowphase/CollideSphereSphere.h"

namespace cairn::physics
{

bool CollideBalls(const Vec3& inCenterA, float inRadiusA, const Vec3& inCenterB, float inRadiusB,
                  const Vec3& inFallbackNormal, float inMaxSeparation, ContactManifold& outManifold)
{
    const Vec3 delta = inCenterB - inCenterA;
    const float distSq = delta.squaredNorm();
    const float reach = inRadiusA + inRadiusB + inMaxSeparation;
    if (distSq > reach * reach) return false;
    const float dist = std::sqrt(distSq);
    // Coincident centres have no preferred direction: any is correct, the caller's is at least stable
    const Vec3 n = dist > 1.0e-6f ? Vec3(delta / dist) : inFallbackNormal;
    outManifold.mNormal = n;
    outManifold.mNumPoints = 1;
    ContactPoint& p = outManifold.mPoints[0];
    p.mPositionOnA = inCenterA + n * inRadiusA;
    p.mPositionOnB = inCenterB - n * inRadiusB;
    p.mPenetration = inRadiusA + inRadiusB - n.dot(delta);
    return true;
}

bool CollideSphereSphere(const SphereShape& inA, const Transform& inTransformA, const SphereShape& inB,
                         const Transform& inTransformB, const CollideSettings& inSettings,
                         ContactManifold& outManifold)
{
    return CollideBalls(inTransformA.mPosition, inA.GetRadius(), inTransformB.mPosition, inB.GetRadius(),
                        Vec3::UnitY(), inSettings.mMaxSeparation, outManifold);
}

} // namespace cairn::physics
