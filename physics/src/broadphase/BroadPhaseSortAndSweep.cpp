#include "cairn/physics/broadphase/BroadPhaseSortAndSweep.h"

#include "cairn/physics/LockWaits.h"
#include "cairn/physics/broadphase/BroadPhaseOverlap.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <mutex>

namespace cairn
{

namespace
{

constexpr uint32_t cNoSlot = 0xffffffffu;    ///< Entry::mSlot of an entry that is not in the snapshot (dirty)
constexpr uint32_t cWideBit = 0x80000000u;   ///< Entry::mSlot bit: the slot is in the wide tier
constexpr uint32_t cNotDirty = 0xffffffffu;  ///< Entry::mDirtyIndex of an entry that is in the snapshot
constexpr uint32_t cMaxStrips = 4096;        ///< More strips only add binary searches
constexpr uint32_t cMaxCells = 4096;         ///< Bounds the cell table of a strip
constexpr uint32_t cMinEntriesPerStrip = 32; ///< Below this a strip's binary search costs more than it saves
constexpr float cInf = std::numeric_limits<float>::infinity();

/// A stored body and where its snapshot copy is.
struct Entry
{
    BroadPhaseBody mBody;     ///< The truth: what queries must report
    uint32_t mSlot = cNoSlot; ///< Narrow slot index, cWideBit | wide slot index, or cNoSlot when dirty
    uint32_t mDirtyIndex = cNotDirty; ///< Index in Layer::mDirty while dirty
};

/// Bounds of a slot as 6 packed floats. A query reads a short run of ~5-20 consecutive slots per strip:
/// packed, that is 1-3 cache lines; as six separate float arrays (SoA) it was 6-12 lines, and measured
/// slower.
struct PackedBounds
{
    float mMinX; ///< World bounds
    float mMaxX; ///< World bounds
    float mMinY; ///< World bounds
    float mMaxY; ///< World bounds
    float mMinZ; ///< World bounds
    float mMaxZ; ///< World bounds
};

/// The slots of a snapshot: bounds, ids and object layers in parallel arrays (ids and layers are only read
/// for candidates that pass the exact test).
struct BoxArrays
{
    /// Empties all arrays, keeping their capacity.
    void Clear()
    {
        mBounds.clear();
        mIDs.clear();
        mLayers.clear();
    }

    /// Appends a body.
    void Push(const BroadPhaseBody& inBody)
    {
        mBounds.emplace_back();
        mIDs.push_back(inBody.mID);
        mLayers.push_back(inBody.mLayer);
        Set(uint32_t(mBounds.size() - 1), inBody);
    }

    /// Overwrites the bounds and layer of slot inIndex.
    void Set(uint32_t inIndex, const BroadPhaseBody& inBody)
    {
        const AABB& bounds = inBody.mBounds;
        mBounds[inIndex] = {bounds.mMin.x(), bounds.mMax.x(), bounds.mMin.y(),
                            bounds.mMax.y(), bounds.mMin.z(), bounds.mMax.z()};
        mLayers[inIndex] = inBody.mLayer;
    }

    /// The bounds of slot inIndex.
    AABB Get(size_t inIndex) const
    {
        const PackedBounds& b = mBounds[inIndex];
        return {Vec3(b.mMinX, b.mMinY, b.mMinZ), Vec3(b.mMaxX, b.mMaxY, b.mMaxZ)};
    }

    std::vector<PackedBounds> mBounds; ///< Per slot
    std::vector<BodyID> mIDs;          ///< Per slot; invalid = dead (removed or moved out since the build)
    std::vector<ObjectLayer> mLayers;  ///< Per slot
};

/// A float's bits mapped to an unsigned integer with the same order, for a single-integer (strip, key) sort.
uint32_t OrderedBits(float inValue)
{
    const uint32_t bits = std::bit_cast<uint32_t>(inValue + 0.0f); // + 0 turns -0 into +0
    return (bits & 0x80000000u) != 0 ? ~bits : (bits | 0x80000000u);
}

/// Margin added to both ends of a query window: covers the float rounding of the window arithmetic (a few ulp
/// of the magnitudes involved), so the window never excludes a body that the exact test accepts.
float WindowPad(float inA, float inB, float inC)
{
    return 1.0e-5f * (std::abs(inA) + std::abs(inB) + inC) + 1.0e-6f;
}

/// Value of the k-th smallest of ioValues (reorders them).
float NthValue(std::vector<float>& ioValues, size_t inK)
{
    std::nth_element(ioValues.begin(), ioValues.begin() + inK, ioValues.end());
    return ioValues[inK];
}

} // namespace

/// What a query window is: every body the exact test may accept has x and z ranges meeting these (up to
/// rounding).
struct BroadPhaseSortAndSweep::Window
{
    float mMinX; ///< Window x range
    float mMaxX; ///< Window x range
    float mMinZ; ///< Window z range
    float mMaxZ; ///< Window z range
};

/// One sorted snapshot: slots in strips along z (by min z), sorted by an x key within a strip, with a cell
/// table per strip. Rebuilt by Build(); between builds slots are only killed (id) or updated in place
/// (bounds). Slot invariants: key <= min x, max x - key <= mReachX, StripOf(min z) == the slot's strip, max z
/// - min z <= mMaxDepthZ.
struct BroadPhaseSortAndSweep::Tier
{
    /// Strip of a z coordinate: monotonic in inZ, so window ends map to the right strip range. NaN gives
    /// inNaN.
    uint32_t StripOf(float inZ, uint32_t inNaN) const
    {
        const float f = (inZ - mStripZ0) * mStripInvDepth;
        if (std::isnan(f)) return inNaN;
        if (f <= 0.0f) return 0;
        if (f >= float(mNumStrips - 1)) return mNumStrips - 1;
        return uint32_t(f);
    }

