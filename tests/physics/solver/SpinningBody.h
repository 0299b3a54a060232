#pragma once

// A solver body of unit inverse mass turning at a given angular velocity, for the angular joint parts' tests.

#include "solver/SolverBody.h"

namespace cairn::physics
{

inline SolverBody Spinning(const Vec3& inAngularVelocity)
{
    SolverBody body;
    body.mLinearVelocity.setZero();
    body.mInverseMass = 1.0f;
    body.mAngularVelocity = inAngularVelocity;
    body.mPadding = 0.0f;
    return body;
}

} // namespace cairn::physics
