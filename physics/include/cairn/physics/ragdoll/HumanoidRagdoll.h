#pragma once

// A standard humanoid ragdoll description: 23 capsule and sphere parts (pelvis, four spine parts, neck, head,
// and per side a clavicle, upper arm, forearm, hand, thigh, shin, foot and toes) joined by swing-twist joints
// with human ranges, standing on its feet at the origin, facing +z. For tests, benchmarks and the demo, and
// as a template for a game's own skeletons: 160 of them make the ragdoll scene of about 3,700 bodies.
//
// Threads: any; it only builds a description.

#include "cairn/physics/ragdoll/Ragdoll.h"

namespace cairn::physics
{

/// The description for a humanoid of inHeight metres (within [0.5, 3]: clamped). Bodies in the moving layer
/// at a density of 1000 kg/m^3; touching parts kept from colliding (DisableCollisionsOfTouchingParts).
RagdollSettings MakeHumanoidRagdoll(float inHeight = 1.8f);

} // namespace cairn::physics
