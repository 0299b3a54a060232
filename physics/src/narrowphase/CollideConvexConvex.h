#pragma once

// The generic convex pair: GJK/EPA (FindConvexContact) gives the normal and the deepest point, then the two
// supporting faces (ConvexShape::GetSupportingFace along the normal) are clipped against each other to give a
// manifold of up to 4 points; when the faces give nothing (a vertex or a round part), the single GJK/EPA
// point is used.

#include "cairn/physics/narrowphase/CollideShapes.h"
#include "narrowphase/ConvexContact.h"

namespace cairn::physics
{

/// Builds the manifold along inContact.mNormal from the supporting faces of A and B; falls back to the single
/// contact point. Always succeeds (at least one point).
void ManifoldFromContact(const ConvexShape& inA, const Transform& inTransformA, const ConvexShape& inB,
                         const Transform& inTransformB, const ConvexContact& inContact, float inMaxSeparation,
                         ContactManifold& outManifold);

/// Collides any two convex shapes with GJK/EPA and face clipping. Returns false when further apart than
/// inSettings.mMaxSeparation.
bool CollideConvexConvex(const ConvexShape& inA, const Transform& inTransformA, const ConvexShape& inB,
                         const Transform& inTransformB, const CollideSettings& inSettings,
                         ContactManifold& outManifold);

} // namespace cairn::physics
