#pragma once

// QuadTreeBodyTable: what the quad-tree broad phase knows of each body index, shared by the trees of all
// broad-phase layers (a body lives in exactly one of them): where its leaf is, its id's sequence, its object
// layer and its exact world AABB. The trees' slot bounds may be wider than a body (they only grow until a
// rebuild); queries test the exact bounds here when a slot is marked loose, so they report exactly the
// bodies whose current AABB matches.
//
// Threads: every field is atomic but two plain bytes, each of one writer (see them). A body's entry is
// written by whoever adds, moves or removes it (the caller serialises operations on one body) and by the
// rebuild commit (under the tree's exclusive modification lock); it is read by queries on any thread. Exact
// bounds use a sequence lock that readers never wait on (fence-free, see StoreBounds): a writer makes the
// version odd, writes the six floats, makes it even; a reader that sees an odd or changed version falls back
// to the slot bounds, which contain the body's old bounds (a move in progress may be reported with its old
// state, as allowed).
//
// The table also holds what the trees share beyond the bodies:
//  - One EpochReclaimer for all of them: a query over several trees (BroadPhaseQuadTree) enters one read
//    section for all its walks instead of one per tree, and its epoch orders the query against a body
//    moving between trees. Advanced by each tree's CollectGarbage (the update thread) and by layer changes,
//    one at a time under mAdvanceMutex.
//  - The transit record: the one body that is changing its object layer right now (BroadPhaseQuadTree::
//    ChangeBodyLayer, serialised by its mutex), in one atomic word so that a reader never sees half of it.
//    While a body moves to another tree it has a leaf in both; a query that walks both trees takes the old
//    leaf if it entered its read section before the record's flip epoch and the new one otherwise, so it
//    reports the body exactly once, and either leaf stays until no query that could take it is left.

#include "broadphase/EpochReclaimer.h"
#include "cairn/physics/body/Layers.h"
#include "cairn/physics/math/AABB.h"

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>

namespace cairn::physics
{

class QuadTreeBodyTable
{
public:
    static constexpr uint32_t cInvalidLocation = 0xffffffffu; ///< Not in any tree
    static constexpr uint32_t cPendingLocation = 0xfffffffeu; ///< Claimed by a batch being prepared

    /// Per-body record; 36 bytes (plus the sequence, kept apart: see Sequence()).
    struct Entry
    {
        std::atomic<uint32_t> mLocation{cInvalidLocation}; ///< node << 2 | slot, or one of the markers above
        std::atomic<uint32_t> mVersion{0};                 ///< Sequence lock of the bounds; odd while written
        std::atomic<float> mBounds[6] = {0, 0, 0, 0, 0, 0}; ///< Exact min xyz, max xyz
        std::atomic<uint8_t> mLayer{0};                     ///< Object layer
        std::atomic<uint8_t> mTree{0xff};                   ///< Id of the tree whose node mLocation names
        /// 1 while BroadPhaseQuadTree::FindCollidingPairs runs and the body is active. Only the physics
        /// step touches it, one call at a time: its ranges mark and unmark it through std::atomic_ref (a body
        /// listed twice may be in two ranges), and its pair walks read it plainly in between. It fills
        /// padding, so it costs no memory.
        mutable uint8_t mActiveInStep = 0;
        /// Sides of the body's slot that the last rebuild stretched ahead of its motion (bit 2a: the min side
        /// of axis a, bit 2a + 1: the max side), so that the next rebuild tells that stretch from the room
        /// the body left behind. Plain: only rebuilds read and write it, one at a time
        /// (BroadPhaseQuadTree::Update rebuilds its trees in turn); a stale value (a body removed and another
        /// added at its index) only makes one slot reach less far. It fills padding, so it costs no memory.
        uint8_t mSlotReachSides = 0;
    };

