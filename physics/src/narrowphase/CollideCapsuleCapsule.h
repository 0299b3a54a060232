#pragma once

// Capsule against capsule: closest points of the two inner segments, then a ball-ball contact. Nearly
// parallel capsules whose segments overlap along their axes get two points (the ends of the overlap) so that
// a capsule lying on another does not rock about a single point.

#include "cairn/physics/narrowphase/CollideShapes.h"
#include "cairn/physics/shapes/CapsuleShape.h"

namespace cairn::physics
{

/// Capsule A against capsule B. Returns false when further apart than inSettings.mMaxSeparation.
bool CollideCapsuleCapsule(const CapsuleShape& inA, const Transform& inTransformA, const CapsuleShape& inB,
                           const Transform& inTransformB, const CollideSettings& inSettings,
                           ContactManifold& outManifold);

} // namespace cairn::physics
