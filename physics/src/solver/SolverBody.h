#pragma once

// A body's velocities as the velocity solver sees them, packed into one 32-byte block: an impulse reads and
// writes one cache line per body, where through Body it touched three (velocities, inverse mass, motion
// type). Filled from the bodies before an island is solved and written back after; owned by the step's
// scratch, each block written only by the thread solving the island it belongs to.

#include "cairn/physics/math/Math.h"

namespace cairn::physics
{

struct alignas(32) SolverBody
{
    Vec3 mLinearVelocity;
    float mInverseMass; ///< 0 for static and kinematic bodies: impulses leave them as they are
    Vec3 mAngularVelocity;
    float mPadding;
};

} // namespace cairn::physics
