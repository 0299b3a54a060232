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
// counts too), the quad tree's StripedSharedMutex, and the brute-force oracle's mutex. The lock-free queries'
// epoch read sections never wait, so they have nothing to count.
// Two kinds are kept apart, because the reference's before and after differ in both: the broad phase's locks
// (the global mutex, the trees' modification lock, the oracle's mutex) and the body locks (shard, static,
// free-list and active-list mutexes).
// Threads: counters per thread (thread_local), written and read by their own thread only.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <shared_mutex>

namespace cairn::physics
{

/// Which of the engine's locks a wait was for.
enum class LockKind : uint8_t
{
    BroadPhase, ///< The global-mutex broad phase's mutex, the trees' modification lock, the oracle's mutex
    Body,       ///< Body shard and static mutexes, the body manager's list mutexes
};
inline constexpr size_t cNumLockKinds = 2;

namespace lock_waits_detail
{
inline thread_local uint64_t tWaitNanoseconds[cNumLockKinds] = {}; ///< Indexed by LockKind
} // namespace lock_waits_detail

/// Nanoseconds this thread has spent waiting for the engine's locks of inKind since it started; take
/// differences.
inline uint64_t GetThisThreadLockWaitNanoseconds(LockKind inKind)
{
    return lock_waits_detail::tWaitNanoseconds[size_t(inKind)];
}

/// The same for every kind.
inline uint64_t GetThisThreadLockWaitNanoseconds()
{
    uint64_t total = 0;
    for (size_t kind = 0; kind < cNumLockKinds; ++kind)
        total += GetThisThreadLockWaitNanoseconds(LockKind(kind));
    return total;
}

/// Adds a wait timed elsewhere to this thread's total of inKind.
inline void AddThisThreadLockWait(LockKind inKind, std::chrono::steady_clock::duration inWait)
{
    if (inWait.count() > 0)
        lock_waits_detail::tWaitNanoseconds[size_t(inKind)] +=
            uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(inWait).count());
}

/// Times a blocking wait (its scope) into this thread's total; for waits that are not a mutex's lock().
class ScopedLockWait
{
public:
    explicit ScopedLockWait(LockKind inKind) : mKind(inKind), mStart(std::chrono::steady_clock::now()) {}
    ~ScopedLockWait() { AddThisThreadLockWait(mKind, std::chrono::steady_clock::now() - mStart); }
    ScopedLockWait(const ScopedLockWait&) = delete;
    ScopedLockWait& operator=(const ScopedLockWait&) = delete;

private:
    LockKind mKind;
    std::chrono::steady_clock::time_point mStart;
};

/// ioLockable.lock(), timed into this thread's total only when try_lock() fails. Works with mutexes and
/// with std::unique_lock.
template <class Lockable> void LockCountingWait(Lockable& ioLockable, LockKind inKind)
{
    if (ioLockable.try_lock()) return;
    ScopedLockWait wait(inKind);
    ioLockable.lock();
}

/// A std::unique_lock on ioMutex, taken by LockCountingWait.
template <class Mutex>
[[nodiscard]] std::unique_lock<Mutex> LockedCountingWait(Mutex& ioMutex, LockKind inKind)
{
    LockCountingWait(ioMutex, inKind);
    return std::unique_lock<Mutex>(ioMutex, std::adopt_lock);
}

/// ioMutex.lock_shared(), timed only when try_lock_shared() fails.
template <class SharedMutex> void LockSharedCountingWait(SharedMutex& ioMutex, LockKind inKind)
{
    if (ioMutex.try_lock_shared()) return;
    ScopedLockWait wait(inKind);
    ioMutex.lock_shared();
}

/// A std::shared_lock on ioMutex, taken by LockSharedCountingWait.
template <class SharedMutex>
[[nodiscard]] std::shared_lock<SharedMutex> SharedLockedCountingWait(SharedMutex& ioMutex, LockKind inKind)
{
    LockSharedCountingWait(ioMutex, inKind);
    return std::shared_lock<SharedMutex>(ioMutex, std::adopt_lock);
}

} // namespace cairn::physics