    explicit QuadTreeBodyTable(uint32_t inMaxBodies)
        : mMaxBodies(inMaxBodies), mEntries(std::make_unique<Entry[]>(inMaxBodies)),
          mSequences(std::make_unique<std::atomic<uint32_t>[]>(inMaxBodies))
    {
        for (uint32_t i = 0; i < inMaxBodies; ++i)
            mSequences[i].store(0, std::memory_order_relaxed); // Construction: published by whoever shares it
    }

    /// A body changing its object layer (see the top of this file), unpacked from the record's word.
    struct Transit
    {
        uint32_t mBody = 0;   ///< Body index
        uint8_t mOldTree = 0; ///< Tree id it leaves (the same as mNewTree for a layer of the same tree)
        uint8_t mNewTree = 0; ///< Tree id it goes to
        ObjectLayer mOldLayer = 0;
        ObjectLayer mNewLayer = 0;
        /// The flip epoch's low cFlipBits bits: a query over both trees that entered its read section at this
        /// epoch or later takes the new leaf, an earlier one the old leaf
        uint32_t mFlip = 0;
    };
    static constexpr uint32_t cFlipBits = 14;
    /// The record's word when no body is in transit: its body field is no body index
    static constexpr uint64_t cNoTransit = ~uint64_t(0);

    /// The transit record as one word (cNoTransit when none). Any thread, any time.
    uint64_t LoadTransit() const
    {
        // Acquire: pairs with StoreTransit's release, so a reader that finds the record sees what the changer
        // did before it (the new leaf's sub-tree, and the new object layer of a same-tree change)
        return mTransit.load(std::memory_order_acquire);
    }
    /// The body index of a record word (0xffffffff, no body, for cNoTransit).
    static uint32_t TransitBody(uint64_t inWord) { return uint32_t(inWord); }
    static Transit UnpackTransit(uint64_t inWord)
    {
        return {uint32_t(inWord),
                uint8_t((inWord >> 32) & 7u),
                uint8_t((inWord >> 35) & 7u),
                ObjectLayer((inWord >> 38) & 63u),
                ObjectLayer((inWord >> 44) & 63u),
                uint32_t(inWord >> 50)};
    }
    /// Publishes a body's transit (or clears it with cNoTransit). The changer only (serialised by its mutex).
    void StoreTransit(uint64_t inWord)
    {
        // Release: see LoadTransit
        mTransit.store(inWord, std::memory_order_release);
    }
    static uint64_t PackTransit(const Transit& inTransit)
    {
        static_assert(cMaxBroadPhaseLayers <= 8 && cMaxObjectLayers <= 64,
                      "the record packs them in 3 and 6 bits");
        return uint64_t(inTransit.mBody) | uint64_t(inTransit.mOldTree & 7u) << 32 |
               uint64_t(inTransit.mNewTree & 7u) << 35 | uint64_t(inTransit.mOldLayer & 63u) << 38 |
               uint64_t(inTransit.mNewLayer & 63u) << 44 |
               uint64_t(inTransit.mFlip & ((1u << cFlipBits) - 1)) << 50;
    }
    /// The low bits of an epoch, as a record's mFlip holds them.
    static uint32_t FlipBits(uint64_t inEpoch) { return uint32_t(inEpoch) & ((1u << cFlipBits) - 1); }
    /// Whether a query that entered its read section at inEpoch is at or past the flip epoch whose low bits
    /// are inFlip. Low bits suffice: while a query's section lasts the epoch is at most one past its entry,
    /// and a record lives for a few epochs, so the two are a few apart, never 2^13.
    static bool IsAtOrPastFlip(uint64_t inEpoch, uint32_t inFlip)
    {
        return ((FlipBits(inEpoch) - inFlip) & ((1u << cFlipBits) - 1)) < (1u << (cFlipBits - 1));
    }

