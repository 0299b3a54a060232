#pragma once

// Scoped body locks for code outside the physics step. Each takes the body's shard mutex (shared for read,
// exclusive for write; a write lock takes the shard's static mutex too, see BodyManager.h) and checks the id,
// so a stale id gives no body instead of another body.
// Taking one inside a step callback (where the step already holds every body mutex), or while this thread
// already holds one (two locks held in any order can deadlock against the step, which takes all of them),
// would risk a deadlock: it is refused instead (GetBody() returns nullptr, WasWrongThread() is true).
// A lock that has to wait adds its wait to the thread's LockWaits total.

#include "cairn/physics/LockWaits.h"
#include "cairn/physics/body/BodyManager.h"

#include <chrono>
#include <mutex>
#include <shared_mutex>

namespace cairn::physics
{

template <bool Write> class BodyLock
{
public:
    BodyLock(const BodyManager& inManager, const BodyID& inID)
    {
        if (!Prepare(inManager, inID)) return;
        mMutex = &inManager.GetMutexForBody(inID.GetIndex());
        if constexpr (Write)
        {
            LockCountingWait(*mMutex, LockKind::Body);
            mStaticMutex = &inManager.GetStaticMutexForBody(inID.GetIndex());
            LockCountingWait(*mStaticMutex, LockKind::Body);
        }
        else
            LockSharedCountingWait(*mMutex, LockKind::Body);
        BodyManager::NoteBodyLockHeld(+1);
        mBody = inManager.TryGetBody(inID);
    }

    ~BodyLock() { Release(); }
    BodyLock(const BodyLock&) = delete;
    BodyLock& operator=(const BodyLock&) = delete;

    /// Unlocks early; GetBody() is null afterwards.
    void Release()
    {
        if (mMutex == nullptr) return;
        if constexpr (Write)
        {
            mStaticMutex->unlock();
            mMutex->unlock();
        }
        else
            mMutex->unlock_shared();
        BodyManager::NoteBodyLockHeld(-1);
        mMutex = nullptr;
        mStaticMutex = nullptr;
        mBody = nullptr;
    }

    bool Succeeded() const { return mBody != nullptr; }
    bool WasWrongThread() const { return mWrongThread; }
    /// The locked body, or nullptr for an unknown or stale id.
    std::conditional_t<Write, Body*, const Body*> GetBody() const { return mBody; }

private:
    /// False when this thread may not lock (inside the step, or holding a lock already) or the id is invalid.
    bool Prepare(const BodyManager& inManager, const BodyID& inID)
    {
        if (BodyManager::IsInsideStep() || BodyManager::GetBodyLocksHeldByThisThread() > 0)
        {
            mWrongThread = true;
            return false;
        }
        return !inID.IsInvalid() && inID.GetIndex() < inManager.GetMaxBodies();
    }

    std::shared_mutex* mMutex = nullptr;
    std::shared_mutex* mStaticMutex = nullptr; ///< Write locks only
    Body* mBody = nullptr;
    bool mWrongThread = false;
};

using BodyLockRead = BodyLock<false>;
using BodyLockWrite = BodyLock<true>;

/// Reads a static body without waiting for the physics step: takes only the shard's static mutex (shared),
/// which the step does not hold (see BodyManager.h). GetBody() is null for a stale id and for a body that is
/// not static (its fields may be changing in the step: read it with BodyLockRead). Same thread rules as
/// BodyLock: not inside the step, not while holding another body lock.
class StaticBodyLockRead
{
public:
    StaticBodyLockRead(const BodyManager& inManager, const BodyID& inID)
    {
        if (BodyManager::IsInsideStep() || BodyManager::GetBodyLocksHeldByThisThread() > 0)
        {
            mWrongThread = true;
            return;
        }
        if (inID.IsInvalid() || inID.GetIndex() >= inManager.GetMaxBodies()) return;
        mMutex = &inManager.GetStaticMutexForBody(inID.GetIndex());
        if (!mMutex->try_lock_shared())
        {
            // Contended (a writer outside the step): time the real wait, not the thread's scheduling
            const auto start = std::chrono::steady_clock::now();
            mMutex->lock_shared();
            const auto wait = std::chrono::steady_clock::now() - start;
            AddThisThreadLockWait(LockKind::Body, wait);
        }
        BodyManager::NoteBodyLockHeld(+1);
        const Body* body = inManager.TryGetBody(inID);
        if (body != nullptr && body->IsStatic()) mBody = body;
        if (body != nullptr && !body->IsStatic())
        {
            // Written only under both mutexes: safe to read here
            mNotStatic = true;
            mMotionType = body->GetMotionType();
        }
    }
    ~StaticBodyLockRead() { Release(); }
    StaticBodyLockRead(const StaticBodyLockRead&) = delete;
    StaticBodyLockRead& operator=(const StaticBodyLockRead&) = delete;

    void Release()
    {
        if (mMutex == nullptr) return;
        mMutex->unlock_shared();
        BodyManager::NoteBodyLockHeld(-1);
        mMutex = nullptr;
        mBody = nullptr;
    }

    /// The locked static body, or nullptr.
    const Body* GetBody() const { return mBody; }
    bool WasWrongThread() const { return mWrongThread; }
    /// The body exists but is not static: only its motion type was read.
    bool WasNotStatic() const { return mNotStatic; }
    MotionType GetNotStaticMotionType() const { return mMotionType; }

private:
    std::shared_mutex* mMutex = nullptr;
    const Body* mBody = nullptr;
    bool mWrongThread = false;
    bool mNotStatic = false;
    MotionType mMotionType = MotionType::Static;
};

} // namespace cairn::physics
