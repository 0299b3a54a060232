#include "solver/RotationJointPart.h"

#include <cmath>

namespace cairn::physics
{

void RotationJointPart::Prepare(const JointBodyMass& inA, const JointBodyMass& inB)
{
    mA = inA;
    mB = inB;
    mActive = InvertJointMassMatrix(inA.mInverseInertia + inB.mInverseInertia, mEffectiveMass);
}

void RotationJointPart::WarmStart(SolverBody& ioA, SolverBody& ioB, float inRatio)
{
    mTotalImpulse *= inRatio;
    if (!mActive) return;
    ioA.mAngularVelocity -= mA.mInverseInertia * mTotalImpulse;
    ioB.mAngularVelocity += mB.mInverseInertia * mTotalImpulse;
}

void RotationJointPart::SolveVelocity(SolverBody& ioA, SolverBody& ioB)
{
    if (!mActive) return;
    const Vec3 impulse = -(mEffectiveMass * (ioB.mAngularVelocity - ioA.mAngularVelocity));
    mTotalImpulse += impulse;
    ioA.mAngularVelocity -= mA.mInverseInertia * impulse;
    ioB.mAngularVelocity += mB.mInverseInertia * impulse;
}

Vec3 RotationJointPart::RotationError(const Quat& inRotationA, const Quat& inRotationB,
                                      const Quat& inRelative)
{
    // The turn from the kept rotation (A's, then the relative one) to B's, as a rotation vector
    Quat error = inRotationB * (inRotationA * inRelative).conjugate();
    if (error.w() < 0.0f) error.coeffs() = -error.coeffs(); // The short way round
    const float sine = error.vec().norm();
    if (sine < 1.0e-7f) return 2.0f * error.vec();
    return (2.0f * std::atan2(sine, error.w()) / sine) * error.vec();
}

PointJointPart::PoseCorrection RotationJointPart::CorrectPositions(const Vec3& inError,
                                                                   float inFraction) const
{
    PointJointPart::PoseCorrection correction;
    if (!mActive) return correction;
    const Vec3 impulse =
        -(mEffectiveMass * ClampCorrection(Vec3(inFraction * inError), cMaxJointAngularCorrection));
    correction.mRotationA = -(mA.mInverseInertia * impulse);
    correction.mRotationB = mB.mInverseInertia * impulse;
    return correction;
}

} // namespace cairn::physics