    /// The trees' shared reclaimer (see the top of this file): queries enter its read sections.
    const EpochReclaimer& GetReclaimer() const { return mReclaimer; }
    /// Advances the shared epoch when no reader of the previous one is left (EpochReclaimer::TryAdvance),
    /// serialised with every other advance. Any thread.
    bool TryAdvanceEpoch()
    {
        const std::lock_guard lock(mAdvanceMutex);
        return mReclaimer.TryAdvance();
    }
    /// Held, no other thread advances the epoch: a layer change reads it, picks its flip and links its leaf
    /// with the epoch standing still (then advances it with TryAdvanceEpochHeld).
    std::mutex& GetAdvanceMutex() { return mAdvanceMutex; }
    /// TryAdvanceEpoch for a caller that holds GetAdvanceMutex.
    bool TryAdvanceEpochHeld() { return mReclaimer.TryAdvance(); }

    uint32_t GetMaxBodies() const { return mMaxBodies; }
    Entry& operator[](uint32_t inIndex) { return mEntries[inIndex]; }
    const Entry& operator[](uint32_t inIndex) const { return mEntries[inIndex]; }
    /// Sequence of the stored id of a body index. A separate array of 4 bytes a body (80 KB for the shared
    /// 20,020-body world) rather than a field of Entry (800 KB): every query hit reads it, and it then stays
    /// in the L2 cache; in Entry it was a cache miss per hit (a quarter of a box query's time).
    std::atomic<uint32_t>& Sequence(uint32_t inIndex) { return mSequences[inIndex]; }
    const std::atomic<uint32_t>& Sequence(uint32_t inIndex) const { return mSequences[inIndex]; }

    /// Stores exact bounds. Only the thread that owns the body's current operation calls it.
    /// No fences (ThreadSanitizer does not model them): each float is stored with release, so a reader that
    /// acquires a new float also sees the odd version stored before it.
    static void StoreBounds(Entry& ioEntry, const AABB& inBounds)
    {
        // Relaxed load: only this thread writes the version
        const uint32_t version = ioEntry.mVersion.load(std::memory_order_relaxed);
        // Relaxed: published by the release stores of the floats that follow
        ioEntry.mVersion.store(version + 1, std::memory_order_relaxed);
        for (int i = 0; i < 3; ++i)
        {
            // Release: see above
            ioEntry.mBounds[i].store(inBounds.mMin[i], std::memory_order_release);
            ioEntry.mBounds[i + 3].store(inBounds.mMax[i], std::memory_order_release);
        }
        // Release: a reader that acquires the even version sees the six floats
        ioEntry.mVersion.store(version + 2, std::memory_order_release);
    }

    /// Reads exact bounds; false when a write was in progress (the caller then uses a conservative box).
    static bool LoadBounds(const Entry& inEntry, AABB& outBounds)
    {
        // Acquire: pairs with the release store of the even version
        const uint32_t before = inEntry.mVersion.load(std::memory_order_acquire);
        if ((before & 1) != 0) return false;
        for (int i = 0; i < 3; ++i)
        {
            // Acquire: keeps the version re-read below after these loads, and a new value implies the odd
            // version is visible to that re-read
            outBounds.mMin[i] = inEntry.mBounds[i].load(std::memory_order_acquire);
            outBounds.mMax[i] = inEntry.mBounds[i + 3].load(std::memory_order_acquire);
        }
        // Relaxed: ordered after the acquire loads above
        return inEntry.mVersion.load(std::memory_order_relaxed) == before;
    }

    /// Bytes used by the table.
    size_t GetMemoryBytes() const
    {
        static_assert(sizeof(Entry) == 36, "the per-body record grew: update the memory figures");
        return size_t(mMaxBodies) * (sizeof(Entry) + sizeof(std::atomic<uint32_t>));
    }

private:
    uint32_t mMaxBodies;
    std::unique_ptr<Entry[]> mEntries;
    std::unique_ptr<std::atomic<uint32_t>[]> mSequences;
    EpochReclaimer mReclaimer;                  ///< Shared by the trees (see the top of this file)
    std::mutex mAdvanceMutex;                   ///< Serialises mReclaimer's advances
    std::atomic<uint64_t> mTransit{cNoTransit}; ///< The transit record (PackTransit), or cNoTransit
};

} // namespace cairn::physics
