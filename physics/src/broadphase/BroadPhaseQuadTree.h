#pragma once

// BroadPhaseQuadTree: the engine's broad phase. One lock-free QuadTree per broad-phase layer (static and
// moving by default), sharing one QuadTreeBodyTable; every query is filtered by object layer and tested
// against exact body bounds, so it returns exactly what BroadPhaseBruteForce returns.
//
// Threads and locks:
//  - Queries: any thread, any time, no lock (one epoch read section of the trees' shared reclaimer for all
//    the trees a query walks; never waits).
//  - AddBodiesPrepare/Abort: any thread, no lock (builds private sub-trees, one per layer of the batch).
//  - AddBodiesFinalize (O(1) per layer: one compare-exchange), RemoveBodies, NotifyBodiesAABBChanged: any
//    thread; each tree's modification lock is taken shared (per-thread stripe) only to stay out of a
//    rebuild's commit. The caller serialises operations on one body.
//  - ChangeBodyLayer: any thread, one at a time (mLayerChangeMutex), not inside a query's visitor (it waits
//    for the queries running when it starts). To another tree: the body gets a leaf in the new tree while it
//    keeps the old one, the transit record (QuadTreeBodyTable) tells each query which leaf is the body, the
//    shared epoch is advanced past the queries that take the old leaf, and only then is the old leaf removed
//    (the no-miss argument is at ChangeBodyLayer in the .cpp). Both trees' modification locks are held shared
//    meanwhile, so a rebuild commit of either waits for the change. Lock order: body mutex (the caller's) <
//    mLayerChangeMutex < the trees' modification locks, in tree order < the table's epoch advance mutex.
//  - Update (rebuild of changed parts + freeing of old nodes) and FindCollidingPairs: the physics step only.
//    The two may run at once on two threads (CanFindPairsDuringUpdate): the pair queries are queries like any
//    other, exact whatever the tree's state, and the table's mActiveInStep bytes belong to FindCollidingPairs
//    alone. A second Update (or RebuildAll) that overlaps a running one, or a second FindCollidingPairs that
//    overlaps a running one (two threads stepping one world), is refused and counted (GetRefusedStepCalls),
//    never run concurrently. FindCollidingPairs walks each tree in a section of its own: a layer change
//    running beside it may give the changing body's pairs twice or not at all (the engine never runs the
//    two at once: the step holds every body lock, and ChangeBodyLayer's caller holds one).
// FindCollidingPairs keeps, per active body, the bodies of the trees that did not change since its last call
// (the static layer) near the body's bounds grown by a margin (PairCandidateCache, physics/src/broadphase):
// while the body stays inside that box and those trees stay unchanged, its pairs with them come from the
// cache instead of a walk, the same pairs. Each tree counts the modification calls that finished on it
// (mTreeChanges), and a tree whose count moved between two pair searches is walked in the second.
// BroadPhaseGlobalMutex wraps it in one reader-writer mutex for the "before" of the reference engine
// (BroadPhaseType::QuadTreeGlobalMutex).
//
// Bad input (the BodyInterface validates first; these are caller bugs) is ignored, never stored: invalid ids,
// indices >= inMaxBodies, unknown object layers, non-finite or inverted bounds (assert in debug), a body
// index that is already present or prepared (the first add stays), removing or moving a body that is not
// present.

#include "broadphase/QuadTree.h"
#include "cairn/physics/broadphase/BroadPhase.h"

#include <array>
#include <bit>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

namespace cairn::physics
{

class PairCandidateCache;

class BroadPhaseQuadTree final : public BroadPhase
{
public:
    /// What the last Update did, summed over the layers.
    struct UpdateStats
    {
        uint32_t mLayersRebuilt = 0;       ///< Trees that had changes
        uint32_t mRelocatedBodies = 0;     ///< Bodies put into new leaves
        uint32_t mKeptNodes = 0;           ///< Unchanged sub-trees kept whole
        double mMaxCommitMicroseconds = 0; ///< Longest exclusive commit (what a modifier may wait)
        bool mOutOfNodes = false;          ///< A rebuild was skipped for lack of nodes (retried next update)
        bool mDeferred =
            false; ///< A rebuild was put off while old nodes wait for slow readers (retried next update)
    };

