// The swing-twist joint's angles (issue 33): a rotation split into a twist about x and a swing about an axis
// across it gives them back; the rotation vector takes the short way round; the elliptic cone's edge, inside
// and outside, and the direction out of it.

#include "constraints/SwingTwist.h"

#include <gtest/gtest.h>
#include <numbers>

namespace cairn::physics
{
namespace
{

TEST(SwingTwistTest, ASwingAfterATwistSplitsBackIntoThem)
{
    const Quat twist(Eigen::AngleAxisf(0.7f, Vec3::UnitX()));
    const Quat swing(Eigen::AngleAxisf(0.4f, Vec3(0.0f, 0.6f, 0.8f)));
    Quat outSwing, outTwist;
    SplitSwingTwist(swing * twist, outSwing, outTwist);
    EXPECT_NEAR(TwistAngle(outTwist), 0.7f, 1.0e-5f);
    EXPECT_LT((RotationVector(outSwing) - 0.4f * Vec3(0.0f, 0.6f, 0.8f)).norm(), 1.0e-5f);
    // A negative twist, and the same rotation as -q
    SplitSwingTwist(Quat(-(swing * twist.conjugate()).coeffs()), outSwing, outTwist);
    EXPECT_NEAR(TwistAngle(outTwist), -0.7f, 1.0e-5f);
    EXPECT_LT((RotationVector(outSwing) - 0.4f * Vec3(0.0f, 0.6f, 0.8f)).norm(), 1.0e-5f);
}

TEST(SwingTwistTest, TheRotationVectorTakesTheShortWayRound)
{
    const float almostRound = 350.0f * std::numbers::pi_v<float> / 180.0f;
    const Vec3 v = RotationVector(Quat(Eigen::AngleAxisf(almostRound, Vec3::UnitZ())));
    EXPECT_NEAR(v.z(), -10.0f * std::numbers::pi_v<float> / 180.0f, 1.0e-5f);
    EXPECT_LT(RotationVector(Quat::Identity()).norm(), 1.0e-9f);
    EXPECT_LT(
        (RotationVector(Quat(Eigen::AngleAxisf(1.0e-4f, Vec3::UnitY()))) - Vec3(0.0f, 1.0e-4f, 0.0f)).norm(),
        1.0e-9f);
}

TEST(SwingTwistTest, TheConeIsAnEllipseOfTheTwoHalfAngles)
{
    Vec3 direction;
    float error = 0.0f;
    // Half angles 0.5 about y (towards the normal), 0.2 about z (in the plane)
    EXPECT_FALSE(SwingPastCone(Vec3(0.0f, 0.49f, 0.0f), 0.5f, 0.2f, 0.0f, direction, error));
    EXPECT_FALSE(SwingPastCone(Vec3(0.0f, 0.0f, -0.19f), 0.5f, 0.2f, 0.0f, direction, error));
    EXPECT_FALSE(
        SwingPastCone(Vec3(0.0f, 0.3f, 0.1f), 0.5f, 0.2f, 0.0f, direction, error)); // 0.36 + 0.25 < 1
    ASSERT_TRUE(SwingPastCone(Vec3(0.0f, 0.0f, -0.3f), 0.5f, 0.2f, 0.0f, direction, error));
    EXPECT_LT((direction - Vec3(0.0f, 0.0f, -1.0f)).norm(), 1.0e-6f);
    EXPECT_NEAR(error, 0.1f, 1.0e-6f);
    ASSERT_TRUE(SwingPastCone(Vec3(0.0f, 0.4f, 0.2f), 0.5f, 0.2f, 0.0f, direction, error));
    EXPECT_GT(direction.z(), direction.y()); // The thin side's gradient is steeper
    EXPECT_GT(error, 0.0f);
    EXPECT_NEAR(direction.norm(), 1.0f, 1.0e-6f);
    // Within the band of the edge, inside: a row already, its error below zero (the gap left)
    ASSERT_TRUE(SwingPastCone(Vec3(0.0f, 0.0f, -0.19f), 0.5f, 0.2f, 0.02f, direction, error));
    EXPECT_NEAR(error, -0.01f, 1.0e-6f);
    EXPECT_FALSE(SwingPastCone(Vec3(0.0f, 0.0f, -0.17f), 0.5f, 0.2f, 0.02f, direction, error));
    // A zero half angle holds that swing at (nearly) nothing
    EXPECT_TRUE(SwingPastCone(Vec3(0.0f, 0.01f, 0.0f), 0.0f, 0.5f, 0.0f, direction, error));
    EXPECT_FALSE(SwingPastCone(Vec3(0.0f, 0.0f, 0.4f), 0.0f, 0.5f, 0.0f, direction, error));
}

} // namespace
} // namespace cairn::physics
