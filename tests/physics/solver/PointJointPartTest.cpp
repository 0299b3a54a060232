// The point joint's rows (issue 33's ball and socket), against what they must do whatever the bodies: the two
// anchors move together after one velocity iteration, momentum is kept, a side that cannot move is left as
// it is, the warm start gives back the step's impulse, and the position rows close the asked part of a gap.

#include "solver/PointJointPart.h"

#include <gtest/gtest.h>
#include <random>

namespace cairn::physics
{
namespace
{

/// A block at rest (SolverBody's Eigen members start uninitialised)
SolverBody AtRest()
{
    SolverBody body;
    body.mLinearVelocity.setZero();
    body.mInverseMass = 0.0f;
    body.mAngularVelocity.setZero();
    body.mPadding = 0.0f;
    return body;
}

struct JointedBody
{
    float mMass = 1.0f;
    Mat3 mInertia = Mat3::Identity(); ///< World space
    Vec3 mPosition = Vec3::Zero();
    SolverBody mVelocity = AtRest();

    JointBodyMass Mass() const { return {1.0f / mMass, mInertia.inverse()}; }
    Vec3 Momentum() const { return mMass * mVelocity.mLinearVelocity; }
    /// About inPoint
    Vec3 AngularMomentum(const Vec3& inPoint) const
    {
        return (mPosition - inPoint).cross(Momentum()) + mInertia * mVelocity.mAngularVelocity;
    }
};

/// A body of random mass, shape (a box's inertia), orientation, place and velocity.
JointedBody RandomBody(std::mt19937& ioRandom)
{
    std::uniform_real_distribution<float> mass(0.1f, 50.0f), size(0.1f, 3.0f), unit(-1.0f, 1.0f);
    JointedBody body;
    body.mMass = mass(ioRandom);
    const Vec3 extent(size(ioRandom), size(ioRandom), size(ioRandom));
    const Vec3 squares = extent.cwiseProduct(extent);
    const Vec3 diagonal =
        body.mMass / 12.0f *
        Vec3(squares.y() + squares.z(), squares.x() + squares.z(), squares.x() + squares.y());
    const Mat3 rotation = Quat(unit(ioRandom), unit(ioRandom), unit(ioRandom), unit(ioRandom) + 1.5f)
                              .normalized()
                              .toRotationMatrix();
    body.mInertia = rotation * diagonal.asDiagonal() * rotation.transpose();
    body.mPosition = 5.0f * Vec3(unit(ioRandom), unit(ioRandom), unit(ioRandom));
    body.mVelocity.mLinearVelocity = 4.0f * Vec3(unit(ioRandom), unit(ioRandom), unit(ioRandom));
    body.mVelocity.mAngularVelocity = 3.0f * Vec3(unit(ioRandom), unit(ioRandom), unit(ioRandom));
    return body;
}

Vec3 AnchorVelocity(const SolverBody& inBody, const Vec3& inArm)
{
    return inBody.mLinearVelocity + inBody.mAngularVelocity.cross(inArm);
}

TEST(PointJointPartTest, OneIterationMakesTheAnchorsMoveTogetherAndKeepsMomentum)
{
    std::mt19937 random(33);
    for (int trial = 0; trial < 200; ++trial)
    {
        JointedBody a = RandomBody(random), b = RandomBody(random);
        const Vec3 anchor = 0.5f * (a.mPosition + b.mPosition); // Joined where they meet
        const Vec3 armA = anchor - a.mPosition, armB = anchor - b.mPosition;
        const Vec3 momentum = a.Momentum() + b.Momentum();
        const Vec3 angularMomentum = a.AngularMomentum(anchor) + b.AngularMomentum(anchor);
        const float before = (AnchorVelocity(b.mVelocity, armB) - AnchorVelocity(a.mVelocity, armA)).norm();

        PointJointPart part;
        part.Prepare(armA, a.Mass(), armB, b.Mass());
        ASSERT_TRUE(part.IsActive());
        part.SolveVelocity(a.mVelocity, b.mVelocity);

        const Vec3 relative = AnchorVelocity(b.mVelocity, armB) - AnchorVelocity(a.mVelocity, armA);
        EXPECT_LT(relative.norm(), 1.0e-4f * std::max(1.0f, before)) << "trial " << trial;
        // Equal and opposite impulses at one point: momentum, and angular momentum about that point, stay
        const float scale = 1.0f + momentum.norm() + a.Momentum().norm() + b.Momentum().norm();
        EXPECT_LT((a.Momentum() + b.Momentum() - momentum).norm(), 1.0e-4f * scale) << "trial " << trial;
        const Vec3 angularAfter = a.AngularMomentum(anchor) + b.AngularMomentum(anchor);
        const float angularScale = 1.0f + angularMomentum.norm() + 10.0f * scale;
        EXPECT_LT((angularAfter - angularMomentum).norm(), 1.0e-4f * angularScale) << "trial " << trial;
        // A second iteration has nothing left to do
        const Vec3 impulse = part.GetTotalImpulse();
        part.SolveVelocity(a.mVelocity, b.mVelocity);
        EXPECT_LT((part.GetTotalImpulse() - impulse).norm(), 1.0e-3f * (1.0f + impulse.norm()));
    }
}

TEST(PointJointPartTest, HeavyAndLightBodiesAlikeAreHeld)
{
    // The mass matrix of a heavy body is small, not singular: a tonne and a gram both get active rows
    for (float mass : {1.0e-3f, 1.0f, 200.0f, 1.0e4f})
    {
        JointedBody body;
        body.mMass = mass;
        body.mInertia = (mass * 0.1f) * Mat3::Identity();
        body.mVelocity.mLinearVelocity = Vec3(0.0f, -3.0f, 0.0f);
        SolverBody world = AtRest();
        PointJointPart part;
        part.Prepare(Vec3::Zero(), JointBodyMass{}, Vec3(0.2f, 0.0f, 0.0f), body.Mass());
        ASSERT_TRUE(part.IsActive()) << mass << " kg";
        part.SolveVelocity(world, body.mVelocity);
        EXPECT_LT(AnchorVelocity(body.mVelocity, Vec3(0.2f, 0.0f, 0.0f)).norm(), 1.0e-4f) << mass << " kg";
    }
}

TEST(PointJointPartTest, ASideThatCannotMoveIsLeftAsItIs)
{
    std::mt19937 random(7);
    JointedBody b = RandomBody(random);
    SolverBody world = AtRest();
    world.mLinearVelocity = Vec3(1.0f, 0.0f, 0.0f); // A kinematic side moving: it keeps moving
    const Vec3 armA(0.0f, 2.0f, 0.0f), armB(0.3f, -0.4f, 0.5f);
    PointJointPart part;
    part.Prepare(armA, JointBodyMass{}, armB, b.Mass());
    ASSERT_TRUE(part.IsActive());
    part.SolveVelocity(world, b.mVelocity);
    EXPECT_EQ(world.mLinearVelocity, Vec3(1.0f, 0.0f, 0.0f));
    EXPECT_EQ(world.mAngularVelocity, Vec3::Zero());
    EXPECT_LT((AnchorVelocity(b.mVelocity, armB) - AnchorVelocity(world, armA)).norm(), 1.0e-4f);

    // Neither side can move: nothing to solve, and no NaN from the zero mass matrix
    PointJointPart none;
    none.Prepare(armA, JointBodyMass{}, armB, JointBodyMass{});
    EXPECT_FALSE(none.IsActive());
    SolverBody other = AtRest();
    none.SolveVelocity(world, other);
    none.WarmStart(world, other);
    EXPECT_EQ(other.mLinearVelocity, Vec3::Zero());
    EXPECT_TRUE(none.CorrectPositions(Vec3::Zero(), Vec3::Ones(), 0.2f).mTranslationB.isZero());
}

TEST(PointJointPartTest, TheWarmStartGivesBackTheStepsImpulse)
{
    std::mt19937 random(11);
    JointedBody a = RandomBody(random), b = RandomBody(random);
    const Vec3 armA(0.2f, 0.5f, -0.1f), armB(-0.3f, -0.5f, 0.2f);
    PointJointPart part;
    part.Prepare(armA, a.Mass(), armB, b.Mass());
    SolverBody solvedA = a.mVelocity, solvedB = b.mVelocity;
    part.SolveVelocity(solvedA, solvedB);

    // The next step prepares again (the arms as they were) and starts from the impulse it kept
    part.Prepare(armA, a.Mass(), armB, b.Mass());
    SolverBody warmA = a.mVelocity, warmB = b.mVelocity;
    part.WarmStart(warmA, warmB);
    EXPECT_LT((warmA.mLinearVelocity - solvedA.mLinearVelocity).norm(), 1.0e-5f);
    EXPECT_LT((warmB.mAngularVelocity - solvedB.mAngularVelocity).norm(), 1.0e-4f);
    // Half of it, and none once reset
    const Vec3 total = part.GetTotalImpulse();
    SolverBody halfA = a.mVelocity, halfB = b.mVelocity;
    part.WarmStart(halfA, halfB, 0.5f);
    EXPECT_LT((part.GetTotalImpulse() - 0.5f * total).norm(), 1.0e-6f * (1.0f + total.norm()));
    part.ResetImpulse();
    SolverBody resetA = a.mVelocity, resetB = b.mVelocity;
    part.WarmStart(resetA, resetB);
    EXPECT_EQ(resetA.mLinearVelocity, a.mVelocity.mLinearVelocity);
}

TEST(PointJointPartTest, APositionIterationClosesTheAskedPartOfTheGap)
{
    std::mt19937 random(5);
    for (int trial = 0; trial < 50; ++trial)
    {
        JointedBody a = RandomBody(random), b = RandomBody(random);
        const Vec3 armA(0.4f, -0.2f, 0.3f), armB(-0.1f, 0.5f, 0.2f);
        // The anchors a centimetre apart, as the drift a step leaves
        b.mPosition = a.mPosition + armA - armB + Vec3(0.006f, -0.004f, 0.007f);
        const Vec3 gap = (b.mPosition + armB) - (a.mPosition + armA);
        PointJointPart part;
        part.Prepare(armA, a.Mass(), armB, b.Mass());
        const PointJointPart::PoseCorrection c =
            part.CorrectPositions(a.mPosition + armA, b.mPosition + armB, 0.2f);
        // Moved as the correction says (rotations to first order, as the arms turn with their body)
        const Vec3 anchorA = a.mPosition + c.mTranslationA + armA + c.mRotationA.cross(armA);
        const Vec3 anchorB = b.mPosition + c.mTranslationB + armB + c.mRotationB.cross(armB);
        EXPECT_LT(((anchorB - anchorA) - 0.8f * gap).norm(), 1.0e-3f * gap.norm()) << "trial " << trial;
    }
}

} // namespace
} // namespace cairn::physics
