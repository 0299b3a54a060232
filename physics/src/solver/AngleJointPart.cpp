#include "solver/AngleJointPart.h"

#include <algorithm>
#include <cmath>

namespace cairn::physics
{

void AngleJointPart::Prepare(const JointBodyMass& inA, const JointBodyMass& inB, const Vec3& inAxis,
                             float inTargetSpeed, float inMinImpulse, float inMaxImpulse,
                             AxisJointPart::Side inSide, float inError)
{
    mLimit = false;
    mBias = 0.0f;
    mMassScale = 1.0f;
    mImpulseScale = 0.0f;
    mAxis = inAxis;
    mAngularA = inA.mInverseInertia * inAxis;
    mAngularB = inB.mInverseInertia * inAxis;
    const float k = inAxis.dot(mAngularA) + inAxis.dot(mAngularB);
    mActive = k > 0.0f && std::isfinite(k);
    mEffectiveMass = mActive ? 1.0f / k : 0.0f;
    if (mSide != inSide) mTotalImpulse = 0.0f; // Another limit than last step's: nothing to warm-start
    mSide = inSide;
    mTargetSpeed = inTargetSpeed;
    mMinImpulse = inMinImpulse;
    mMaxImpulse = inMaxImpulse;
    mError = inError;
    mTotalImpulse = std::clamp(mTotalImpulse, mMinImpulse, mMaxImpulse);
    if (!mActive) mTotalImpulse = 0.0f;
}

void AngleJointPart::PrepareLimit(const JointBodyMass& inA, const JointBodyMass& inB, const Vec3& inAxis,
                                  AxisJointPart::Side inSide, float inError, float inDeltaTime)
{
    Prepare(inA, inB, inAxis, 0.0f, -cLargeFloat, cLargeFloat, inSide, inError);
    mLimit = true;
    mBias = AxisJointPart::SpeculativeBias(inSide, inError, inDeltaTime);
}

void AngleJointPart::PrepareSpring(const JointBodyMass& inA, const JointBodyMass& inB, const Vec3& inAxis,
                                   float inError, float inFrequency, float inDamping, float inDeltaTime,
                                   float inMinImpulse, float inMaxImpulse)
{
    Prepare(inA, inB, inAxis, 0.0f, inMinImpulse, inMaxImpulse, AxisJointPart::Side::Both, 0.0f);
    const SoftStep soft = SoftStep::Of(inFrequency, inDamping, inDeltaTime);
    mBias = soft.mBiasPerError * inError;
    mMassScale = soft.mMassScale;
    mImpulseScale = soft.mImpulseScale;
}

void AngleJointPart::WarmStart(SolverBody& ioA, SolverBody& ioB, float inRatio)
{
    mTotalImpulse *= inRatio;
    if (mActive) Apply(ioA, ioB, mTotalImpulse);
}

PointJointPart::PoseCorrection AngleJointPart::CorrectPositions(float inFraction) const
{
    PointJointPart::PoseCorrection correction;
    // Only a limit has a position; an equality (equal limits) pushes against its error either way
    if (!mActive || !mLimit || !AxisJointPart::PushesAgainst(mSide, mError)) return correction;
    const float impulse = -mEffectiveMass * ClampCorrection(inFraction * mError, cMaxJointAngularCorrection);
    correction.mRotationA = -impulse * mAngularA;
    correction.mRotationB = impulse * mAngularB;
    return correction;
}

} // namespace cairn::physics
