#pragma once

// The two linear rows that keep a point of body B on a line through a point of body A (the slider joint's,
// issue 33): for the two directions n1, n2 across the line's axis (fixed in A), u . n1 = u . n2 = 0, where u
// is B's point less A's. A row's rate is the relative velocity of the two points along n_i, A's point taken
// at B's (its arm r_A + u: A turning swings the line under B's point). One 2x2 effective mass for the two
// (Jolt block-solves its slider's two axes the same way), an accumulated impulse for the warm start, and
// position rows that move B's point back onto the line after integration. Motion along the axis stays free.
//
// Threads: the one solving the island the joint is in; no locks.

#include "solver/PointJointPart.h"

#include <Eigen/Core>

namespace cairn::physics
{

class LineJointPart
{
public:
    /// inArmA: A's centre of mass to B's point (r_A + u); inArmB: B's to its point; inAxis: the line's
    /// direction now (unit, world space, turning with A); inOffset: u, B's point less A's. Inactive (its
    /// impulse dropped) when neither side can move.
    void Prepare(const Vec3& inArmA, const JointBodyMass& inA, const Vec3& inArmB, const JointBodyMass& inB,
                 const Vec3& inAxis, const Vec3& inOffset);
    bool IsActive() const { return mActive; }
    void WarmStart(SolverBody& ioA, SolverBody& ioB, float inRatio = 1.0f);
    void SolveVelocity(SolverBody& ioA, SolverBody& ioB);
    void ResetImpulse() { mTotalImpulse.setZero(); }
    /// The impulse accumulated this step across the line, on B (N s, world space).
    Vec3 GetTotalImpulse() const { return mAcross[0] * mTotalImpulse[0] + mAcross[1] * mTotalImpulse[1]; }
    /// A position iteration on the offset Prepare was given: the moves that take inFraction of its part
    /// across the line out (to first order in the rotations).
    PointJointPart::PoseCorrection CorrectPositions(float inFraction) const;

private:
    void Apply(SolverBody& ioA, SolverBody& ioB, const Eigen::Vector2f& inImpulse) const;

    JointBodyMass mA;
    JointBodyMass mB;
    Vec3 mAcross[2];    ///< n1, n2
    Vec3 mArmCrossA[2]; ///< (r_A + u) x n_i
    Vec3 mArmCrossB[2]; ///< r_B x n_i
    float mError[2]{};  ///< u . n_i
    Eigen::Matrix2f mEffectiveMass = Eigen::Matrix2f::Zero();
    Eigen::Vector2f mTotalImpulse = Eigen::Vector2f::Zero();
    bool mActive = false;
};

} // namespace cairn::physics
