#pragma once

// The swing-twist joint's friction (issue 33, ragdolls): a torque of at most a bound about each of A's frame
// axes that resists B's spin relative to A. The three axes are solved as one 3x3 block, not as three angle
// rows in turn: the rows each waited for the one before to write the bodies' spins, a chain that was most of
// a ragdoll joint's velocity iteration; the block's three products run side by side. Its accumulated impulse
// (in the frame's axes, so it follows A as A turns, and kept for the next step's warm start) is clamped to
// the bound on each axis.
//
// Threads: the one solving the island the joint is in; no locks.

#include "solver/PointJointPart.h"

namespace cairn::physics
{

class AngularFrictionPart
{
public:
    /// inFrame: A's frame axes in world space (the columns). inBound: the most impulse about each axis this
    /// step (N m s, the torque times the step). Inactive when the bound is not above zero or neither side
    /// can turn.
    void Prepare(const JointBodyMass& inA, const JointBodyMass& inB, const Mat3& inFrame, float inBound);
    void Deactivate()
    {
        mActive = false;
        mTotalImpulse.setZero();
    }
    bool IsActive() const { return mActive; }
    void WarmStart(SolverBody& ioA, SolverBody& ioB, float inRatio = 1.0f);
    void SolveVelocity(SolverBody& ioA, SolverBody& ioB);
    /// In the frame's axes.
    const Vec3& GetTotalImpulse() const { return mTotalImpulse; }
    void ResetImpulse() { mTotalImpulse.setZero(); }

private:
    void Apply(SolverBody& ioA, SolverBody& ioB, const Vec3& inFrameImpulse) const;

    Mat3 mImpulsePerSpin = Mat3::Zero();  ///< frame^T K^-1: the frame's impulse that stops a world spin
    Mat3 mSpinPerImpulseA = Mat3::Zero(); ///< IA^-1 frame: A's spin change per frame impulse
    Mat3 mSpinPerImpulseB = Mat3::Zero(); ///< IB^-1 frame
    Vec3 mTotalImpulse = Vec3::Zero();
    float mBound = 0.0f;
    bool mActive = false;
};

// Defined here so that JointStage, which calls them for every joint in every velocity iteration, inlines them
inline void AngularFrictionPart::Apply(SolverBody& ioA, SolverBody& ioB, const Vec3& inFrameImpulse) const
{
    ioA.mAngularVelocity -= mSpinPerImpulseA * inFrameImpulse;
    ioB.mAngularVelocity += mSpinPerImpulseB * inFrameImpulse;
}

inline void AngularFrictionPart::SolveVelocity(SolverBody& ioA, SolverBody& ioB)
{
    if (!mActive) return;
    const Vec3 impulse = -(mImpulsePerSpin * (ioB.mAngularVelocity - ioA.mAngularVelocity));
    const Vec3 total = (mTotalImpulse + impulse).cwiseMax(-mBound).cwiseMin(mBound);
    const Vec3 applied = total - mTotalImpulse;
    mTotalImpulse = total;
    Apply(ioA, ioB, applied);
}

} // namespace cairn::physics
