#pragma once

// One angular row about an axis between bodies A and B: a hinge's limit (one-sided), its motor (a target
// relative spin, or a spring towards a target angle: the soft step of AxisJointPart; either within what its
// torque gives in a step) or its friction (a motor towards no spin with the friction torque's bound).
// Sequential impulses; a limit's error is taken out on the poses after integration, as the other joints'
// rows.
//
// Threads: the one solving the island the joint is in; no locks.

#include "solver/AxisJointPart.h"

namespace cairn::physics
{

class AngleJointPart
{
public:
    /// A row about inAxis (unit, world space): the relative spin (B's less A's) along it is taken towards
    /// inTargetSpeed (rad/s), the accumulated impulse kept within [inMinImpulse, inMaxImpulse] (N m s) and,
    /// for a limit, to its side. inError: a limit's angle past it (rad), for the position rows.
    void Prepare(const JointBodyMass& inA, const JointBodyMass& inB, const Vec3& inAxis, float inTargetSpeed,
                 float inMinImpulse, float inMaxImpulse, AxisJointPart::Side inSide, float inError);
    /// A limit's row (or, inSide Both, an equality: the angle held): no speed target, no bound but its side;
    /// the position pass takes out inError. A limit not reached yet (inError on its allowed side) is
    /// speculative, as AxisJointPart's: the bodies may close the gap in this step of inDeltaTime, no more.
    void PrepareLimit(const JointBodyMass& inA, const JointBodyMass& inB, const Vec3& inAxis,
                      AxisJointPart::Side inSide, float inError, float inDeltaTime);
    /// A position motor's row: a spring of inFrequency (Hz, above 0) and damping ratio inDamping pulling the
    /// angle error inError (rad: the angle less the target) to zero, within [inMinImpulse, inMaxImpulse].
    void PrepareSpring(const JointBodyMass& inA, const JointBodyMass& inB, const Vec3& inAxis, float inError,
                       float inFrequency, float inDamping, float inDeltaTime, float inMinImpulse,
                       float inMaxImpulse);
    /// No row this step (a limit not reached, no motor, no friction): its impulse dropped.
    void Deactivate()
    {
        mActive = false;
        mTotalImpulse = 0.0f;
    }
    bool IsActive() const { return mActive; }
    void WarmStart(SolverBody& ioA, SolverBody& ioB, float inRatio = 1.0f);
    void SolveVelocity(SolverBody& ioA, SolverBody& ioB);
    float GetTotalImpulse() const { return mTotalImpulse; }
    void ResetImpulse() { mTotalImpulse = 0.0f; }
    /// A limit's position iteration (PrepareLimit's): the turns that take inFraction of its error out. Zero
    /// for a motor or friction row.
    PointJointPart::PoseCorrection CorrectPositions(float inFraction) const;

private:
    void Apply(SolverBody& ioA, SolverBody& ioB, float inImpulse) const;

    Vec3 mAxis = Vec3::UnitX();
    Vec3 mAngularA = Vec3::Zero(); ///< IA^-1 axis
    Vec3 mAngularB = Vec3::Zero();
    float mEffectiveMass = 0.0f;
    float mTargetSpeed = 0.0f;
    float mBias = 0.0f;         ///< A spring's velocity bias
    float mMassScale = 1.0f;    ///< A spring's, of the effective mass
    float mImpulseScale = 0.0f; ///< A spring's, of the accumulated impulse
    float mMinImpulse = 0.0f;
    float mMaxImpulse = 0.0f;
    float mError = 0.0f;
    float mTotalImpulse = 0.0f;
    AxisJointPart::Side mSide = AxisJointPart::Side::Both;
    bool mLimit = false; ///< Prepared by PrepareLimit: it has a position error to take out
    bool mActive = false;
};

// Defined here so that JointStage, which calls them for every joint in every velocity iteration, inlines them
inline void AngleJointPart::Apply(SolverBody& ioA, SolverBody& ioB, float inImpulse) const
{
    ioA.mAngularVelocity -= inImpulse * mAngularA;
    ioB.mAngularVelocity += inImpulse * mAngularB;
}

inline void AngleJointPart::SolveVelocity(SolverBody& ioA, SolverBody& ioB)
{
    if (!mActive) return;
    const float spin = mAxis.dot(ioB.mAngularVelocity - ioA.mAngularVelocity);
    const float impulse0 =
        -mMassScale * mEffectiveMass * (spin - mTargetSpeed + mBias) - mImpulseScale * mTotalImpulse;
    const float total =
        AxisJointPart::ClampToSide(std::clamp(mTotalImpulse + impulse0, mMinImpulse, mMaxImpulse), mSide);
    const float impulse = total - mTotalImpulse;
    mTotalImpulse = total;
    Apply(ioA, ioB, impulse);
}

} // namespace cairn::physics
