#pragma once

// AtomicUnionFind: groups active dynamic bodies connected by contacts into simulation islands while the
// narrow phase is still finding the contacts, with a lock-free union-find. Bodies are named by their dense
// index in the active list. Static and kinematic bodies never link: the caller only passes pairs of dynamic
// bodies. Islands are numbered by their lowest body, so the result does not depend on the order of the links.
//
// Threads:
//  - Reset and Finalize: one thread, while no other thread uses the object. The threads that call Union and
//    Find must be started (or released by a barrier) after Reset and joined (or stopped by a barrier) before
//    Finalize: that start and that join are the happens-before edges that publish the plain data.
//  - Union and Find: any number of threads at once, between Reset and Finalize. Lock-free: a Union retries
//    only when another thread has just changed the same link (or the weak exchange failed spuriously).
//  - GetNumIslands, GetIsland, GetBodies: after Finalize, from any thread, as plain read-only data.
//
// Why it is correct: each body holds an atomic link to a body of its own set; a root is a body linked to
// itself. A link only ever changes to a lower index, so following links ends, every tree's root is its lowest
// body, and a body that stopped being a root never becomes one again. Union changes a root's link only, with
// a compare-exchange that expects the root to still be linked to itself: if another thread linked that root
// first, the exchange fails and the Union starts again from the root's new link. A successful exchange hangs
// one whole tree under a body of the other (lower) tree, which is the merge; it is the linearization point of
// the Union. A Union whose two Finds meet at one root needs no change: sets only ever merge, so the two
// bodies stay together from then on. The AtomicMin that shortens paths only lowers the link of a non-root to
// another body of its own tree, with a lower index than that link: the tree keeps its bodies and its root,
// and no cycle can form because links strictly decrease.
//
// Memory order: relaxed everywhere. The links publish no other data, only themselves; every value a link ever
// holds is a body of the same set with an index no higher than the body, so a stale load is still a correct
// (only longer) path, and the compare-exchange, a read-modify-write, always sees the link's latest value.
// Coherence of each single atomic is all the algorithm uses. Finalize reads the links after the join, which
// orders every Union before it.
//
// Bad input: an index >= the number of bodies asserts in debug; in release Union ignores it and Find returns
// the index unchanged, so no memory outside the links is touched. Linking a body to itself does nothing.

#include <atomic>
#include <cassert>
#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

namespace cairn::physics
{

class AtomicUnionFind
{
public:
    /// Work counted by the counting Union, for benchmarks. One instance per thread: plain counters.
    struct Statistics
    {
        uint64_t mNumUnions = 0; ///< Union calls
        uint64_t mNumFinds = 0;  ///< Finds made by those Unions (two per attempt)
        uint64_t mFindLoops = 0; ///< Links followed by the Finds of those Unions
        uint64_t mRetries = 0;   ///< Failed compare-exchanges (another thread linked the root first)
    };

    AtomicUnionFind() = default;
    AtomicUnionFind(const AtomicUnionFind&) = delete;
    AtomicUnionFind& operator=(const AtomicUnionFind&) = delete;

    /// Starts a step with inNumBodies bodies, each its own island. Allocates only when the count grows past
    /// every earlier one.
    void Reset(uint32_t inNumBodies);

    /// Adds bodies inNumBodies.. (each its own island) to a step in progress, keeping the links made so far:
    /// bodies woken in the middle of a step join the active list after the others. One thread, while no
    /// Union or Find runs (as Reset).
    void Grow(uint32_t inNumBodies);

    /// Puts two bodies (active-list indices) in the same island. Any thread, concurrently.
    void Union(uint32_t inA, uint32_t inB) { UnionImpl<false>(inA, inB, nullptr); }
    /// Union that also adds its work to ioStatistics (the plain Union compiles without the counting).
    void Union(uint32_t inA, uint32_t inB, Statistics& ioStatistics)
    {
        UnionImpl<true>(inA, inB, &ioStatistics);
    }

