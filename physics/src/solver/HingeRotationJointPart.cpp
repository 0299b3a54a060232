#include "solver/HingeRotationJointPart.h"

#include <cmath>

namespace cairn::physics
{

void HingeRotationJointPart::Prepare(const JointBodyMass& inA, const JointBodyMass& inB, const Vec3& inAxisA,
                                     const Vec3& inAxisB)
{
    mA = inA;
    mB = inB;
    const Vec3 b2 = AnyPerpendicular(inAxisB);
    const Vec3 b3 = inAxisB.cross(b2);
    mRow[0] = b2.cross(inAxisA);
    mRow[1] = b3.cross(inAxisA);
    mError[0] = inAxisA.dot(b2);
    mError[1] = inAxisA.dot(b3);
    const Mat3 inverseInertia = inA.mInverseInertia + inB.mInverseInertia;
    Eigen::Matrix2f k;
    for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j)
            k(i, j) = mRow[i].dot(inverseInertia * mRow[j]);
    mActive = InvertJointMassMatrix(k, mEffectiveMass);
    if (!mActive) mTotalImpulse.setZero();
}

void HingeRotationJointPart::Apply(SolverBody& ioA, SolverBody& ioB, const Eigen::Vector2f& inImpulse) const
{
    const Vec3 angular = mRow[0] * inImpulse[0] + mRow[1] * inImpulse[1];
    ioA.mAngularVelocity -= mA.mInverseInertia * angular;
    ioB.mAngularVelocity += mB.mInverseInertia * angular;
}

void HingeRotationJointPart::WarmStart(SolverBody& ioA, SolverBody& ioB, float inRatio)
{
    mTotalImpulse *= inRatio;
    if (mActive) Apply(ioA, ioB, mTotalImpulse);
}

void HingeRotationJointPart::SolveVelocity(SolverBody& ioA, SolverBody& ioB)
{
    if (!mActive) return;
    const Vec3 spin = ioB.mAngularVelocity - ioA.mAngularVelocity;
    const Eigen::Vector2f rate(mRow[0].dot(spin), mRow[1].dot(spin));
    const Eigen::Vector2f impulse = -(mEffectiveMass * rate);
    mTotalImpulse += impulse;
    Apply(ioA, ioB, impulse);
}

PointJointPart::PoseCorrection HingeRotationJointPart::CorrectPositions(float inFraction) const
{
    PointJointPart::PoseCorrection correction;
    if (!mActive) return correction;
    const Eigen::Vector2f step = ClampCorrection(
        Eigen::Vector2f(inFraction * Eigen::Vector2f(mError[0], mError[1])), cMaxJointAngularCorrection);
    const Eigen::Vector2f impulse = -(mEffectiveMass * step);
    const Vec3 angular = mRow[0] * impulse[0] + mRow[1] * impulse[1];
    correction.mRotationA = -(mA.mInverseInertia * angular);
    correction.mRotationB = mB.mInverseInertia * angular;
    return correction;
}

} // namespace cairn::physics
