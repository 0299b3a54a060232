#include "solver/LineJointPart.h"

#include <cmath>

namespace cairn::physics
{

void LineJointPart::Prepare(const Vec3& inArmA, const JointBodyMass& inA, const Vec3& inArmB,
                            const JointBodyMass& inB, const Vec3& inAxis, const Vec3& inOffset)
{
    mA = inA;
    mB = inB;
    mAcross[0] = AnyPerpendicular(inAxis);
    mAcross[1] = inAxis.cross(mAcross[0]);
    for (int i = 0; i < 2; ++i)
    {
        mArmCrossA[i] = inArmA.cross(mAcross[i]);
        mArmCrossB[i] = inArmB.cross(mAcross[i]);
        mError[i] = inOffset.dot(mAcross[i]);
    }
    // K = J M^-1 J^T; n1 . n2 = 0, so the linear part is on the diagonal only
    Eigen::Matrix2f k;
    for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j)
            k(i, j) = (i == j ? inA.mInverseMass + inB.mInverseMass : 0.0f) +
                      mArmCrossA[i].dot(inA.mInverseInertia * mArmCrossA[j]) +
                      mArmCrossB[i].dot(inB.mInverseInertia * mArmCrossB[j]);
    mActive = InvertJointMassMatrix(k, mEffectiveMass);
    if (!mActive) mTotalImpulse.setZero();
}

void LineJointPart::Apply(SolverBody& ioA, SolverBody& ioB, const Eigen::Vector2f& inImpulse) const
{
    const Vec3 linear = mAcross[0] * inImpulse[0] + mAcross[1] * inImpulse[1];
    ioA.mLinearVelocity -= mA.mInverseMass * linear;
    ioA.mAngularVelocity -=
        mA.mInverseInertia * (mArmCrossA[0] * inImpulse[0] + mArmCrossA[1] * inImpulse[1]);
    ioB.mLinearVelocity += mB.mInverseMass * linear;
    ioB.mAngularVelocity +=
        mB.mInverseInertia * (mArmCrossB[0] * inImpulse[0] + mArmCrossB[1] * inImpulse[1]);
}

void LineJointPart::WarmStart(SolverBody& ioA, SolverBody& ioB, float inRatio)
{
    mTotalImpulse *= inRatio;
    if (mActive) Apply(ioA, ioB, mTotalImpulse);
}

void LineJointPart::SolveVelocity(SolverBody& ioA, SolverBody& ioB)
{
    if (!mActive) return;
    const Vec3 linear = ioB.mLinearVelocity - ioA.mLinearVelocity;
    Eigen::Vector2f rate;
    for (int i = 0; i < 2; ++i)
        rate[i] = mAcross[i].dot(linear) + mArmCrossB[i].dot(ioB.mAngularVelocity) -
                  mArmCrossA[i].dot(ioA.mAngularVelocity);
    const Eigen::Vector2f impulse = -(mEffectiveMass * rate);
    mTotalImpulse += impulse;
    Apply(ioA, ioB, impulse);
}

PointJointPart::PoseCorrection LineJointPart::CorrectPositions(float inFraction) const
{
    PointJointPart::PoseCorrection correction;
    if (!mActive) return correction;
    const Eigen::Vector2f step = ClampCorrection(
        Eigen::Vector2f(inFraction * Eigen::Vector2f(mError[0], mError[1])), cMaxJointLinearCorrection);
    const Eigen::Vector2f impulse = -(mEffectiveMass * step);
    const Vec3 linear = mAcross[0] * impulse[0] + mAcross[1] * impulse[1];
    correction.mTranslationA = -mA.mInverseMass * linear;
    correction.mRotationA = -(mA.mInverseInertia * (mArmCrossA[0] * impulse[0] + mArmCrossA[1] * impulse[1]));
    correction.mTranslationB = mB.mInverseMass * linear;
    correction.mRotationB = mB.mInverseInertia * (mArmCrossB[0] * impulse[0] + mArmCrossB[1] * impulse[1]);
    return correction;
}

} // namespace cairn::physics
