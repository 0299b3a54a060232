#pragma once

// CollideShapes: the narrow phase entry point. Dispatches a shape pair to the dedicated routine for that pair
// (sphere/box/capsule combinations, box-box SAT with clipping), GJK + EPA with face clipping for any other
// convex pair, convex against each triangle of a mesh or height field, and recursion into compounds.
// Pure function over immutable shapes: safe from any thread. No heap allocation.
//
// Conventions: the result does not depend on the argument order other than by the side it is seen from. A
// routine that only exists for (B, A) is called swapped and its manifold flipped (normal negated, points and
// sub-shape ids swapped). mNormal points from A towards B, mPenetration = dot(positionOnA - positionOnB,
// mNormal) (> 0 overlapping, < 0 speculative). Sub-shape ids: the triangle's mSubShape for a mesh or height
// field side, the child index for a compound side (for nested compounds, the outermost child index), 0 else.
// See CollideConvexTriangles.h for one-sided meshes and internal edges, ConvexContact.h for GJK/EPA.

#include "cairn/physics/narrowphase/ContactManifold.h"

namespace cairn::physics
{

struct CollideSettings
{
    /// Points separated by less than this still produce (speculative) contacts with negative penetration,
    /// which lets the solver stop fast bodies before they tunnel. Metres.
    float mMaxSeparation = 0.02f;
    /// A contact at a mesh's internal edge or vertex takes the triangle's face normal, with the depth below
    /// its plane (CollideConvexTriangles.h), so that bodies slide across seams. That depth is the plane's,
    /// which reaches beyond the triangle: a shape beside the triangle and below its plane gets a contact it
    /// is not in. Harmless within a speculative distance; a shape cast, which looks metres ahead, turns it
    /// off and takes each triangle's true nearest feature.
    bool mFaceNormalsAtInternalEdges = true;
    /// A shape cast's remaining displacement of A (world space), or zero. When set, a mesh's or height
    /// field's triangles are taken from A's bounds swept along it (grown by cSweptTriangleMargin) instead of
    /// A's bounds grown by mMaxSeparation all round: a cast looks that far ahead, not that far around.
    Vec3 mSweep = Vec3::Zero();
};

/// How far round A's swept bounds a shape cast takes triangles (metres): beyond any cast tolerance.
inline constexpr float cSweptTriangleMargin = 0.01f;

/// Collides shape A at inTransformA with shape B at inTransformB and reports every manifold with at least one
/// point whose penetration >= -inSettings.mMaxSeparation. Mesh/height-field pairs with each other produce
/// nothing (neither can move). Returns the number of manifolds reported.
int CollideShapes(const Shape& inShapeA, const Transform& inTransformA, const Shape& inShapeB,
                  const Transform& inTransformB, const CollideSettings& inSettings,
                  ManifoldVisitor inVisitor);

} // namespace cairn::physics