    /// Cell of an x key within a strip: monotonic in inX, NaN gives 0 (the start of the strip).
    uint32_t CellOf(float inX) const
    {
        const float f = (inX - mCellX0) * mCellInvWidth;
        if (!(f > 0.0f)) return 0;
        if (f >= float(mNumCells - 1)) return mNumCells - 1;
        return uint32_t(f);
    }

    /// First slot of inStrip whose key may be >= inKey (every later slot of the strip with such a key follows
    /// it): an O(1) replacement for a binary search over the strip.
    uint32_t FirstSlotFrom(uint32_t inStrip, float inKey) const
    {
        return mCellStart[size_t(inStrip) * (mNumCells + 1) + CellOf(inKey)];
    }

    /// Strip of slot inSlot.
    uint32_t StripOfSlot(uint32_t inSlot) const
    {
        return uint32_t(std::upper_bound(mStripStart.begin(), mStripStart.end(), inSlot) -
                        mStripStart.begin()) -
               1;
    }

    /// True when inBounds may live in slot inSlot (the slot invariants).
    bool FitsSlot(uint32_t inSlot, const AABB& inBounds) const
    {
        const float key = mKeys[inSlot];
        return key <= inBounds.mMin.x() && inBounds.mMax.x() - key <= mReachX &&
               inBounds.mMax.z() - inBounds.mMin.z() <= mMaxDepthZ &&
               StripOf(inBounds.mMin.z(), 0) == StripOfSlot(inSlot);
    }

