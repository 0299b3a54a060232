#pragma once

// The three linear rows that hold a point of body A on a point of body B: the ball-and-socket joint, and the
// translation half of the fixed, hinge and swing-twist joints (issue 33). Sequential impulses as the contacts
// (SequentialImpulseSolver.h): the velocity rows take the relative velocity of the two points to zero with
// one 3x3 effective mass (Catto, GDC 2009; Jolt and Box2D block-solve the point the same way), an impulse
// accumulated over the step and kept for the next one's warm start; the drift the velocity rows leave is
// taken out on the poses after integration (non-linear Gauss-Seidel, as the contacts' position iterations),
// never by a Baumgarte velocity that would add energy.
//
// Works on SolverBody blocks and world-space arms; a static or kinematic side has a zero inverse mass and
// inertia, so impulses leave it as it is. Threads: the one solving the island the joint is in; no locks.

#include "cairn/physics/math/Math.h"
#include "solver/SolverBody.h"

namespace cairn::physics
{

/// A body as a joint's rows see it: its inverse mass and world inverse inertia (both zero when it is not
/// dynamic).
struct JointBodyMass
{
    float mInverseMass = 0.0f;
    Mat3 mInverseInertia = Mat3::Zero();
};

/// The most one position iteration moves a joint's error (Box2D's maximum linear and angular corrections): a
/// joint made far from its pose, or torn open by a hard hit, closes over several iterations instead of
/// throwing its bodies.
inline constexpr float cMaxJointLinearCorrection = 0.2f;   ///< m
inline constexpr float cMaxJointAngularCorrection = 0.14f; ///< rad (8 degrees)
/// inStep with its length at most inMax.
template <class Vector> Vector ClampCorrection(const Vector& inStep, float inMax)
{
    const float length = inStep.norm();
    return length > inMax ? Vector(inStep * (inMax / length)) : inStep;
}
inline float ClampCorrection(float inStep, float inMax)
{
    return inStep > inMax ? inMax : inStep < -inMax ? -inMax : inStep;
}

/// The inverse of a joint's 3x3 mass matrix inK into outInverse; false (and zero) when it has none. Singular
/// relative to K's own scale, not by an absolute threshold: a heavy body's matrix is small, not singular.
bool InvertJointMassMatrix(const Mat3& inK, Mat3& outInverse);
/// The same for a pair of rows' 2x2 mass matrix (a hinge's axis rows, a slider's line rows).
bool InvertJointMassMatrix(const Eigen::Matrix2f& inK, Eigen::Matrix2f& outInverse);

class PointJointPart
{
public:
    /// Sets the rows for the arms inArmA and inArmB (world space, from each centre of mass to its anchor).
    /// The effective mass is zero, and the part inactive, when neither side can move (both static, or
    /// kinematic) or the 3x3 mass matrix cannot be inverted; the accumulated impulse is kept (warm start).
    void Prepare(const Vec3& inArmA, const JointBodyMass& inA, const Vec3& inArmB, const JointBodyMass& inB);
    bool IsActive() const { return mActive; }

    /// Applies the accumulated impulse, scaled by inRatio (1: the last step's as it was; 0: none).
    void WarmStart(SolverBody& ioA, SolverBody& ioB, float inRatio = 1.0f);
    /// One velocity iteration: the impulse that makes the two points move together, accumulated.
    void SolveVelocity(SolverBody& ioA, SolverBody& ioB);
    /// The impulse accumulated over this step's iterations (on B; A takes its opposite), N s.
    const Vec3& GetTotalImpulse() const { return mTotalImpulse; }
    void ResetImpulse() { mTotalImpulse.setZero(); }

    /// A position iteration's correction for the anchors at inAnchorA and inAnchorB (world space, after
    /// integration, with the arms Prepare was given): the translations and rotation vectors that move the
    /// two bodies so that inFraction of the gap closes (to first order in the rotation). Zero when inactive.
    struct PoseCorrection
    {
        Vec3 mTranslationA = Vec3::Zero();
        Vec3 mRotationA = Vec3::Zero();
        Vec3 mTranslationB = Vec3::Zero();
        Vec3 mRotationB = Vec3::Zero();
    };
    PoseCorrection CorrectPositions(const Vec3& inAnchorA, const Vec3& inAnchorB, float inFraction) const;

private:
    void Apply(SolverBody& ioA, SolverBody& ioB, const Vec3& inImpulse) const;

    Vec3 mArmA = Vec3::Zero();
    Vec3 mArmB = Vec3::Zero();
    JointBodyMass mA;
    JointBodyMass mB;
    Mat3 mEffectiveMass = Mat3::Zero(); ///< The inverse of the 3x3 mass matrix K
    Vec3 mTotalImpulse = Vec3::Zero();
    bool mActive = false;
};

// Defined here so that JointStage, which calls them for every joint in every velocity iteration, inlines them
inline void PointJointPart::Apply(SolverBody& ioA, SolverBody& ioB, const Vec3& inImpulse) const
{
    ioA.mLinearVelocity -= mA.mInverseMass * inImpulse;
    ioA.mAngularVelocity -= mA.mInverseInertia * mArmA.cross(inImpulse);
    ioB.mLinearVelocity += mB.mInverseMass * inImpulse;
    ioB.mAngularVelocity += mB.mInverseInertia * mArmB.cross(inImpulse);
}

inline void PointJointPart::SolveVelocity(SolverBody& ioA, SolverBody& ioB)
{
    if (!mActive) return;
    const Vec3 relative = ioB.mLinearVelocity + ioB.mAngularVelocity.cross(mArmB) - ioA.mLinearVelocity -
                          ioA.mAngularVelocity.cross(mArmA);
    const Vec3 impulse = -(mEffectiveMass * relative);
    mTotalImpulse += impulse;
    Apply(ioA, ioB, impulse);
}

} // namespace cairn::physics
