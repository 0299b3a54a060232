#include "solver/AxisJointPart.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace cairn::physics
{

SoftStep SoftStep::Of(float inFrequency, float inDamping, float inDeltaTime)
{
    const float omega = 2.0f * std::numbers::pi_v<float> * inFrequency; // Angular frequency
    const float a1 = 2.0f * inDamping + inDeltaTime * omega;
    const float a2 = inDeltaTime * omega * a1;
    const float a3 = 1.0f / (1.0f + a2);
    return {omega / a1, a2 * a3, a3};
}

void AxisJointPart::Prepare(const Vec3& inArmA, const JointBodyMass& inA, const Vec3& inArmB,
                            const JointBodyMass& inB, const Vec3& inAxis, float inError, Side inSide,
                            float inFrequency, float inDamping, float inDeltaTime)
{
    mMotor = false;
    mMinImpulse = -cLargeFloat;
    mMaxImpulse = cLargeFloat;
    mAxis = inAxis;
    mArmCrossA = inArmA.cross(inAxis);
    mArmCrossB = inArmB.cross(inAxis);
    mAngularA = inA.mInverseInertia * mArmCrossA;
    mAngularB = inB.mInverseInertia * mArmCrossB;
    mInverseMassA = inA.mInverseMass;
    mInverseMassB = inB.mInverseMass;
    const float k =
        inA.mInverseMass + inB.mInverseMass + mArmCrossA.dot(mAngularA) + mArmCrossB.dot(mAngularB);
    mActive = k > 0.0f && std::isfinite(k);
    mEffectiveMass = mActive ? 1.0f / k : 0.0f;
    if (mSide != inSide) mTotalImpulse = 0.0f; // Another limit than last step's: nothing to warm-start
    mSide = inSide;
    mSoft = inFrequency > 0.0f;
    mBias = 0.0f;
    mMassScale = 1.0f;
    mImpulseScale = 0.0f;
    if (mSoft && mActive)
    {
        const SoftStep soft = SoftStep::Of(inFrequency, inDamping, inDeltaTime);
        mBias = soft.mBiasPerError * inError;
        mMassScale = soft.mMassScale;
        mImpulseScale = soft.mImpulseScale;
    }
    else
        mBias = SpeculativeBias(inSide, inError, inDeltaTime);
    if (!mActive) mTotalImpulse = 0.0f;
}

void AxisJointPart::PrepareMotor(const Vec3& inArmA, const JointBodyMass& inA, const Vec3& inArmB,
                                 const JointBodyMass& inB, const Vec3& inAxis, float inTargetSpeed,
                                 float inMinImpulse, float inMaxImpulse)
{
    Prepare(inArmA, inA, inArmB, inB, inAxis, 0.0f, Side::Both, 0.0f, 0.0f, 0.0f);
    // The rate the row drives to zero is the speed less the target
    mBias = -inTargetSpeed;
    BoundAsMotor(inMinImpulse, inMaxImpulse);
}

void AxisJointPart::PrepareSpringMotor(const Vec3& inArmA, const JointBodyMass& inA, const Vec3& inArmB,
                                       const JointBodyMass& inB, const Vec3& inAxis, float inError,
                                       float inFrequency, float inDamping, float inDeltaTime,
                                       float inMinImpulse, float inMaxImpulse)
{
    Prepare(inArmA, inA, inArmB, inB, inAxis, inError, Side::Both, inFrequency, inDamping, inDeltaTime);
    BoundAsMotor(inMinImpulse, inMaxImpulse);
}

void AxisJointPart::BoundAsMotor(float inMinImpulse, float inMaxImpulse)
{
    mMinImpulse = inMinImpulse;
    mMaxImpulse = inMaxImpulse;
    mMotor = true;
    mTotalImpulse = std::clamp(mTotalImpulse, mMinImpulse, mMaxImpulse); // The bound may have shrunk
}

void AxisJointPart::Apply(SolverBody& ioA, SolverBody& ioB, float inImpulse) const
{
    ioA.mLinearVelocity -= (mInverseMassA * inImpulse) * mAxis;
    ioA.mAngularVelocity -= inImpulse * mAngularA;
    ioB.mLinearVelocity += (mInverseMassB * inImpulse) * mAxis;
    ioB.mAngularVelocity += inImpulse * mAngularB;
}

void AxisJointPart::WarmStart(SolverBody& ioA, SolverBody& ioB, float inRatio)
{
    mTotalImpulse *= inRatio;
    if (mActive) Apply(ioA, ioB, mTotalImpulse);
}

void AxisJointPart::SolveVelocity(SolverBody& ioA, SolverBody& ioB)
{
    if (!mActive) return;
    const float speed = mAxis.dot(ioB.mLinearVelocity - ioA.mLinearVelocity) +
                        mArmCrossB.dot(ioB.mAngularVelocity) - mArmCrossA.dot(ioA.mAngularVelocity);
    float impulse = -mMassScale * mEffectiveMass * (speed + mBias) - mImpulseScale * mTotalImpulse;
    // A limit's accumulated impulse stays on its side (it may take back what earlier iterations gave)
    const float total = mTotalImpulse + impulse;
    const float clamped = std::clamp(ClampToSide(total, mSide), mMinImpulse, mMaxImpulse);
    impulse = clamped - mTotalImpulse;
    mTotalImpulse = clamped;
    Apply(ioA, ioB, impulse);
}

PointJointPart::PoseCorrection AxisJointPart::CorrectPositions(float inError, float inFraction) const
{
    PointJointPart::PoseCorrection correction;
    if (!mActive || mSoft || mMotor) return correction;
    // Only an error the row pushes against: too short for a lower limit, too long for an upper one
    if (!PushesAgainst(mSide, inError)) return correction;
    const float impulse = -mEffectiveMass * ClampCorrection(inFraction * inError, cMaxJointLinearCorrection);
    correction.mTranslationA = -(mInverseMassA * impulse) * mAxis;
    correction.mRotationA = -impulse * mAngularA;
    correction.mTranslationB = (mInverseMassB * impulse) * mAxis;
    correction.mRotationB = impulse * mAngularB;
    return correction;
}

} // namespace cairn::physics