    /// Rebuilds from the entries at inPositions of ioEntries, whose mSlot become inTierBit | slot. inHeadroom
    /// is subtracted from the keys (and added to the reach) so that moves of up to that much stay in place.
    void Build(std::vector<Entry>& ioEntries, const std::vector<uint32_t>& inPositions, float inHeadroom,
               uint32_t inTierBit, std::vector<std::pair<uint64_t, uint32_t>>& ioScratchOrder)
    {
        const uint32_t count = uint32_t(inPositions.size());

        // Deepest body and z range of min z, for the strips
        float maxDepth = 0.0f, minZ = cInf, maxMinZ = -cInf;
        for (uint32_t position : inPositions)
        {
            const AABB& bounds = ioEntries[position].mBody.mBounds;
            maxDepth = std::max(maxDepth, bounds.mMax.z() - bounds.mMin.z());
            minZ = std::min(minZ, bounds.mMin.z());
            maxMinZ = std::max(maxMinZ, bounds.mMin.z());
        }

        // Strips about as deep as the deepest body (a small query then meets ~2 strips), but holding enough
        // entries each that a strip visit pays off
        mNumStrips = 1;
        mStripZ0 = count > 0 ? minZ : 0.0f;
        mStripInvDepth = 0.0f;
        const float extentZ = count > 0 ? maxMinZ - minZ : 0.0f;
        if (extentZ > 0.0f)
        {
            const float stripDepth = std::max(maxDepth, extentZ * float(cMinEntriesPerStrip) / float(count));
            mNumStrips = uint32_t(std::clamp(std::floor(extentZ / stripDepth), 1.0f, float(cMaxStrips)));
            mStripInvDepth = mNumStrips > 1 ? float(mNumStrips) / extentZ : 0.0f;
        }

        // Sort by (strip, key) in one integer comparison
        ioScratchOrder.clear();
        for (uint32_t position : inPositions)
        {
            const AABB& bounds = ioEntries[position].mBody.mBounds;
            const uint64_t strip = StripOf(bounds.mMin.z(), 0);
            ioScratchOrder.emplace_back((strip << 32) | OrderedBits(bounds.mMin.x() - inHeadroom), position);
        }
        std::sort(ioScratchOrder.begin(), ioScratchOrder.end());

        // Fill the slots; the invariants are computed from the stored floats so they hold exactly as checked
        mKeys.clear();
        mBoxes.Clear();
        mStripStart.assign(mNumStrips + 1, 0);
        float reach = 0.0f;
        for (const auto& [sortKey, position] : ioScratchOrder)
        {
            Entry& entry = ioEntries[position];
            const AABB& bounds = entry.mBody.mBounds;
            const float key = bounds.mMin.x() - inHeadroom;
            reach = std::max(reach, bounds.mMax.x() - key);
            entry.mSlot = inTierBit | uint32_t(mKeys.size());
            entry.mDirtyIndex = cNotDirty;
            mKeys.push_back(key);
            mBoxes.Push(entry.mBody);
            ++mStripStart[(sortKey >> 32) + 1];
        }
        for (uint32_t strip = 0; strip < mNumStrips; ++strip)
            mStripStart[strip + 1] += mStripStart[strip];
        // reach already covers a move of -headroom (key = min x - headroom); add room for a move of +headroom
        mReachX = reach + inHeadroom;
        mMaxDepthZ = maxDepth;

        // Cells along x half a reach wide (the skip to the window start is then ~1/4 reach of slots on
        // average), but not more cells than entries
        mNumCells = 1;
        mCellX0 = count > 0 ? *std::min_element(mKeys.begin(), mKeys.end()) : 0.0f;
        mCellInvWidth = 0.0f;
        const float extentX = count > 0 ? *std::max_element(mKeys.begin(), mKeys.end()) - mCellX0 : 0.0f;
        if (extentX > 0.0f && mReachX > 0.0f)
        {
            const float cells = std::min(std::floor(2.0f * extentX / mReachX),
                                         std::max(1.0f, float(count) / float(mNumStrips)));
            mNumCells = uint32_t(std::clamp(cells, 1.0f, float(cMaxCells)));
            mCellInvWidth = mNumCells > 1 ? float(mNumCells) / extentX : 0.0f;
        }
        mCellStart.resize(size_t(mNumStrips) * (mNumCells + 1));
        for (uint32_t strip = 0; strip < mNumStrips; ++strip)
        {
            uint32_t* starts = &mCellStart[size_t(strip) * (mNumCells + 1)];
            uint32_t slot = mStripStart[strip];
            for (uint32_t cell = 0; cell <= mNumCells; ++cell)
            {
                while (slot < mStripStart[strip + 1] && CellOf(mKeys[slot]) < cell)
                    ++slot;
                starts[cell] = slot;
            }
        }
    }

    /// Calls inTest on the bounds of every slot whose bounds can meet inWindow, then inVisit on the live ones
    /// in inMask that pass; returns false when inVisit asked to stop.
    template <class Test, class Visit>
    bool Scan(const Window& inWindow, ObjectLayerMask inMask, Test& inTest, Visit& inVisit) const
    {
        if (mKeys.empty()) return true;

        // Keys in [min x - reach, max x], strips from the one of min z - depth; NaN ends widen the window
        const float padX = WindowPad(inWindow.mMinX, inWindow.mMaxX, mReachX);
        float keyLow = inWindow.mMinX - mReachX - padX;
        float keyHigh = inWindow.mMaxX + padX;
        if (std::isnan(keyLow)) keyLow = -cInf;
        if (std::isnan(keyHigh)) keyHigh = cInf;
        const float padZ = WindowPad(inWindow.mMinZ, inWindow.mMaxZ, mMaxDepthZ);
        const uint32_t stripLow = StripOf(inWindow.mMinZ - mMaxDepthZ - padZ, 0);
        const uint32_t stripHigh = StripOf(inWindow.mMaxZ + padZ, mNumStrips - 1);

        const float* keys = mKeys.data();
        for (uint32_t strip = stripLow; strip <= stripHigh; ++strip)
        {
            const float* end = keys + mStripStart[strip + 1];
            const float* key = keys + FirstSlotFrom(strip, keyLow);
            while (key != end && *key < keyLow)
                ++key;
            for (; key != end && *key <= keyHigh; ++key)
            {
                const size_t slot = size_t(key - keys);
                if (!inTest(mBoxes.Get(slot))) continue;
                const BodyID id = mBoxes.mIDs[slot];
                if (id.IsInvalid() || !IsInLayerMask(inMask, mBoxes.mLayers[slot])) continue;
                if (!inVisit(id)) return false;
            }
        }
        return true;
    }

