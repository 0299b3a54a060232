#pragma once

// NodeAllocator: a fixed-capacity pool of node indices [0, capacity) with a lock-free free list, so that
// adding bodies to the quad tree never calls the heap allocator on the hot path. Indices never used before
// come from a high-water mark, so they are handed out in increasing order and the caller can back them with
// storage lazily (the quad tree allocates node chunks as the mark passes them).
//
// Threads: Allocate and Free may be called from any thread at any time, concurrently.
// Lock-free: the free list is a Treiber stack. The head is one 64-bit atomic holding (tag << 32 | index);
// every successful pop or push increments the tag, so a compare-exchange that read the head before another
// thread popped X, popped Y and pushed X back (the ABA problem) fails instead of installing a stale next.
// The next links are atomics: a popper may read the link of an index another thread has just popped and is
// reusing; that read is not a data race, and its (possibly stale) value is discarded because the tagged
// compare-exchange fails.
// The allocator hands out indices only; the caller owns the node storage and must not free an index that a
// concurrent reader may still follow (the quad tree frees only nodes that were never published).

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <memory>

namespace cairn::physics
{

class NodeAllocator
{
public:
    static constexpr uint32_t cInvalidIndex = 0xffffffffu;

    /// All inCapacity indices start free. inCapacity < cInvalidIndex.
    explicit NodeAllocator(uint32_t inCapacity)
        : mCapacity(inCapacity), mNext(std::make_unique<std::atomic<uint32_t>[]>(inCapacity))
    {
        // Single-threaded construction: relaxed is enough, the object is published by whoever shares it
        mHead.store(cInvalidIndex, std::memory_order_relaxed);
        mHighWater.store(0, std::memory_order_relaxed);    // Construction: see above
        mNumAllocated.store(0, std::memory_order_relaxed); // Statistic only, see GetNumAllocated
    }

    NodeAllocator(const NodeAllocator&) = delete;
    NodeAllocator& operator=(const NodeAllocator&) = delete;

    /// Pops a free index, or cInvalidIndex when the pool is exhausted or fewer than inKeepFree + 1 indices
    /// are free (a soft reserve for callers that must not run out: approximate under concurrency).
    uint32_t Allocate(uint32_t inKeepFree = 0)
    {
        // Relaxed: a statistic used as a soft limit; concurrent allocations may overshoot it by their number
        if (mCapacity - std::min(mCapacity, mNumAllocated.load(std::memory_order_relaxed)) <= inKeepFree)
            return cInvalidIndex;
        // Acquire: pairs with the release of Free so that the next link of the head index is visible
        uint64_t head = mHead.load(std::memory_order_acquire);
        for (;;)
        {
            const uint32_t index = uint32_t(head);
            if (index == cInvalidIndex) return AllocateFresh();
            // Relaxed: the acquire on the head already ordered this after the push that wrote it; a stale
            // value only happens when the head changed, and then the tagged compare-exchange below fails
            const uint32_t next = mNext[index].load(std::memory_order_relaxed);
            const uint64_t newHead = ((head >> 32) + 1) << 32 | next;
            // Acquire on success and failure: we follow the new head's next link on the next iteration or
            // the caller reuses the node that the freeing thread wrote before its release
            if (mHead.compare_exchange_weak(head, newHead, std::memory_order_acquire,
                                            std::memory_order_acquire))
            {
                mNumAllocated.fetch_add(1, std::memory_order_relaxed); // Statistic only
                return index;
            }
        }
    }

    /// Pushes inIndex back. It must have come from Allocate and must no longer be reachable by readers.
    void Free(uint32_t inIndex)
    {
        // Relaxed: the release compare-exchange below publishes everything we wrote before it
        uint64_t head = mHead.load(std::memory_order_relaxed);
        for (;;)
        {
            // Relaxed: ordered before the head update by the release below
            mNext[inIndex].store(uint32_t(head), std::memory_order_relaxed);
            const uint64_t newHead = ((head >> 32) + 1) << 32 | inIndex;
            // Release on success: a popper that acquires this head sees our next link (and the node's last
            // writes); relaxed on failure: we only retry with the fresh head
            if (mHead.compare_exchange_weak(head, newHead, std::memory_order_release,
                                            std::memory_order_relaxed))
            {
                mNumAllocated.fetch_sub(1, std::memory_order_relaxed); // Statistic only
                return;
            }
        }
    }

    /// Indices ever handed out are below this (the storage the caller must back).
    uint32_t GetHighWater() const
    {
        // Relaxed: a statistic; Allocate's callers learn their own index directly
        return std::min(mHighWater.load(std::memory_order_relaxed), mCapacity);
    }

    /// Capacity given at construction.
    uint32_t GetCapacity() const { return mCapacity; }

    /// Indices currently handed out (approximate while other threads allocate or free).
    uint32_t GetNumAllocated() const
    {
        return mNumAllocated.load(std::memory_order_relaxed); // Statistic only: no ordering needed
    }

private:
    /// An index never handed out before, or cInvalidIndex when the capacity is used up.
    uint32_t AllocateFresh()
    {
        // Relaxed: the counter only has to hand out distinct values; the index's storage is the caller's
        const uint32_t index = mHighWater.fetch_add(1, std::memory_order_relaxed);
        if (index >= mCapacity)
        {
            mHighWater.store(mCapacity,
                             std::memory_order_relaxed); // Keep it from wrapping; any order is fine
            return cInvalidIndex;
        }
        mNumAllocated.fetch_add(1, std::memory_order_relaxed); // Statistic only
        return index;
    }

    uint32_t mCapacity;                             ///< Number of indices managed
    std::unique_ptr<std::atomic<uint32_t>[]> mNext; ///< Free list link of each free index
    std::atomic<uint64_t> mHead;                    ///< (ABA tag << 32) | first free index
    std::atomic<uint32_t> mHighWater;               ///< Indices below it have been handed out at least once
    std::atomic<uint32_t> mNumAllocated;            ///< Statistic
};

} // namespace cairn::physics
