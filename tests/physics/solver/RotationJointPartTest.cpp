// The fixed joint's rotation rows (issue 33): one iteration stops the relative spin and keeps the angular
// momentum; the rotation error is the turn from the kept rotation to the body's, the short way round; a
// position iteration takes out the asked part of it.

#include "solver/RotationJointPart.h"

#include "physics/solver/SpinningBody.h"

#include <gtest/gtest.h>
#include <numbers>

namespace cairn::physics
{
namespace
{

TEST(RotationJointPartTest, OneIterationStopsTheRelativeSpinAndKeepsAngularMomentum)
{
    const Mat3 inertiaA = Vec3(2.0f, 3.0f, 4.0f).asDiagonal();
    const Mat3 rotation =
        Quat(Eigen::AngleAxisf(0.7f, Vec3(1.0f, 2.0f, 3.0f).normalized())).toRotationMatrix();
    const Mat3 inertiaB = rotation * Vec3(0.5f, 1.0f, 0.2f).asDiagonal() * rotation.transpose();
    SolverBody a = Spinning(Vec3(1.0f, -2.0f, 0.5f)), b = Spinning(Vec3(-3.0f, 1.0f, 2.0f));
    const Vec3 momentum = inertiaA * a.mAngularVelocity + inertiaB * b.mAngularVelocity;
    RotationJointPart part;
    part.Prepare({1.0f, inertiaA.inverse()}, {1.0f, inertiaB.inverse()});
    ASSERT_TRUE(part.IsActive());
    part.SolveVelocity(a, b);
    EXPECT_LT((b.mAngularVelocity - a.mAngularVelocity).norm(), 1.0e-4f);
    EXPECT_LT((inertiaA * a.mAngularVelocity + inertiaB * b.mAngularVelocity - momentum).norm(), 1.0e-4f);

    // Against the world (no inverse inertia): B stops turning, the world stays
    RotationJointPart toWorld;
    SolverBody world = Spinning(Vec3::Zero());
    toWorld.Prepare({}, {1.0f, inertiaB.inverse()});
    b = Spinning(Vec3(1.0f, 1.0f, 1.0f));
    toWorld.SolveVelocity(world, b);
    EXPECT_LT(b.mAngularVelocity.norm(), 1.0e-5f);
    EXPECT_EQ(world.mAngularVelocity, Vec3::Zero());
    // A heavy body's small inverse inertia is not a singular matrix
    RotationJointPart heavy;
    heavy.Prepare({}, {1.0e-4f, (1.0e-4f * Vec3(1.0f, 2.0f, 3.0f)).asDiagonal()});
    EXPECT_TRUE(heavy.IsActive());
    RotationJointPart none;
    none.Prepare({}, {});
    EXPECT_FALSE(none.IsActive());
}

TEST(RotationJointPartTest, TheErrorIsTheTurnFromTheKeptRotationTheShortWayRound)
{
    const Quat a(Eigen::AngleAxisf(0.4f, Vec3::UnitX()));
    const Quat relative(Eigen::AngleAxisf(1.1f, Vec3(0.0f, 1.0f, 1.0f).normalized()));
    EXPECT_LT(RotationJointPart::RotationError(a, a * relative, relative).norm(), 1.0e-6f);
    // B turned 0.3 rad about y (world) past where the joint keeps it
    const Quat turn(Eigen::AngleAxisf(0.3f, Vec3::UnitY()));
    EXPECT_LT(
        (RotationJointPart::RotationError(a, turn * a * relative, relative) - Vec3(0.0f, 0.3f, 0.0f)).norm(),
        1.0e-5f);
    // 350 degrees one way is 10 the other
    const float almostRound = 350.0f * std::numbers::pi_v<float> / 180.0f;
    const Vec3 error = RotationJointPart::RotationError(
        Quat::Identity(), Quat(Eigen::AngleAxisf(almostRound, Vec3::UnitZ())), Quat::Identity());
    EXPECT_LT((error - Vec3(0.0f, 0.0f, -10.0f * std::numbers::pi_v<float> / 180.0f)).norm(), 1.0e-5f);
}

TEST(RotationJointPartTest, APositionIterationTakesOutTheAskedPartOfTheError)
{
    const Mat3 inverseA = Vec3(0.5f, 0.25f, 1.0f).asDiagonal(),
               inverseB = Vec3(2.0f, 1.0f, 0.5f).asDiagonal();
    RotationJointPart part;
    part.Prepare({1.0f, inverseA}, {1.0f, inverseB});
    const Vec3 error(0.01f, -0.02f, 0.005f);
    const PointJointPart::PoseCorrection c = part.CorrectPositions(error, 0.2f);
    // B's turn less A's closes a fifth of the error (first order)
    EXPECT_LT((c.mRotationB - c.mRotationA + 0.2f * error).norm(), 1.0e-6f);
    EXPECT_TRUE(c.mTranslationA.isZero());
}

} // namespace
} // namespace cairn::physics
