#include "narrowphase/CollideCapsuleCapsule.h"

#include "narrowphase/ClosestPoints.h"
#include "narrowphase/CollideSphereSphere.h"

#include <algorithm>

namespace cairn::physics
{

namespace
{

/// Axes closer than this to parallel (about 2.5 degrees) get a two-point manifold.
constexpr float cParallelCos = 0.999f;

} // namespace

bool CollideCapsuleCapsule(const CapsuleShape& inA, const Transform& inTransformA, const CapsuleShape& inB,
                           const Transform& inTransformB, const CollideSettings& inSettings,
                           ContactManifold& outManifold)
{
    const Vec3 axisA = inTransformA.RotateVector(Vec3(0.0f, inA.GetHalfHeight(), 0.0f));
    const Vec3 axisB = inTransformB.RotateVector(Vec3(0.0f, inB.GetHalfHeight(), 0.0f));
    const Vec3 a0 = inTransformA.mPosition - axisA;
    const Vec3 a1 = inTransformA.mPosition + axisA;
    const Vec3 b0 = inTransformB.mPosition - axisB;
    const Vec3 b1 = inTransformB.mPosition + axisB;
    const float rA = inA.GetRadius();
    const float rB = inB.GetRadius();

    float s;
    float t;
    Vec3 cA;
    Vec3 cB;
    const float distSq = ClosestPointsSegmentSegment(a0, a1, b0, b1, s, t, cA, cB);
    const float reach = rA + rB + inSettings.mMaxSeparation;
    if (distSq > reach * reach) return false;

    // Crossing segments: the normal is perpendicular to both axes, oriented from A's centre towards B's
    Vec3 fallback = axisA.cross(axisB);
    if (fallback.squaredNorm() < 1.0e-12f)
        fallback = AnyPerpendicular(axisA.squaredNorm() > 0.0f ? Vec3(axisA) : Vec3(Vec3::UnitY()));
    fallback.normalize();
    if (fallback.dot(inTransformB.mPosition - inTransformA.mPosition) < 0.0f) fallback = -fallback;
    if (!CollideBalls(cA, rA, cB, rB, fallback, inSettings.mMaxSeparation, outManifold)) return false;

    const float lenA = 2.0f * axisA.norm();
    const float lenB = 2.0f * axisB.norm();
    if (lenA < 1.0e-6f || lenB < 1.0e-6f) return true;
    const Vec3 dirA = axisA * (2.0f / lenA);
    const Vec3 dirB = axisB * (2.0f / lenB);
    if (std::abs(dirA.dot(dirB)) < cParallelCos) return true;

    // Parallel: the part of B's segment that projects onto A's segment gives the two ends of the contact
    const float tb0 = dirA.dot(b0 - a0);
    const float tb1 = dirA.dot(b1 - a0);
    const float lo = std::max(0.0f, std::min(tb0, tb1));
    const float hi = std::min(lenA, std::max(tb0, tb1));
    if (hi - lo < 1.0e-4f) return true;

    const Vec3 n = outManifold.mNormal;
    int count = 0;
    for (const float proj : {lo, hi})
    {
        // Point of B's segment with this projection, and the point of A's segment there
        const float u = std::clamp((proj - tb0) / (tb1 - tb0), 0.0f, 1.0f);
        const Vec3 onB = b0 + (b1 - b0) * u;
        const Vec3 onA = a0 + dirA * proj;
        ContactPoint& p = outManifold.mPoints[count];
        p.mPositionOnA = onA + n * rA;
        p.mPositionOnB = onB - n * rB;
        p.mPenetration = (p.mPositionOnA - p.mPositionOnB).dot(n);
        if (p.mPenetration >= -inSettings.mMaxSeparation) ++count;
    }
    if (count > 0) outManifold.mNumPoints = count;
    return true;
}

} // namespace cairn::physics