    /// Checks the sort order, the cell table and the slot counts.
    bool Validate() const
    {
        if (mStripStart.size() != mNumStrips + 1 || mStripStart.back() != mKeys.size() ||
            mBoxes.mIDs.size() != mKeys.size() || mCellStart.size() != size_t(mNumStrips) * (mNumCells + 1))
            return false;
        for (uint32_t strip = 0; strip < mNumStrips; ++strip)
        {
            if (!std::is_sorted(mKeys.begin() + mStripStart[strip], mKeys.begin() + mStripStart[strip + 1]))
                return false;
            // Every slot lies at or after its cell's start and before the next cell's start
            for (uint32_t slot = mStripStart[strip]; slot < mStripStart[strip + 1]; ++slot)
                if (FirstSlotFrom(strip, mKeys[slot]) > slot ||
                    mCellStart[size_t(strip) * (mNumCells + 1) + CellOf(mKeys[slot]) + 1] <= slot)
                    return false;
        }
        return true;
    }

    std::vector<float> mKeys;                ///< Per slot: x sort key (<= min x), sorted within each strip
    BoxArrays mBoxes;                        ///< Per slot, strip by strip, sorted by key within a strip
    std::vector<uint32_t> mStripStart{0, 0}; ///< mNumStrips + 1 offsets into the slots
    std::vector<uint32_t> mCellStart{
        0, 0};                   ///< Per strip, mNumCells + 1 entries: first slot whose key's cell >= c
    uint32_t mNumStrips = 1;     ///< >= 1
    uint32_t mNumCells = 1;      ///< Cells per strip, >= 1
    float mStripZ0 = 0.0f;       ///< z where strip 0 starts
    float mStripInvDepth = 0.0f; ///< 1 / strip depth (0 with a single strip)
    float mCellX0 = 0.0f;        ///< x where cell 0 starts
    float mCellInvWidth = 0.0f;  ///< 1 / cell width (0 with a single cell)
    float mReachX = 0.0f;        ///< Every slot: max x - key <= mReachX
    float mMaxDepthZ = 0.0f;     ///< Every slot: max z - min z <= mMaxDepthZ
};

/// The entries and snapshot of one broad-phase layer.
struct BroadPhaseSortAndSweep::Layer
{
    /// Tier of an entry's slot (mSlot != cNoSlot).
    Tier& TierOf(const Entry& inEntry) { return mTiers[(inEntry.mSlot & cWideBit) != 0 ? 1 : 0]; }

    /// Kills the snapshot copy of inEntry (if any).
    void KillSlot(Entry& ioEntry)
    {
        if (ioEntry.mSlot == cNoSlot) return;
        TierOf(ioEntry).mBoxes.mIDs[ioEntry.mSlot & ~cWideBit] = BodyID();
        ioEntry.mSlot = cNoSlot;
        ++mNumDead;
    }

    /// Puts the entry at inPosition on the dirty list.
    void MakeDirty(uint32_t inPosition)
    {
        Entry& entry = mEntries[inPosition];
        assert(entry.mSlot == cNoSlot && entry.mDirtyIndex == cNotDirty);
        entry.mDirtyIndex = uint32_t(mDirty.size());
        mDirty.push_back(inPosition);
    }

    /// Takes the entry at inPosition off the dirty list (swap-remove).
    void RemoveFromDirty(uint32_t inPosition)
    {
        const uint32_t index = mEntries[inPosition].mDirtyIndex;
        if (index == cNotDirty) return;
        mDirty[index] = mDirty.back();
        mEntries[mDirty[index]].mDirtyIndex = index;
        mDirty.pop_back();
        mEntries[inPosition].mDirtyIndex = cNotDirty;
    }

