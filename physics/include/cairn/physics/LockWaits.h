#pragma once

// LockWaits: how long the calling thread has been blocked on the engine's locks. The reference engine judged
// its broad phase by this kind of figure (one read-write mutex: 500 us a thread per frame; the lock-free
// trees and 32 body mutexes: 10 us). A program reads the counter before and after a piece of work (a
// game-object job, a tile collection) to see what waiting cost that work.
//
// How: every engine lock that can block tries first and times only an acquire that had to wait, as Jolt's
// profiled mutexes do. So an uncontended lock pays nothing extra, and the figure is waiting alone: not the
// atomic operations of free locks, not work done while holding one.
// Counted: the body shard and static mutexes (BodyLock, StaticBodyLockRead, LockAllBodies, body creation and
// destruction), the body manager's free-list and active-list mutexes, the global-mutex broad phase's
// WriterFairSharedMutex (a reader that finds a writer waiting, or another reader passing its turnstile,
// counts too), the quad tree's StripedSharedMutex, and the comparison broad phases' mutexes (brute force,
// sort and sweep). The lock-free queries' epoch read sections never wait, so they have nothing to count.
// Threads: one counter per thread (thread_local), written and read by its own thread only.

#include <chrono>
#include <cstdint>
#include <mutex>
#include <shared_mutex>

namespace cairn
{

namespace lock_waits_detail
{
inline thread_local uint64_t tWaitNanoseconds = 0;
} // namespace lock_waits_detail

/// Nanoseconds this thread has spent waiting for the engine's locks since it started; take differences.
inline uint64_t GetThisThreadLockWaitNanoseconds()
{
    return lock_waits_detail::tWaitNanoseconds;
}

/// Adds a wait timed elsewhere to this thread's total.
inline void AddThisThreadLockWait(std::chrono::steady_clock::duration inWait)
{
    if (inWait.count() > 0)
        lock_waits_detail::tWaitNanoseconds +=
            uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(inWait).count());
}

/// Times a blocking wait (its scope) into this thread's total; for waits that are not a mutex's lock().
class ScopedLockWait
{
public:
    ScopedLockWait() : mStart(std::chrono::steady_clock::now()) {}
    ~ScopedLockWait() { AddThisThreadLockWait(std::chrono::steady_clock::now() - mStart); }
    ScopedLockWait(const ScopedLockWait&) = delete;
    ScopedLockWait& operator=(const ScopedLockWait&) = delete;

private:
    std::chrono::steady_clock::time_point mStart;
};

/// ioLockable.lock(), timed into this thread's total only when try_lock() fails. Works with mutexes and
/// with std::unique_lock.
template <class Lockable> void LockCountingWait(Lockable& ioLockable)
{
    if (ioLockable.try_lock()) return;
    ScopedLockWait wait;
    ioLockable.lock();
}

/// A std::unique_lock on ioMutex, taken by LockCountingWait.
template <class Mutex> [[nodiscard]] std::unique_lock<Mutex> LockedCountingWait(Mutex& ioMutex)
{
    LockCountingWait(ioMutex);
    return std::unique_lock<Mutex>(ioMutex, std::adopt_lock);
}

/// ioMutex.lock_shared(), timed only when try_lock_shared() fails.
template <class SharedMutex> void LockSharedCountingWait(SharedMutex& ioMutex)
{
    if (ioMutex.try_lock_shared()) return;
    ScopedLockWait wait;
    ioMutex.lock_shared();
}

/// A std::shared_lock on ioMutex, taken by LockSharedCountingWait.
template <class SharedMutex>
[[nodiscard]] std::shared_lock<SharedMutex> SharedLockedCountingWait(SharedMutex& ioMutex)
{
    LockSharedCountingWait(ioMutex);
    return std::shared_lock<SharedMutex>(ioMutex, std::adopt_lock);
}

} // namespace cairn
