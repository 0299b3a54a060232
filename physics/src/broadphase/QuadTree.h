#pragma once

// QuadTree: a lock-free 4-wide bounding volume tree of bodies, one per broad-phase layer of
// BroadPhaseQuadTree (after the design in ../shared/reference/talk-architecting-jolt-gdc2022.txt).
//
// Threads and locks:
//  - Queries (CollideAABox, CollideSphere, CollidePoint, CastRay, CastAABox, GetBodyBounds): any thread, any
//    time, no lock. A query runs inside a read section of the EpochReclaimer that the trees of one body table
//    share (its own, or, with a MultiTreeQuery, the section of the caller that walks several trees), so no
//    node it can reach is freed under it; it never waits.
//  - BuildSubTree / FreeSubTree: any thread, no lock; they only touch nodes not reachable from the root.
//  - LinkSubTree, RemoveBody, MoveBody: any thread, concurrently with each other and with queries. They take
//    this tree's StripedSharedMutex shared (their own stripe: no contention between them) only to keep out of
//    the rebuild's short commit; their *Held forms run under a MoveScope the caller holds. The caller
//    serialises operations on one body.
//  - A body changing trees (BroadPhaseQuadTree::ChangeBodyLayer, see QuadTreeBodyTable's transit record):
//    BuildSecondLeaf, LinkSubTreeHeld, RemoveBodyHeld and AdoptSecondLeaf, under MoveScopes of both trees
//    for the whole change, so that no rebuild commit of either sees the body with two leaves.
//  - Rebuild and CollectGarbage: one thread at a time (the physics update) across all the trees that share a
//    QuadTreeBodyTable (its mSlotReachSides is the rebuilds' own), concurrently with the rest. A
//    rebuild builds the new tree off the live one with no lock, then commits (relocates the bodies it moved,
//    re-parents kept nodes, links what was linked meanwhile, swaps the root) under the exclusive side of the
//    modification lock: modifiers may wait for that commit (measured by the broad-phase benchmark), queries
//    never do. Old nodes are retired by epoch and freed by a later CollectGarbage.
// Why lock-free is safe:
//  - A sub-tree is built privately and published with one compare-exchange (release) of a child slot or of
//    the root index; readers load child indices with acquire, so they see fully built nodes.
//  - A slot being published starts empty and only grows (atomic min/max), so a reader sees either no sub-tree
//    or one with bounds containing everything below it once the linker has finished.
//  - Slot bounds only grow until a rebuild (MoveBody: atomic min on mins, max on maxes, up to the root), so a
//    query may see bounds that are too wide, never too narrow for the body's previous or new bounds. A slot
//    that grew is marked loose and queries then test the body's exact bounds from the QuadTreeBodyTable.
//  - Removal empties the slot; a concurrent query reports the body or not.
//  - Nodes are freed only after every read section that might reach them has ended (EpochReclaimer).
//  - A body in transit between two trees (one at a time, QuadTreeBodyTable) has a leaf in each for a while: a
//    walk with a MultiTreeQuery over both reports the leaf its entry epoch picks, any other walk reports
//    the leaf it finds (it cannot find the other). A body in transit passes a layer filter with either of
//    its two object layers.
//    Modifiers need no read section: they reach nodes only through body locations and parent links, which
//    the commit points at the new tree before it releases the exclusive lock, so a modification that starts
//    after a commit never touches a node that commit retired.
// Queries allocate nothing: fixed-size traversal stack (spilling to the heap only for degenerate depths).

#include "broadphase/EpochReclaimer.h"
#include "broadphase/NodeAllocator.h"
#include "broadphase/QuadTreeBodyTable.h"
#include "broadphase/StripedSharedMutex.h"
#include "cairn/physics/broadphase/BroadPhase.h"

#include <atomic>
#include <cstddef>
#include <memory>
#include <span>
#include <vector>

namespace cairn::physics
{

namespace quadtree
{
struct BuildItem;
struct RebuildScratch;
} // namespace quadtree

class QuadTree
{
public:
    /// Child slot value: a node index, a body index with cBodyFlag set, or cInvalidChild.
    static constexpr uint32_t cInvalidChild = 0xffffffffu;
    static constexpr uint32_t cBodyFlag = 0x80000000u;
    static constexpr uint32_t cInvalidNode = NodeAllocator::cInvalidIndex;

