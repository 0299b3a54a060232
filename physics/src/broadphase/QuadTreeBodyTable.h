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

#include "cairn/physics/math/AABB.h"

#include <atomic>
#include <cstdint>
#include <memory>

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
        /// 1 while BroadPhaseQuadTree::FindCollidingPairs runs and the body is active. Plain: only the
        /// physics step touches it, one call at a time; it fills padding, so it costs no memory.
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
};

} // namespace cairn::physics
