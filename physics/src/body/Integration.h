#pragma once

// Integration: symplectic Euler, the one place a step moves bodies. Its velocity half (forces, gravity,
// damping and the speed limits) runs first, on the bodies of each round of the contacts stage; its position
// half runs once the solver has the final velocities, from every path of the solve (islands, groups, colored
// islands, bodies alone, kinematic bodies). The position solver's corrections move poses through here too
// (CorrectPose), so no other code writes a body's pose during a step.
//
// Threads: the step's jobs, each on bodies of its own; the world inverse inertia kept per active body is
// written by the velocity half of that body's job and read by the narrow phase after the round's velocity
// loop has joined.

#include "cairn/physics/body/Body.h"
#include "cairn/physics/math/Math.h"

#include <cstdint>
#include <span>
#include <vector>

namespace cairn::physics
{

struct StepContext;

/// What a body's velocity half added to its velocities: gravity's and the forces' share of this step.
struct VelocityChange
{
    Vec3 mLinear;
    Vec3 mAngular;
};

class Integration
{
public:
    /// Before a round's velocities: room for the world inertia of active bodies [0, inNumActive).
    void BeginRound(size_t inNumActive) { mInverseInertia.resize(inNumActive); }
    /// The velocity half for the active-list entries inBodies (kinematic bodies only get their limits).
    void IntegrateVelocities(const StepContext& inContext, std::span<const uint32_t> inBodies);
    /// World inverse inertia of a body at the start of the step: zero unless dynamic.
    Mat3 InverseInertiaOf(const Body& inBody) const;
    /// The velocity change that gravity, force and torque gave inBody this step (damping and the limits left
    /// out): zero for a body that is not dynamic or was asleep at the velocity half.
    VelocityChange ForceVelocityChangeOf(const StepContext& inContext, const Body& inBody) const;

    /// The position half: uses the velocity after gravity and contacts.
    static void IntegratePositions(Body& ioBody, float inDeltaTime);
    /// The position solver's correction (a pseudo-impulse): moves the centre of mass by inTranslation and
    /// turns the body by the rotation vector inRotation, without touching its velocity.
    static void CorrectPose(Body& ioBody, const Vec3& inTranslation, const Vec3& inRotation);

private:
    std::vector<Mat3>
        mInverseInertia; ///< Per active dynamic body: world inverse inertia, from the velocities
};

} // namespace cairn::physics
