#pragma once

// StripedSharedMutex: a reader-writer lock whose shared side is spread over 32 stripes, so that many threads
// taking it shared (the quad tree's movers, removers and linkers) do not bounce one cache line between them;
// the exclusive side takes every stripe (the quad tree's rebuild commit, which is short and rare).
// Each stripe is a WriterFairSharedMutex, so a waiting exclusive locker is not starved by a stream of shared
// ones. Threads: any. Not recursive. Lock order for the exclusive side: stripes in increasing index, so two
// exclusive lockers cannot deadlock.

#include "cairn/physics/broadphase/ThreadStripe.h"
#include "cairn/physics/broadphase/WriterFairSharedMutex.h"

namespace cairn
{

class StripedSharedMutex
{
public:
    static constexpr uint32_t cNumStripes = 32;

    /// Shared lock on this thread's stripe; pass the returned stripe to UnlockShared.
    uint32_t LockShared()
    {
        const uint32_t stripe = GetThreadStripe(cNumStripes);
        mStripes[stripe].mMutex.lock_shared();
        return stripe;
    }
    void UnlockShared(uint32_t inStripe) { mStripes[inStripe].mMutex.unlock_shared(); }

    /// Exclusive lock: every stripe, in order.
    void lock()
    {
        for (Stripe& stripe : mStripes)
            stripe.mMutex.lock();
    }
    void unlock()
    {
        for (Stripe& stripe : mStripes)
            stripe.mMutex.unlock();
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
        WriterFairSharedMutex mMutex;
    };
    Stripe mStripes[cNumStripes];
};

} // namespace cairn
