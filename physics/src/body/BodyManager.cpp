#include "cairn/physics/body/BodyManager.h"

#include "PublishedPoseStore.h"
#include "body/StepCallbackScope.h"
#include "cairn/physics/LockWaits.h"
#include "cairn/physics/PhysicsSettings.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <memory>
#include <new>
#include <string>

namespace cairn::physics
{

namespace
{
// Set on the stepping thread while it holds every body mutex, and on a step's job thread while it runs a game
// callback (StepCallbackScope); read only by that same thread
thread_local bool tInsideStep = false;
// Body locks this thread holds through BodyLock; read and written only by that same thread
thread_local uint32_t tBodyLocksHeld = 0;

Status ValidateSettings(const BodyCreationSettings& inSettings)
{
    auto invalid = [](std::string inWhat)
    { return Status(MakeError(ErrorCode::InvalidArgument, std::move(inWhat))); };
    if (inSettings.mShape == nullptr) return invalid("body has no shape");
    if (!IsValidWorldPosition(inSettings.mPosition))
        return invalid("body position is NaN, infinite or beyond 1e6 m");
    if (!IsValidRotation(inSettings.mRotation))
        return invalid("body rotation is not a finite unit quaternion");
    if (!IsFiniteLength(inSettings.mLinearVelocity) || !IsFiniteLength(inSettings.mAngularVelocity))
        return invalid("body velocity is NaN, infinite or too large to square");
    if (!std::isfinite(inSettings.mFriction) || inSettings.mFriction < 0.0f)
        return invalid("friction must be finite and >= 0");
    if (!(inSettings.mRestitution >= 0.0f && inSettings.mRestitution <= 1.0f))
        return invalid("restitution must be in [0, 1]");
    if (!(inSettings.mLinearDamping >= 0.0f) || !(inSettings.mAngularDamping >= 0.0f) ||
        !std::isfinite(inSettings.mLinearDamping) || !std::isfinite(inSettings.mAngularDamping))
        return invalid("damping must be finite and >= 0");
    if (!(std::abs(inSettings.mGravityFactor) <= 1e3f))
        return invalid("gravity factor must be in [-1e3, 1e3]");
    // Finite limits keep every body's speed finite, kinematic ones included (a step at most moves it by them)
    if (!(inSettings.mMaxLinearVelocity > 0.0f && inSettings.mMaxLinearVelocity <= 1e5f) ||
        !(inSettings.mMaxAngularVelocity > 0.0f && inSettings.mMaxAngularVelocity <= 1e5f))
        return invalid("velocity limits must be in (0, 1e5] m/s and rad/s");
    // A value outside the enum would be a body that is none of the three (never integrated, yet active) and
    // would spill out of its two bits into the layer of its published pose
    if (!IsValidMotionType(inSettings.mMotionType)) return invalid("motion type is not a MotionType");
    if (inSettings.mMotionQuality != MotionQuality::Discrete &&
        inSettings.mMotionQuality != MotionQuality::LinearCast)
        return invalid("motion quality is not a MotionQuality");
    const CollisionGroup& group = inSettings.mCollisionGroup;
    if (group.mSubGroupID >=
        (group.mFilter != nullptr ? group.mFilter->GetNumSubGroups() : GroupFilterTable::cMaxSubGroups))
        return invalid("collision sub-group is beyond its group's filter table (or 4096 without one)");
    const AABB bounds = inSettings.mShape->GetWorldBounds({inSettings.mPosition, inSettings.mRotation});
    if (!bounds.IsFinite()) return invalid("body bounds are not finite");
    // An empty or inverted box (a shape built around its checked Create) would be dropped by the broad phase
    if (bounds.IsEmpty()) return invalid("body bounds are empty: the shape has no extent");
    if (inSettings.mMotionType == MotionType::Dynamic)
        return Body::CheckDynamicMass(*inSettings.mShape, inSettings.mDensity);
    return Status::Ok();
}
} // namespace

bool BodyManager::BodiesCollide(const Body& inA, const Body& inB) const
{
    const uint32_t group = inA.GetCollisionGroupID();
    if (group == CollisionGroup::cNoGroup || group != inB.GetCollisionGroupID()) return true;
    const GroupFilterTable* table = mGroupFilters[inA.GetID().GetIndex()] != nullptr
                                        ? mGroupFilters[inA.GetID().GetIndex()].get()
                                        : mGroupFilters[inB.GetID().GetIndex()].get();
    return table != nullptr && table->CanCollide(inA.GetCollisionSubGroupID(), inB.GetCollisionSubGroupID());
}

namespace
{
/// Memory for inCount objects, none constructed. Not value-initialized: the pages of slots a world never uses
/// are never written, so they take no memory.
template <class T> T* AllocateSlots(uint32_t inCount)
{
    return static_cast<T*>(::operator new(size_t(inCount) * sizeof(T), std::align_val_t(alignof(T))));
}
} // namespace

BodyManager::BodyManager(uint32_t inMaxBodies, uint32_t inNumMutexes)
    : mMaxBodies(std::clamp(inMaxBodies, 1u, PhysicsSettings::cMaxBodiesLimit)),
      mMutexMask(std::bit_floor(std::clamp(inNumMutexes, 1u, cNumBodyMutexes)) - 1),
      mBodies(AllocateSlots<Body>(mMaxBodies)), mSlotInUse(new bool[mMaxBodies]()),
      mGroupFilters(AllocateSlots<std::shared_ptr<const GroupFilterTable>>(mMaxBodies)),
      mPoses(std::make_unique<PublishedPoseStore>(mMaxBodies))
{
    // Reserved whole, so that DestroyBody's push never allocates
    mFreeList.reserve(mMaxBodies);
    mActiveBodies.reserve(mMaxBodies);
}

BodyManager::~BodyManager()
{
    std::destroy_n(mBodies.get(), mSlotsConstructed);
    std::destroy_n(mGroupFilters.get(), mSlotsConstructed);
}

uint32_t BodyManager::GetNumBodies() const
{
    const auto lock = LockedCountingWait(mFreeListMutex, LockKind::Body);
    return mNumBodies;
}

Result<BodyID> BodyManager::CreateBody(const BodyCreationSettings& inSettings)
{
    if (Status status = ValidateSettings(inSettings); !status) return status.GetError();
    if (!MayTakeBodyLocks())
        return MakeError(ErrorCode::WrongThread,
                         "CreateBody called inside the physics step or while holding a body lock");

    uint32_t index;
    {
        const auto lock = LockedCountingWait(mFreeListMutex, LockKind::Body);
        // A freed slot first (its memory is warm), else the lowest never used: low indices pack the hot part
        // of the array
        if (!mFreeList.empty())
        {
            index = mFreeList.back();
            mFreeList.pop_back();
        }
        else if (mSlotsConstructed < mMaxBodies)
        {
            // Constructed here, so that slots [0, mSlotsConstructed) always hold a Body, its ids from
            // sequence 0. No body lock: nothing reads a slot before CreateBody marks it in use, under the
            // body's locks
            index = mSlotsConstructed;
            std::construct_at(&mBodies[index])->mID = BodyID(index, 0);
            std::construct_at(&mGroupFilters[index]);
            ++mSlotsConstructed;
        }
        else
            return MakeError(ErrorCode::OutOfCapacity,
                             "body manager is full (" + std::to_string(mMaxBodies) + " bodies)");
        ++mNumBodies;
    }

    const auto lock = LockedCountingWait(GetMutexForBody(index), LockKind::Body);
    const auto staticLock = LockedCountingWait(GetStaticMutexForBody(index), LockKind::Body);
    Body& body = mBodies[index];
    const BodyID id(index, body.mID.GetSequence());
    body.Init(id, inSettings);
    mGroupFilters[index] = inSettings.mCollisionGroup.mFilter;
    mSlotInUse[index] = true;
    mPoses->Publish(body);
    return id;
}

Status BodyManager::DestroyBody(const BodyID& inID)
{
    if (!MayTakeBodyLocks())
        return MakeError(ErrorCode::WrongThread,
                         "DestroyBody called inside the physics step or while holding a body lock");
    if (inID.IsInvalid() || inID.GetIndex() >= mMaxBodies)
        return MakeError(ErrorCode::InvalidBodyID, "unknown body id");
    ShapeRef shape; // Kept until no query can be using it
    {
        const auto lock = LockedCountingWait(GetMutexForBody(inID.GetIndex()), LockKind::Body);
        const auto staticLock = LockedCountingWait(GetStaticMutexForBody(inID.GetIndex()), LockKind::Body);
        Body* body = TryGetBody(inID);
        if (body == nullptr) return MakeError(ErrorCode::InvalidBodyID, "stale or unknown body id");
        if (body->mInWorld || body->mAddPending)
            return MakeError(ErrorCode::AlreadyAdded,
                             "remove the body from the world (or abort its add batch) before destroying it");
        shape = std::move(body->mShape);
        // A new sequence makes every copy of the old id stale
        body->mID = BodyID(inID.GetIndex(), inID.GetSequence() + 1);
        mSlotInUse[inID.GetIndex()] = false;
        mGroupFilters[inID.GetIndex()].reset();
        mPoses->Publish(*body); // Names the shape no more, so it can be retired
    }
    mPoses->Retire(std::move(shape));
    const auto lock = LockedCountingWait(mFreeListMutex, LockKind::Body);
    mFreeList.push_back(inID.GetIndex());
    --mNumBodies;
    return Status::Ok();
}

void BodyManager::ActivateBody(Body& ioBody)
{
    if (ioBody.IsActive() || ioBody.IsStatic() || !ioBody.mInWorld) return;
    ioBody.mSleepTimer = 0.0f;
    // The step already owns every body mutex, and with it the list
    std::unique_lock<std::mutex> lock(mActiveListMutex, std::defer_lock);
    if (!IsInsideStep())
    {
        LockCountingWait(lock, LockKind::Body);
        // Woken from outside: the bodies it slept with may rest on it; the next step wakes them (it holds
        // every lock, so it can walk the island's ring safely)
        ioBody.mWakeIsland = true;
    }
    ioBody.SetActiveIndex(uint32_t(mActiveBodies.size()));
    mActiveBodies.push_back(ioBody.mID.GetIndex());
    mPoses->Publish(ioBody);
    NotifyChange(BodyChangeKind::Woke, ioBody, ioBody.mBounds);
}

void BodyManager::DeactivateBody(Body& ioBody)
{
    if (!ioBody.IsActive()) return;
    std::unique_lock<std::mutex> lock(mActiveListMutex, std::defer_lock);
    if (!IsInsideStep()) LockCountingWait(lock, LockKind::Body);
    // Swap-remove: the last body takes this body's place in the list
    const uint32_t slot = ioBody.GetActiveIndex();
    const uint32_t last = mActiveBodies.back();
    mActiveBodies[slot] = last;
    mBodies[last].SetActiveIndex(slot); // another body, but its index is guarded by the list mutex we hold
    mActiveBodies.pop_back();
    ioBody.SetActiveIndex(Body::cInactive);
    ioBody.mLinearVelocity.setZero();
    ioBody.mAngularVelocity.setZero();
    // A sleeping body's forces are not kept for when it wakes: they belonged to the Update that put it to
    // sleep
    ioBody.mForce.setZero();
    ioBody.mTorque.setZero();
    ioBody.mSleepTimer = 0.0f;
    mPoses->Publish(ioBody);
    NotifyChange(BodyChangeKind::FellAsleep, ioBody, ioBody.mBounds);
}

bool BodyManager::AddChangeListener(BodyChangeListener* inListener)
{
    if (inListener == nullptr) return false;
    for (std::atomic<BodyChangeListener*>& slot : mChangeListeners)
    {
        BodyChangeListener* expected = nullptr;
        // Release: publishes the listener's construction to NotifyChange's acquire; relaxed on failure (the
        // slot is taken, try the next)
        if (slot.compare_exchange_strong(expected, inListener, std::memory_order_release,
                                         std::memory_order_relaxed))
            return true;
    }
    return false;
}

void BodyManager::RemoveChangeListener(BodyChangeListener* inListener)
{
    for (std::atomic<BodyChangeListener*>& slot : mChangeListeners)
    {
        BodyChangeListener* expected = inListener;
        // Relaxed: the contract has no thread changing bodies meanwhile, so nobody is inside the listener
        slot.compare_exchange_strong(expected, nullptr, std::memory_order_relaxed);
    }
}

void BodyManager::NotifyChange(BodyChangeKind inKind, const Body& inBody, const AABB& inOldBounds) const
{
    const BodyChange change{inKind,
                            inBody.mID,
                            inBody.mMotionType,
                            inBody.mObjectLayer,
                            inBody.IsActive(),
                            inOldBounds,
                            inBody.mInWorld ? inBody.mBounds : AABB::Empty()};
    for (const std::atomic<BodyChangeListener*>& slot : mChangeListeners)
        // Acquire: pairs with the release in AddChangeListener
        if (BodyChangeListener* listener = slot.load(std::memory_order_acquire); listener != nullptr)
            listener->OnBodyChanged(change);
}

void BodyManager::PublishPose(const Body& inBody)
{
    mPoses->Publish(inBody);
}

void BodyManager::RetireShape(ShapeRef&& ioShape)
{
    mPoses->Retire(std::move(ioShape));
}

void BodyManager::CollectRetiredShapes()
{
    mPoses->CollectRetired();
}

void BodyManager::LockAllBodies() const
{
    assert(!tInsideStep);
    for (uint32_t m = 0; m <= mMutexMask; ++m) // In index order: see the lock order above
        LockCountingWait(mBodyMutexes[m].mMutex, LockKind::Body);
    tInsideStep = true;
}

void BodyManager::UnlockAllBodies() const
{
    tInsideStep = false;
    for (uint32_t m = 0; m <= mMutexMask; ++m)
        mBodyMutexes[m].mMutex.unlock();
}

bool BodyManager::IsInsideStep()
{
    return tInsideStep;
}

StepCallbackScope::StepCallbackScope() : mWasInside(tInsideStep)
{
    tInsideStep = true;
}

StepCallbackScope::~StepCallbackScope()
{
    tInsideStep = mWasInside;
}

uint32_t BodyManager::GetBodyLocksHeldByThisThread()
{
    return tBodyLocksHeld;
}

void BodyManager::NoteBodyLockHeld(int inDelta)
{
    tBodyLocksHeld = uint32_t(int(tBodyLocksHeld) + inDelta);
}

} // namespace cairn::physics