    /// One node: four child slots, each with its bounds in SIMD layout. Every field is atomic because
    /// readers traverse while writers grow bounds and fill slots. 128 bytes, aligned: exactly two
    /// cache lines (at 120 unaligned bytes most nodes straddled three, and queries are bound by node misses).
    struct alignas(64) Node
    {
        std::atomic<float> mMinX[4];     ///< Slot bounds; an empty slot has min = +cLargeFloat, max = -large
        std::atomic<float> mMinY[4];     ///< See mMinX
        std::atomic<float> mMinZ[4];     ///< See mMinX
        std::atomic<float> mMaxX[4];     ///< See mMinX
        std::atomic<float> mMaxY[4];     ///< See mMinX
        std::atomic<float> mMaxZ[4];     ///< See mMinX
        std::atomic<uint32_t> mChild[4]; ///< Tagged child: node index, cBodyFlag | body index, or invalid
        std::atomic<uint32_t> mParent;   ///< Parent node index or cInvalidNode for a root
        std::atomic<bool> mChanged;      ///< Bounds or children changed since the last rebuild
        std::atomic<uint8_t> mLoose;     ///< Bit s: slot s holds a body whose slot bounds may be too wide
    };
    // The bound rows are 16-byte aligned: queries read each as one SIMD load (QuadTreeInternal.h)
    static_assert(offsetof(Node, mMinY) % 16 == 0 && offsetof(Node, mMaxZ) % 16 == 0 &&
                  alignof(Node) % 16 == 0);

    /// A query that walks several trees of one body table under one read section of the table's reclaimer,
    /// which the caller holds for all of them (BroadPhaseQuadTree): the section's entry epoch, and the trees
    /// it walks (a bit per tree id). With it a body in transit between two of them is reported by one walk
    /// only.
    struct MultiTreeQuery
    {
        uint64_t mEpoch = 0; ///< EpochReclaimer::ReadScope::GetEpoch of the caller's section
        uint32_t mTrees = 0; ///< Bit t: the query walks tree id t
    };

    /// A prepared, not yet linked sub-tree.
    struct SubTree
    {
        uint32_t mChild = cInvalidChild;    ///< Root node of the sub-tree, or invalid when empty
        AABB mBounds;                       ///< Bounds of everything in it
        uint32_t mNumBodies = 0;            ///< Bodies in it
        uint32_t mSpareRoot = cInvalidNode; ///< Reserved for a new root if the root is full when linking
    };

    /// What a rebuild did.
    struct RebuildStats
    {
        bool mRebuilt = false;          ///< False when nothing had changed (or the node pool ran out)
        bool mOutOfNodes = false;       ///< The pool could not hold the new tree; the old one stays
        bool mDeferred = false;         ///< Skipped: too many retired nodes wait for slow readers
        uint32_t mRelocatedBodies = 0;  ///< Bodies moved to new leaves
        uint32_t mKeptNodes = 0;        ///< Unchanged sub-trees kept whole
        uint32_t mNewNodes = 0;         ///< Nodes of the new tree
        uint32_t mRetiredNodes = 0;     ///< Old nodes handed to the reclaimer
        double mCommitMicroseconds = 0; ///< Time under the exclusive modification lock
    };

    /// Node memory.
    struct MemoryStats
    {
        uint32_t mNodesInUse = 0;    ///< Allocated (live, prepared or retired)
        uint32_t mNodesRetired = 0;  ///< Waiting for the reclaimer
        size_t mNodeBytesInUse = 0;  ///< mNodesInUse * sizeof(Node)
        size_t mNodeBytesBacked = 0; ///< Storage allocated for nodes (chunks)
    };

    /// ioBodies: the body table shared by the trees of one broad phase (must outlive the tree). inTreeId:
    /// this tree's id in the table (distinct per tree sharing it). inMaxNodes: node pool capacity (storage is
    /// allocated in chunks as the pool's high-water mark grows). inRebuildReserve: nodes that BuildSubTree
    /// leaves free for rebuilds, so that a tree bloated by adds and removes can always be rebuilt (and its
    /// old nodes freed) instead of staying stuck at a full pool.
    QuadTree(QuadTreeBodyTable& ioBodies, uint8_t inTreeId, uint32_t inMaxNodes,
             uint32_t inRebuildReserve = 0);
    ~QuadTree();
    QuadTree(const QuadTree&) = delete;
    QuadTree& operator=(const QuadTree&) = delete;

