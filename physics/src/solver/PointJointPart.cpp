#include "solver/PointJointPart.h"

#include <Eigen/LU>
#include <cmath>

namespace cairn::physics
{

bool InvertJointMassMatrix(const Mat3& inK, Mat3& outInverse)
{
    bool invertible = false;
    float determinant = 0.0f;
    // No absolute threshold (Eigen's default, 1e-5, refused a 200 kg body's matrix): the relative test below
    inK.computeInverseAndDetWithCheck(outInverse, determinant, invertible, 0.0f);
    const float scale = inK.cwiseAbs().maxCoeff();
    const bool ok = invertible && scale > 0.0f && std::isfinite(determinant) &&
                    std::abs(determinant) > 1.0e-12f * scale * scale * scale && outInverse.allFinite();
    if (!ok) outInverse.setZero();
    return ok;
}

bool InvertJointMassMatrix(const Eigen::Matrix2f& inK, Eigen::Matrix2f& outInverse)
{
    const float determinant = inK.determinant();
    const float scale = inK.cwiseAbs().maxCoeff();
    const bool ok =
        scale > 0.0f && std::isfinite(determinant) && std::abs(determinant) > 1.0e-10f * scale * scale;
    outInverse = ok ? Eigen::Matrix2f(inK.inverse()) : Eigen::Matrix2f::Zero();
    return ok;
}

void PointJointPart::Prepare(const Vec3& inArmA, const JointBodyMass& inA, const Vec3& inArmB,
                             const JointBodyMass& inB)
{
    mArmA = inArmA;
    mArmB = inArmB;
    mA = inA;
    mB = inB;
    // K = (1/mA + 1/mB) I - [rA] IA^-1 [rA] - [rB] IB^-1 [rB]: the point's velocity change per unit impulse
    const Mat3 skewA = Skew(inArmA), skewB = Skew(inArmB);
    const Mat3 k = (inA.mInverseMass + inB.mInverseMass) * Mat3::Identity() -
                   skewA * inA.mInverseInertia * skewA - skewB * inB.mInverseInertia * skewB;
    mActive = InvertJointMassMatrix(k, mEffectiveMass);
}

void PointJointPart::WarmStart(SolverBody& ioA, SolverBody& ioB, float inRatio)
{
    mTotalImpulse *= inRatio;
    if (mActive) Apply(ioA, ioB, mTotalImpulse);
}

PointJointPart::PoseCorrection PointJointPart::CorrectPositions(const Vec3& inAnchorA, const Vec3& inAnchorB,
                                                                float inFraction) const
{
    PoseCorrection correction;
    if (!mActive) return correction;
    // The same rows on positions: the "impulse" whose velocity change, applied for one unit of time, closes
    // inFraction of the gap
    const Vec3 impulse = -(mEffectiveMass * ClampCorrection(Vec3(inFraction * (inAnchorB - inAnchorA)),
                                                            cMaxJointLinearCorrection));
    correction.mTranslationA = -mA.mInverseMass * impulse;
    correction.mRotationA = -(mA.mInverseInertia * mArmA.cross(impulse));
    correction.mTranslationB = mB.mInverseMass * impulse;
    correction.mRotationB = mB.mInverseInertia * mArmB.cross(impulse);
    return correction;
}

} // namespace cairn::physics
