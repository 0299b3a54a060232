#include "cairn/physics/constraints/ConstraintInterface.h"

#include "cairn/physics/body/BodyLock.h"
#include "constraints/ConstraintManager.h"
#include "constraints/JointGeometry.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace cairn::physics
{

namespace
{
Error WrongThread()
{
    return {ErrorCode::WrongThread,
            "constraint calls are refused inside the physics step and while this thread "
            "holds a body lock"};
}
/// A joint of inType between the settings' two bodies, the rest of it as Joint starts it.
template <class Settings> Joint JointOf(JointType inType, const Settings& inSettings)
{
    Joint joint;
    joint.mType = inType;
    joint.mBodyA = inSettings.mBodyA;
    joint.mBodyB = inSettings.mBodyB;
    return joint;
}
Error StaleID()
{
    return {ErrorCode::InvalidArgument, "stale or unknown constraint id"};
}
/// A hinge or a slider: the joints with a motor and a position along their free motion.
bool HasMotor(const Joint& inJoint)
{
    return inJoint.mType == JointType::Hinge || inJoint.mType == JointType::Slider;
}
/// The checks a hinge's (inAngles) or a slider's motor needs; a message names the joint.
Status CheckMotor(const MotorSettings& inMotor, bool inAngles)
{
    constexpr float cMaxForce = 1.0e12f, cMaxSpeed = 1.0e4f, cMaxPlace = 1.0e6f;
    const char* joint = inAngles ? "hinge" : "slider";
    if (inMotor.mMode != MotorMode::Off && inMotor.mMode != MotorMode::Velocity &&
        inMotor.mMode != MotorMode::Position)
        return MakeError(ErrorCode::InvalidArgument, std::string(joint) + ": unknown motor mode");
    if (!(inMotor.mMaxForce >= 0.0f && inMotor.mMaxForce <= cMaxForce &&
          std::abs(inMotor.mTargetVelocity) <= cMaxSpeed))
        return MakeError(ErrorCode::InvalidArgument,
                         std::string(joint) +
                             ": a motor's force must be finite and at least 0, its speed finite");
    const float maxPlace = inAngles ? std::numbers::pi_v<float> + 1.0e-5f : cMaxPlace;
    if (!(std::abs(inMotor.mTargetPosition) <= maxPlace))
        return MakeError(ErrorCode::InvalidArgument,
                         std::string(joint) + (inAngles ? ": a motor's target angle must be within [-pi, pi]"
                                                        : ": a motor's target place must be finite"));
    if (inMotor.mMode == MotorMode::Position &&
        !(inMotor.mSpring.mFrequency > 0.0f && inMotor.mSpring.mFrequency <= 1.0e4f &&
          inMotor.mSpring.mDamping >= 0.0f && inMotor.mSpring.mDamping <= 1.0e4f))
        return MakeError(ErrorCode::InvalidArgument,
                         std::string(joint) +
                             ": a position motor's spring needs a frequency above 0 and a damping at least 0 "
                             "(both finite, at most 1e4)");
    return Status::Ok();
}
} // namespace

ConstraintInterface::ConstraintInterface(ConstraintManager& ioManager, BodyManager& ioBodies)
    : mManager(ioManager), mBodies(ioBodies)
{
}

void ConstraintInterface::WakeBody(const BodyID& inID)
{
    if (inID.IsInvalid()) return;
    BodyLockWrite lock(mBodies, inID);
    Body* body = lock.GetBody();
    if (body != nullptr && body->IsInWorld() && body->IsDynamic()) mBodies.ActivateBody(*body);
}

Result<ConstraintID> ConstraintInterface::Add(Joint& ioJoint, const Vec3& inPointA, const Vec3& inPointB)
{
    if (!BodyManager::MayTakeBodyLocks()) return WrongThread();
    if (!IsValidWorldPosition(inPointA) || !IsValidWorldPosition(inPointB))
        return MakeError(ErrorCode::InvalidArgument, "joint point is NaN, infinite or beyond the world");
    if (ioJoint.mBodyA.IsInvalid() && ioJoint.mBodyB.IsInvalid())
        return MakeError(ErrorCode::InvalidArgument, "a joint needs a body on at least one side");
    if (ioJoint.mBodyA == ioJoint.mBodyB)
        return MakeError(ErrorCode::InvalidArgument, "a joint joins two different bodies");
    ioJoint.mEnabled = true;
    // Each side's anchor in its centre-of-mass frame, from the body's pose now (one body lock at a time,
    // released before the joints' mutex: the step takes the body mutexes first)
    Quat rotationA = Quat::Identity(), rotationB = Quat::Identity();
    auto anchor = [&](const BodyID& inID, const Vec3& inPoint, Vec3& outLocal, Quat& outRotation) -> Status
    {
        if (inID.IsInvalid())
        {
            outLocal = inPoint;
            return Status::Ok();
        }
        BodyLockRead lock(mBodies, inID);
        if (lock.WasWrongThread()) return WrongThread();
        const Body* body = lock.GetBody();
        if (body == nullptr) return MakeError(ErrorCode::InvalidBodyID, "stale or unknown body id");
        outLocal = body->GetRotation().conjugate() * (inPoint - body->GetCenterOfMassPosition());
        outRotation = body->GetRotation();
        return Status::Ok();
    };
    if (Status a = anchor(ioJoint.mBodyA, inPointA, ioJoint.mLocalA, rotationA); !a) return a.GetError();
    if (Status b = anchor(ioJoint.mBodyB, inPointB, ioJoint.mLocalB, rotationB); !b) return b.GetError();
    ioJoint.mRelativeRotation = (rotationA.conjugate() * rotationB).normalized();
    // Directions given in world space into each body's frame (the world's side keeps them)
    ioJoint.mLocalAxisA = rotationA.conjugate() * ioJoint.mLocalAxisA;
    ioJoint.mLocalNormalA = rotationA.conjugate() * ioJoint.mLocalNormalA;
    ioJoint.mLocalAxisB = rotationB.conjugate() * ioJoint.mLocalAxisB;
    ioJoint.mLocalNormalB = rotationB.conjugate() * ioJoint.mLocalNormalB;
    ioJoint.mLocalFrameA = (rotationA.conjugate() * ioJoint.mLocalFrameA).normalized();
    ioJoint.mLocalFrameB = (rotationB.conjugate() * ioJoint.mLocalFrameB).normalized();
    ConstraintID id;
    {
        std::lock_guard lock(mManager.GetMutex());
        if (!mManager.Add(ioJoint, cMaxConstraints, id))
            return MakeError(ErrorCode::OutOfCapacity, "too many constraints");
    }
    WakeBody(ioJoint.mBodyA);
    WakeBody(ioJoint.mBodyB);
    return id;
}

Result<ConstraintID> ConstraintInterface::AddPoint(const PointConstraintSettings& inSettings)
{
    Joint joint = JointOf(JointType::Point, inSettings);
    return Add(joint, inSettings.mPoint, inSettings.mPoint);
}

Result<ConstraintID> ConstraintInterface::AddFixed(const FixedConstraintSettings& inSettings)
{
    Joint joint = JointOf(JointType::Fixed, inSettings);
    return Add(joint, inSettings.mPoint, inSettings.mPoint);
}

Result<ConstraintID> ConstraintInterface::AddHinge(const HingeConstraintSettings& inSettings)
{
    constexpr float cPi = std::numbers::pi_v<float>, cMaxTorque = 1.0e12f;
    const float axisLength = inSettings.mHingeAxis.norm();
    if (!(axisLength > 1.0e-6f && axisLength < 1.0e12f))
        return MakeError(ErrorCode::InvalidArgument, "a hinge axis must be finite and not zero");
    if (!(inSettings.mLimitsMin >= -cPi - 1.0e-5f && inSettings.mLimitsMin <= inSettings.mLimitsMax &&
          inSettings.mLimitsMax <= cPi + 1.0e-5f))
        return MakeError(ErrorCode::InvalidArgument, "hinge limits must be within [-pi, pi] with min <= max");
    if (!(inSettings.mMaxFrictionTorque >= 0.0f && inSettings.mMaxFrictionTorque <= cMaxTorque))
        return MakeError(ErrorCode::InvalidArgument,
                         "a hinge's friction torque must be finite and at least 0");
    if (Status motor = CheckMotor(inSettings.mMotor, true); !motor) return motor.GetError();
    Joint joint = JointOf(JointType::Hinge, inSettings);
    const Vec3 axis = inSettings.mHingeAxis / axisLength;
    const Vec3 normal = AnyPerpendicular(axis);
    joint.mLocalAxisA = joint.mLocalAxisB = axis; // World space here: Add turns them into the bodies' frames
    joint.mLocalNormalA = joint.mLocalNormalB = normal;
    joint.mLimitsMin = std::max(inSettings.mLimitsMin, -cPi);
    joint.mLimitsMax = std::min(inSettings.mLimitsMax, cPi);
    joint.mMaxFriction = inSettings.mMaxFrictionTorque;
    joint.mMotor = inSettings.mMotor;
    return Add(joint, inSettings.mPoint, inSettings.mPoint);
}

Result<ConstraintID> ConstraintInterface::AddSlider(const SliderConstraintSettings& inSettings)
{
    constexpr float cMaxForce = 1.0e12f;
    const float axisLength = inSettings.mSliderAxis.norm();
    if (!(axisLength > 1.0e-6f && axisLength < 1.0e12f))
        return MakeError(ErrorCode::InvalidArgument, "a slider axis must be finite and not zero");
    if (!(inSettings.mLimitsMin <= inSettings.mLimitsMax))
        return MakeError(ErrorCode::InvalidArgument, "slider limits must not be NaN, and min <= max");
    if (!(inSettings.mMaxFrictionForce >= 0.0f && inSettings.mMaxFrictionForce <= cMaxForce))
        return MakeError(ErrorCode::InvalidArgument,
                         "a slider's friction force must be finite and at least 0");
    if (Status motor = CheckMotor(inSettings.mMotor, false); !motor) return motor.GetError();
    Joint joint = JointOf(JointType::Slider, inSettings);
    joint.mLocalAxisA = joint.mLocalAxisB =
        inSettings.mSliderAxis / axisLength; // Add: into the bodies' frames
    // A limit beyond the world is none (and keeps the rows' errors finite)
    joint.mLimitsMin = std::max(inSettings.mLimitsMin, -cLargeFloat);
    joint.mLimitsMax = std::min(inSettings.mLimitsMax, cLargeFloat);
    joint.mMaxFriction = inSettings.mMaxFrictionForce;
    joint.mMotor = inSettings.mMotor;
    return Add(joint, inSettings.mPoint, inSettings.mPoint);
}

Result<ConstraintID> ConstraintInterface::AddSwingTwist(const SwingTwistConstraintSettings& inSettings)
{
    constexpr float cPi = std::numbers::pi_v<float>, cMaxTorque = 1.0e12f, cSlack = 1.0e-5f;
    const float twistLength = inSettings.mTwistAxis.norm(), planeLength = inSettings.mPlaneAxis.norm();
    if (!(twistLength > 1.0e-6f && twistLength < 1.0e12f && planeLength > 1.0e-6f && planeLength < 1.0e12f))
        return MakeError(ErrorCode::InvalidArgument, "swing-twist axes must be finite and not zero");
    const Vec3 twist = inSettings.mTwistAxis / twistLength;
    Vec3 plane = inSettings.mPlaneAxis / planeLength;
    if (!(std::abs(twist.dot(plane)) <= 1.0e-3f))
        return MakeError(ErrorCode::InvalidArgument, "swing-twist axes must be perpendicular");
    plane = (plane - twist.dot(plane) * twist).normalized(); // Exactly, for the frame
    if (!(inSettings.mNormalHalfConeAngle >= 0.0f && inSettings.mNormalHalfConeAngle <= cPi + cSlack &&
          inSettings.mPlaneHalfConeAngle >= 0.0f && inSettings.mPlaneHalfConeAngle <= cPi + cSlack))
        return MakeError(ErrorCode::InvalidArgument, "swing-twist half cone angles must be within [0, pi]");
    if (!(inSettings.mTwistMinAngle >= -cPi - cSlack &&
          inSettings.mTwistMinAngle <= inSettings.mTwistMaxAngle &&
          inSettings.mTwistMaxAngle <= cPi + cSlack))
        return MakeError(ErrorCode::InvalidArgument,
                         "swing-twist twist limits must be within [-pi, pi] with min <= max");
    if (!(inSettings.mMaxFrictionTorque >= 0.0f && inSettings.mMaxFrictionTorque <= cMaxTorque))
        return MakeError(ErrorCode::InvalidArgument,
                         "a swing-twist's friction torque must be finite and at least 0");
    Joint joint = JointOf(JointType::SwingTwist, inSettings);
    Mat3 frame;
    frame.col(0) = twist;
    frame.col(1) = plane;
    frame.col(2) = twist.cross(plane);
    joint.mLocalFrameA = joint.mLocalFrameB =
        Quat(frame); // World space here: Add turns them into the bodies'
    joint.mNormalHalfCone = std::min(inSettings.mNormalHalfConeAngle, cPi);
    joint.mPlaneHalfCone = std::min(inSettings.mPlaneHalfConeAngle, cPi);
    joint.mLimitsMin = std::max(inSettings.mTwistMinAngle, -cPi);
    joint.mLimitsMax = std::min(inSettings.mTwistMaxAngle, cPi);
    joint.mMaxFriction = inSettings.mMaxFrictionTorque;
    return Add(joint, inSettings.mPoint, inSettings.mPoint);
}

Result<ConstraintID> ConstraintInterface::AddDistance(const DistanceConstraintSettings& inSettings)
{
    // A distance or limit beyond this is not a joint but bad input (the world is smaller)
    constexpr float cMaxDistance = 1.0e6f;
    const float now = (inSettings.mPointB - inSettings.mPointA).norm();
    const float minDistance = inSettings.mMinDistance < 0.0f ? now : inSettings.mMinDistance;
    const float maxDistance = inSettings.mMaxDistance < 0.0f ? now : inSettings.mMaxDistance;
    if (!(minDistance >= 0.0f && minDistance <= maxDistance && maxDistance <= cMaxDistance))
        return MakeError(ErrorCode::InvalidArgument,
                         "distance limits must be finite, at least 0, at most 1e6 m and min <= max");
    const SpringSettings& spring = inSettings.mLimitsSpring;
    if (!(spring.mFrequency >= 0.0f && spring.mFrequency <= 1.0e4f && spring.mDamping >= 0.0f &&
          spring.mDamping <= 1.0e4f))
        return MakeError(ErrorCode::InvalidArgument,
                         "a spring's frequency and damping must be finite and at least 0 (at most 1e4)");
    Joint joint = JointOf(JointType::Distance, inSettings);
    joint.mMinDistance = minDistance;
    joint.mMaxDistance = maxDistance;
    joint.mSpring = spring;
    return Add(joint, inSettings.mPointA, inSettings.mPointB);
}

Status ConstraintInterface::SetMotor(ConstraintID inID, const MotorSettings& inMotor)
{
    if (!BodyManager::MayTakeBodyLocks()) return WrongThread();
    BodyID a, b;
    {
        std::lock_guard lock(mManager.GetMutex());
        Joint* joint = mManager.Find(inID);
        if (joint == nullptr) return StaleID();
        if (!HasMotor(*joint))
            return MakeError(ErrorCode::InvalidArgument, "only a hinge or a slider has a motor");
        if (Status motor = CheckMotor(inMotor, joint->mType == JointType::Hinge); !motor) return motor;
        joint->mMotor = inMotor;
        a = joint->mBodyA;
        b = joint->mBodyB;
    }
    // A door at rest asleep: it must wake to move
    WakeBody(a);
    WakeBody(b);
    return Status::Ok();
}

Result<float> ConstraintInterface::GetPosition(ConstraintID inID) const
{
    if (!BodyManager::MayTakeBodyLocks()) return WrongThread();
    Joint joint;
    {
        std::lock_guard lock(mManager.GetMutex());
        const Joint* found = mManager.Find(inID);
        if (found == nullptr) return StaleID();
        if (!HasMotor(*found))
            return MakeError(ErrorCode::InvalidArgument, "only a hinge or a slider has a position");
        joint = *found;
    }
    // Each side's rotation and anchor now (one body lock at a time, none with the joints' mutex)
    auto pose = [&](const BodyID& inID, const Vec3& inLocal, Quat& outRotation, Vec3& outAnchor) -> Status
    {
        outRotation = Quat::Identity();
        outAnchor = inLocal; // The world's side: its point
        if (inID.IsInvalid()) return Status::Ok();
        BodyLockRead lock(mBodies, inID);
        if (lock.WasWrongThread()) return WrongThread();
        const Body* body = lock.GetBody();
        if (body == nullptr) return MakeError(ErrorCode::InvalidBodyID, "a body of the joint is gone");
        outRotation = body->GetRotation();
        outAnchor = body->GetCenterOfMassPosition() + body->GetRotation() * inLocal;
        return Status::Ok();
    };
    Quat rotationA, rotationB;
    Vec3 anchorA, anchorB;
    if (Status a = pose(joint.mBodyA, joint.mLocalA, rotationA, anchorA); !a) return a.GetError();
    if (Status b = pose(joint.mBodyB, joint.mLocalB, rotationB, anchorB); !b) return b.GetError();
    return joint.mType == JointType::Hinge ? HingeAngle(joint, rotationA, rotationB)
                                           : SliderPlace(joint, anchorA, anchorB, rotationA);
}

Status ConstraintInterface::SetBreakThresholds(ConstraintID inID, float inForce, float inTorque)
{
    if (!BodyManager::MayTakeBodyLocks()) return WrongThread();
    if (!(inForce >= 0.0f) || !(inTorque >= 0.0f))
        return MakeError(ErrorCode::InvalidArgument,
                         "break thresholds must be at least 0 (cLargeFloat: never)");
    std::lock_guard lock(mManager.GetMutex());
    Joint* joint = mManager.Find(inID);
    if (joint == nullptr) return StaleID();
    joint->mBreakForce = std::min(inForce, cLargeFloat);
    joint->mBreakTorque = std::min(inTorque, cLargeFloat);
    return Status::Ok();
}

Result<std::vector<BrokenConstraint>> ConstraintInterface::TakeBrokenConstraints()
{
    if (!BodyManager::MayTakeBodyLocks()) return WrongThread();
    std::lock_guard lock(mManager.GetMutex());
    std::vector<BrokenConstraint> broken;
    broken.swap(mManager.GetBroken());
    return broken;
}

Status ConstraintInterface::Remove(ConstraintID inID)
{
    if (!BodyManager::MayTakeBodyLocks()) return WrongThread();
    BodyID a, b;
    {
        std::lock_guard lock(mManager.GetMutex());
        const Joint* joint = mManager.Find(inID);
        if (joint == nullptr) return StaleID();
        a = joint->mBodyA;
        b = joint->mBodyB;
        mManager.Remove(inID);
    }
    WakeBody(a);
    WakeBody(b);
    return Status::Ok();
}

Status ConstraintInterface::SetEnabled(ConstraintID inID, bool inEnabled)
{
    if (!BodyManager::MayTakeBodyLocks()) return WrongThread();
    BodyID a, b;
    {
        std::lock_guard lock(mManager.GetMutex());
        Joint* joint = mManager.Find(inID);
        if (joint == nullptr) return StaleID();
        if (inEnabled && !joint->mEnabled) // No warm start from before
        {
            joint->mPart.ResetImpulse();
            joint->mAxisPart.ResetImpulse();
            joint->mRotationPart.ResetImpulse();
            joint->mHingePart.ResetImpulse();
            joint->mLimitPart.ResetImpulse();
            joint->mMotorPart.ResetImpulse();
            joint->mLinePart.ResetImpulse();
            joint->mAxisMotorPart.ResetImpulse();
            joint->mSwingPart.ResetImpulse();
            joint->mFrictionPart.ResetImpulse();
        }
        joint->mEnabled = inEnabled;
        a = joint->mBodyA;
        b = joint->mBodyB;
    }
    WakeBody(a);
    WakeBody(b);
    return Status::Ok();
}

Result<bool> ConstraintInterface::IsEnabled(ConstraintID inID) const
{
    if (!BodyManager::MayTakeBodyLocks()) return WrongThread();
    std::lock_guard lock(mManager.GetMutex());
    const Joint* joint = mManager.Find(inID);
    if (joint == nullptr) return StaleID();
    return joint->mEnabled;
}

Result<uint32_t> ConstraintInterface::GetNumConstraints() const
{
    if (!BodyManager::MayTakeBodyLocks()) return WrongThread();
    std::lock_guard lock(mManager.GetMutex());
    return mManager.GetNumInUse();
}

} // namespace cairn::physics
