// The hinge joint (issue 33): a velocity motor reaches its speed and a limit stops a door; equal limits hold
// an angle under load; a position motor follows the implicit spring step; a door opened and closed by motors
// set while the world runs, woken from sleep by a new one; friction slows a spin as its torque says.

#include "JointFixture.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace cairn::test
{
namespace
{

TEST_F(JointTest, AHingeMotorReachesItsSpeedAndALimitStopsTheDoor)
{
    // A wheel (a box turning about its own centre, so gravity gives no torque) on a hinge to the world with
    // a velocity motor: it spins up to the target within the motor's torque
    const float target = 2.0f;
    const BodyID wheel = AddWheel(0.0f);
    HingeConstraintSettings motor;
    motor.mBodyB = wheel;
    motor.mPoint = Vec3(0.0f, 3.0f, 0.0f);
    motor.mHingeAxis = Vec3(0.0f, 0.0f, 1.0f);
    motor.mMotor.mMode = MotorMode::Velocity;
    motor.mMotor.mTargetVelocity = target;
    motor.mMotor.mMaxForce = 500.0f;
    ASSERT_TRUE(Joints().AddHinge(motor).IsOk());
    Step(60);
    const Vec3 spin = Bodies().GetAngularVelocity(wheel).Value();
    EXPECT_NEAR(spin.z(), target, 0.05f * target);    // The 5 %
    EXPECT_LT(std::hypot(spin.x(), spin.y()), 0.01f); // About its axis only
    EXPECT_LT((Position(wheel) - Vec3(0.0f, 3.0f, 0.0f)).norm(), 0.005f);

    // A door hinged at its edge on a vertical axis, pushed open fast: the limit at 0.5 rad stops it there,
    // and the door keeps to its axis under gravity
    ResetWorld(PhysicsSettings{});
    BodyCreationSettings doorSettings = DynamicSettings(Box(Vec3(0.5f, 1.0f, 0.05f)), Vec3(0.5f, 1.2f, 0.0f));
    doorSettings.mAngularVelocity = Vec3(0.0f, 3.0f, 0.0f);
    doorSettings.mLinearVelocity = Vec3(0.0f, 0.0f, -1.5f); // The hinge edge at rest
    doorSettings.mAllowSleeping = false;
    const BodyID door = AddDynamic(doorSettings);
    HingeConstraintSettings hinge;
    hinge.mBodyB = door;
    hinge.mPoint = Vec3(0.0f, 1.2f, 0.0f);
    hinge.mHingeAxis = Vec3(0.0f, 1.0f, 0.0f);
    hinge.mLimitsMin = -0.5f;
    hinge.mLimitsMax = 0.5f;
    ASSERT_TRUE(Joints().AddHinge(hinge).IsOk());
    float widest = 0.0f, tilt = 0.0f;
    for (int step = 0; step < 90; ++step)
    {
        Step(1);
        const Quat rotation = Bodies().GetRotation(door).Value();
        const Vec3 across = rotation * Vec3::UnitX();
        widest = std::max(widest, std::abs(std::atan2(-across.z(), across.x())));
        tilt = std::max(tilt, std::acos(std::clamp((rotation * Vec3::UnitY()).y(), -1.0f, 1.0f)));
    }
    // The limit's row starts once the angle is past it: one step's travel at 3 rad/s (0.05 rad) at most, and
    // 3 s of 3 rad/s would be far past it
    EXPECT_LT(widest, 0.5f + 3.0f / 60.0f);
    EXPECT_GT(widest, 0.45f); // It did swing to the limit
    EXPECT_LT(tilt, 1.0f * std::numbers::pi_v<float> / 180.0f);
}

TEST_F(JointTest, AHingeWithEqualLimitsTurnsToThatAngleAndHoldsItUnderLoad)
{
    // A beam hinged at its end on a horizontal axis, its limits both 0.3 rad from where it is made: the
    // position pass turns it there and the row holds it against gravity's torque, as a fixed joint would
    BodyCreationSettings beamSettings =
        DynamicSettings(Box(Vec3(0.5f, 0.05f, 0.05f)), Vec3(0.5f, 3.0f, 0.0f));
    beamSettings.mAllowSleeping = false; // The position pass turns it with no speed: it would look at rest
    const BodyID beam = AddDynamic(beamSettings);
    HingeConstraintSettings hinge;
    hinge.mBodyB = beam;
    hinge.mPoint = Vec3(0.0f, 3.0f, 0.0f);
    hinge.mHingeAxis = Vec3(0.0f, 0.0f, 1.0f);
    hinge.mLimitsMin = hinge.mLimitsMax = 0.3f;
    ASSERT_TRUE(Joints().AddHinge(hinge).IsOk());
    Step(120);
    const Vec3 along = Bodies().GetRotation(beam).Value() * Vec3::UnitX();
    EXPECT_NEAR(std::atan2(along.y(), along.x()), 0.3f, 0.01f); // Raised 0.3 rad, not sagging
    EXPECT_LT(Bodies().GetAngularVelocity(beam).Value().norm(), 0.01f);
}

TEST_F(JointTest, AHingePositionMotorFollowsTheImplicitSpringStep)
{
    // A wheel turning about its own centre (no other row pulls on its spin) driven to 1 rad by a position
    // motor: each step its spin is the implicit Euler step of the spring, v' = (v - h w^2 C) / (1 + 2 z h w +
    // h^2 w^2), and its angle C' = C + h v' (relative to the target), whatever its inertia
    const BodyID wheel = AddWheel(0.0f);
    HingeConstraintSettings hinge;
    hinge.mBodyB = wheel;
    hinge.mPoint = Vec3(0.0f, 3.0f, 0.0f);
    hinge.mHingeAxis = Vec3(0.0f, 0.0f, 1.0f);
    hinge.mMotor.mMode = MotorMode::Position;
    hinge.mMotor.mTargetPosition = 1.0f;
    hinge.mMotor.mMaxForce = 1.0e6f; // Never reached: the spring alone
    hinge.mMotor.mSpring = {2.0f, 0.7f};
    const Result<ConstraintID> id = Joints().AddHinge(hinge);
    ASSERT_TRUE(id.IsOk());
    const float h = 1.0f / 60.0f, omega = 2.0f * std::numbers::pi_v<float> * 2.0f, zeta = 0.7f;
    float error = -1.0f, spin = 0.0f, worst = 0.0f;
    for (int step = 0; step < 120; ++step)
    {
        Step(1);
        spin = (spin - h * omega * omega * error) / (1.0f + 2.0f * zeta * h * omega + h * h * omega * omega);
        error += h * spin;
        worst = std::max(worst, std::abs(Joints().GetPosition(id.Value()).Value() - (1.0f + error)));
    }
    EXPECT_LT(worst, 0.002f);
    EXPECT_NEAR(Joints().GetPosition(id.Value()).Value(), 1.0f, 0.01f); // There after 2 s
}

TEST_F(JointTest, ADoorOpensAndClosesAsItsMotorIsToldWhileTheWorldRuns)
{
    // A door hinged at its edge on a vertical axis, limits 0 to 1.6 rad: a velocity motor opens it, then
    // (from outside the step) a position motor closes it; asleep once shut, a new motor wakes it
    BodyCreationSettings doorSettings = DynamicSettings(Box(Vec3(0.5f, 1.0f, 0.05f)), Vec3(0.5f, 1.2f, 0.0f));
    doorSettings.mAngularDamping = 0.0f;
    const BodyID door = AddDynamic(doorSettings);
    HingeConstraintSettings hinge;
    hinge.mBodyB = door;
    hinge.mPoint = Vec3(0.0f, 1.2f, 0.0f);
    hinge.mHingeAxis = Vec3(0.0f, 1.0f, 0.0f);
    hinge.mLimitsMin = 0.0f;
    hinge.mLimitsMax = 1.6f;
    hinge.mMotor = {MotorMode::Velocity, 1.0f, 0.0f, 2000.0f, {}};
    const Result<ConstraintID> id = Joints().AddHinge(hinge);
    ASSERT_TRUE(id.IsOk());
    Step(60);
    EXPECT_NEAR(Joints().GetPosition(id.Value()).Value(), 1.0f, 0.05f); // A second at 1 rad/s
    ASSERT_TRUE(
        Joints().SetMotor(id.Value(), {MotorMode::Position, 0.0f, 0.0f, 2000.0f, {1.5f, 1.0f}}).IsOk());
    Step(180);
    EXPECT_LT(std::abs(Joints().GetPosition(id.Value()).Value()), 0.02f);
    // The position rows read the same angle as the door's own rotation: its face turned about y
    const Vec3 across = Bodies().GetRotation(door).Value() * Vec3::UnitX();
    EXPECT_NEAR(Joints().GetPosition(id.Value()).Value(), std::atan2(-across.z(), across.x()), 1.0e-4f);

    // Motor off: it falls asleep shut; told to open, it wakes and opens
    ASSERT_TRUE(Joints().SetMotor(id.Value(), {}).IsOk());
    for (int step = 0; step < 600 && Bodies().IsActive(door).Value(); ++step)
        Step(1);
    ASSERT_FALSE(Bodies().IsActive(door).Value());
    ASSERT_TRUE(Joints().SetMotor(id.Value(), {MotorMode::Velocity, 1.0f, 0.0f, 2000.0f, {}}).IsOk());
    Step(30);
    EXPECT_GT(Joints().GetPosition(id.Value()).Value(), 0.4f);
}

TEST_F(JointTest, HingeFrictionSlowsASpinAsItsTorqueSays)
{
    // A spinning wheel on a hinge with friction torque T and no motor: its spin drops by T t / I
    const BodyID wheel = AddWheel(5.0f);
    HingeConstraintSettings hinge;
    hinge.mBodyB = wheel;
    hinge.mPoint = Vec3(0.0f, 3.0f, 0.0f);
    hinge.mHingeAxis = Vec3(0.0f, 0.0f, 1.0f);
    hinge.mMaxFrictionTorque = 20.0f;
    ASSERT_TRUE(Joints().AddHinge(hinge).IsOk());
    Step(30);
    // A box of 1 x 1 x 0.2 m at 1000 kg/m^3: 200 kg, I about z = m (1 + 1) / 12
    const float inertia = 200.0f * 2.0f / 12.0f;
    EXPECT_NEAR(Bodies().GetAngularVelocity(wheel).Value().z(), 5.0f - 20.0f * 0.5f / inertia, 0.02f);
}

} // namespace
} // namespace cairn::test
