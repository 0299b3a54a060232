#pragma once

// Scoped body locks for code outside the physics step. Each takes the body's shard mutex (shared for read,
// exclusive for write) and checks the id, so a stale id gives no body instead of another body.
// Taking one inside a step callback (where the step already holds every body mutex), or while this thread
// already holds one (two locks held in any order can deadlock against the step, which takes all of them),
// would risk a deadlock: it is refused instead (GetBody() returns nullptr, WasWrongThread() is true).

#include "cairn/physics/body/BodyManager.h"

#include <mutex>
#include <shared_mutex>

namespace cairn
{

template <bool Write> class BodyLock
{
public:
    BodyLock(const BodyManager& inManager, const BodyID& inID)
    {
        if (BodyManager::IsInsideStep() || BodyManager::GetBodyLocksHeldByThisThread() > 0)
        {
            mWrongThread = true;
            return;
        }
        if (inID.IsInvalid() || inID.GetIndex() >= inManager.GetMaxBodies()) return;
        mMutex = &inManager.GetMutexForBody(inID.GetIndex());
        if constexpr (Write)
            mMutex->lock();
        else
            mMutex->lock_shared();
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
            mMutex->unlock();
        else
            mMutex->unlock_shared();
        BodyManager::NoteBodyLockHeld(-1);
        mMutex = nullptr;
        mBody = nullptr;
    }

    bool Succeeded() const { return mBody != nullptr; }
    bool WasWrongThread() const { return mWrongThread; }
    /// The locked body, or nullptr for an unknown or stale id.
    std::conditional_t<Write, Body*, const Body*> GetBody() const { return mBody; }

private:
    std::shared_mutex* mMutex = nullptr;
    Body* mBody = nullptr;
    bool mWrongThread = false;
};

using BodyLockRead = BodyLock<false>;
using BodyLockWrite = BodyLock<true>;

} // namespace cairn