    /// Builds a sub-tree of inBodies off the live tree and records each body's location, id and exact bounds.
    /// Bodies with invalid bounds, indices or layers, and bodies already present in any tree of the table,
    /// are skipped. Returns an empty SubTree when nothing valid was given or the node pool ran out.
    SubTree BuildSubTree(std::span<const BroadPhaseBody> inBodies);
    /// Returns the nodes of an unlinked sub-tree to the pool and forgets its bodies.
    void FreeSubTree(const SubTree& inSubTree);
    /// Makes a built sub-tree visible in O(1); never fails (a full root uses the sub-tree's spare node).
    void LinkSubTree(const SubTree& inSubTree);

    /// Removes a linked body; false (ignored) when inBody is not in this tree (exact id).
    bool RemoveBody(BodyID inBody);
    /// Stores the body's new exact bounds and grows its slot (and the parents') to contain them.
    void MoveBody(BodyID inBody, const AABB& inBounds);
    /// A shared hold of the tree's modification lock over several moves (a batch pays for the lock once; a
    /// rebuild commit waits for the whole batch), or over a body's change of trees. The holder calls only the
    /// *Held modifying methods of the tree (the lock is not recursive).
    class MoveScope
    {
    public:
        explicit MoveScope(QuadTree& inTree) : mTree(inTree), mLock(inTree.mModificationLock) {}
        QuadTree& GetTree() const { return mTree; }

    private:
        QuadTree& mTree;
        StripedSharedMutex::SharedLock mLock;
    };
    /// MoveBody under a MoveScope of this tree; false (nothing changed) when the body is not in it.
    bool MoveBodyHeld(const MoveScope& inScope, BodyID inBody, const AABB& inBounds);
    /// Sets the object layer of a linked body (same broad-phase layer).
    void SetBodyLayer(BodyID inBody, ObjectLayer inLayer);

    /// A body changing trees (see the top of this file), in the order the change calls them:
    /// A private one-body sub-tree for body index inIndex, which is linked in another tree of the table: the
    /// table entry is left alone. outLocation: the leaf's location. An empty SubTree when out of nodes.
    SubTree BuildSecondLeaf(uint32_t inIndex, const AABB& inBounds, uint32_t& outLocation);
    /// LinkSubTree under a MoveScope of this tree.
    void LinkSubTreeHeld(const MoveScope& inScope, const SubTree& inSubTree);
    /// RemoveBody under a MoveScope of this tree.
    bool RemoveBodyHeld(const MoveScope& inScope, BodyID inBody);
    /// Makes the leaf that BuildSecondLeaf made (at inLocation, linked since) the body's location in the
    /// table, once the body's leaf in its old tree is removed.
    void AdoptSecondLeaf(const MoveScope& inScope, uint32_t inIndex, uint32_t inLocation);

