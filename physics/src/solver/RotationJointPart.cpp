#include "solver/RotationJointPart.h"

#include <cmath>

namespace cairn::physics
{

void RotationJointPart::Prepare(const JointBodyMass& inA, const JointBodyMass& inB)
{
    mA = inA;
    mB = inB;
    const Mat3 k = inA.mInverseInertia + inB.mInverseInertia;
    bool invertible = false;
    float determinant = 0.0f;
    // No absolute threshold (Eigen's default, 1e-5, refused a 200 kg body's matrix): the relative test below
    k.computeInverseAndDetWithCheck(mEffectiveMass, determinant, invertible, 0.0f);
    const float scale = k.cwiseAbs().maxCoeff();
    mActive = invertible && scale > 0.0f && std::isfinite(determinant) &&
              std::abs(determinant) > 1.0e-12f * scale * scale * scale && mEffectiveMass.allFinite();
    if (!mActive) mEffectiveMass.setZero();
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
    const Vec3 impulse = -(mEffectiveMass * (inFraction * inError));
    correction.mRotationA = -(mA.mInverseInertia * impulse);
    correction.mRotationB = mB.mInverseInertia * impulse;
    return correction;
}

} // namespace cairn::physics
