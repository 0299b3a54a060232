// Breaking joints (issue 33): a joint holding more force or torque than its threshold is disabled at the
// step's end and reported once, with what it held; one under its threshold holds; a broken joint enabled
// again mends; bad thresholds are refused.

#include "JointFixture.h"

#include <cmath>
#include <limits>

namespace cairn::test
{
namespace
{

TEST_F(JointTest, AJointHoldingMoreThanItsThresholdBreaksOnceAndSaysWhatItHeld)
{
    // Two 4.19 kg balls (r 0.1 m) hanging from points of the world: each joint holds m g = 41.1 N. The first
    // may hold 0.8 m g, the second 1.2 m g
    const float weight = 1000.0f * 4.0f / 3.0f * std::numbers::pi_v<float> * 0.001f * 9.81f;
    BodyID balls[2];
    ConstraintID joints[2];
    for (int i = 0; i < 2; ++i)
    {
        BodyCreationSettings settings = DynamicSettings(Sphere(0.1f), Vec3(2.0f * float(i), 3.0f, 0.0f));
        settings.mAllowSleeping = false;
        balls[i] = AddDynamic(settings);
        PointConstraintSettings joint;
        joint.mBodyB = balls[i];
        joint.mPoint = Vec3(2.0f * float(i), 3.1f, 0.0f);
        joints[i] = Joints().AddPoint(joint).Value();
        ASSERT_TRUE(
            Joints().SetBreakThresholds(joints[i], (i == 0 ? 0.8f : 1.2f) * weight, cLargeFloat).IsOk());
    }
    Step(1);
    const std::vector<BrokenConstraint> broken = Joints().TakeBrokenConstraints().Value();
    ASSERT_EQ(broken.size(), 1u);
    EXPECT_EQ(broken[0].mID, joints[0]);
    EXPECT_NEAR(broken[0].mForce, weight, 0.05f * weight); // What it held that step: the ball's weight
    EXPECT_FALSE(Joints().IsEnabled(joints[0]).Value());
    Step(30);
    EXPECT_LT(Position(balls[0]).y(), 2.0f);                       // Fell half a second
    EXPECT_NEAR(Position(balls[1]).y(), 3.0f, 0.002f);             // Held
    EXPECT_TRUE(Joints().TakeBrokenConstraints().Value().empty()); // Reported once

    // A weld whose torque gives: a 1 m beam (0.1 x 0.1 m, 10 kg) welded at its end holds m g L / 2
    ResetWorld(PhysicsSettings{});
    BodyCreationSettings beamSettings =
        DynamicSettings(Box(Vec3(0.5f, 0.05f, 0.05f)), Vec3(0.5f, 3.0f, 0.0f));
    beamSettings.mAllowSleeping = false;
    const BodyID beam = AddDynamic(beamSettings);
    FixedConstraintSettings weld;
    weld.mBodyB = beam;
    weld.mPoint = Vec3(0.0f, 3.0f, 0.0f);
    const ConstraintID welded = Joints().AddFixed(weld).Value();
    const float torque = 10.0f * 9.81f * 0.5f;
    ASSERT_TRUE(Joints().SetBreakThresholds(welded, cLargeFloat, 0.9f * torque).IsOk());
    Step(1);
    const std::vector<BrokenConstraint> snapped = Joints().TakeBrokenConstraints().Value();
    ASSERT_EQ(snapped.size(), 1u);
    EXPECT_NEAR(snapped[0].mTorque, torque, 0.1f * torque);

    // Enabled again with a threshold it can meet: it holds the beam where it is
    ASSERT_TRUE(Joints().SetBreakThresholds(welded, cLargeFloat, 2.0f * torque).IsOk());
    ASSERT_TRUE(Joints().SetEnabled(welded, true).IsOk());
    const Vec3 before = Position(beam);
    Step(30);
    EXPECT_LT((Position(beam) - before).norm(), 0.01f);
    EXPECT_TRUE(Joints().TakeBrokenConstraints().Value().empty());
}

TEST_F(JointTest, BadBreakThresholdsAreRefused)
{
    const BodyID ball = AddDynamic(DynamicSettings(Sphere(0.1f), Vec3(0.0f, 3.0f, 0.0f)));
    PointConstraintSettings settings;
    settings.mBodyB = ball;
    settings.mPoint = Vec3(0.0f, 3.1f, 0.0f);
    const ConstraintID joint = Joints().AddPoint(settings).Value();
    EXPECT_EQ(Joints().SetBreakThresholds(joint, -1.0f, 1.0f).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_EQ(Joints().SetBreakThresholds(joint, 1.0f, std::nanf("")).GetError().mCode,
              ErrorCode::InvalidArgument);
    EXPECT_TRUE(Joints().SetBreakThresholds(joint, std::numeric_limits<float>::infinity(), 0.0f).IsOk());
    ASSERT_TRUE(Joints().Remove(joint).IsOk());
    EXPECT_EQ(Joints().SetBreakThresholds(joint, 1.0f, 1.0f).GetError().mCode, ErrorCode::InvalidArgument);
}

} // namespace
} // namespace cairn::test
