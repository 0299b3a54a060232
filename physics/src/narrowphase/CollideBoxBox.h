#pragma once

// Box against box with the separating axis test over the 15 candidate axes (3 face normals of each box and
// the 9 cross products of their edges). The axis of least penetration wins, with a bias towards face axes
// (A's faces first, then B's, then edges) so that a resting box does not flicker between equivalent axes.
// A face axis gives up to 4 points by clipping the incident face against the reference face; an edge axis
// gives the single pair of closest points of the two edges, unless it lies within about 8 degrees of the best
// face axis: there a face lies nearly flat on the other box, and the two faces most aligned with the edge
// axis are clipped along it, the edges' pair among their points. A face manifold never claims more clearance
// than its axis has (KeepTheContactGap).

#include "cairn/physics/narrowphase/CollideShapes.h"
#include "cairn/physics/shapes/BoxShape.h"

namespace cairn::physics
{

/// Which kind of axis the separating axis test picked.
enum class BoxBoxAxis : uint8_t
{
    FaceA, ///< A face normal of A: A's face is the reference for clipping
    FaceB, ///< A face normal of B: B's face is the reference
    Edge,  ///< The cross product of an edge of A and an edge of B: a single point
};

/// A face axis of B only wins over A's best face axis by more than this (metres).
inline constexpr float cBoxFaceBBias = 1.0e-4f;
/// An edge axis only wins over the best face axis by more than this (metres).
inline constexpr float cBoxEdgeBias = 5.0e-4f;
/// An edge axis whose cosine with the best face axis is at least this (about 8 degrees apart) is read through
/// the faces.
inline constexpr float cBoxEdgeAxisNearFaceCos = 0.99f;

/// Box A against box B. Returns false when further apart than inSettings.mMaxSeparation. outAxis (optional)
/// tells which axis kind was chosen.
bool CollideBoxBox(const BoxShape& inA, const Transform& inTransformA, const BoxShape& inB,
                   const Transform& inTransformB, const CollideSettings& inSettings,
                   ContactManifold& outManifold, BoxBoxAxis* outAxis = nullptr);

} // namespace cairn::physics
