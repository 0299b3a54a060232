#include "broadphase/BroadPhaseQuadTree.h"

#include "PairCandidateCache.h"
#include "broadphase/BroadPhaseOverlap.h"
#include "math/CpuPause.h"

#include <cassert>
#include <thread>

namespace cairn::physics
{

/// A prepared batch: one private sub-tree per broad-phase layer. Owned by the caller until finalized/aborted.
struct BroadPhaseQuadTree::Batch
{
    std::array<QuadTree::SubTree, cMaxBroadPhaseLayers> mSubTrees;
};

/// Admits one call of a kind of physics-step call at a time (Update and RebuildAll share the rebuild state;
/// FindCollidingPairs owns the active marks); a second one of the same kind that overlaps it is a caller bug
/// (two threads stepping one world) and is refused and counted instead of racing on that state.
class BroadPhaseQuadTree::StepCallGuard
{
public:
    StepCallGuard(const BroadPhaseQuadTree& inBroadPhase, std::atomic<bool>& ioActive)
        : mBroadPhase(inBroadPhase), mActive(ioActive)
    {
        // Acquire: we take over the state the previous call of this kind left behind (released below)
        mOwner = !mActive.exchange(true, std::memory_order_acquire);
        if (!mOwner) mBroadPhase.mRefusedStepCalls.fetch_add(1, std::memory_order_relaxed); // Statistic
    }
    ~StepCallGuard()
    {
        // Release: the next call of this kind sees everything this one wrote
        if (mOwner) mActive.store(false, std::memory_order_release);
    }
    StepCallGuard(const StepCallGuard&) = delete;
    StepCallGuard& operator=(const StepCallGuard&) = delete;
    bool IsOwner() const { return mOwner; }

private:
    const BroadPhaseQuadTree& mBroadPhase;
    std::atomic<bool>& mActive;
    bool mOwner;
};

BroadPhaseQuadTree::BroadPhaseQuadTree(uint32_t inMaxBodies, const LayerSetup& inLayers)
    : mMaxBodies(std::min(inMaxBodies, QuadTree::cBodyFlag - 1)), mLayerSetup(inLayers), mBodies(mMaxBodies),
      mCandidateCache(std::make_unique<PairCandidateCache>())
{
    // A full rebuild needs at most ~1.4 nodes per body (4-wide, at least one body per leaf slot group);
    // batches may not take the last 2 per body, so a rebuild always finds its nodes. Storage is backed on
    // demand.
    const uint32_t rebuildReserve = uint32_t(std::min<uint64_t>(2ull * mMaxBodies + 1024, 1u << 28));
    const uint32_t maxNodes = 2 * rebuildReserve;
    for (uint32_t layer = 0; layer < mLayerSetup.GetNumBroadPhaseLayers(); ++layer)
    {
        mTrees.push_back(std::make_unique<QuadTree>(mBodies, uint8_t(layer), maxNodes, rebuildReserve));
        mTrees.back()->SetMovedSlotMargin(cMovedSlotMargin);
        mTrees.back()->SetMovedSlotReach(cMovedSlotReach);
        mObjectLayersOfTree[layer] = mLayerSetup.GetObjectLayersIn(BroadPhaseLayer(layer));
    }
}

BroadPhaseQuadTree::~BroadPhaseQuadTree() = default;

ObjectLayerMask BroadPhaseQuadTree::MaskForTree(uint32_t inTree, ObjectLayerMask inMask) const
{
    const ObjectLayerMask inTreeMask = mObjectLayersOfTree[inTree];
    if ((inTreeMask & inMask) == 0) return 0;
    return (inTreeMask & ~inMask) == 0 ? cAllObjectLayers : inMask;
}

BroadPhase::AddState BroadPhaseQuadTree::AddBodiesPrepare(std::span<const BroadPhaseBody> inBodies)
{
    // Split by broad-phase layer; off the hot path (loading thread), so the heap is fine here. A batch of one
    // layer (a streamed tile's statics) is used as it is: copying it cost a page fault every 4 KB
    auto isValid = [&](const BroadPhaseBody& inBody)
    {
        const bool ok = !inBody.mID.IsInvalid() && inBody.mID.GetIndex() < mMaxBodies &&
                        mLayerSetup.IsValid(inBody.mLayer) && IsValidBroadPhaseBounds(inBody.mBounds);
        assert(ok && "BroadPhaseQuadTree: invalid body id, object layer or bounds");
        return ok;
    };
    std::array<size_t, cMaxBroadPhaseLayers> counts{};
    bool allValid = true;
    for (const BroadPhaseBody& body : inBodies)
        if (isValid(body))
            ++counts[mLayerSetup.GetBroadPhaseLayer(body.mLayer)];
        else
            allValid = false;
    std::array<std::vector<BroadPhaseBody>, cMaxBroadPhaseLayers> perLayer;
    std::array<std::span<const BroadPhaseBody>, cMaxBroadPhaseLayers> bodiesOf;
    for (uint32_t layer = 0; layer < mTrees.size(); ++layer)
    {
        if (allValid && counts[layer] == inBodies.size())
        {
            bodiesOf[layer] = inBodies;
            break;
        }
        if (counts[layer] == 0) continue;
        perLayer[layer].reserve(counts[layer]);
        for (const BroadPhaseBody& body : inBodies)
            if (isValid(body) && mLayerSetup.GetBroadPhaseLayer(body.mLayer) == layer)
                perLayer[layer].push_back(body);
        bodiesOf[layer] = perLayer[layer];
    }
    auto batch = std::make_unique<Batch>();
    for (uint32_t layer = 0; layer < mTrees.size(); ++layer)
    {
        if (bodiesOf[layer].empty()) continue;
        batch->mSubTrees[layer] = mTrees[layer]->BuildSubTree(bodiesOf[layer]);
        // Valid bodies but no sub-tree: the layer's node pool is out of nodes (bodies already present are
        // skipped silently, as documented, and give a sub-tree of the others or an empty one)
        bool anyNew = false;
        for (const BroadPhaseBody& body : bodiesOf[layer])
            // Relaxed: the caller owns these bodies' operations
            anyNew |= mBodies[body.mID.GetIndex()].mLocation.load(std::memory_order_relaxed) ==
                      QuadTreeBodyTable::cInvalidLocation;
        if (batch->mSubTrees[layer].mChild == QuadTree::cInvalidChild && anyNew)
        {
            AddBodiesAbort(batch.release());
            return nullptr;
        }
    }
    return batch.release();
}

void BroadPhaseQuadTree::AddBodiesFinalize(AddState inState)
{
    if (inState == nullptr) return;
    std::unique_ptr<Batch> batch(static_cast<Batch*>(inState));
    for (uint32_t layer = 0; layer < mTrees.size(); ++layer)
    {
        const QuadTree::SubTree& subTree = batch->mSubTrees[layer];
        if (subTree.mChild == QuadTree::cInvalidChild) continue;
        mTrees[layer]->LinkSubTree(subTree);
        mBodyCount.fetch_add(subTree.mNumBodies, std::memory_order_relaxed); // Statistic
        CountTreeChanges(1u << layer);
    }
}

void BroadPhaseQuadTree::AddBodiesAbort(AddState inState)
{
    if (inState == nullptr) return;
    std::unique_ptr<Batch> batch(static_cast<Batch*>(inState));
    for (uint32_t layer = 0; layer < mTrees.size(); ++layer)
        mTrees[layer]->FreeSubTree(batch->mSubTrees[layer]);
}

void BroadPhaseQuadTree::CountTreeChanges(uint32_t inTrees)
{
    for (; inTrees != 0; inTrees &= inTrees - 1)
        // Release: a FindCollidingPairs that acquires the new count sees the change made before it
        mTreeChanges[std::countr_zero(inTrees)].fetch_add(1, std::memory_order_release);
}

uint32_t BroadPhaseQuadTree::RemoveBody(BodyID inBody)
{
    if (inBody.IsInvalid() || inBody.GetIndex() >= mMaxBodies) return 0;
    // Relaxed: the caller serialises operations on this body, so its layer is stable
    const ObjectLayer layer = mBodies[inBody.GetIndex()].mLayer.load(std::memory_order_relaxed);
    if (!mLayerSetup.IsValid(layer) || !TreeOf(layer).RemoveBody(inBody)) return 0;
    mBodyCount.fetch_sub(1, std::memory_order_relaxed); // Statistic
    return 1u << TreeIndexOf(layer);
}

void BroadPhaseQuadTree::RemoveBodies(std::span<const BodyID> inBodies)
{
    uint32_t changed = 0;
    for (BodyID id : inBodies)
        changed |= RemoveBody(id);
    CountTreeChanges(changed);
}

uint32_t BroadPhaseQuadTree::MoveBody(const BroadPhaseBody& inBody,
                                      std::optional<QuadTree::MoveScope>& ioScope)
{
    const uint32_t index = inBody.mID.GetIndex();
    const bool ok = !inBody.mID.IsInvalid() && index < mMaxBodies && mLayerSetup.IsValid(inBody.mLayer) &&
                    IsValidBroadPhaseBounds(inBody.mBounds);
    assert(ok && "BroadPhaseQuadTree: invalid body id, object layer or bounds");
    if (!ok) return 0;
    // Relaxed: the caller serialises operations on this body
    const ObjectLayer oldLayer = mBodies[index].mLayer.load(std::memory_order_relaxed);
    if (!mLayerSetup.IsValid(oldLayer)) return 0;
    QuadTree& oldTree = TreeOf(oldLayer);
    QuadTree& newTree = TreeOf(inBody.mLayer);
    if (&oldTree == &newTree)
    {
        if (!ioScope.has_value() || &ioScope->GetTree() != &oldTree) ioScope.emplace(oldTree);
        if (!oldTree.MoveBodyHeld(*ioScope, inBody.mID, inBody.mBounds)) return 0;
        if (oldLayer != inBody.mLayer) oldTree.SetBodyLayer(inBody.mID, inBody.mLayer);
        return 1u << TreeIndexOf(oldLayer);
    }
    if (!oldTree.Contains(inBody.mID)) return 0;
    // Another broad-phase layer: the slow path, a remove and a one-body add, which lock on their own
    ioScope.reset();
    oldTree.RemoveBody(inBody.mID);
    const QuadTree::SubTree subTree = newTree.BuildSubTree(std::span(&inBody, 1));
    if (subTree.mChild == QuadTree::cInvalidChild)
        mBodyCount.fetch_sub(1, std::memory_order_relaxed); // Out of nodes: the body left the broad phase
    else
        newTree.LinkSubTree(subTree);
    return 1u << TreeIndexOf(oldLayer) | 1u << TreeIndexOf(inBody.mLayer);
}

void BroadPhaseQuadTree::NotifyBodiesAABBChanged(std::span<const BroadPhaseBody> inBodies)
{
    // A batch (the step's moved bodies) lies scattered over the body table and the tree: the table entries
    // are fetched 8 bodies ahead and the nodes 4 ahead (from the entries fetched before), so that the misses
    // of a move overlap those of the next ones instead of following each other
    constexpr size_t cTableAhead = 8, cNodeAhead = 4;
    uint32_t changed = 0;
    std::optional<QuadTree::MoveScope> scope;
    for (size_t i = 0; i < inBodies.size(); ++i)
    {
        if (i + cTableAhead < inBodies.size())
            if (const uint32_t index = inBodies[i + cTableAhead].mID.GetIndex(); index < mMaxBodies)
            {
                // An entry may straddle two cache lines: its first and last bytes
                const char* entry = reinterpret_cast<const char*>(&mBodies[index]);
                __builtin_prefetch(entry);
                __builtin_prefetch(entry + sizeof(QuadTreeBodyTable::Entry) - 1);
            }
        if (i + cNodeAhead < inBodies.size())
            if (const BroadPhaseBody& ahead = inBodies[i + cNodeAhead]; mLayerSetup.IsValid(ahead.mLayer))
                TreeOf(ahead.mLayer).PrefetchNodeOf(ahead.mID.GetIndex());
        changed |= MoveBody(inBodies[i], scope);
    }
    scope.reset(); // Before the change counts: a search that sees them must see the moves
    CountTreeChanges(changed);
}

void BroadPhaseQuadTree::WaitForEpoch(uint64_t inEpoch)
{
    if (mBodies.GetReclaimer().GetEpoch() >= inEpoch) return;
    // The queries of the previous epoch are leaving (a query lasts microseconds): pause between tries, and
    // yield now and then, for a query thread that lost its core inside its section holds the epoch back. The
    // wait a layer change may have, counted like the broad phase's other lock waits
    const ScopedLockWait wait(LockKind::BroadPhase);
    for (uint32_t attempt = 1; mBodies.GetReclaimer().GetEpoch() < inEpoch; ++attempt)
    {
        if (mBodies.TryAdvanceEpoch()) continue;
        if (attempt % 64 == 0)
            std::this_thread::yield();
        else
            CpuPause();
    }
}

// Why no query misses the body or reports it twice (cross-tree change; QuadTreeBodyTable has the record):
//  1. The body's second leaf is linked in the new tree with the record already stored, and the flip epoch f
//     is the current epoch + 1, all under the table's advance mutex: so every query that enters its section
//     at f or later sees the new leaf and the record, and a query that entered before (at f - 1 or earlier)
//     sees the record whenever it sees the new leaf (the record is stored first, the link publishes both).
//  2. A query over both trees takes the new leaf if its entry epoch is f or later, the old one otherwise:
//     exactly one of the two leaves, while both exist. A query over one of them takes the leaf it finds.
//  3. The old leaf is removed only once the epoch is f + 1: no query that entered before f is left, so none
//     that takes the old leaf can still be looking for it.
//  4. The record is cleared only once the epoch is two past its value g right after the removal (read under
//     the advance mutex, so every advance after g follows the removal): a query still in flight that could
//     have seen the old leaf (it entered at g or earlier) is gone, so none meets a leaf it cannot tell.
//  5. The object layer the table holds changes while the record stands, and the record lets either layer
//     through a query's filter; inWhileInBoth (the published layer) runs between 1 and 3, so a query filtered
//     to either layer finds the body in the tree it walks for as long as that layer is published.
// Same-tree change: one leaf; the record stands while the table's layer changes and inWhileInBoth runs, so a
// filtered query lets the body through under either layer meanwhile.
bool BroadPhaseQuadTree::ChangeBodyLayer(BodyID inBody, ObjectLayer inLayer,
                                         FunctionRef<void()> inWhileInBoth)
{
    const uint32_t index = inBody.GetIndex();
    const bool ok = !inBody.IsInvalid() && index < mMaxBodies && mLayerSetup.IsValid(inLayer);
    assert(ok && "BroadPhaseQuadTree: invalid body id or object layer");
    if (!ok) return false;
    QuadTreeBodyTable::Entry& entry = mBodies[index];
    // Relaxed: the caller serialises operations on this body, so its layer is stable
    const ObjectLayer oldLayer = entry.mLayer.load(std::memory_order_relaxed);
    if (!mLayerSetup.IsValid(oldLayer) || !TreeOf(oldLayer).Contains(inBody)) return false;
    if (oldLayer == inLayer)
    {
        inWhileInBoth();
        return true;
    }
    const auto lock = LockedCountingWait(mLayerChangeMutex, LockKind::BroadPhase);
    const uint32_t oldTree = TreeIndexOf(oldLayer), newTree = TreeIndexOf(inLayer);
    QuadTreeBodyTable::Transit transit{index, uint8_t(oldTree), uint8_t(newTree), oldLayer, inLayer, 0};
    if (oldTree == newTree)
    {
        mBodies.StoreTransit(QuadTreeBodyTable::PackTransit(transit));
        // Release: a query that reads the new layer reads the record after it (see QuadTree's walk)
        entry.mLayer.store(inLayer, std::memory_order_release);
        inWhileInBoth();
        mBodies.StoreTransit(QuadTreeBodyTable::cNoTransit);
        CountTreeChanges(1u << oldTree);
        return true;
    }
    {
        QuadTree& from = *mTrees[oldTree];
        QuadTree& to = *mTrees[newTree];
        // Both modification locks for the whole change, in tree order (a rebuild takes one at a time)
        const QuadTree::MoveScope lowScope(oldTree < newTree ? from : to);
        const QuadTree::MoveScope highScope(oldTree < newTree ? to : from);
        const QuadTree::MoveScope& fromScope = oldTree < newTree ? lowScope : highScope;
        const QuadTree::MoveScope& toScope = oldTree < newTree ? highScope : lowScope;
        uint32_t newLocation = QuadTreeBodyTable::cInvalidLocation;
        const QuadTree::SubTree leaf = to.BuildSecondLeaf(index, from.GetBodyBounds(inBody), newLocation);
        if (leaf.mChild == QuadTree::cInvalidChild) return false; // Out of nodes: nothing changed
        uint64_t flip;
        {
            // 1. above: the epoch stands still from its read to the link
            const std::lock_guard epochLock(mBodies.GetAdvanceMutex());
            flip = mBodies.GetReclaimer().GetEpoch() + 1;
            transit.mFlip = QuadTreeBodyTable::FlipBits(flip);
            mBodies.StoreTransit(QuadTreeBodyTable::PackTransit(transit));
            to.LinkSubTreeHeld(toScope, leaf);
            mBodies.TryAdvanceEpochHeld();
        }
        // Release: as in the same-tree case (5. above)
        entry.mLayer.store(inLayer, std::memory_order_release);
        inWhileInBoth();
        WaitForEpoch(flip + 1); // 3.
        from.RemoveBodyHeld(fromScope, inBody);
        to.AdoptSecondLeaf(toScope, index, newLocation);
        uint64_t removedAt;
        {
            const std::lock_guard epochLock(mBodies.GetAdvanceMutex()); // 4.
            removedAt = mBodies.GetReclaimer().GetEpoch();
        }
        WaitForEpoch(removedAt + 2);
        mBodies.StoreTransit(QuadTreeBodyTable::cNoTransit);
    }
    CountTreeChanges(1u << oldTree | 1u << newTree); // After the locks: see NotifyBodiesAABBChanged
    return true;
}

void BroadPhaseQuadTree::Update()
{
    UpdateImpl(false);
}

void BroadPhaseQuadTree::RebuildAll()
{
    UpdateImpl(true);
}

void BroadPhaseQuadTree::UpdateImpl(bool inFull)
{
    const StepCallGuard guard(*this, mUpdateActive);
    if (!guard.IsOwner()) return;
    mLastUpdate = {};
    for (const std::unique_ptr<QuadTree>& tree : mTrees)
    {
        tree->CollectGarbage();
        const QuadTree::RebuildStats stats = tree->Rebuild(inFull);
        mLastUpdate.mLayersRebuilt += stats.mRebuilt ? 1 : 0;
        mLastUpdate.mRelocatedBodies += stats.mRelocatedBodies;
        mLastUpdate.mKeptNodes += stats.mKeptNodes;
        mLastUpdate.mMaxCommitMicroseconds =
            std::max(mLastUpdate.mMaxCommitMicroseconds, stats.mCommitMicroseconds);
        mLastUpdate.mOutOfNodes |= stats.mOutOfNodes;
        mLastUpdate.mDeferred |= stats.mDeferred;
    }
}

void BroadPhaseQuadTree::CollideAABox(const AABB& inBox, const BroadPhaseQueryFilter& inFilter,
                                      BodyVisitor inVisitor) const
{
    ForEachTree(inFilter.mObjectLayers,
                [&](const QuadTree& inTree, ObjectLayerMask inMask, const QuadTree::MultiTreeQuery* inMulti)
                {
                    inTree.CollideAABox(inBox, inMask, inVisitor, inMulti);
                    return true;
                });
}

void BroadPhaseQuadTree::CollideSphere(const Vec3& inCenter, float inRadius,
                                       const BroadPhaseQueryFilter& inFilter, BodyVisitor inVisitor) const
{
    ForEachTree(inFilter.mObjectLayers,
                [&](const QuadTree& inTree, ObjectLayerMask inMask, const QuadTree::MultiTreeQuery* inMulti)
                {
                    inTree.CollideSphere(inCenter, inRadius, inMask, inVisitor, inMulti);
                    return true;
                });
}

void BroadPhaseQuadTree::CollidePoint(const Vec3& inPoint, const BroadPhaseQueryFilter& inFilter,
                                      BodyVisitor inVisitor) const
{
    ForEachTree(inFilter.mObjectLayers,
                [&](const QuadTree& inTree, ObjectLayerMask inMask, const QuadTree::MultiTreeQuery* inMulti)
                {
                    inTree.CollidePoint(inPoint, inMask, inVisitor, inMulti);
                    return true;
                });
}

void BroadPhaseQuadTree::CastRay(const RayCast& inRay, const BroadPhaseQueryFilter& inFilter,
                                 RayBodyVisitor inVisitor) const
{
    if (!IsFiniteCast(inRay.mOrigin, inRay.mDirection)) return;
    float maxFraction = 1.0f; // Shared by the trees, so a close hit in one prunes the others
    ForEachTree(inFilter.mObjectLayers,
                [&](const QuadTree& inTree, ObjectLayerMask inMask, const QuadTree::MultiTreeQuery* inMulti)
                { return inTree.CastRay(inRay, inMask, maxFraction, inVisitor, inMulti); });
}

void BroadPhaseQuadTree::CastAABox(const AABB& inBox, const Vec3& inDisplacement,
                                   const BroadPhaseQueryFilter& inFilter, RayBodyVisitor inVisitor) const
{
    if (!IsFiniteCast(inBox, inDisplacement)) return;
    float maxFraction = 1.0f; // As in CastRay
    ForEachTree(inFilter.mObjectLayers,
                [&](const QuadTree& inTree, ObjectLayerMask inMask, const QuadTree::MultiTreeQuery* inMulti)
                { return inTree.CastAABox(inBox, inDisplacement, inMask, maxFraction, inVisitor, inMulti); });
}

uint32_t BroadPhaseQuadTree::PrepareCachedTrees(uint32_t inNumActive) const
{
    uint32_t cached = 0;
    for (uint32_t tree = 0; tree < mTrees.size(); ++tree)
    {
        // Acquire: pairs with CountTreeChanges; a change whose count we see is in the walks that follow
        const uint64_t changes = mTreeChanges[tree].load(std::memory_order_acquire);
        if (changes == mSeenTreeChanges[tree] && mTrees[tree]->GetNumBodies() >= cMinCachedTreeBodies)
            cached |= 1u << tree;
        mSeenTreeChanges[tree] = changes;
    }
    if (mCandidateCacheMargin <= 0.0f) cached = 0;
    // A tree that changed drops out of the set for at least one call, so a set equal to the last one means
    // none of its trees changed since this generation's entries were filled
    if (cached != mCachedTrees)
    {
        ++mCandidateCacheGeneration;
        mCachedTrees = cached;
    }
    if (cached != 0) mCandidateCache->Prepare(inNumActive);
    return cached;
}

void BroadPhaseQuadTree::FindCollidingPairs(std::span<const BodyID> inActiveBodies,
                                            const LayerSetup& inLayers, BodyPairVisitor inVisitor,
                                            const ParallelRanges* inParallel) const
{
    const StepCallGuard guard(*this, mPairsActive);
    if (!guard.IsOwner()) return;
    auto isPresent = [&](BodyID inID)
    {
        if (inID.IsInvalid() || inID.GetIndex() >= mMaxBodies) return false;
        // Relaxed: the step owns the active bodies' operations while it runs
        const ObjectLayer layer = mBodies[inID.GetIndex()].mLayer.load(std::memory_order_relaxed);
        return mLayerSetup.IsValid(layer) && TreeOf(layer).Contains(inID);
    };
    // The loops over the active bodies run in ranges on the step's threads when it gives them: each body's
    // table entry is a likely miss (the last step's moves wrote it from other threads), and on one thread the
    // two passes that mark and unmark them were a serial stretch of every step
    auto forRanges = [&](FunctionRef<void(uint32_t, uint32_t)> inRange)
    {
        if (inParallel != nullptr)
            (*inParallel)(uint32_t(inActiveBodies.size()), inRange);
        else
            inRange(0, uint32_t(inActiveBodies.size()));
    };
    // Mark the active bodies that are present, so that a pair of two active bodies is reported only once. A
    // body listed twice may be in two ranges: the marks are exchanged atomically, so one of them sees it
    std::atomic<bool> listedTwice{false};
    auto mark = [&](uint32_t inBegin, uint32_t inEnd)
    {
        bool twice = false;
        for (uint32_t i = inBegin; i < inEnd; ++i)
            if (const BodyID id = inActiveBodies[i]; isPresent(id))
                // Relaxed: the ranges' ParallelRanges call returns before the marks are read
                twice |= std::atomic_ref<uint8_t>(mBodies[id.GetIndex()].mActiveInStep)
                             .exchange(1, std::memory_order_relaxed) != 0;
        if (twice) listedTwice.store(true, std::memory_order_relaxed); // As above
    };
    forRanges(mark);
    // A body listed twice would have two threads write its cache entry: no cache then (a caller bug)
    const uint32_t cachedTrees = PrepareCachedTrees(uint32_t(inActiveBodies.size())) &
                                 (listedTwice.load(std::memory_order_relaxed) ? 0u : ~0u);
    const uint64_t generation = mCandidateCacheGeneration;
    const float margin = mCandidateCacheMargin;

    auto findRange = [&](uint32_t inBegin, uint32_t inEnd)
    {
        CandidateCacheStats stats;
        for (uint32_t position = inBegin; position < inEnd; ++position)
        {
            // The entries are scattered (hashed by body index): fetch one 16 bodies ahead, so that its miss
            // overlaps the walks in between (4 ahead hid less of it: a TLB miss too, likely)
            constexpr uint32_t cEntryAhead = 16;
            if (cachedTrees != 0 && position + cEntryAhead < inEnd)
                mCandidateCache->Prefetch(inActiveBodies[position + cEntryAhead].GetIndex());
            const BodyID id = inActiveBodies[position];
            if (!isPresent(id)) continue;
            const uint32_t selfIndex = id.GetIndex();
            const ObjectLayer selfLayer =
                mBodies[selfIndex].mLayer.load(std::memory_order_relaxed); // See above
            const AABB bounds = TreeOf(selfLayer).GetBodyBounds(id);
            const ObjectLayerMask collidesWith = inLayers.GetCollisionMask(selfLayer);
            auto report = [&](BodyID inOther)
            {
                const uint32_t otherIndex = inOther.GetIndex();
                // Skip itself; of two active bodies the lower index reports
                if (otherIndex != selfIndex &&
                    (mBodies[otherIndex].mActiveInStep == 0 || otherIndex > selfIndex))
                    inVisitor(id, inOther);
            };
            // The changing trees are walked; the others, if any, go through the cache below
            uint32_t cachedOfBody = 0;
            ForEachTreeIndexed(collidesWith,
                               [&](uint32_t inTreeIndex, const QuadTree& inTree, ObjectLayerMask inMask)
                               {
                                   if ((cachedTrees >> inTreeIndex) & 1u)
                                       cachedOfBody |= 1u << inTreeIndex;
                                   else
                                       inTree.CollideAABox(bounds, inMask, report);
                               });
            if (cachedOfBody == 0) continue;
            auto walkCached = [&](const AABB& inBox, auto&& inVisit)
            {
                ForEachTreeIndexed(collidesWith,
                                   [&](uint32_t inTreeIndex, const QuadTree& inTree, ObjectLayerMask inMask)
                                   {
                                       if ((cachedOfBody >> inTreeIndex) & 1u)
                                           inTree.CollideAABoxWithBounds(inBox, inMask, inVisit);
                                   });
            };
            auto reportOverlapping = [&](BodyID inOther, const AABB& inOtherBounds)
            {
                if (AABBsOverlap(inOtherBounds, bounds)) report(inOther);
            };
            PairCandidateCache::Entry* entry = mCandidateCache->FindOrClaim(selfIndex);
            if (entry == nullptr)
            {
                walkCached(bounds, reportOverlapping);
                ++stats.mUncached;
                continue;
            }
            // This body's entry of this generation: its grown box says where the body was
            const bool known = entry->mGeneration == generation && entry->mID == id;
            if (known && entry->mCollidesWith == collidesWith && entry->mGrownBounds.Contains(bounds))
            {
                if (entry->mNumCandidates <= PairCandidateCache::cMaxCandidates)
                {
                    for (uint32_t c = 0; c < entry->mNumCandidates; ++c)
                        reportOverlapping(entry->mCandidates[c].mID, entry->mCandidates[c].mBounds);
                    ++stats.mReused;
                }
                else
                {
                    walkCached(bounds, reportOverlapping);
                    ++stats.mWalked;
                }
                continue;
            }
            // New, stale or left its box: walk with grown bounds and remember what is there. A body that left
            // its box is moving: the box also reaches as far ahead as it moved since the box was made (at
            // most 4 margins: a teleported body must not get a box so large that it holds too many candidates
            // for as long as it stays inside). pile2k: 58 -> 77 % of the static queries served
            AABB grown = bounds.Expanded(margin);
            if (known)
            {
                const float reach = 4.0f * margin;
                const Vec3 ahead =
                    (bounds.Center() - entry->mGrownBounds.Center()).cwiseMax(-reach).cwiseMin(reach);
                grown.Encapsulate(AABB(grown.mMin + ahead, grown.mMax + ahead));
            }
            uint32_t count = 0;
            walkCached(grown,
                       [&](BodyID inOther, const AABB& inOtherBounds)
                       {
                           if (count < PairCandidateCache::cMaxCandidates)
                               entry->mCandidates[count] = {inOther, inOtherBounds};
                           ++count;
                           reportOverlapping(inOther, inOtherBounds);
                       });
            entry->mID = id;
            entry->mGeneration = generation;
            entry->mCollidesWith = collidesWith;
            entry->mGrownBounds = grown;
            entry->mNumCandidates = std::min(count, PairCandidateCache::cMaxCandidates + 1);
            ++stats.mRefilled;
        }
        // Relaxed: statistics
        mCandidateCacheReused.fetch_add(stats.mReused, std::memory_order_relaxed);
        mCandidateCacheWalked.fetch_add(stats.mWalked, std::memory_order_relaxed);
        mCandidateCacheRefilled.fetch_add(stats.mRefilled, std::memory_order_relaxed);
        mCandidateCacheUncached.fetch_add(stats.mUncached, std::memory_order_relaxed);
    };
    // The trees are queried from several threads at once (queries are lock-free); the marks above are only
    // read
    forRanges(findRange);

    auto unmark = [&](uint32_t inBegin, uint32_t inEnd)
    {
        for (uint32_t i = inBegin; i < inEnd; ++i)
            if (const BodyID id = inActiveBodies[i]; !id.IsInvalid() && id.GetIndex() < mMaxBodies)
                // Relaxed, atomic only for a body listed twice (two ranges): the next call's marks come after
                // this ParallelRanges call returns
                std::atomic_ref<uint8_t>(mBodies[id.GetIndex()].mActiveInStep)
                    .store(0, std::memory_order_relaxed);
    };
    forRanges(unmark);
}

BroadPhaseQuadTree::CandidateCacheStats BroadPhaseQuadTree::GetCandidateCacheStats() const
{
    // Relaxed: statistics
    return {mCandidateCacheReused.load(std::memory_order_relaxed),
            mCandidateCacheWalked.load(std::memory_order_relaxed),
            mCandidateCacheRefilled.load(std::memory_order_relaxed),
            mCandidateCacheUncached.load(std::memory_order_relaxed)};
}

void BroadPhaseQuadTree::SetCandidateCacheMargin(float inMargin)
{
    // NaN or negative: off (a clear "no" rather than boxes that never contain anything)
    mCandidateCacheMargin = inMargin > 0.0f && inMargin < cLargeFloat ? inMargin : 0.0f;
}

size_t BroadPhaseQuadTree::GetBodyCount() const
{
    return size_t(std::max<int64_t>(0, mBodyCount.load(std::memory_order_relaxed))); // Statistic
}

BroadPhaseQuadTree::MemoryStats BroadPhaseQuadTree::GetMemoryStats() const
{
    MemoryStats stats;
    stats.mBodyTableBytes = mBodies.GetMemoryBytes();
    stats.mNodeSize = sizeof(QuadTree::Node);
    stats.mCandidateCacheBytes = mCandidateCache->GetMemoryBytes(); // Between steps only, like the margin
    for (const std::unique_ptr<QuadTree>& tree : mTrees)
    {
        const QuadTree::MemoryStats treeStats = tree->GetMemoryStats();
        stats.mNodeBytesInUse += treeStats.mNodeBytesInUse;
        stats.mNodeBytesBacked += treeStats.mNodeBytesBacked;
        stats.mNodesInUse += treeStats.mNodesInUse;
        stats.mNodesRetired += treeStats.mNodesRetired;
    }
    return stats;
}

bool BroadPhaseQuadTree::Validate() const
{
    int64_t total = 0;
    for (const std::unique_ptr<QuadTree>& tree : mTrees)
    {
        const int64_t count = tree->Validate();
        if (count < 0) return false;
        total += count;
    }
    return total == mBodyCount.load(std::memory_order_relaxed); // Single-threaded: any order
}

} // namespace cairn::physics
