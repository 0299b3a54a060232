#pragma once

// The two angular rows that keep body B's hinge axis on body A's (the hinge joint's, with PointJointPart for
// the point): for the two directions b2, b3 perpendicular to B's axis b1, a1 . b2 = a1 . b3 = 0, whose rate
// is the relative spin along b_i x a1. One 2x2 effective mass, an accumulated impulse for the warm start, and
// position rows that turn the axes back together after integration. The spin about the axis stays free.
//
// Threads: the one solving the island the joint is in; no locks.

#include "solver/PointJointPart.h"

#include <Eigen/Core>

namespace cairn::physics
{

class HingeRotationJointPart
{
public:
    /// inAxisA, inAxisB: each body's hinge axis in world space now (unit).
    void Prepare(const JointBodyMass& inA, const JointBodyMass& inB, const Vec3& inAxisA,
                 const Vec3& inAxisB);
    bool IsActive() const { return mActive; }
    void WarmStart(SolverBody& ioA, SolverBody& ioB, float inRatio = 1.0f);
    void SolveVelocity(SolverBody& ioA, SolverBody& ioB);
    void ResetImpulse() { mTotalImpulse.setZero(); }
    /// The angular impulse accumulated this step on B (N m s, world space).
    Vec3 GetTotalImpulse() const { return mRow[0] * mTotalImpulse[0] + mRow[1] * mTotalImpulse[1]; }
    /// A position iteration on the axes Prepare was given: the turns that take inFraction of their
    /// misalignment out (to first order).
    PointJointPart::PoseCorrection CorrectPositions(float inFraction) const;

private:
    void Apply(SolverBody& ioA, SolverBody& ioB, const Eigen::Vector2f& inImpulse) const;

    JointBodyMass mA;
    JointBodyMass mB;
    Vec3 mRow[2];      ///< b_i x a1
    float mError[2]{}; ///< a1 . b_i
    Eigen::Matrix2f mEffectiveMass = Eigen::Matrix2f::Zero();
    Eigen::Vector2f mTotalImpulse = Eigen::Vector2f::Zero();
    bool mActive = false;
};

} // namespace cairn::physics
