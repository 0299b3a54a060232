#pragma once

// Sphere against capsule: the closest point of the capsule's segment to the sphere centre turns it into a
// ball-ball contact.

#include "cairn/physics/narrowphase/CollideShapes.h"
#include "cairn/physics/shapes/CapsuleShape.h"
#include "cairn/physics/shapes/SphereShape.h"

namespace cairn::physics
{

/// Sphere A against capsule B. Returns false when further apart than inSettings.mMaxSeparation.
bool CollideSphereCapsule(const SphereShape& inA, const Transform& inTransformA, const CapsuleShape& inB,
                          const Transform& inTransformB, const CollideSettings& inSettings,
                          ContactManifold& outManifold);

} // namespace cairn::physics
