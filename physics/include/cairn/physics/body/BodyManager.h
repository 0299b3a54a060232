#pragma once

// BodyManager: owns every Body in a fixed array (so a Body never moves in memory), hands out BodyIDs, and
// owns the sharded read-write mutexes that guard them (body index i is guarded by mutex i % shards; 32 shards
// by default, 1 for the "before" mode that measures a single global body lock,
// PhysicsSettings::mNumBodyMutexes).
//
// Threads and locks:
//  - A body's fields: its shard mutex (shared to read, exclusive to write). The physics step holds them all
//    exclusively while it runs (LockAllBodies), so code inside the step reads and writes bodies without
//    locks.
//  - Free list and body count: mFreeListMutex. Lock order: body mutex < mFreeListMutex < mActiveListMutex.
//  - Active list: mActiveListMutex, taken by threads that (de)activate a body while holding its body mutex;
//    the step holds every body mutex, so it may read and change the list without taking mActiveListMutex.
//  - A thread never holds two body mutexes except LockAllBodies (in index order, so no cycle).
//  - Each shard has a second mutex, its static mutex, which the step does not take. Every write to a body
//    outside the step (BodyLockWrite, CreateBody, DestroyBody) holds it exclusively as well, taken after the
//    body mutex; the step never writes a static body. So a thread holding only the static mutex (shared) may
//    read a static body while the step runs: StaticBodyLockRead, with which background navmesh jobs read
//    level geometry without waiting for a whole step.
//  - Every one of these mutexes that has to wait adds its wait to the thread's LockWaits total.
//  - Published poses (PublishedPose.h): written by whoever writes the body (under its write lock, or the
//    step), read by any thread with no lock at all.

#include "cairn/physics/body/Body.h"
#include "cairn/physics/body/BodyChangeListener.h"
#include "cairn/physics/math/Result.h"

#include <array>
#include <atomic>
#include <memory>
#include <mutex>
#include <new>
#include <shared_mutex>
#include <span>
#include <vector>

namespace cairn::physics
{

class PublishedPoseStore;

class BodyManager
{
public:
    static constexpr uint32_t cNumBodyMutexes = 32; ///< Shards at most (and by default)

    /// inMaxBodies is clamped to [1, PhysicsSettings::cMaxBodiesLimit] (every slot's storage is set aside at
    /// once: 2^32 of them threw bad_alloc); PhysicsSystem::Create refuses a count out of range instead.
    /// inNumMutexes: shards, a power of two from 1 to cNumBodyMutexes (others are rounded down into range).
    explicit BodyManager(uint32_t inMaxBodies, uint32_t inNumMutexes = cNumBodyMutexes);
    ~BodyManager();

    uint32_t GetMaxBodies() const { return mMaxBodies; }
    /// Bodies created and not destroyed.
    uint32_t GetNumBodies() const;

    /// Validates the settings and creates a body (not yet in the world). Any thread.
    Result<BodyID> CreateBody(const BodyCreationSettings& inSettings);
    /// Destroys a body that is not in the world. Any thread.
    Status DestroyBody(const BodyID& inID);

    /// The mutex guarding body index inIndex.
    std::shared_mutex& GetMutexForBody(uint32_t inIndex) const
    {
        return mBodyMutexes[inIndex & mMutexMask].mMutex;
    }

    /// The shard's static mutex (see above).
    std::shared_mutex& GetStaticMutexForBody(uint32_t inIndex) const
    {
        return mStaticMutexes[inIndex & mMutexMask].mMutex;
    }

    /// The body for inID if it exists and has not been destroyed, else nullptr. The caller must hold the
    /// body's mutex (or be the physics step).
    Body* TryGetBody(const BodyID& inID) const
    {
        Body* body = TryGetBodyAtIndex(inID.GetIndex());
        return body != nullptr && body->mID == inID ? body : nullptr;
    }
    /// The body in slot inIndex whatever its sequence, or nullptr when the slot is free. Same locking as
    /// TryGetBody. Inline: the step calls it for every body in every phase.
    Body* TryGetBodyAtIndex(uint32_t inIndex) const
    {
        return inIndex < mMaxBodies && mSlotInUse[inIndex] ? &mBodies[inIndex] : nullptr;
    }

    static constexpr uint32_t cMaxChangeListeners = 8;
    /// Adds a listener told about bodies added, removed, moved, falling asleep and waking (several may
    /// listen: e.g. a navmesh per agent profile). False when cMaxChangeListeners are registered already. Add
    /// and remove while no other thread changes bodies, and keep a listener alive while it is registered.
    bool AddChangeListener(BodyChangeListener* inListener);
    /// Removes a listener added before (nothing happens for one that is not registered).
    void RemoveChangeListener(BodyChangeListener* inListener);
    /// Tells the listeners about a change of inBody (whose lock the caller holds, or the step).
    void NotifyChange(BodyChangeKind inKind, const Body& inBody, const AABB& inOldBounds) const;

    /// Puts a dynamic or kinematic body in the world into the active list. Caller holds the body's mutex
    /// exclusively, or is the step.
    void ActivateBody(Body& ioBody);
    /// Takes a body out of the active list and zeroes its velocities. Same locking as ActivateBody.
    void DeactivateBody(Body& ioBody);

