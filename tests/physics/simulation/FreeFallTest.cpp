#include "SimulationFixture.h"

namespace cairn::test
{
using namespace cairn::physics;

using FreeFallTest = SimulationFixture;

// Symplectic Euler: v_n = -g n dt, y_n = y_0 - g dt^2 n (n + 1) / 2
TEST_F(FreeFallTest, MatchesClosedFormOfSymplecticEuler)
{
    BodyCreationSettings settings = DynamicSettings(Sphere(0.5f), Vec3(0, 10, 0));
    settings.mLinearDamping = 0.0f;
    const BodyID sphere = AddDynamic(settings);

    const int steps = 60;
    Step(steps);

    const double g = 9.81;
    const double dt = cDeltaTime;
    const double expectedY = 10.0 - g * dt * dt * steps * (steps + 1) / 2.0;
    EXPECT_NEAR(Position(sphere).y(), expectedY, 1.0e-4);
    EXPECT_NEAR(Velocity(sphere).y(), -g * dt * steps, 1.0e-4);
    EXPECT_FLOAT_EQ(Position(sphere).x(), 0.0f);
}

TEST_F(FreeFallTest, CollisionStepsSplitTheUpdate)
{
    BodyCreationSettings settings = DynamicSettings(Sphere(0.5f), Vec3(0, 10, 0));
    settings.mLinearDamping = 0.0f;
    const BodyID sphere = AddDynamic(settings);
    // 30 updates of 1/30 s in 2 collision steps each = 60 steps of 1/60 s
    for (int i = 0; i < 30; ++i)
        ASSERT_TRUE(UpdateWorld(2.0f * cDeltaTime, 2).IsOk());
    const double dt = cDeltaTime;
    EXPECT_NEAR(Position(sphere).y(), 10.0 - 9.81 * dt * dt * 60 * 61 / 2.0, 1.0e-4);
}

TEST_F(FreeFallTest, GravityFactorAndDampingApply)
{
    BodyCreationSettings floating = DynamicSettings(Sphere(0.5f), Vec3(0, 10, 0));
    floating.mGravityFactor = 0.0f;
    const BodyID still = AddDynamic(floating);
    BodyCreationSettings damped = DynamicSettings(Sphere(0.5f), Vec3(5, 10, 0));
    damped.mGravityFactor = 0.0f;
    damped.mLinearDamping = 1.0f;
    damped.mLinearVelocity = Vec3(1, 0, 0);
    const BodyID slowed = AddDynamic(damped);
    Step(60);
    EXPECT_FLOAT_EQ(Position(still).y(), 10.0f);
    // dv/dt = -v: after 1 s the speed is about 1/e
    EXPECT_NEAR(Velocity(slowed).x(), std::exp(-1.0f), 0.01f);
}

} // namespace cairn::test
