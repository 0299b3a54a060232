#pragma once

// The exact AABB-level tests every broad phase uses, in one place so that all implementations (the
// brute-force oracle and the quad tree) agree bit for bit on touching and grazing cases: an equivalence test
// compares their results as exact sets, so they must not each round in their own way.
// Pure functions on values: safe from any thread.

#include "cairn/physics/broadphase/BroadPhase.h"

#include <cmath>

namespace cairn::physics
{

/// Bounds a broad phase accepts: finite and not inverted (min <= max on every axis). Anything else is a
/// caller bug (the body interface validates first); broad phases assert in debug and ignore the body.
inline bool IsValidBroadPhaseBounds(const AABB& inBounds)
{
    return inBounds.IsFinite() && (inBounds.mMin.array() <= inBounds.mMax.array()).all();
}

/// True when object layer inLayer is in inMask.
inline bool IsInLayerMask(ObjectLayerMask inMask, ObjectLayer inLayer)
{
    return ((inMask >> inLayer) & 1u) != 0;
}

/// AABB::Overlaps (closed intervals: touching counts) evaluated without branches: in a scan the six
/// comparisons are cheaper than the mispredicted early-outs of Eigen's all(). Same IEEE comparisons, so the
/// same result.
inline bool AABBsOverlap(const AABB& inA, const AABB& inB)
{
    // int, not bool, operands: the bitwise and is the point, and Clang warns on it over bools
    return (int(inA.mMin.x() <= inB.mMax.x()) & int(inB.mMin.x() <= inA.mMax.x()) &
            int(inA.mMin.y() <= inB.mMax.y()) & int(inB.mMin.y() <= inA.mMax.y()) &
            int(inA.mMin.z() <= inB.mMax.z()) & int(inB.mMin.z() <= inA.mMax.z())) != 0;
}

/// AABB::Contains without branches, for the same reason.
inline bool AABBContains(const AABB& inBox, const Vec3& inPoint)
{
    return (int(inBox.mMin.x() <= inPoint.x()) & int(inPoint.x() <= inBox.mMax.x()) &
            int(inBox.mMin.y() <= inPoint.y()) & int(inPoint.y() <= inBox.mMax.y()) &
            int(inBox.mMin.z() <= inPoint.z()) & int(inPoint.z() <= inBox.mMax.z())) != 0;
}

/// Closed-interval sphere-box test: the point of the box closest to the centre is within inRadius. The
/// squared distance is summed as (x + y) + z, the order of the quad tree's 4-wide node test, which decides a
/// tight slot alone: Eigen's squaredNorm sums in another order, and a body on the sphere's surface came out 1
/// ulp apart.
inline bool SphereOverlapsAABB(const Vec3& inCenter, float inRadius, const AABB& inBox)
{
    const Vec3 d = inCenter - inCenter.cwiseMax(inBox.mMin).cwiseMin(inBox.mMax);
    return (d.x() * d.x() + d.y() * d.y()) + d.z() * d.z() <= inRadius * inRadius;
}

/// Precomputed swept-box cast: the box centre is ray-cast against each body box grown by the box half extents
/// (Minkowski sum), so one slab test per body answers "where does the moving box first touch it".
struct SweptAABox
{
    /// Prepares the cast of inBox along inDisplacement.
    SweptAABox(const AABB& inBox, const Vec3& inDisplacement)
        : mCenter(inBox.Center()), mHalfExtent(inBox.HalfExtent()),
          mInvDisplacement(SafeReciprocal(inDisplacement))
    {
    }

    /// Entry fraction into inBody's box, or a value > inMaxFraction when missed.
    float EntryFraction(const AABB& inBody, float inMaxFraction) const
    {
        const AABB grown(inBody.mMin - mHalfExtent, inBody.mMax + mHalfExtent);
        return grown.RayEntryFraction(mCenter, mInvDisplacement, inMaxFraction);
    }

    Vec3 mCenter;          ///< Start of the ray: the box centre
    Vec3 mHalfExtent;      ///< Added around every body box
    Vec3 mInvDisplacement; ///< SafeReciprocal of the displacement
};

} // namespace cairn::physics
