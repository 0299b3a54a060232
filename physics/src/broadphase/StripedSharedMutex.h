#pragma once

// StripedSharedMutex: a reader-writer lock whose shared side is spread over 32 stripes of atomic counters,
// so that many threads taking it shared (the quad tree's movers, removers and linkers) do not bounce one
// cache line between them; the exclusive side (the quad tree's rebuild commit: short and rare) raises a flag
// and waits until every stripe is empty.
//
// Built on atomics rather than 32 OS mutexes on purpose: the physics step holds all 32 body mutexes while it
// rebuilds, and 32 more held at once would exceed ThreadSanitizer's lock-tracking limit (64 per thread).
// Waiting: a shared locker that finds the flag raised, and the exclusive locker waiting for stripes to empty,
// yield the CPU in a loop; both waits last at most one commit or one modification (microseconds).
// Threads: any. Not recursive. Exclusive lockers are serialised by mWriterMutex. Both waits are added to the
// waiting thread's LockWaits total.
// Memory orders: the shared side's increment and flag check and the exclusive side's flag raise and count
// check are seq_cst (a store-load pattern in each thread that acquire/release does not order); the unlocks
// are release and pair with the acquire of the next locker's loads.

#include "broadphase/ThreadStripe.h"
#include "cairn/physics/LockWaits.h"

#include <atomic>
#include <mutex>
#include <thread>

namespace cairn::physics
{

class StripedSharedMutex
{
public:
    static constexpr uint32_t cNumStripes = 32;

    /// Shared lock on this thread's stripe; pass the returned stripe to UnlockShared.
    uint32_t LockShared()
    {
        const uint32_t stripe = GetThreadStripe(cNumStripes);
        std::atomic<uint32_t>& count = mStripes[stripe].mCount;
        for (;;)
        {
            count.fetch_add(1, std::memory_order_seq_cst); // seq_cst: see the header comment
            if (!mWriter.load(std::memory_order_seq_cst)) return stripe;
            // A commit is running or waiting: step aside so that it can finish, then retry
            count.fetch_sub(1, std::memory_order_release); // Release: nothing was touched, but keep it paired
            ScopedLockWait wait(LockKind::BroadPhase);
            while (mWriter.load(std::memory_order_acquire)) // Acquire: pairs with the release in unlock()
                std::this_thread::yield();
        }
    }

    void UnlockShared(uint32_t inStripe)
    {
        // Release: our modifications happen before the exclusive locker sees the count drop
        mStripes[inStripe].mCount.fetch_sub(1, std::memory_order_release);
    }

    /// Exclusive lock: raises the flag, then waits until no shared holder is left.
    void lock()
    {
        LockCountingWait(mWriterMutex, LockKind::BroadPhase);
        mWriter.store(true, std::memory_order_seq_cst); // seq_cst: see the header comment
        for (const Stripe& stripe : mStripes)
            if (stripe.mCount.load(std::memory_order_seq_cst) != 0) // seq_cst: see the header comment
            {
                ScopedLockWait wait(LockKind::BroadPhase);
                while (stripe.mCount.load(std::memory_order_seq_cst) != 0) // As above
                    std::this_thread::yield();
            }
    }

    void unlock()
    {
        mWriter.store(false, std::memory_order_release); // Release: the commit's writes before new holders
        mWriterMutex.unlock();
    }

    /// RAII shared lock.
    class SharedLock
    {
    public:
        explicit SharedLock(StripedSharedMutex& inMutex) : mMutex(inMutex), mStripe(inMutex.LockShared()) {}
        ~SharedLock() { mMutex.UnlockShared(mStripe); }
        SharedLock(const SharedLock&) = delete;
        SharedLock& operator=(const SharedLock&) = delete;

    private:
        StripedSharedMutex& mMutex;
        uint32_t mStripe;
    };

private:
    struct alignas(64) Stripe
    {
        std::atomic<uint32_t> mCount{0}; ///< Shared holders on this stripe (and ones backing off)
    };

    Stripe mStripes[cNumStripes];
    std::atomic<bool> mWriter{false}; ///< An exclusive locker is in or waiting
    std::mutex mWriterMutex;          ///< Serialises exclusive lockers
};

} // namespace cairn::physics
