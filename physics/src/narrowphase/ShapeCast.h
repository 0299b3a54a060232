#pragma once

// ShapeCast: where a shape translated along a displacement (its rotation fixed) first meets another shape,
// by conservative advancement over CollideShapes. Each manifold CollideShapes reports is a separating plane
// (its normal, from the moving shape A towards B) with the points' gaps along it: A can advance by
// gap / (displacement . normal) before that plane stops separating, because every point of a translated
// shape moves alike. The smallest such advance over the manifolds A approaches is safe against all of them,
// so the cast never passes through B, whatever the pair (convex, mesh, height field, compound), as far as the
// manifolds' points bound the gap. Where a pair's routine overstates it (a box's clipped face points can lie
// farther than its nearest corner) and an advance lands past the allowed depth (in any manifold, for a cast
// that starts clear of B), the cast bisects back to the touch between the last fraction clear of B and that
// one; an advance that overstated gap carries right through B is not caught. A manifold A does not approach
// (parallel or moving away) cannot stop it: a shape already overlapping B and leaving it, or sliding along
// it, is not stopped. Against a mesh or height field each triangle counts by its true nearest feature: no
// face normal at an internal edge (CollideSettings::mFaceNormalsAtInternalEdges), whose plane depth would
// stop a shape beside the triangle, not in it; the normal reported at a seam is the edge's.
// Used by the step's continuous collision (which lets a body sink a little before stopping it) and by the
// world's shape-cast queries (which stop at the touch). Pure function over immutable shapes: any thread.

#include "cairn/physics/narrowphase/ContactManifold.h"

#include <optional>

namespace cairn::physics
{

struct ShapeCastSettings
{
    /// A is stopped once it sinks this deep into B (metres, >= 0): 0 stops it at the touch.
    float mAllowedPenetration = 0.0f;
    /// The cast ends with the gap to the allowed depth within this (metres, > 0): the fraction it reports is
    /// at most this short of the exact one, along the normal.
    float mTolerance = 1.0e-4f;
    /// The cast ends, with no hit, past this fraction of the displacement (in (0, 1]): a search for the
    /// closest of several bodies passes the best fraction so far.
    float mMaxFraction = 1.0f;
    /// It stops after this many advances, where it is: short of B, never past it, and reported as a hit.
    int mMaxIterations = 32;
};

struct ShapeCastHit
{
    float mFraction = 0.0f;    ///< Along the displacement, in [0, 1)
    ContactManifold mManifold; ///< The manifold that stopped A, at that fraction (normal from A towards B)
    int mDeepestPoint = 0;     ///< The index of its point nearest the allowed depth
};

/// The tolerance of the world's shape-cast queries from inStart (metres): a tenth of a millimetre, and more
/// far from the origin, where a float step of the coordinates is larger than that and the contact depths are
/// only as exact as the coordinates.
inline float QueryCastTolerance(const Vec3& inStart)
{
    return 1.0e-4f + 1.0e-6f * inStart.cwiseAbs().maxCoeff();
}

/// The first fraction of inDisplacement at which inShapeA, translated from inStartA, sinks into inShapeB at
/// inTransformB by inSettings.mAllowedPenetration (to within the tolerance) while approaching it; nullopt
/// when it does not by inSettings.mMaxFraction. A zero displacement approaches nothing: its hits are the
/// manifolds within the tolerance of the allowed depth at the start, at fraction 0.
std::optional<ShapeCastHit> CastShapeAgainst(const Shape& inShapeA, const Transform& inStartA,
                                             const Vec3& inDisplacement, const Shape& inShapeB,
                                             const Transform& inTransformB,
                                             const ShapeCastSettings& inSettings);

} // namespace cairn::physics
