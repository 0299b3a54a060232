// The slider's line rows (issue 33), against what they must do whatever the bodies: one velocity iteration
// leaves B's point no speed across the line (A's point taken at B's, turning with A), momentum kept and the
// impulse across the line only; the warm start gives the step's impulse back; a position iteration takes
// out the asked part of B's offset from the line (first order).

#include "solver/LineJointPart.h"

#include <gtest/gtest.h>

namespace cairn::physics
{
namespace
{

SolverBody Moving(float inInverseMass, const Vec3& inLinear, const Vec3& inAngular)
{
    SolverBody body;
    body.mLinearVelocity = inLinear;
    body.mInverseMass = inInverseMass;
    body.mAngularVelocity = inAngular;
    body.mPadding = 0.0f;
    return body;
}

/// The velocity of B's point less that of the same place fixed to A (inArmAtB: from A's centre to it)
Vec3 RelativePointVelocity(const SolverBody& inA, const SolverBody& inB, const Vec3& inArmAtB,
                           const Vec3& inArmB)
{
    return inB.mLinearVelocity + inB.mAngularVelocity.cross(inArmB) - inA.mLinearVelocity -
           inA.mAngularVelocity.cross(inArmAtB);
}

struct Scene
{
    float mMassA = 3.0f, mMassB = 0.5f;
    Mat3 mInertiaA = Vec3(2.0f, 1.0f, 3.0f).asDiagonal();
    Mat3 mInertiaB = Vec3(0.1f, 0.3f, 0.2f).asDiagonal();
    Vec3 mArmA = Vec3(0.4f, -0.2f, 0.1f);     ///< A's centre to A's point
    Vec3 mOffset = Vec3(0.6f, 0.01f, -0.02f); ///< B's point less A's: mostly along the axis
    Vec3 mArmB = Vec3(-0.3f, 0.1f, 0.2f);
    Vec3 mAxis = Vec3(1.0f, 0.2f, -0.1f).normalized();

    JointBodyMass A() const { return {1.0f / mMassA, mInertiaA.inverse()}; }
    JointBodyMass B() const { return {1.0f / mMassB, mInertiaB.inverse()}; }
    Vec3 ArmAtB() const { return mArmA + mOffset; }
};

TEST(LineJointPartTest, OneIterationLeavesNoSpeedAcrossTheLineAndKeepsMomentum)
{
    const Scene scene;
    LineJointPart part;
    part.Prepare(scene.ArmAtB(), scene.A(), scene.mArmB, scene.B(), scene.mAxis, scene.mOffset);
    ASSERT_TRUE(part.IsActive());
    SolverBody a = Moving(1.0f / scene.mMassA, Vec3(0.3f, -1.0f, 0.2f), Vec3(0.5f, 0.1f, -0.4f));
    SolverBody b = Moving(1.0f / scene.mMassB, Vec3(-2.0f, 0.5f, 1.0f), Vec3(-1.0f, 2.0f, 0.3f));
    const Vec3 momentum = scene.mMassA * a.mLinearVelocity + scene.mMassB * b.mLinearVelocity;
    part.SolveVelocity(a, b);
    const Vec3 relative = RelativePointVelocity(a, b, scene.ArmAtB(), scene.mArmB);
    EXPECT_LT((relative - relative.dot(scene.mAxis) * scene.mAxis).norm(), 1.0e-4f);
    EXPECT_LT((scene.mMassA * a.mLinearVelocity + scene.mMassB * b.mLinearVelocity - momentum).norm(),
              1.0e-4f);
    EXPECT_NEAR(part.GetTotalImpulse().dot(scene.mAxis), 0.0f, 1.0e-5f); // Across the line only

    // The warm start applies the accumulated impulse again: from the same start it gives the same velocities
    SolverBody a2 = Moving(1.0f / scene.mMassA, Vec3(0.3f, -1.0f, 0.2f), Vec3(0.5f, 0.1f, -0.4f));
    SolverBody b2 = Moving(1.0f / scene.mMassB, Vec3(-2.0f, 0.5f, 1.0f), Vec3(-1.0f, 2.0f, 0.3f));
    part.WarmStart(a2, b2);
    EXPECT_LT((a2.mLinearVelocity - a.mLinearVelocity).norm(), 1.0e-5f);
    EXPECT_LT((b2.mAngularVelocity - b.mAngularVelocity).norm(), 1.0e-5f);

    // Against the world (nothing moves on A's side): B's point stops across the line, the world stays
    LineJointPart toWorld;
    toWorld.Prepare(scene.mOffset, {}, scene.mArmB, scene.B(), scene.mAxis, scene.mOffset);
    SolverBody world = Moving(0.0f, Vec3::Zero(), Vec3::Zero());
    SolverBody c = Moving(1.0f / scene.mMassB, Vec3(1.0f, 1.0f, 1.0f), Vec3(0.0f, 1.0f, 0.0f));
    toWorld.SolveVelocity(world, c);
    const Vec3 pointVelocity = c.mLinearVelocity + c.mAngularVelocity.cross(scene.mArmB);
    EXPECT_LT((pointVelocity - pointVelocity.dot(scene.mAxis) * scene.mAxis).norm(), 1.0e-4f);
    EXPECT_TRUE(world.mLinearVelocity.isZero());
    LineJointPart none;
    none.Prepare(scene.mOffset, {}, scene.mArmB, {}, scene.mAxis, scene.mOffset);
    EXPECT_FALSE(none.IsActive());
}

TEST(LineJointPartTest, APositionIterationTakesOutTheAskedPartOfTheOffsetAcrossTheLine)
{
    const Scene scene;
    LineJointPart part;
    part.Prepare(scene.ArmAtB(), scene.A(), scene.mArmB, scene.B(), scene.mAxis, scene.mOffset);
    const float fraction = 0.2f;
    const PointJointPart::PoseCorrection c = part.CorrectPositions(fraction);
    // B's point and A's (taken at B's) moved by the correction, to first order in the turns; A's axis turns
    // with A
    const Vec3 moveA = c.mTranslationA + c.mRotationA.cross(scene.ArmAtB());
    const Vec3 moveB = c.mTranslationB + c.mRotationB.cross(scene.mArmB);
    const Vec3 offset = scene.mOffset + moveB - moveA;
    const Vec3 axis = scene.mAxis + c.mRotationA.cross(scene.mAxis);
    const Vec3 acrossBefore = scene.mOffset - scene.mOffset.dot(scene.mAxis) * scene.mAxis;
    const Vec3 acrossAfter = offset - offset.dot(axis) * axis;
    // A fifth of it out (first order: a little left over from the turns' second-order terms)
    EXPECT_NEAR(acrossAfter.norm(), (1.0f - fraction) * acrossBefore.norm(), 0.02f * acrossBefore.norm());
}

} // namespace
} // namespace cairn::physics