    /// The root of the body's set: the lowest body of the set when no Union runs, and a body of the set with
    /// an index <= inBody while Unions run. Any thread, concurrently.
    uint32_t Find(uint32_t inBody) const
    {
        if (!IsValid(inBody)) return inBody;
        return FindImpl<false>(inBody, nullptr);
    }

    /// Numbers the islands 0..N-1 in order of their lowest body (independent of thread timing) and lists
    /// their bodies, in O(N). One thread, after every Union has finished.
    void Finalize();

    uint32_t GetNumBodies() const { return mNumBodies; }
    /// Valid after Finalize.
    uint32_t GetNumIslands() const { return uint32_t(mIslandStart.size()) - 1; }
    /// Island of a body; valid after Finalize.
    uint32_t GetIsland(uint32_t inBody) const { return mIslandOfBody[inBody]; }
    /// Bodies of an island (active-list indices), ascending; valid after Finalize.
    std::span<const uint32_t> GetBodies(uint32_t inIsland) const
    {
        return {mBodies.data() + mIslandStart[inIsland], mBodies.data() + mIslandStart[inIsland + 1]};
    }

private:
    bool IsValid(uint32_t inBody) const
    {
        assert(inBody < mNumBodies && "body index out of range");
        return inBody < mNumBodies;
    }

    template <bool CountLoops> uint32_t FindImpl(uint32_t inBody, Statistics* ioStatistics) const
    {
        if constexpr (CountLoops) ++ioStatistics->mNumFinds;
        uint32_t body = inBody;
        for (;;)
        {
            // Relaxed: a stale link is an older, higher body of the same set, so the walk stays in the set
            const uint32_t link = mLinks[body].load(std::memory_order_relaxed);
            if (link == body) return body;
            if constexpr (CountLoops) ++ioStatistics->mFindLoops;
            body = link;
        }
    }

    template <bool CountLoops> void UnionImpl(uint32_t inA, uint32_t inB, Statistics* ioStatistics)
    {
        if (!IsValid(inA) || !IsValid(inB) || inA == inB) return;
        if constexpr (CountLoops) ++ioStatistics->mNumUnions;
        uint32_t low = inA;
        uint32_t high = inB;
        for (;;)
        {
            low = FindImpl<CountLoops>(low, ioStatistics);
            high = FindImpl<CountLoops>(high, ioStatistics);
            if (low == high) break;
            if (low > high) std::swap(low, high);
            // Relaxed on success and failure: the exchange only needs the latest value of this one link. It
            // fails when high is no longer a root (or spuriously); high then holds its newer link (or
            // itself), from which the next Find continues within the same set
            if (mLinks[high].compare_exchange_weak(high, low, std::memory_order_relaxed,
                                                   std::memory_order_relaxed))
                break;
            if constexpr (CountLoops) ++ioStatistics->mRetries;
        }
        // Both bodies now reach low in one step, which keeps the Finds of their other contacts short
        AtomicMin(mLinks[inA], low);
        AtomicMin(mLinks[inB], low);
    }

    static void AtomicMin(std::atomic<uint32_t>& ioLink, uint32_t inValue)
    {
        // Relaxed: only this link's own latest value matters, and the exchange rereads it when it fails
        uint32_t current = ioLink.load(std::memory_order_relaxed);
        while (inValue < current && !ioLink.compare_exchange_weak(current, inValue, std::memory_order_relaxed,
                                                                  std::memory_order_relaxed))
        {
        }
    }

    std::unique_ptr<std::atomic<uint32_t>[]> mLinks; ///< Per body: a lower or equal body of its set
    uint32_t mNumBodies = 0;                         ///< Bodies of the current step
    uint32_t mCapacity = 0;                          ///< Links allocated, kept across steps
    std::vector<uint32_t> mIslandOfBody;             ///< Island number per body
    std::vector<uint32_t> mIslandStart = {0};        ///< Offsets into mBodies, one past the end for the last
    std::vector<uint32_t> mBodies;                   ///< Bodies grouped by island
    std::vector<uint32_t> mCursor;                   ///< Scratch for the counting sort, kept across steps
};

} // namespace cairn::physics
