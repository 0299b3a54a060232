// A joint's limit rows (issue 33): which limit a value is at, past or near; and a limit not reached yet lets
// the bodies close the gap in one step and no more (speculative), while one passed stops their speed into it.

#include "solver/AxisJointPart.h"

#include <gtest/gtest.h>

namespace cairn::physics
{
namespace
{

TEST(AxisJointPartTest, ARowStartsPastALimitOrWithinItsBand)
{
    AxisJointPart::Side side;
    float error = 0.0f;
    EXPECT_FALSE(AxisJointPart::LimitRow(0.5f, 0.0f, 1.0f, 0.01f, side, error));
    ASSERT_TRUE(AxisJointPart::LimitRow(1.2f, 0.0f, 1.0f, 0.01f, side, error)); // Past the upper
    EXPECT_EQ(side, AxisJointPart::Side::Negative);
    EXPECT_NEAR(error, 0.2f, 1.0e-6f);
    ASSERT_TRUE(AxisJointPart::LimitRow(0.995f, 0.0f, 1.0f, 0.01f, side, error)); // Near it
    EXPECT_EQ(side, AxisJointPart::Side::Negative);
    EXPECT_NEAR(error, -0.005f, 1.0e-6f);
    ASSERT_TRUE(AxisJointPart::LimitRow(0.004f, 0.0f, 1.0f, 0.01f, side, error)); // Near the lower
    EXPECT_EQ(side, AxisJointPart::Side::Positive);
    EXPECT_NEAR(error, 0.004f, 1.0e-6f);
    ASSERT_TRUE(AxisJointPart::LimitRow(0.3f, 0.2f, 0.2f, 0.01f, side, error)); // Equal limits: held
    EXPECT_EQ(side, AxisJointPart::Side::Both);
    // A range narrower than two bands: the nearer limit
    ASSERT_TRUE(AxisJointPart::LimitRow(0.004f, 0.0f, 0.01f, 0.01f, side, error));
    EXPECT_EQ(side, AxisJointPart::Side::Positive);
}

SolverBody Moving(float inInverseMass, const Vec3& inVelocity)
{
    SolverBody body;
    body.mLinearVelocity = inVelocity;
    body.mInverseMass = inInverseMass;
    body.mAngularVelocity.setZero();
    body.mPadding = 0.0f;
    return body;
}

TEST(AxisJointPartTest, ALimitNotReachedLetsTheGapCloseInOneStepAndNoMore)
{
    // B 5 mm short of its upper limit along x, moving at 3 m/s into it, steps of 1/60 s: it may go 0.3 m/s
    const float h = 1.0f / 60.0f;
    const JointBodyMass world, b{1.0f, Mat3::Identity()};
    SolverBody fixed = Moving(0.0f, Vec3::Zero()), body = Moving(1.0f, Vec3(3.0f, 0.0f, 0.0f));
    AxisJointPart limit;
    limit.Prepare(Vec3::Zero(), world, Vec3::Zero(), b, Vec3::UnitX(), -0.005f, AxisJointPart::Side::Negative,
                  0.0f, 0.0f, h);
    limit.SolveVelocity(fixed, body);
    EXPECT_NEAR(body.mLinearVelocity.x(), 0.005f / h, 1.0e-4f);
    // Moving away from it: the row leaves it alone (it only pulls back)
    body = Moving(1.0f, Vec3(-1.0f, 0.0f, 0.0f));
    limit.ResetImpulse(); // A new step's row, with nothing accumulated
    limit.Prepare(Vec3::Zero(), world, Vec3::Zero(), b, Vec3::UnitX(), -0.005f, AxisJointPart::Side::Negative,
                  0.0f, 0.0f, h);
    limit.SolveVelocity(fixed, body);
    EXPECT_FLOAT_EQ(body.mLinearVelocity.x(), -1.0f);
    // Past it: no speed further in (the position pass takes the rest out)
    body = Moving(1.0f, Vec3(3.0f, 0.0f, 0.0f));
    limit.ResetImpulse();
    limit.Prepare(Vec3::Zero(), world, Vec3::Zero(), b, Vec3::UnitX(), 0.02f, AxisJointPart::Side::Negative,
                  0.0f, 0.0f, h);
    limit.SolveVelocity(fixed, body);
    EXPECT_NEAR(body.mLinearVelocity.x(), 0.0f, 1.0e-5f);
}

} // namespace
} // namespace cairn::physics
