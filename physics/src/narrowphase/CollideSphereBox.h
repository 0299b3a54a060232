#pragma once

// Sphere against box, in the box's local frame: the clamped centre is the closest box point. A centre inside
// the box is pushed out through the face with the least penetration.

#include "cairn/physics/narrowphase/CollideShapes.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/SphereShape.h"

namespace cairn::physics
{

/// Sphere A against box B. Returns false when further apart than inSettings.mMaxSeparation.
bool CollideSphereBox(const SphereShape& inA, const Transform& inTransformA, const BoxShape& inB,
                      const Transform& inTransformB, const CollideSettings& inSettings,
                      ContactManifold& outManifold);

} // namespace cairn::physics
