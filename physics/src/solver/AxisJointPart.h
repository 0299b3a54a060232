#pragma once

// One linear row along an axis between a point of A and a point of B: the distance joint's length, its limits
// and its spring (issue 33), the slider's limit, and (PrepareMotor) the slider's motor or friction. Hard, the
// row is a sequential impulse with the drift taken out on the poses (as PointJointPart); soft (a spring of a
// frequency and damping ratio), it is the soft step of Catto (GDC 2011) and Box2D v3: the impulse that an
// implicit Euler step of the spring and damper gives, v' = (v - h w^2 C) / (1 + 2 z h w + h^2 w^2) along the
// axis for the row's effective mass, with no position pass. A limit pushes one way only: the accumulated
// impulse is clamped to its side.
//
// Threads: the one solving the island the joint is in; no locks.

#include "solver/PointJointPart.h"

#include <algorithm>

namespace cairn::physics
{

/// Box2D v3's b2MakeSoft, Catto's soft step (GDC 2011): the implicit Euler step of a spring of frequency f
/// and damping ratio z on a row's effective mass m gives the impulse -mMassScale m (v + mBiasPerError C) -
/// mImpulseScale (the impulse accumulated so far) for the speed v and error C.
struct SoftStep
{
    float mBiasPerError = 0.0f;
    float mMassScale = 1.0f;
    float mImpulseScale = 0.0f;
    static SoftStep Of(float inFrequency, float inDamping, float inDeltaTime);
};

class AxisJointPart
{
public:
    /// Which impulses the row may apply along the axis (on B; A takes the opposite).
    enum class Side : uint8_t
    {
        Both,     ///< An equality: the length itself
        Positive, ///< A lower limit: B pushed away from A only
        Negative, ///< An upper limit: B pulled towards A only
    };
    /// inTotal kept on the side a row of inSide may push (unchanged for Both).
    static float ClampToSide(float inTotal, Side inSide)
    {
        return inSide == Side::Positive   ? std::max(inTotal, 0.0f)
               : inSide == Side::Negative ? std::min(inTotal, 0.0f)
                                          : inTotal;
    }
    /// Whether a row of inSide pushes against the error inError: too short (or too little turned) for a
    /// lower limit, too long for an upper one, either way for an equality.
    static bool PushesAgainst(Side inSide, float inError)
    {
        return !((inSide == Side::Positive && inError >= 0.0f) ||
                 (inSide == Side::Negative && inError <= 0.0f));
    }
    /// A hard limit row's velocity bias: for a limit not reached yet (inError on its allowed side), the rate
    /// that closes the gap left in the step of inDeltaTime (speculative); none past it or for an equality.
    static float SpeculativeBias(Side inSide, float inError, float inDeltaTime)
    {
        return inSide != Side::Both && !PushesAgainst(inSide, inError) && inDeltaTime > 0.0f
                   ? inError / inDeltaTime
                   : 0.0f;
    }
    /// The side and error of a row that keeps inValue within [inMin, inMax]: an equality when they are equal,
    /// else the limit it is past or within inBand of (the error then on the allowed side: the row lets it
    /// close the rest of the way in the step, see Prepare); false (no row) while it is further within.
    static bool LimitRow(float inValue, float inMin, float inMax, float inBand, Side& outSide,
                         float& outError)
    {
        if (inMin == inMax)
            outSide = Side::Both;
        else if (inValue < inMin + inBand && inValue - inMin <= inMax - inValue)
            outSide = Side::Positive;
        else if (inValue > inMax - inBand)
            outSide = Side::Negative;
        else
            return false;
        outError = inValue - (outSide == Side::Negative ? inMax : inMin);
        return true;
    }

