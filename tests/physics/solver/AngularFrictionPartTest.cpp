// The swing-twist joint's friction block (issue 33): within its bound one iteration stops the relative spin
// and keeps the angular momentum; past it the impulse about each of A's frame axes is the bound, in the
// frame's axes and not the world's; the warm start applies the kept impulse, clamped to a new bound.

#include "solver/AngularFrictionPart.h"

#include "physics/solver/SpinningBody.h"

#include <gtest/gtest.h>
#include <numbers>

namespace cairn::physics
{
namespace
{

const Mat3 cInertiaA = Vec3(2.0f, 3.0f, 4.0f).asDiagonal();
const Mat3 cInertiaB = Vec3(0.5f, 1.0f, 0.2f).asDiagonal();

Mat3 TiltedFrame()
{
    return Quat(Eigen::AngleAxisf(0.7f, Vec3(1.0f, 2.0f, 3.0f).normalized())).toRotationMatrix();
}

TEST(AngularFrictionPartTest, WithinItsBoundOneIterationStopsTheRelativeSpinAndKeepsAngularMomentum)
{
    SolverBody a = Spinning(Vec3(0.1f, -0.2f, 0.05f)), b = Spinning(Vec3(-0.3f, 0.1f, 0.2f));
    const Vec3 momentum = cInertiaA * a.mAngularVelocity + cInertiaB * b.mAngularVelocity;
    AngularFrictionPart part;
    part.Prepare({1.0f, cInertiaA.inverse()}, {1.0f, cInertiaB.inverse()}, TiltedFrame(), 100.0f);
    ASSERT_TRUE(part.IsActive());
    part.SolveVelocity(a, b);
    EXPECT_LT((b.mAngularVelocity - a.mAngularVelocity).norm(), 1.0e-5f);
    EXPECT_LT((cInertiaA * a.mAngularVelocity + cInertiaB * b.mAngularVelocity - momentum).norm(), 1.0e-5f);
    // The impulse kept is the one that stopped the spin, in the frame's axes
    const Vec3 worldImpulse = TiltedFrame() * part.GetTotalImpulse();
    EXPECT_LT((cInertiaB * (b.mAngularVelocity - Vec3(-0.3f, 0.1f, 0.2f)) - worldImpulse).norm(), 1.0e-5f);

    // No bound, or nothing that can turn: no row
    AngularFrictionPart off;
    off.Prepare({1.0f, cInertiaA.inverse()}, {1.0f, cInertiaB.inverse()}, TiltedFrame(), 0.0f);
    EXPECT_FALSE(off.IsActive());
    off.Prepare({}, {}, TiltedFrame(), 1.0f);
    EXPECT_FALSE(off.IsActive());
}

TEST(AngularFrictionPartTest, PastItsBoundTheImpulseAboutEachFrameAxisIsTheBound)
{
    // B alone (A the world) spins fast about the world's x axis; the frame is turned 45 degrees about z, so
    // the spin has a part along the frame's x and y axes and none along z
    const float bound = 0.01f;
    const Mat3 frame =
        Quat(Eigen::AngleAxisf(0.25f * std::numbers::pi_v<float>, Vec3::UnitZ())).toRotationMatrix();
    const Mat3 isotropic = Mat3::Identity() * 0.5f; // Inertia 0.5 about every axis
    SolverBody world = Spinning(Vec3::Zero()), b = Spinning(Vec3(10.0f, 0.0f, 0.0f));
    AngularFrictionPart part;
    part.Prepare({}, {1.0f, isotropic.inverse()}, frame, bound);
    ASSERT_TRUE(part.IsActive());
    part.SolveVelocity(world, b);
    // Each frame axis with spin took the whole bound against it; the frame's z none
    EXPECT_NEAR(part.GetTotalImpulse().x(), -bound, 1.0e-7f);
    EXPECT_NEAR(part.GetTotalImpulse().y(), bound, 1.0e-7f); // The frame's y is (-1, 1, 0) / sqrt 2
    EXPECT_NEAR(part.GetTotalImpulse().z(), 0.0f, 1.0e-7f);
    // In the world: sqrt 2 times the bound against the spin about x (a box in the frame, not a ball)
    const Vec3 expected = Vec3(10.0f - std::sqrt(2.0f) * bound / 0.5f, 0.0f, 0.0f);
    EXPECT_LT((b.mAngularVelocity - expected).norm(), 1.0e-5f);
    EXPECT_EQ(world.mAngularVelocity, Vec3::Zero());
    // Another iteration adds nothing: the bound is spent
    const Vec3 before = b.mAngularVelocity;
    part.SolveVelocity(world, b);
    EXPECT_LT((b.mAngularVelocity - before).norm(), 1.0e-6f);
}

TEST(AngularFrictionPartTest, TheWarmStartAppliesTheKeptImpulseWithinTheNewBound)
{
    const Mat3 isotropic = Mat3::Identity();
    SolverBody world = Spinning(Vec3::Zero()), b = Spinning(Vec3(0.0f, 0.0f, 5.0f));
    AngularFrictionPart part;
    part.Prepare({}, {1.0f, isotropic}, Mat3::Identity(), 0.5f);
    part.SolveVelocity(world, b);
    ASSERT_NEAR(part.GetTotalImpulse().z(), -0.5f, 1.0e-6f);
    // The next step's bound is smaller: the kept impulse is cut to it before it is applied
    part.Prepare({}, {1.0f, isotropic}, Mat3::Identity(), 0.2f);
    b = Spinning(Vec3(0.0f, 0.0f, 5.0f));
    part.WarmStart(world, b);
    EXPECT_NEAR(b.mAngularVelocity.z(), 4.8f, 1.0e-6f);
    // Half of it, then none after a Deactivate
    b = Spinning(Vec3(0.0f, 0.0f, 5.0f));
    part.WarmStart(world, b, 0.5f);
    EXPECT_NEAR(b.mAngularVelocity.z(), 4.9f, 1.0e-6f);
    part.Deactivate();
    EXPECT_EQ(part.GetTotalImpulse(), Vec3::Zero());
}

} // namespace
} // namespace cairn::physics
