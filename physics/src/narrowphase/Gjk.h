#pragma once

// GJK (Gilbert-Johnson-Keerthi): distance and closest points between two convex supports, working on the
// Minkowski difference A - B. Each support can be inflated by a radius (its support point moves outwards by
// that much), which turns a core into the full shape, or the full shape into a slightly fatter one for EPA.
// Fixed-size simplex, no allocation, at most cMaxIterations support calls per shape.

#include "narrowphase/ConvexSupport.h"

namespace cairn::physics
{

/// The simplex GJK ends with: up to 4 points of the Minkowski difference with the support points they came
/// from.
struct GjkSimplex
{
    int mCount = 0;
    Vec3 mY[4] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()}; ///< mA[i] - mB[i]
    Vec3 mA[4] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()}; ///< Support point on A
    Vec3 mB[4] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()}; ///< Support point on B
};

struct GjkResult
{
    /// The Minkowski difference contains the origin (or is within cOverlapDistance of it): distance is 0
    /// and the closest points are meaningless; run EPA.
    bool mOverlapping = false;
    /// The shapes were proven further apart than the query's inMaxDistance; nothing else is set.
    bool mBeyondMaxDistance = false;
    float mDistance = 0.0f;      ///< Distance between the (inflated) supports
    Vec3 mPointA = Vec3::Zero(); ///< Closest point on A (world space)
    Vec3 mPointB = Vec3::Zero(); ///< Closest point on B
    GjkSimplex mSimplex;         ///< Final simplex (input for EPA when overlapping)
};

class Gjk
{
public:
    static constexpr int cMaxIterations = 64;
    /// Below this distance (metres) GJK reports overlap: the origin is on the simplex within float precision.
    static constexpr float cOverlapDistance = 1.0e-6f;

    /// Closest points between A inflated by inInflationA and B inflated by inInflationB. Stops early with
    /// mBeyondMaxDistance when the distance is proven larger than inMaxDistance.
    static GjkResult ClosestPoints(const ConvexSupport& inA, float inInflationA, const ConvexSupport& inB,
                                   float inInflationB, float inMaxDistance);
};

} // namespace cairn::physics
