#pragma once

// The three angular rows that keep body B's rotation relative to body A's as it was (the fixed joint's, with
// PointJointPart for the translation; later the slider's). Sequential impulses on the relative angular
// velocity with the 3x3 effective mass K = IA^-1 + IB^-1, an accumulated impulse for the warm start, and
// position rows that turn the bodies back by part of the rotation error after integration.
//
// Threads: the one solving the island the joint is in; no locks.

#include "solver/PointJointPart.h"

namespace cairn::physics
{

class RotationJointPart
{
public:
    /// Inactive when neither side can turn (K not invertible).
    void Prepare(const JointBodyMass& inA, const JointBodyMass& inB);
    bool IsActive() const { return mActive; }
    void WarmStart(SolverBody& ioA, SolverBody& ioB, float inRatio = 1.0f);
    void SolveVelocity(SolverBody& ioA, SolverBody& ioB);
    const Vec3& GetTotalImpulse() const { return mTotalImpulse; }
    void ResetImpulse() { mTotalImpulse.setZero(); }

    /// The rotation error of B against A: the rotation vector (world space) that turns B from where
    /// inRelative (B's rotation in A's frame, as the joint keeps it) puts it to where it is.
    static Vec3 RotationError(const Quat& inRotationA, const Quat& inRotationB, const Quat& inRelative);
    /// A position iteration: the turns that take inFraction of inError out (to first order). Zero if
    /// inactive.
    PointJointPart::PoseCorrection CorrectPositions(const Vec3& inError, float inFraction) const;

private:
    JointBodyMass mA;
    JointBodyMass mB;
    Mat3 mEffectiveMass = Mat3::Zero();
    Vec3 mTotalImpulse = Vec3::Zero();
    bool mActive = false;
};

} // namespace cairn::physics
