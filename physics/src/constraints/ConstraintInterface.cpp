#include "cairn/physics/constraints/ConstraintInterface.h"

#include "cairn/physics/body/BodyLock.h"
#include "constraints/ConstraintManager.h"

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
bool IsWrongThread()
{
    return BodyManager::IsInsideStep() || BodyManager::GetBodyLocksHeldByThisThread() > 0;
}
Error StaleID()
{
    return {ErrorCode::InvalidArgument, "stale or unknown constraint id"};
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

Result<ConstraintID> ConstraintInterface::AddPoint(const PointConstraintSettings& inSettings)
{
    if (IsWrongThread()) return WrongThread();
    if (!IsValidWorldPosition(inSettings.mPoint))
        return MakeError(ErrorCode::InvalidArgument, "joint point is NaN, infinite or beyond the world");
    if (inSettings.mBodyA.IsInvalid() && inSettings.mBodyB.IsInvalid())
        return MakeError(ErrorCode::InvalidArgument, "a joint needs a body on at least one side");
    if (inSettings.mBodyA == inSettings.mBodyB)
        return MakeError(ErrorCode::InvalidArgument, "a joint joins two different bodies");
    Joint joint;
    joint.mEnabled = true;
    joint.mBodyA = inSettings.mBodyA;
    joint.mBodyB = inSettings.mBodyB;
    // Each side's anchor in its centre-of-mass frame, from the body's pose now (one body lock at a time,
    // released before the joints' mutex: the step takes the body mutexes first)
    auto anchor = [&](const BodyID& inID, Vec3& outLocal) -> Status
    {
        if (inID.IsInvalid())
        {
            outLocal = inSettings.mPoint;
            return Status::Ok();
        }
        BodyLockRead lock(mBodies, inID);
        if (lock.WasWrongThread()) return WrongThread();
        const Body* body = lock.GetBody();
        if (body == nullptr) return MakeError(ErrorCode::InvalidBodyID, "stale or unknown body id");
        outLocal = body->GetRotation().conjugate() * (inSettings.mPoint - body->GetCenterOfMassPosition());
        return Status::Ok();
    };
    if (Status a = anchor(joint.mBodyA, joint.mLocalA); !a) return a.GetError();
    if (Status b = anchor(joint.mBodyB, joint.mLocalB); !b) return b.GetError();
    ConstraintID id;
    {
        std::lock_guard lock(mManager.GetMutex());
        if (!mManager.Add(joint, cMaxConstraints, id))
            return MakeError(ErrorCode::OutOfCapacity, "too many constraints");
    }
    WakeBody(joint.mBodyA);
    WakeBody(joint.mBodyB);
    return id;
}

Status ConstraintInterface::Remove(ConstraintID inID)
{
    if (IsWrongThread()) return WrongThread();
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
    if (IsWrongThread()) return WrongThread();
    BodyID a, b;
    {
        std::lock_guard lock(mManager.GetMutex());
        Joint* joint = mManager.Find(inID);
        if (joint == nullptr) return StaleID();
        if (inEnabled && !joint->mEnabled) joint->mPart.ResetImpulse(); // No warm start from before
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
    if (IsWrongThread()) return WrongThread();
    std::lock_guard lock(mManager.GetMutex());
    const Joint* joint = mManager.Find(inID);
    if (joint == nullptr) return StaleID();
    return joint->mEnabled;
}

Result<uint32_t> ConstraintInterface::GetNumConstraints() const
{
    if (IsWrongThread()) return WrongThread();
    std::lock_guard lock(mManager.GetMutex());
    return mManager.GetNumInUse();
}

} // namespace cairn::physics
