#pragma once

// ConstraintManager: the joints, in slots that ids name (ConstraintID: slot and generation).
// Threads: ConstraintInterface's calls, from any thread, under mMutex. The physics step, on the updating
// thread and its jobs, while PhysicsSystem::Update holds mMutex for the whole Update (taken after the body
// mutexes; the interface never holds a body lock and this mutex at once): it reads the slots, and writes a
// joint's part (its impulse, kept for the next step's warm start) only from the thread that solves the
// joint's island.

#include "cairn/physics/constraints/ConstraintInterface.h"
#include "solver/AngleJointPart.h"
#include "solver/AngularFrictionPart.h"
#include "solver/AxisJointPart.h"
#include "solver/HingeRotationJointPart.h"
#include "solver/LineJointPart.h"
#include "solver/PointJointPart.h"
#include "solver/RotationJointPart.h"

#include <mutex>
#include <vector>

namespace cairn::physics
{

enum class JointType : uint8_t
{
    Point,
    Distance,
    Fixed,
    Hinge,
    Slider,
    SwingTwist,
};

struct Joint
{
    JointType mType = JointType::Point;
    uint32_t mSequence = 0;
    bool mInUse = false;
    bool mEnabled = false;
    BodyID mBodyA; ///< Invalid: the world
    BodyID mBodyB;
    /// The anchor in each body's centre-of-mass frame (in world space for the world's side)
    Vec3 mLocalA = Vec3::Zero();
    Vec3 mLocalB = Vec3::Zero();
    PointJointPart mPart; ///< Point, fixed, hinge
    /// B's rotation in A's frame at creation (A's: the world's for the world's side)
    Quat mRelativeRotation = Quat::Identity();
    RotationJointPart mRotationPart; ///< Fixed, slider
    // Distance
    float mMinDistance = 0.0f;
    float mMaxDistance = 0.0f;
    SpringSettings mSpring;
    AxisJointPart mAxisPart; ///< Distance; the slider's limit
    // Hinge and slider: the axis and a direction across it in each body's frame (given in world space until
    // the joint is stored), the limits (rad for a hinge, m for a slider), friction and motor (torques and
    // rad/s for a hinge, forces and m/s for a slider)
    Vec3 mLocalAxisA = Vec3::Zero();
    Vec3 mLocalAxisB = Vec3::Zero();
    Vec3 mLocalNormalA = Vec3::Zero();
    Vec3 mLocalNormalB = Vec3::Zero();
    float mLimitsMin = 0.0f;
    float mLimitsMax = 0.0f;
    float mMaxFriction = 0.0f;
    MotorSettings mMotor;
    // Breaking: the thresholds (N, N m) and what the last step held
    float mBreakForce = cLargeFloat;
    float mBreakTorque = cLargeFloat;
    HingeRotationJointPart mHingePart;
    AngleJointPart mLimitPart;
    AngleJointPart mMotorPart; ///< The hinge's motor, or its friction while the motor is off
    LineJointPart mLinePart;   ///< Slider
    // Swing-twist: the joint's frame (x twist, y plane, z normal) in each body's frame (given in world space
    // until the joint is stored; the world's side keeps it), the cone's half angles (the twist's range is in
    // mLimitsMin and mLimitsMax, its friction in mMaxFriction)
    Quat mLocalFrameA = Quat::Identity();
    Quat mLocalFrameB = Quat::Identity();
    float mNormalHalfCone = 0.0f;
    float mPlaneHalfCone = 0.0f;
    AngleJointPart mSwingPart;         ///< The cone, while the swing is past it
    AngularFrictionPart mFrictionPart; ///< About the frame's axes
    AxisJointPart mAxisMotorPart;      ///< The slider's motor, or its friction while the motor is off
};

class ConstraintManager
{
public:
    std::mutex& GetMutex() const { return mMutex; }

    // Under the mutex:
    /// The joint inID names, or null for a stale or unknown id.
    Joint* Find(ConstraintID inID)
    {
        if (inID.GetIndex() >= mJoints.size()) return nullptr;
        Joint& joint = mJoints[inID.GetIndex()];
        return joint.mInUse && joint.mSequence == inID.GetSequence() ? &joint : nullptr;
    }
    /// Stores inJoint in a free slot (the lowest freed first, else a new one); false when full.
    bool Add(Joint inJoint, uint32_t inMaxJoints, ConstraintID& outID)
    {
        if (mNumInUse >= inMaxJoints) return false;
        uint32_t index = uint32_t(mJoints.size());
        if (!mFree.empty())
        {
            index = mFree.back();
            mFree.pop_back();
        }
        else
            mJoints.emplace_back();
        inJoint.mSequence = mJoints[index].mSequence + 1; // A new generation: the slot's old ids go stale
        inJoint.mInUse = true;
        mJoints[index] = inJoint;
        ++mNumInUse;
        outID = ConstraintID(index, inJoint.mSequence);
        return true;
    }
    void Remove(ConstraintID inID)
    {
        Joint& joint = mJoints[inID.GetIndex()];
        joint.mInUse = false;
        mFree.push_back(inID.GetIndex());
        --mNumInUse;
    }
    uint32_t GetNumInUse() const { return mNumInUse; }
    /// The joints broken and not yet taken (the step appends, TakeBrokenConstraints empties it)
    std::vector<BrokenConstraint>& GetBroken() { return mBroken; }
    /// Every slot, in use or not (the step walks them in slot order: the same order on every run).
    std::vector<Joint>& GetJoints() { return mJoints; }

private:
    mutable std::mutex mMutex;
    std::vector<Joint> mJoints;
    std::vector<uint32_t> mFree;
    uint32_t mNumInUse = 0;
    std::vector<BrokenConstraint> mBroken;
};

} // namespace cairn::physics