    /// Margin (m) by which a rebuild grows the slot of a body that moved since the previous rebuild (0: exact
    /// slots), or cMovedSlotMarginShare of the body's box's smallest size where that is less. A body then
    /// moves inside its slot for a while without writing to any node (no cache line taken from the other
    /// cores, no node marked changed for the next rebuild); queries test its exact bounds. Update thread, or
    /// before the tree is shared.
    void SetMovedSlotMargin(float inMargin)
    {
        mMovedSlotMargin = inMargin > 0.0f && inMargin < cLargeFloat ? inMargin : 0.0f;
    }
    /// The most a moved slot's margin takes of the body's box's smallest size: the full margin around a small
    /// body (a ragdoll's forearm) made its slot reach far more neighbours' than its box does, and every pair
    /// walk that met the slot paid for a leaf test; a body that small moves less inside its slot before it
    /// leaves it, and writes a node then.
    static constexpr float cMovedSlotMarginShare = 0.15f;
    /// Longest stretch of a moved body's slot ahead of its motion (see SetMovedSlotReach).
    static constexpr float cMaxMovedSlotReach = 1.0f;
    /// How far ahead a rebuild stretches the slot of a body that moved since the previous rebuild, in
    /// multiples of that move (on each axis, past the margin, at most cMaxMovedSlotReach; 0: no stretch). A
    /// falling or sliding body then crosses its slot in that many steps without writing a node: no ancestor
    /// grown up to the root on every step (cache lines taken from the other core) and no path for the next
    /// rebuild. Needs a margin (SetMovedSlotMargin). A body that stops inside a stretched slot keeps it until
    /// a rebuild visits its node again (its moves no longer change the tree): queries then test its exact
    /// bounds for a little longer. Update thread, or before the tree is shared.
    void SetMovedSlotReach(float inMoves)
    {
        mMovedSlotReach = inMoves > 0.0f && inMoves < cLargeFloat ? inMoves : 0.0f;
    }
    /// Rebuilds the changed parts (everything when inFull) into a new tree and swaps it in. Update thread.
    RebuildStats Rebuild(bool inFull);
    /// Advances the reclaimer and frees retired nodes that no query can reach any more. Update thread.
    void CollectGarbage();

    /// Bodies whose exact bounds overlap inBox. inMask: object layers to report.
    void CollideAABox(const AABB& inBox, ObjectLayerMask inMask, BodyVisitor inVisitor,
                      const MultiTreeQuery* inMulti = nullptr) const;
    /// As CollideAABox, with each body's bounds as the query saw them: exact, or, while a move of the body is
    /// being written, its slot's (which contain the old bounds).
    void CollideAABoxWithBounds(const AABB& inBox, ObjectLayerMask inMask,
                                FunctionRef<void(BodyID, const AABB&)> inVisitor,
                                const MultiTreeQuery* inMulti = nullptr) const;
    /// Bodies whose exact bounds are within inRadius of inCenter.
    void CollideSphere(const Vec3& inCenter, float inRadius, ObjectLayerMask inMask, BodyVisitor inVisitor,
                       const MultiTreeQuery* inMulti = nullptr) const;
    /// Bodies whose exact bounds contain inPoint.
    void CollidePoint(const Vec3& inPoint, ObjectLayerMask inMask, BodyVisitor inVisitor,
                      const MultiTreeQuery* inMulti = nullptr) const;
    /// Bodies whose exact bounds the segment enters before ioMaxFraction (which the visitor can lower; a
    /// negative value stops). Returns false when the visitor stopped the cast.
    bool CastRay(const RayCast& inRay, ObjectLayerMask inMask, float& ioMaxFraction, RayBodyVisitor inVisitor,
                 const MultiTreeQuery* inMulti = nullptr) const;
    /// Bodies whose exact bounds the swept box touches before ioMaxFraction; as CastRay.
    bool CastAABox(const AABB& inBox, const Vec3& inDisplacement, ObjectLayerMask inMask,
                   float& ioMaxFraction, RayBodyVisitor inVisitor,
                   const MultiTreeQuery* inMulti = nullptr) const;

    /// Bodies linked (a snapshot: others may be adding and removing).
    uint32_t GetNumBodies() const
    {
        return mNumBodies.load(std::memory_order_relaxed); // Relaxed: a size hint, see mNumBodies
    }
    /// True when the body (exact id) is in a built or linked sub-tree of this tree.
    bool Contains(BodyID inBody) const;
    /// Starts fetching the cache lines of the node that holds body index inIndex, if it is in this tree: a
    /// hint for a caller about to move it (the moves of a batch otherwise wait for each node in turn).
    /// Reads nothing it relies on; any thread.
    void PrefetchNodeOf(uint32_t inIndex) const;
    /// Bounds of a body of this tree: exact when readable, else its slot bounds (a superset); empty if
    /// absent.
    AABB GetBodyBounds(BodyID inBody) const;
    /// Current slot bounds of a body (the grown ones). For tests.
    AABB GetBodySlotBounds(BodyID inBody) const;
    /// Node pool usage.
    MemoryStats GetMemoryStats() const;
    /// Checks the structure (parents, body locations, slot bounds containing children); for single-threaded
    /// tests. Returns the number of bodies reachable from the root, or -1 on the first violation.
    int64_t Validate() const;

private:
    /// Nodes retired by one rebuild, freed when the reclaimer says no reader can reach them.
    struct RetiredBatch
    {
        uint64_t mEpoch;              ///< Epoch when the nodes became unreachable for new readers
        std::vector<uint32_t> mNodes; ///< Node indices to free
    };
    using LeafCallback = FunctionRef<void(const quadtree::BuildItem& inItem, uint32_t inNode, int inSlot)>;