    ObjectLayerMask mObjectLayers = 0; ///< The object layers that live here (from the LayerSetup)
    std::vector<Entry> mEntries;       ///< Unordered; swap-remove
    std::vector<uint32_t> mDirty;      ///< Positions in mEntries of entries not in the snapshot
    bool mMovedSinceBuild = false; ///< A body moved since the last Rebuild: give the next build x headroom
    Tier mTiers[2];                ///< Narrow bodies, then wide ones (cWideBit in Entry::mSlot)
    uint32_t mNumDead = 0;         ///< Killed slots since the build
};

BroadPhaseSortAndSweep::BroadPhaseSortAndSweep(uint32_t inMaxBodies, const LayerSetup& inLayers)
    : mMaxBodies(inMaxBodies), mLayerSetup(inLayers), mLayers(inLayers.GetNumBroadPhaseLayers()),
      mLocation(inMaxBodies, cNotPresent), mActiveScratch(inMaxBodies, 0)
{
    assert(inMaxBodies < (1u << (32 - cLayerBits)));
    for (uint32_t layer = 0; layer < mLayers.size(); ++layer)
        mLayers[layer].mObjectLayers = inLayers.GetObjectLayersIn(BroadPhaseLayer(layer));
}

BroadPhaseSortAndSweep::~BroadPhaseSortAndSweep() = default;

namespace
{

/// A prepared batch: the validated bodies.
struct SortAndSweepAddBatch
{
    std::vector<BroadPhaseBody> mBodies; ///< Accepted bodies of the span given to AddBodiesPrepare
};

} // namespace

BroadPhase::AddState BroadPhaseSortAndSweep::AddBodiesPrepare(std::span<const BroadPhaseBody> inBodies)
{
    SortAndSweepAddBatch* batch = new SortAndSweepAddBatch;
    batch->mBodies.reserve(inBodies.size());
    for (const BroadPhaseBody& body : inBodies)
    {
        const bool ok = !body.mID.IsInvalid() && body.mID.GetIndex() < mMaxBodies &&
                        mLayerSetup.IsValid(body.mLayer) && IsValidBroadPhaseBounds(body.mBounds);
        assert(ok && "BroadPhaseSortAndSweep: invalid body id, object layer or bounds");
        if (ok) batch->mBodies.push_back(body);
    }
    return batch;
}

void BroadPhaseSortAndSweep::AddBodiesFinalize(AddState inState)
{
    SortAndSweepAddBatch* batch = static_cast<SortAndSweepAddBatch*>(inState);
    {
        const auto lock = LockedCountingWait(mMutex, LockKind::BroadPhase);
        for (const BroadPhaseBody& body : batch->mBodies)
            InsertBody(body);
    }
    delete batch;
}

void BroadPhaseSortAndSweep::AddBodiesAbort(AddState inState)
{
    delete static_cast<SortAndSweepAddBatch*>(inState);
}

void BroadPhaseSortAndSweep::InsertBody(const BroadPhaseBody& inBody)
{
    const uint32_t index = inBody.mID.GetIndex();
    // A second add of the same index is a caller bug; the first add wins
    if (mLocation[index] != cNotPresent) return;
    const uint32_t layerIndex = mLayerSetup.GetBroadPhaseLayer(inBody.mLayer);
    Layer& layer = mLayers[layerIndex];
    const uint32_t position = uint32_t(layer.mEntries.size());
    layer.mEntries.push_back({inBody, cNoSlot, cNotDirty});
    layer.MakeDirty(position);
    mLocation[index] = (position << cLayerBits) | layerIndex;
    ++mBodyCount;
}

void BroadPhaseSortAndSweep::RemoveAt(uint32_t inLayer, uint32_t inPosition)
{
    Layer& layer = mLayers[inLayer];
    Entry& entry = layer.mEntries[inPosition];
    mLocation[entry.mBody.mID.GetIndex()] = cNotPresent;
    layer.KillSlot(entry);
    layer.RemoveFromDirty(inPosition);

    // Swap-remove: the last entry takes the hole; its map entry and dirty-list reference follow it
    const uint32_t last = uint32_t(layer.mEntries.size() - 1);
    if (inPosition != last)
    {
        entry = layer.mEntries[last];
        mLocation[entry.mBody.mID.GetIndex()] = (inPosition << cLayerBits) | inLayer;
        if (entry.mDirtyIndex != cNotDirty) layer.mDirty[entry.mDirtyIndex] = inPosition;
    }
    layer.mEntries.pop_back();
    --mBodyCount;
}

uint32_t BroadPhaseSortAndSweep::FindLocation(BodyID inID) const
{
    if (inID.IsInvalid() || inID.GetIndex() >= mMaxBodies) return cNotPresent;
    const uint32_t location = mLocation[inID.GetIndex()];
    // A stale id (same slot, other sequence) is not present
    if (location == cNotPresent ||
        mLayers[location & ((1u << cLayerBits) - 1)].mEntries[location >> cLayerBits].mBody.mID != inID)
        return cNotPresent;
    return location;
}

void BroadPhaseSortAndSweep::RemoveBodies(std::span<const BodyID> inBodies)
{
    const auto lock = LockedCountingWait(mMutex, LockKind::BroadPhase);
    for (BodyID id : inBodies)
        if (const uint32_t location = FindLocation(id); location != cNotPresent)
            RemoveAt(location & ((1u << cLayerBits) - 1), location >> cLayerBits);
}

void BroadPhaseSortAndSweep::NotifyBodiesAABBChanged(std::span<const BroadPhaseBody> inBodies)
{
    const auto lock = LockedCountingWait(mMutex, LockKind::BroadPhase);
    for (const BroadPhaseBody& body : inBodies)
    {
        const uint32_t location = FindLocation(body.mID);
        if (location == cNotPresent) continue;
        const bool ok = mLayerSetup.IsValid(body.mLayer) && IsValidBroadPhaseBounds(body.mBounds);
        assert(ok && "BroadPhaseSortAndSweep: invalid object layer or bounds");
        if (!ok) continue;

        const uint32_t layerIndex = location & ((1u << cLayerBits) - 1);
        const uint32_t position = location >> cLayerBits;
        if (mLayerSetup.GetBroadPhaseLayer(body.mLayer) != layerIndex)
        {
            // The object layer moved the body to another broad-phase layer
            RemoveAt(layerIndex, position);
            InsertBody(body);
            continue;
        }

        Layer& layer = mLayers[layerIndex];
        layer.mMovedSinceBuild = true;
        Entry& entry = layer.mEntries[position];
        entry.mBody = body;
        if (entry.mSlot == cNoSlot) continue; // Dirty: queries read mEntries directly
        Tier& tier = layer.TierOf(entry);
        if (tier.FitsSlot(entry.mSlot & ~cWideBit, body.mBounds))
            tier.mBoxes.Set(entry.mSlot & ~cWideBit, body);
        else
        {
            layer.KillSlot(entry);
            layer.MakeDirty(position);
        }
    }
}

void BroadPhaseSortAndSweep::Update()
{
    const auto lock = LockedCountingWait(mMutex, LockKind::BroadPhase);
    for (Layer& layer : mLayers)
        if (!layer.mDirty.empty() || layer.mNumDead != 0) Rebuild(layer);
}

void BroadPhaseSortAndSweep::Rebuild(Layer& ioLayer)
{
    const std::vector<Entry>& entries = ioLayer.mEntries;
    const size_t count = entries.size();

    // Typical sizes: the median sets the wide threshold and the headroom
    mScratchWidths.clear();
    mScratchDepths.clear();
    for (const Entry& entry : entries)
    {
        mScratchWidths.push_back(entry.mBody.mBounds.mMax.x() - entry.mBody.mBounds.mMin.x());
        mScratchDepths.push_back(entry.mBody.mBounds.mMax.z() - entry.mBody.mBounds.mMin.z());
    }
    float medianWidth = 0.0f, wideWidth = cInf, wideDepth = cInf;
    if (count > 0)
    {
        // Wide = above 4x the median, but never more than ~1% per axis: the percentile bounds the wide tier
        const size_t percentile = std::min(count - 1, count * 99 / 100);
        medianWidth = NthValue(mScratchWidths, count / 2);
        wideWidth = std::max(4.0f * medianWidth, NthValue(mScratchWidths, percentile));
        const float medianDepth = NthValue(mScratchDepths, count / 2);
        wideDepth = std::max(4.0f * medianDepth, NthValue(mScratchDepths, percentile));
    }
    // Headroom lets small moves of a moving layer stay in place, at the price of a wider window
    const float headroom = ioLayer.mMovedSinceBuild ? 0.25f * medianWidth : 0.0f;

    mScratchNarrow.clear();
    mScratchWide.clear();
    for (uint32_t position = 0; position < count; ++position)
    {
        const AABB& bounds = entries[position].mBody.mBounds;
        const bool wide =
            bounds.mMax.x() - bounds.mMin.x() > wideWidth || bounds.mMax.z() - bounds.mMin.z() > wideDepth;
        (wide ? mScratchWide : mScratchNarrow).push_back(position);
    }
    ioLayer.mTiers[0].Build(ioLayer.mEntries, mScratchNarrow, headroom, 0, mScratchOrder);
    ioLayer.mTiers[1].Build(ioLayer.mEntries, mScratchWide, headroom, cWideBit, mScratchOrder);

    ioLayer.mDirty.clear();
    ioLayer.mNumDead = 0;
    ioLayer.mMovedSinceBuild = false;
}

template <class Test, class Visit>
bool BroadPhaseSortAndSweep::QueryLayer(const Layer& inLayer, const Window& inWindow, ObjectLayerMask inMask,
                                        Test& inTest, Visit& inVisit) const
{
    if (!inLayer.mTiers[0].Scan(inWindow, inMask, inTest, inVisit) ||
        !inLayer.mTiers[1].Scan(inWindow, inMask, inTest, inVisit))
        return false;

    // Entries added or moved out of their slot since the build
    for (uint32_t position : inLayer.mDirty)
    {
        const BroadPhaseBody& body = inLayer.mEntries[position].mBody;
        if (!inTest(body.mBounds) || !IsInLayerMask(inMask, body.mLayer)) continue;
        if (!inVisit(body.mID)) return false;
    }
    return true;
}

template <class Test, class Visit>
void BroadPhaseSortAndSweep::Query(const Window& inWindow, ObjectLayerMask inMask, Test&& inTest,
                                   Visit&& inVisit) const
{
    for (const Layer& layer : mLayers)
        if ((layer.mObjectLayers & inMask) != 0 && !QueryLayer(layer, inWindow, inMask, inTest, inVisit))
            return;
}

template <class Test>
void BroadPhaseSortAndSweep::VisitOverlapping(const Window& inWindow, ObjectLayerMask inMask, Test&& inTest,
                                              BodyVisitor inVisitor) const
{
    const auto lock = SharedLockedCountingWait(mMutex, LockKind::BroadPhase);
    Query(inWindow, inMask, inTest,
          [&](BodyID inID)
          {
              inVisitor(inID);
              return true;
          });
}

void BroadPhaseSortAndSweep::CollideAABox(const AABB& inBox, const BroadPhaseQueryFilter& inFilter,
                                          BodyVisitor inVisitor) const
{
    const Window window{inBox.mMin.x(), inBox.mMax.x(), inBox.mMin.z(), inBox.mMax.z()};
    VisitOverlapping(
        window, inFilter.mObjectLayers, [&](const AABB& inBounds) { return AABBsOverlap(inBounds, inBox); },
        inVisitor);
}

void BroadPhaseSortAndSweep::CollideSphere(const Vec3& inCenter, float inRadius,
                                           const BroadPhaseQueryFilter& inFilter, BodyVisitor inVisitor) const
{
    // The exact test squares the radius, so a negative radius acts as its absolute value
    const float radius = std::abs(inRadius);
    const Window window{inCenter.x() - radius, inCenter.x() + radius, inCenter.z() - radius,
                        inCenter.z() + radius};
    VisitOverlapping(
        window, inFilter.mObjectLayers,
        [&](const AABB& inBounds) { return SphereOverlapsAABB(inCenter, inRadius, inBounds); }, inVisitor);
}

void BroadPhaseSortAndSweep::CollidePoint(const Vec3& inPoint, const BroadPhaseQueryFilter& inFilter,
                                          BodyVisitor inVisitor) const
{
    const Window window{inPoint.x(), inPoint.x(), inPoint.z(), inPoint.z()};
    VisitOverlapping(
        window, inFilter.mObjectLayers, [&](const AABB& inBounds) { return AABBContains(inBounds, inPoint); },
        inVisitor);
}

void BroadPhaseSortAndSweep::CastRay(const RayCast& inRay, const BroadPhaseQueryFilter& inFilter,
                                     RayBodyVisitor inVisitor) const
{
    if (!IsFiniteCast(inRay.mOrigin, inRay.mDirection)) return;
    // The window holds the whole segment (fraction 0..1); pruning by the visitor only makes it conservative
    const Vec3 end = inRay.mOrigin + inRay.mDirection;
    const Window window{std::min(inRay.mOrigin.x(), end.x()), std::max(inRay.mOrigin.x(), end.x()),
                        std::min(inRay.mOrigin.z(), end.z()), std::max(inRay.mOrigin.z(), end.z())};
    const Vec3 invDirection = SafeReciprocal(inRay.mDirection);
    float maxFraction = 1.0f;
    float fraction = 0.0f;
    const auto lock = SharedLockedCountingWait(mMutex, LockKind::BroadPhase);
    Query(
        window, inFilter.mObjectLayers,
        [&](const AABB& inBounds)
        {
            fraction = inBounds.RayEntryFraction(inRay.mOrigin, invDirection, maxFraction);
            return fraction <= maxFraction;
        },
        [&](BodyID inID)
        {
            // The visitor can only shrink the range (the window was computed for the full segment)
            maxFraction = std::min(maxFraction, inVisitor(inID, fraction));
            return maxFraction >= 0.0f;
        });
}

void BroadPhaseSortAndSweep::CastAABox(const AABB& inBox, const Vec3& inDisplacement,
                                       const BroadPhaseQueryFilter& inFilter, RayBodyVisitor inVisitor) const
{
    if (!IsFiniteCast(inBox, inDisplacement)) return;
    const SweptAABox sweep(inBox, inDisplacement);
    // Absolute half extents: with an inverted box the grown body box is inverted too, and the slab test then
    // accepts the swapped slab, which still lies within body +- |half extent|
    const Vec3 halfExtent = sweep.mHalfExtent.cwiseAbs();
    const Vec3 end = sweep.mCenter + inDisplacement;
    const Window window{std::min(sweep.mCenter.x(), end.x()) - halfExtent.x(),
                        std::max(sweep.mCenter.x(), end.x()) + halfExtent.x(),
                        std::min(sweep.mCenter.z(), end.z()) - halfExtent.z(),
                        std::max(sweep.mCenter.z(), end.z()) + halfExtent.z()};
    float maxFraction = 1.0f;
    float fraction = 0.0f;
    const auto lock = SharedLockedCountingWait(mMutex, LockKind::BroadPhase);
    Query(
        window, inFilter.mObjectLayers,
        [&](const AABB& inBounds)
        {
            fraction = sweep.EntryFraction(inBounds, maxFraction);
            return fraction <= maxFraction;
        },
        [&](BodyID inID)
        {
            maxFraction = std::min(maxFraction, inVisitor(inID, fraction));
            return maxFraction >= 0.0f;
        });
}

void BroadPhaseSortAndSweep::FindCollidingPairs(std::span<const BodyID> inActiveBodies,
                                                const LayerSetup& inLayers, BodyPairVisitor inVisitor,
                                                const ParallelRanges* /*inParallel: runs serially*/) const
{
    const auto lock = SharedLockedCountingWait(mMutex, LockKind::BroadPhase);

    // Mark the active bodies that are present, so that a pair of two active bodies is reported only once
    for (BodyID id : inActiveBodies)
        if (FindLocation(id) != cNotPresent) mActiveScratch[id.GetIndex()] = 1;

    for (BodyID id : inActiveBodies)
    {
        const uint32_t location = FindLocation(id);
        if (location == cNotPresent) continue;
        const BroadPhaseBody& self =
            mLayers[location & ((1u << cLayerBits) - 1)].mEntries[location >> cLayerBits].mBody;
        const AABB& bounds = self.mBounds;
        const uint32_t selfIndex = id.GetIndex();
        const Window window{bounds.mMin.x(), bounds.mMax.x(), bounds.mMin.z(), bounds.mMax.z()};
        Query(
            window, inLayers.GetCollisionMask(self.mLayer),
            [&](const AABB& inBounds) { return AABBsOverlap(inBounds, bounds); },
            [&](BodyID inOther)
            {
                const uint32_t otherIndex = inOther.GetIndex();
                // Skip itself; of two active bodies only the one with the lower index reports the pair
                if (otherIndex != selfIndex && (mActiveScratch[otherIndex] == 0 || otherIndex > selfIndex))
                    inVisitor(id, inOther);
                return true;
            });
    }

    for (BodyID id : inActiveBodies)
        if (!id.IsInvalid() && id.GetIndex() < mMaxBodies) mActiveScratch[id.GetIndex()] = 0;
}

size_t BroadPhaseSortAndSweep::GetBodyCount() const
{
    const auto lock = SharedLockedCountingWait(mMutex, LockKind::BroadPhase);
    return mBodyCount;
}

bool BroadPhaseSortAndSweep::Validate() const
{
    const auto lock = SharedLockedCountingWait(mMutex, LockKind::BroadPhase);
    size_t count = 0;
    for (uint32_t layerIndex = 0; layerIndex < mLayers.size(); ++layerIndex)
    {
        const Layer& layer = mLayers[layerIndex];
        count += layer.mEntries.size();
        uint32_t dead = 0;
        for (const Tier& tier : layer.mTiers)
        {
            if (!tier.Validate()) return false;
            for (const BodyID id : tier.mBoxes.mIDs)
                dead += id.IsInvalid() ? 1 : 0;
        }
        if (dead != layer.mNumDead) return false;
        for (uint32_t index = 0; index < layer.mDirty.size(); ++index)
            if (layer.mDirty[index] >= layer.mEntries.size() ||
                layer.mEntries[layer.mDirty[index]].mDirtyIndex != index)
                return false;

        for (uint32_t position = 0; position < layer.mEntries.size(); ++position)
        {
            const Entry& entry = layer.mEntries[position];
            const BroadPhaseBody& body = entry.mBody;
            if (mLocation[body.mID.GetIndex()] != ((position << cLayerBits) | layerIndex) ||
                mLayerSetup.GetBroadPhaseLayer(body.mLayer) != layerIndex ||
                !IsValidBroadPhaseBounds(body.mBounds))
                return false;
            // Exactly one of: in the snapshot, on the dirty list
            if ((entry.mSlot == cNoSlot) == (entry.mDirtyIndex == cNotDirty)) return false;
            if (entry.mSlot == cNoSlot) continue;
            const Tier& tier = layer.mTiers[(entry.mSlot & cWideBit) != 0 ? 1 : 0];
            const uint32_t slot = entry.mSlot & ~cWideBit;
            const BoxArrays& boxes = tier.mBoxes;
            if (slot >= boxes.mIDs.size() || boxes.mIDs[slot] != body.mID ||
                boxes.mLayers[slot] != body.mLayer || boxes.Get(slot).mMin != body.mBounds.mMin ||
                boxes.Get(slot).mMax != body.mBounds.mMax || !tier.FitsSlot(slot, body.mBounds))
                return false;
        }
    }
    if (count != mBodyCount) return false;
    size_t present = 0;
    for (uint32_t location : mLocation)
        present += location != cNotPresent ? 1 : 0;
    return present == mBodyCount;
}

} // namespace cairn