    /// Memory of the whole broad phase.
    struct MemoryStats
    {
        size_t mBodyTableBytes = 0;  ///< Per-body records (sized by inMaxBodies)
        size_t mNodeBytesInUse = 0;  ///< Nodes allocated, old (retired) trees included
        size_t mNodeBytesBacked = 0; ///< Node storage allocated (chunks)
        uint32_t mNodesInUse = 0;    ///< Nodes allocated
        uint32_t mNodesRetired = 0;  ///< Of which waiting to be freed
        size_t mNodeSize = 0;        ///< Bytes per node
        /// FindCollidingPairs' cache, sized by the active bodies (not the bodies), so not in the per-body
        /// figures
        size_t mCandidateCacheBytes = 0;
    };

    /// How FindCollidingPairs served the active bodies' queries of unchanged trees, since construction.
    struct CandidateCacheStats
    {
        uint64_t mReused = 0; ///< From the cache: no walk
        uint64_t mWalked = 0; ///< Inside the grown box but with too many candidates to keep: walked
        /// Walked with grown bounds and remembered (first time, left the box, changes)
        uint64_t mRefilled = 0;
        uint64_t mUncached = 0; ///< Walked because the cache table was full
    };

    /// Margin by which a body's bounds are grown for its cached candidates (the default, 0.25 m, keeps a
    /// falling or sliding box's candidates for a few steps); 0 turns the cache off. Not during
    /// FindCollidingPairs: set it between steps.
    static constexpr float cDefaultCandidateCacheMargin = 0.25f;
    /// Smaller trees are always walked: their few hundred nodes stay in the cache, and a walk costs about
    /// what the candidate cache's own lookup does (a cache miss on the body's entry). The pyramid's floor
    /// (one static body) cost 1.7 % of its step in lookups.
    static constexpr uint32_t cMinCachedTreeBodies = 1024;
    /// Slot margin of the bodies that moved since a tree's last rebuild (QuadTree::SetMovedSlotMargin; less
    /// for a small body): a resting body's jitter stays inside, so its moves write no node.
    static constexpr float cMovedSlotMargin = 0.05f;
    /// Stretch of a moved body's slot ahead of its motion, in moves since the last rebuild
    /// (QuadTree::SetMovedSlotReach): a box falling 10 cm a step then leaves its slot after 2, 5, then 11
    /// steps (the 1 m cap), not after every one.
    static constexpr float cMovedSlotReach = 2.0f;

    /// inMaxBodies: body indices are < inMaxBodies. inLayers is copied. Node pools hold 2 * inMaxBodies +
    /// 1,024 nodes per layer (the new and old trees of a fully changed layer fit twice over).
    BroadPhaseQuadTree(uint32_t inMaxBodies, const LayerSetup& inLayers);
    ~BroadPhaseQuadTree() override;
    BroadPhaseQuadTree(const BroadPhaseQuadTree&) = delete;
    BroadPhaseQuadTree& operator=(const BroadPhaseQuadTree&) = delete;

    /// Builds one private sub-tree per broad-phase layer of the batch; no lock.
    AddState AddBodiesPrepare(std::span<const BroadPhaseBody> inBodies) override;
    /// Links each prepared sub-tree in O(1).
    void AddBodiesFinalize(AddState inState) override;
    /// Frees the prepared sub-trees.
    void AddBodiesAbort(AddState inState) override;
    /// Empties each body's slot and marks its path changed.
    void RemoveBodies(std::span<const BodyID> inBodies) override;
    /// Stores the exact bounds and grows the slots up to the root. A body whose object layer moved it to
    /// another broad-phase layer is moved to that tree (removed, then added: a query may miss it meanwhile).
    void NotifyBodiesAABBChanged(std::span<const BroadPhaseBody> inBodies) override;
    /// See BroadPhase, and the top of this file. False when the new tree's node pool has no room for the
    /// body's second leaf.
    bool ChangeBodyLayer(BodyID inBody, ObjectLayer inLayer, FunctionRef<void()> inWhileInBoth) override;
    /// Frees old nodes no query can reach, then rebuilds the changed parts of every tree. Physics step only.
    void Update() override;
    /// True: the pair queries are lock-free queries, exact whatever the trees' state.
    bool CanFindPairsDuringUpdate() const override { return true; }
    /// Update with a full rebuild of every tree (benchmarks, level loads).
    void RebuildAll();