    /// Frees the retired batches that the reclaimer's current epoch makes safe. Update thread.
    void FreeReclaimableNodes();

    /// Builds private nodes over ioItems (reordered): split at the midpoint of the longest axis of the
    /// centres, then the largest part again, up to four parts per node, recursively; parts that fit a leaf
    /// are not split further, neighbouring small parts are merged and small parts are pulled up into free
    /// slots, so that leaves are full. inOnLeaf is called for every placed item. Returns the root
    /// and its bounds, or an invalid child when out of nodes. Every allocated node is appended to ioNewNodes.
    SubTree BuildNodes(std::span<quadtree::BuildItem> ioItems, uint32_t inKeepFree,
                       std::vector<uint32_t>& ioNewNodes, LeafCallback inOnLeaf);
    /// Recursive part of BuildNodes for [inBegin, inEnd) (non-empty).
    SubTree BuildRange(quadtree::BuildItem* inBegin, quadtree::BuildItem* inEnd, uint32_t inParent,
                       uint32_t inKeepFree, std::vector<uint32_t>& ioNewNodes, LeafCallback inOnLeaf);

    static constexpr uint32_t cChunkShift = 10; ///< Nodes are stored in chunks of 1,024 (123 KB)
    static constexpr uint32_t cChunkSize = 1u << cChunkShift;

    Node& GetNode(uint32_t inIndex) const
    {
        // Acquire: pairs with the release that installed the chunk (a node index reaches another thread only
        // after a release publication anyway; this keeps the chunk pointer itself ordered too)
        return mChunks[inIndex >> cChunkShift].load(std::memory_order_acquire)[inIndex & (cChunkSize - 1)];
    }
    /// Allocates a node with four empty slots and the given parent (storage backed on demand), leaving at
    /// least inKeepFree nodes in the pool.
    uint32_t AllocateNode(uint32_t inParent, uint32_t inKeepFree = 0);
    /// Sets the node's Changed flag unless it is set (no write then).
    static void MarkChanged(Node& ioNode);
    /// Empties a private node's slots for (re)use.
    void ResetNode(uint32_t inNode, uint32_t inParent);
    /// Sets a slot of a node that is not published yet.
    static void InitSlot(Node& ioNode, int inSlot, uint32_t inChild, const AABB& inBounds);
    /// Grows slot inSlot of inNode by inBounds with atomic min/max.
    static void GrowSlot(Node& ioNode, int inSlot, const AABB& inBounds);
    /// Empties a slot (bounds and child).
    static void ClearSlot(Node& ioNode, int inSlot);
    /// The slot a rebuild gives a body that moved (see SetMovedSlotReach): inBounds grown by the margin and,
    /// on each axis, stretched ahead by the room the body left behind in inOldSlot. That room is only on a
    /// side the last rebuild did not stretch (inStretchedSides, the body table's mSlotReachSides): a stretch
    /// the body has not used is not a move, else an idle body's slot would grow at every rebuild.
    /// outStretchedSides: the sides stretched now.
    AABB MovedSlot(const AABB& inBounds, const AABB& inOldSlot, uint8_t inStretchedSides,
                   uint8_t& outStretchedSides) const;
    /// Slot bounds as read now (each float atomically).
    static AABB LoadSlot(const Node& inNode, int inSlot)
    {
        // Acquire: pairs with the releases in GrowSlot (see there)
        return AABB(Vec3(inNode.mMinX[inSlot].load(std::memory_order_acquire),
                         inNode.mMinY[inSlot].load(std::memory_order_acquire),
                         inNode.mMinZ[inSlot].load(std::memory_order_acquire)),
                    Vec3(inNode.mMaxX[inSlot].load(std::memory_order_acquire),
                         inNode.mMaxY[inSlot].load(std::memory_order_acquire),
                         inNode.mMaxZ[inSlot].load(std::memory_order_acquire)));
    }
    /// Grows the slot holding inNode in its parent, and so on up to the root; marks every node changed.
    void PropagateUp(uint32_t inNode, const AABB& inBounds);
    /// Marks inNode and its ancestors changed.
    void MarkChangedUp(uint32_t inNode);
    /// Depth-first walk under a read section (its own, or inMulti's). inTest4(SlotBounds4, Array4f&
    /// fractions)
    /// -> slot mask decides which slots to descend or report; inTest(exact AABB, float& fraction) -> bool
    /// re-tests a body whose slot is loose; inLeaf(BodyID, fraction) -> bool returns false to stop (or
    /// inLeaf(BodyID, fraction, bounds) to get the bounds tested too). Returns false when stopped.
    template <class Test4, class Test, class LeafVisit>
    bool Walk(ObjectLayerMask inMask, const MultiTreeQuery* inMulti, Test4&& inTest4, Test&& inTest,
              LeafVisit&& inLeaf) const;
    template <class Test4, class Test, class LeafVisit>
    bool WalkInSection(ObjectLayerMask inMask, const MultiTreeQuery* inMulti, Test4&& inTest4, Test&& inTest,
                       LeafVisit&& inLeaf) const;
    /// Whether a walk reports the leaf of body index inIndex, which the transit record inTransit names, in
    /// this tree, for a query filtered by inMask (checked when inCheckLayers).
    bool ReportsTransitLeaf(uint64_t inTransit, const MultiTreeQuery* inMulti, ObjectLayerMask inMask,
                            bool inCheckLayers) const;

