#pragma once

// ConvexContact: the single deepest contact of two convex supports, from GJK on their cores and, when the
// cores touch or overlap, EPA on the full shapes.
//
// Core + radius: GJK runs on the cores (sphere = point, capsule = segment, box/hull/triangle = itself). When
// the cores are apart, the closest core points give the normal exactly and the radii are added afterwards
// (this is exact and fast for round shapes and gives speculative contacts for free). Only when the cores are
// within cCoreTouchDistance does EPA run, on the full shapes inflated by a further cEpaInflation on each side
// so that the origin lies well inside the Minkowski difference even for touching polytopes (EPA on an origin
// sitting on the boundary is ill-conditioned). The inflation is removed from the result exactly: inflating
// both shapes by r adds exactly 2r to the penetration depth along the same normal.

#include "narrowphase/ConvexSupport.h"

namespace cairn::physics
{

struct ConvexContact
{
    Vec3 mNormal = Vec3::UnitY(); ///< Unit, from A towards B
    Vec3 mPointA = Vec3::Zero();  ///< On A's surface
    Vec3 mPointB = Vec3::Zero();  ///< On B's surface
    float mPenetration = 0.0f;    ///< dot(mPointA - mPointB, mNormal); < 0 when separated
};

/// Cores closer than this (metres) count as touching and go to EPA.
inline constexpr float cCoreTouchDistance = 1.0e-4f;
/// Extra radius both shapes get for EPA (metres), removed from the result.
inline constexpr float cEpaInflation = 1.0e-3f;

/// Deepest contact between A and B. Returns false when they are further apart than inMaxSeparation.
bool FindConvexContact(const ConvexSupport& inA, const ConvexSupport& inB, float inMaxSeparation,
                       ConvexContact& outContact);

} // namespace cairn::physics
