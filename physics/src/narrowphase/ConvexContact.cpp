#include "narrowphase/ConvexContact.h"

#include "narrowphase/Epa.h"

namespace cairn::physics
{

bool FindConvexContact(const ConvexSupport& inA, const ConvexSupport& inB, float inMaxSeparation,
                       ConvexContact& outContact)
{
    const float rA = inA.GetRadius();
    const float rB = inB.GetRadius();
    const GjkResult core = Gjk::ClosestPoints(inA, 0.0f, inB, 0.0f, rA + rB + inMaxSeparation);
    if (core.mBeyondMaxDistance) return false;

    if (!core.mOverlapping && core.mDistance > cCoreTouchDistance)
    {
        const Vec3 n = (core.mPointB - core.mPointA) / core.mDistance;
        outContact.mNormal = n;
        outContact.mPointA = core.mPointA + n * rA;
        outContact.mPointB = core.mPointB - n * rB;
        outContact.mPenetration = rA + rB - core.mDistance;
        return outContact.mPenetration >= -inMaxSeparation;
    }

    const float inflA = rA + cEpaInflation;
    const float inflB = rB + cEpaInflation;
    const GjkResult full = Gjk::ClosestPoints(inA, inflA, inB, inflB, cLargeFloat);
    PenetrationResult pen;
    if (full.mOverlapping && Epa::Penetration(inA, inflA, inB, inflB, full.mSimplex, pen))
    {
        outContact.mNormal = pen.mNormal;
        outContact.mPointA = pen.mPointA - pen.mNormal * cEpaInflation;
        outContact.mPointB = pen.mPointB + pen.mNormal * cEpaInflation;
        outContact.mPenetration = pen.mDepth - 2.0f * cEpaInflation;
        return true;
    }

    // EPA could not build a polytope (cannot happen for shapes with volume): separate along the centres
    Vec3 n = inB.GetCenter() - inA.GetCenter();
    n = n.squaredNorm() > 1.0e-12f ? Vec3(n.normalized()) : Vec3(Vec3::UnitY());
    outContact.mNormal = n;
    outContact.mPointA = inA.GetSupport(n, rA);
    outContact.mPointB = inB.GetSupport(-n, rB);
    outContact.mPenetration = (outContact.mPointA - outContact.mPointB).dot(n);
    return outContact.mPenetration >= -inMaxSeparation;
}

} // namespace cairn::physics
