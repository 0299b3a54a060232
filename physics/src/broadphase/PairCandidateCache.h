#pragma once

// PairCandidateCache: what BroadPhaseQuadTree::FindCollidingPairs remembers, for each active body, of the
// bodies of the trees that did not change between its calls (the static layer, in practice): the ones
// overlapping the body's bounds grown by a margin, with their bounds. While the body's bounds stay inside
// that grown box and those trees stay unchanged, its pairs with them are exactly the remembered bodies whose
// bounds overlap its own, and no tree is walked. A body resting on the ground keeps its box for many steps; a
// walk of the 20,020-body static tree costs about 0.24 us, a cached lookup a few tens of ns.
//
// An open-addressing table keyed by body index (the active list's order changes as bodies sleep and wake),
// sized to twice the active bodies and cleared when stale keys fill it.
//
// Threads: owned by FindCollidingPairs, which runs one call at a time (its StepCallGuard). Prepare runs on
// the calling thread before the pair search's parallel ranges. During them, a body's entry is claimed and
// written only by the thread that runs the range holding that body (the caller makes sure no body is listed
// twice); other threads only load the atomic keys while they probe past it. The next call reads what a range
// wrote after the range's ParallelFor returned, which orders it.

#include "cairn/physics/body/BodyID.h"
#include "cairn/physics/body/Layers.h"
#include "cairn/physics/math/AABB.h"

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>

namespace cairn::physics
{

class PairCandidateCache
{
public:
    /// Candidates kept a body: a box resting among statics has a handful; more and the body's cached trees
    /// are walked (with its exact bounds) until it leaves its grown box.
    static constexpr uint32_t cMaxCandidates = 6;

    struct Candidate
    {
        BodyID mID;
        AABB mBounds; ///< Exact, as of the walk that found it (its tree has not changed since)
    };

    struct Entry
    {
        std::atomic<uint32_t> mKey{cEmptyKey}; ///< Body index, or cEmptyKey
        BodyID mID;                            ///< The exact body the candidates are for
        uint32_t mNumCandidates = 0;           ///< Above cMaxCandidates: too many, none kept
        uint64_t mGeneration = 0;              ///< Valid when equal to the broad phase's (0: never)
        ObjectLayerMask mCollidesWith = 0;     ///< The object layers the candidates were filtered by
        AABB mGrownBounds;                     ///< The walked box: the body's bounds grown by the margin
        Candidate mCandidates[cMaxCandidates];
    };

    static constexpr uint32_t cEmptyKey = 0xffffffffu;

    /// Makes room for inNumActive bodies: a larger table (all entries lost) when it is under twice that, a
    /// cleared one when bodies that left the active list fill over half of it. Calling thread, before the
    /// ranges.
    void Prepare(uint32_t inNumActive);
    /// The entry of body index inIndex, claimed (with a fresh, invalid payload) if it has none; nullptr when
    /// the table is too full (the body's trees are then walked). Any range thread, for its own bodies.
    Entry* FindOrClaim(uint32_t inIndex);
    /// Starts fetching the first cache lines of body index inIndex's likely entry (a hint; reads nothing).
    void Prefetch(uint32_t inIndex) const
    {
        if (mCapacity == 0) return;
        const char* entry = reinterpret_cast<const char*>(&mEntries[HomeSlot(inIndex)]);
        __builtin_prefetch(entry);
        __builtin_prefetch(entry + 64);
        __builtin_prefetch(entry + 128);
    }
    /// Bytes held (the table). Any thread.
    size_t GetMemoryBytes() const
    {
        return mBytes.load(std::memory_order_relaxed); // Relaxed: a statistic
    }

private:
    /// Where inIndex's probe starts. Fibonacci hashing: neighbouring indices spread over the table
    uint32_t HomeSlot(uint32_t inIndex) const { return (inIndex * 2654435761u) >> mHashShift; }

    std::unique_ptr<Entry[]> mEntries;
    uint32_t mCapacity = 0;        ///< A power of two, or 0 before the first Prepare
    uint32_t mHashShift = 32;      ///< 32 - log2(mCapacity): the hash's top bits index the table
    std::atomic<size_t> mBytes{0}; ///< mCapacity * sizeof(Entry), for GetMemoryBytes on any thread
    /// Claimed entries. Relaxed: a counter, compared only against a fill limit (a claim that a racing one
    /// pushes past the limit is still a valid entry; the limit keeps probes short, not correct)
    std::atomic<uint32_t> mUsed{0};
};

} // namespace cairn::physics