    void CollideAABox(const AABB& inBox, const BroadPhaseQueryFilter& inFilter,
                      BodyVisitor inVisitor) const override;
    void CollideSphere(const Vec3& inCenter, float inRadius, const BroadPhaseQueryFilter& inFilter,
                       BodyVisitor inVisitor) const override;
    void CollidePoint(const Vec3& inPoint, const BroadPhaseQueryFilter& inFilter,
                      BodyVisitor inVisitor) const override;
    void CastRay(const RayCast& inRay, const BroadPhaseQueryFilter& inFilter,
                 RayBodyVisitor inVisitor) const override;
    void CastAABox(const AABB& inBox, const Vec3& inDisplacement, const BroadPhaseQueryFilter& inFilter,
                   RayBodyVisitor inVisitor) const override;
    /// Each present active body's exact bounds against the trees of the layers it collides with; a pair of
    /// two active bodies is reported once (by the lower index). Physics step only.
    void FindCollidingPairs(std::span<const BodyID> inActiveBodies, const LayerSetup& inLayers,
                            BodyPairVisitor inVisitor,
                            const ParallelRanges* inParallel = nullptr) const override;

    size_t GetBodyCount() const override;

    void SetCandidateCacheMargin(float inMargin);
    float GetCandidateCacheMargin() const { return mCandidateCacheMargin; }
    CandidateCacheStats GetCandidateCacheStats() const;
    const UpdateStats& GetLastUpdateStats() const { return mLastUpdate; }
    MemoryStats GetMemoryStats() const;
    /// Validates every tree (single-threaded tests); false on the first violation or a count mismatch.
    bool Validate() const;

    /// Step calls refused because another of the same kind was running (Update or RebuildAll during one of
    /// them, FindCollidingPairs during another): two threads stepping one world. Such a call returns without
    /// doing anything.
    uint64_t GetRefusedStepCalls() const
    {
        return mRefusedStepCalls.load(std::memory_order_relaxed); // Statistic
    }

private:
    struct Batch;
    class StepCallGuard;

    /// The tree a body of object layer inLayer lives in.
    QuadTree& TreeOf(ObjectLayer inLayer) const { return *mTrees[mLayerSetup.GetBroadPhaseLayer(inLayer)]; }
    /// Object-layer mask to pass to tree inTree for a query filtered by inMask (all layers when the filter
    /// lets every layer of the tree through, so the tree skips the per-body layer check); 0 to skip the tree.
    ObjectLayerMask MaskForTree(uint32_t inTree, ObjectLayerMask inMask) const;
    /// Calls inQuery(tree, mask, multi) for every tree that a query filtered by inMask must walk, until it
    /// returns false. A query of several trees walks them all in one read section of the shared reclaimer
    /// (multi names it; null for a query of one tree, whose walk enters its own): one section instead of one
    /// a tree, and the section's epoch picks one leaf of a body moving between two of them.
    template <class Query> void ForEachTree(ObjectLayerMask inMask, Query&& inQuery) const
    {
        std::array<ObjectLayerMask, cMaxBroadPhaseLayers> masks{};
        uint32_t trees = 0;
        for (uint32_t tree = 0; tree < mTrees.size(); ++tree)
            if ((masks[tree] = MaskForTree(tree, inMask)) != 0) trees |= 1u << tree;
        auto walk = [&](const QuadTree::MultiTreeQuery* inMulti)
        {
            for (uint32_t left = trees; left != 0; left &= left - 1)
                if (const uint32_t tree = uint32_t(std::countr_zero(left));
                    !inQuery(*mTrees[tree], masks[tree], inMulti))
                    return;
        };
        if (std::popcount(trees) < 2) return walk(nullptr);
        const EpochReclaimer::ReadScope section(mBodies.GetReclaimer());
        const QuadTree::MultiTreeQuery multi{section.GetEpoch(), trees};
        walk(&multi);
    }
    /// As ForEachTree, with the tree's index; the query returns nothing (visits every tree).
    template <class Query> void ForEachTreeIndexed(ObjectLayerMask inMask, Query&& inQuery) const
    {
        for (uint32_t tree = 0; tree < mTrees.size(); ++tree)
            if (const ObjectLayerMask mask = MaskForTree(tree, inMask); mask != 0)
                inQuery(tree, *mTrees[tree], mask);
    }
    void UpdateImpl(bool inFull);
    /// Index of the tree a body of object layer inLayer lives in.
    uint32_t TreeIndexOf(ObjectLayer inLayer) const { return mLayerSetup.GetBroadPhaseLayer(inLayer); }
    /// Counts a finished modification call on each tree of inTrees (a bit per tree).
    void CountTreeChanges(uint32_t inTrees);
    /// Remove and move of one body; return the trees they changed (a bit per tree).
    uint32_t RemoveBody(BodyID inBody);
    /// ioScope: the move scope of the tree of the body before, kept for the next body when it is that body's
    /// tree too (a batch takes each tree's lock once), released before any other modification.
    uint32_t MoveBody(const BroadPhaseBody& inBody, std::optional<QuadTree::MoveScope>& ioScope);
    /// Waits (yielding, counted as a broad-phase lock wait) until the shared epoch is inEpoch or more,
    /// advancing it as soon as no reader of the previous one is left.
    void WaitForEpoch(uint64_t inEpoch);
    /// Trees FindCollidingPairs may serve from the pair cache in this call (a bit per tree): those whose
    /// change count is the one the last call saw, with cMinCachedTreeBodies or more. Starts a new cache
    /// generation when that set differs from the last call's. FindCollidingPairs only.
    uint32_t PrepareCachedTrees(uint32_t inNumActive) const;

