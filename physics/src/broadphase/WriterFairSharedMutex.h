#pragma once

// WriterFairSharedMutex: a std::shared_mutex behind a turnstile, so that a waiting writer is not starved by a
// continuous stream of readers. glibc's std::shared_mutex prefers readers: with two threads querying in a
// loop, the broad phase's mover got 2 batches of moves through in a second (it should get thousands), and the
// physics step would wait for Update() just as long.
//
// How: a writer holds mTurnstile while it waits for the exclusive lock; a reader passes through mTurnstile
// (lock, unlock) before taking the shared lock. Once a writer waits, new readers queue behind it; readers
// already inside finish, the writer gets in. Readers pay one uncontended mutex lock/unlock. Threads: any. Not
// recursive: a thread holding it (shared or exclusive) must not lock it again. Satisfies SharedLockable, so
// std::unique_lock and std::shared_lock work with it. A lock that has to wait adds its wait to the thread's
// LockWaits total.

#include "cairn/physics/LockWaits.h"

#include <mutex>
#include <shared_mutex>

namespace cairn::physics
{

class WriterFairSharedMutex
{
public:
    /// Exclusive lock: blocks new readers while waiting.
    void lock()
    {
        if (try_lock()) return;
        ScopedLockWait wait(LockKind::BroadPhase);
        std::lock_guard turnstile(mTurnstile);
        mMutex.lock();
    }
    /// Exclusive lock if it is free and no writer waits for it.
    bool try_lock()
    {
        if (!mTurnstile.try_lock()) return false;
        const bool locked = mMutex.try_lock();
        mTurnstile.unlock();
        return locked;
    }
    /// Releases the exclusive lock.
    void unlock() { mMutex.unlock(); }

    /// Shared lock: waits behind any writer that is already waiting.
    void lock_shared()
    {
        if (try_lock_shared()) return;
        ScopedLockWait wait(LockKind::BroadPhase);
        {
            std::lock_guard turnstile(mTurnstile);
        }
        mMutex.lock_shared();
    }
    /// Shared lock if no writer holds it or waits for it.
    bool try_lock_shared()
    {
        if (!mTurnstile.try_lock()) return false; // A writer waits (or another reader is passing through)
        mTurnstile.unlock();
        return mMutex.try_lock_shared();
    }
    /// Releases a shared lock.
    void unlock_shared() { mMutex.unlock_shared(); }

private:
    std::mutex mTurnstile;    ///< Held by a writer from the moment it wants the lock until it has it
    std::shared_mutex mMutex; ///< The lock proper
};

} // namespace cairn::physics
