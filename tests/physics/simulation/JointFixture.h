#pragma once

// The joint tests' fixture (issue 33): the simulation fixture with the constraint interface at hand. Outside
// an anonymous namespace: the suites of several files share it (a gtest suite has one fixture type).

#include "SimulationFixture.h"

namespace cairn::test
{

class JointTest : public SimulationFixture
{
protected:
    ConstraintInterface& Joints() { return System().GetConstraintInterface(); }
    /// A 200 kg box wheel (1 x 1 x 0.2 m) at (0, 3, 0) spinning about z at inSpin, kept awake, its spin
    /// undamped
    BodyID AddWheel(float inSpin)
    {
        BodyCreationSettings settings = DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.1f)), Vec3(0.0f, 3.0f, 0.0f));
        settings.mAngularDamping = 0.0f;
        settings.mAngularVelocity = Vec3(0.0f, 0.0f, inSpin);
        settings.mAllowSleeping = false;
        return AddDynamic(settings);
    }
};

} // namespace cairn::test