    /// The body's location when this exact id (index and sequence) is linked in this tree or in a sub-tree
    /// built for it (acquire), else cInvalidLocation.
    uint32_t FindLocation(BodyID inBody) const;
    /// Number of sub-trees linked into the root chain since phase 1 of a rebuild. Rebuild commit only.
    uint32_t CountLateSubTrees(uint32_t inOldRoot) const;
    /// Links the unmarked sub-trees that linkers put into the old root chain during a rebuild into the new
    /// (private) root, using the spare nodes for new roots. Rebuild commit only.
    uint32_t LinkLateSubTrees(uint32_t inOldRoot, uint32_t inNewRoot, std::vector<uint32_t>& ioSpares,
                              std::vector<uint32_t>& ioRetired);
    bool IsMarked(uint32_t inNode) const
    {
        return inNode < mRebuildMark.size() && mRebuildMark[inNode] == mRebuildStamp;
    }

    QuadTreeBodyTable& mBodies;                    ///< Shared per-body records
    uint8_t mTreeId;                               ///< This tree's id in mBodies
    uint32_t mRebuildReserve;                      ///< See the constructor
    NodeAllocator mAllocator;                      ///< Hands out node indices
    std::unique_ptr<std::atomic<Node*>[]> mChunks; ///< Node storage, allocated on demand
    std::atomic<uint32_t> mRoot;                   ///< Current root node
    StripedSharedMutex mModificationLock;          ///< Shared: modifiers; exclusive: rebuild commit
    std::vector<RetiredBatch> mRetired;            ///< Update thread only: nodes waiting to be freed
    std::atomic<uint32_t> mNumRetired{0};          ///< Statistic: nodes in mRetired
    std::vector<uint64_t>
        mFreeMarks; ///< Update thread only: a bit per node being freed (all zero between calls)
    /// Bodies linked: queries skip an empty tree without entering its read section (relaxed: a body whose
    /// link finished before a query started is counted in the same thread before its link, so the query sees
    /// it)
    std::atomic<uint32_t> mNumBodies{0};
    std::unique_ptr<quadtree::RebuildScratch> mRebuildScratch; ///< Update thread only: reused arrays
    std::vector<uint32_t> mRebuildMark;                        ///< Update thread only: node -> rebuild stamp
    uint32_t mRebuildStamp = 0;                                ///< Update thread only
    float mMovedSlotMargin = 0.0f;                             ///< Update thread only (SetMovedSlotMargin)
    float mMovedSlotReach = 0.0f;                              ///< Update thread only (SetMovedSlotReach)
};

} // namespace cairn::physics