    const uint32_t mMaxBodies;                     ///< Body indices are below this
    const LayerSetup mLayerSetup;                  ///< Copy of the constructor's setup; immutable
    QuadTreeBodyTable mBodies;                     ///< Shared by the trees
    std::vector<std::unique_ptr<QuadTree>> mTrees; ///< One per broad-phase layer; the vector is immutable
    std::array<ObjectLayerMask, cMaxBroadPhaseLayers> mObjectLayersOfTree{}; ///< Immutable
    std::atomic<int64_t> mBodyCount{0}; ///< Bodies linked (relaxed: a statistic)
    std::mutex mLayerChangeMutex; ///< ChangeBodyLayer, one at a time: the table holds one transit record
    UpdateStats mLastUpdate;      ///< Physics step only
    mutable std::atomic<bool> mUpdateActive{false};     ///< Update or RebuildAll is running (StepCallGuard)
    mutable std::atomic<bool> mPairsActive{false};      ///< FindCollidingPairs is running (StepCallGuard)
    mutable std::atomic<uint64_t> mRefusedStepCalls{0}; ///< Statistic
    /// Per tree: modification calls (add, remove, move) finished on it. Incremented with release after the
    /// change is in the tree, loaded with acquire by FindCollidingPairs: a count it sees implies it sees the
    /// change; a change it missed moves the count for the next call.
    std::array<std::atomic<uint64_t>, cMaxBroadPhaseLayers> mTreeChanges{};
    // The pair cache's state: FindCollidingPairs only (one call at a time: StepCallGuard)
    std::unique_ptr<PairCandidateCache> mCandidateCache;                   ///< See PairCandidateCache
    mutable std::array<uint64_t, cMaxBroadPhaseLayers> mSeenTreeChanges{}; ///< Counts the last call saw
    mutable uint32_t mCachedTrees = 0;                                     ///< Trees the generation covers
    mutable uint64_t mCandidateCacheGeneration = 1; ///< Entries of another generation are stale
    float mCandidateCacheMargin =
        cDefaultCandidateCacheMargin; ///< Between steps only (SetCandidateCacheMargin)
    /// CandidateCacheStats, summed per range (relaxed: statistics)
    mutable std::atomic<uint64_t> mCandidateCacheReused{0}, mCandidateCacheWalked{0},
        mCandidateCacheRefilled{0}, mCandidateCacheUncached{0};
};

} // namespace cairn::physics