    /// Sets the row along inAxis (unit, world space) for the arms and masses given, with the position error
    /// inError (the length now less the length wanted, m). inFrequency > 0 (Hz) makes it a spring with the
    /// damping ratio inDamping; 0 a hard row. A hard limit not reached yet (the error on its allowed side) is
    /// speculative: it lets the bodies close the gap in this step, and no more (a row that waits until the
    /// limit is passed lets them through it, and the position pass moves them back without their speed).
    /// Inactive (and its impulse dropped) when neither side can move.
    void Prepare(const Vec3& inArmA, const JointBodyMass& inA, const Vec3& inArmB, const JointBodyMass& inB,
                 const Vec3& inAxis, float inError, Side inSide, float inFrequency, float inDamping,
                 float inDeltaTime);
    /// A motor or friction row instead (the slider's): the relative speed along inAxis (unit) taken towards
    /// inTargetSpeed (m/s), the accumulated impulse kept within [inMinImpulse, inMaxImpulse] (N s: a force's
    /// bound times the step). No position pass.
    void PrepareMotor(const Vec3& inArmA, const JointBodyMass& inA, const Vec3& inArmB,
                      const JointBodyMass& inB, const Vec3& inAxis, float inTargetSpeed, float inMinImpulse,
                      float inMaxImpulse);
    /// A position motor's row: a spring of inFrequency (Hz, above 0) and damping ratio inDamping pulling the
    /// error inError (m: the place less the target) to zero, within [inMinImpulse, inMaxImpulse].
    void PrepareSpringMotor(const Vec3& inArmA, const JointBodyMass& inA, const Vec3& inArmB,
                            const JointBodyMass& inB, const Vec3& inAxis, float inError, float inFrequency,
                            float inDamping, float inDeltaTime, float inMinImpulse, float inMaxImpulse);
    /// No row this step (a limit not reached, no motor, no friction): its impulse dropped.
    void Deactivate()
    {
        mActive = false;
        mTotalImpulse = 0.0f;
    }
    bool IsActive() const { return mActive; }
    bool IsSoft() const { return mSoft; }

    void WarmStart(SolverBody& ioA, SolverBody& ioB, float inRatio = 1.0f);
    void SolveVelocity(SolverBody& ioA, SolverBody& ioB);
    /// N s, along the axis, on B
    float GetTotalImpulse() const { return mTotalImpulse; }
    void ResetImpulse() { mTotalImpulse = 0.0f; }

    /// A hard row's position iteration for the error inError now (the same sign rules): the moves that take
    /// inFraction of it out. Zero for a soft or inactive row, or an error on the side the row allows.
    PointJointPart::PoseCorrection CorrectPositions(float inError, float inFraction) const;

private:
    void Apply(SolverBody& ioA, SolverBody& ioB, float inImpulse) const;
    /// Makes the prepared row a motor's: its accumulated impulse within [inMinImpulse, inMaxImpulse], no
    /// position pass.
    void BoundAsMotor(float inMinImpulse, float inMaxImpulse);

    Vec3 mAxis = Vec3::UnitX();
    Vec3 mAngularA = Vec3::Zero(); ///< inv inertia A (rA x n)
    Vec3 mAngularB = Vec3::Zero(); ///< inv inertia B (rB x n)
    Vec3 mArmCrossA = Vec3::Zero();
    Vec3 mArmCrossB = Vec3::Zero();
    float mInverseMassA = 0.0f;
    float mInverseMassB = 0.0f;
    float mEffectiveMass = 0.0f;
    float mBias = 0.0f;         ///< Soft: the spring's velocity bias
    float mMassScale = 1.0f;    ///< Soft: of the effective mass
    float mImpulseScale = 0.0f; ///< Soft: of the accumulated impulse
    float mTotalImpulse = 0.0f;
    float mMinImpulse = -cLargeFloat; ///< A motor's bounds on the accumulated impulse (a limit's: none)
    float mMaxImpulse = cLargeFloat;
    Side mSide = Side::Both;
    bool mSoft = false;
    bool mMotor = false;
    bool mActive = false;
};

} // namespace cairn::physics