    /// Indices of active bodies. Physics step only (it holds every body mutex).
    std::span<const uint32_t> GetActiveBodiesUnsafe() const { return mActiveBodies; }

    /// Publishes inBody's pose (PublishedPose.h). The caller holds the body's write lock, or is the step.
    void PublishPose(const Body& inBody);
    /// Keeps a shape that a published pose named until no PoseReader can hold it (a destroyed body's, or one
    /// a body's shape was replaced by): the body must be published without it first. Any thread; not under a
    /// body lock (freeing a shape may take long).
    void RetireShape(ShapeRef&& ioShape);
    /// Frees the shapes of destroyed bodies that no PoseReader can hold any more. Any thread (the updating
    /// thread calls it after each Update).
    void CollectRetiredShapes();
    /// Whether two bodies' collision groups let them collide (CollisionGroup.h; their layers aside). The
    /// caller holds both bodies' locks, or is the step.
    bool BodiesCollide(const Body& inA, const Body& inB) const;
    /// The published poses, for PoseReader.
    const PublishedPoseStore& GetPublishedPoses() const { return *mPoses; }

    /// True on the thread that holds every body lock (inside a step), and on a step's job thread while it
    /// runs a game callback (a ContactListener's): locking calls there would deadlock.
    static bool IsInsideStep();
    /// Body locks (BodyLockRead/Write) the calling thread holds now. A thread may hold one at a time: a
    /// second, or a step started while holding one, could deadlock against the step, which takes them all.
    static uint32_t GetBodyLocksHeldByThisThread();
    /// Whether a call that takes body locks (one at a time) may run on this thread: not inside the step and
    /// not while it holds a body lock, where it would deadlock.
    static bool MayTakeBodyLocks() { return !IsInsideStep() && GetBodyLocksHeldByThisThread() == 0; }
    /// Bookkeeping for BodyLock: +1 when it locks, -1 when it unlocks.
    static void NoteBodyLockHeld(int inDelta);

private:
    friend class PhysicsStep;
    friend class PhysicsSystem; // Update takes every body lock for the step (LockAllBodies)

    /// Locks every body mutex for write, in index order, and marks this thread as inside the step. Update
    /// only: a caller that does not release them on every way out (an exception too) locks the world for
    /// good.
    void LockAllBodies() const;
    /// Unlocks what LockAllBodies locked and clears the mark.
    void UnlockAllBodies() const;
    struct alignas(64) PaddedMutex // one cache line each, so shards do not false-share
    {
        mutable std::shared_mutex mMutex;
    };

    /// Published poses with the step's privileges (it publishes the motion of every active body).
    PublishedPoseStore& GetPublishedPosesForStep() { return *mPoses; }
    /// Active list with the step's privileges (it holds every body mutex).
    std::vector<uint32_t>& GetActiveBodiesForStep() { return mActiveBodies; }

    /// Frees a per-slot array's memory (~BodyManager destroys what was constructed in it first).
    template <class T> struct SlotStorageDeleter
    {
        void operator()(T* inSlots) const { ::operator delete(inSlots, std::align_val_t(alignof(T))); }
    };
    template <class T> using SlotStorage = std::unique_ptr<T[], SlotStorageDeleter<T>>;

    uint32_t mMaxBodies;
    uint32_t mMutexMask; ///< Shards - 1 (a power of two minus one); set at construction
    /// mMaxBodies slots of memory, in which CreateBody constructs a slot's Body (and its group table pointer
    /// below) the first time it hands that slot out (slots go out in index order, a freed one first): a
    /// world writes memory for the bodies it has held, not for its capacity (65,536 bodies by default: about
    /// 18 MB). Nothing reads a slot from mSlotsConstructed on: its mSlotInUse is false. Guarded per body by
    /// its shard mutex
    SlotStorage<Body> mBodies;
    std::unique_ptr<bool[]> mSlotInUse; ///< Guarded per slot by its shard mutex
    /// Each slot's body's group table (kept out of Body: a cold pointer the step reads only for two parts of
    /// one group). Guarded per slot by its shard mutex
    SlotStorage<std::shared_ptr<const GroupFilterTable>> mGroupFilters;
    std::unique_ptr<PublishedPoseStore> mPoses; ///< A record per slot; see PublishedPoseStore.h
    mutable PaddedMutex mBodyMutexes[cNumBodyMutexes];
    mutable PaddedMutex mStaticMutexes[cNumBodyMutexes]; ///< Also held by writers outside the step
    std::array<std::atomic<BodyChangeListener*>, cMaxChangeListeners> mChangeListeners{}; ///< Null: free

    mutable std::mutex mFreeListMutex;
    std::vector<uint32_t> mFreeList; ///< Freed slots, the last freed on top. Guarded by mFreeListMutex
    uint32_t mSlotsConstructed = 0;  ///< Slots [0, this) hold a Body. Guarded by mFreeListMutex
    uint32_t mNumBodies = 0;         ///< Guarded by mFreeListMutex

    std::mutex mActiveListMutex;
    std::vector<uint32_t> mActiveBodies; ///< Guarded by mActiveListMutex (or all body mutexes)
};

} // namespace cairn::physics
