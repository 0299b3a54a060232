#pragma once

// QuadTree: a lock-free 4-wide bounding volume tree of bodies (the building block of the quad-tree broad
// phase, after Jolt's design: see ../shared/reference/talk-architecting-jolt-gdc2022.txt).
//
// Threads:
//  - BuildSubTree / FreeSubTree: any thread, concurrently with everything; they only touch nodes that are not
//    reachable from the root yet (allocated from the lock-free NodeAllocator).
//  - LinkSubTree, RemoveBody, MoveBody, queries: any thread, concurrently with each other. The caller
//    serialises operations on the same body (add, remove and move of one body index never overlap).
// Why lock-free is safe:
//  - A sub-tree is built privately and published with one compare-exchange (release) of a child slot or of
//    the root index; readers load child indices with acquire, so they see the fully built nodes.
//  - A slot being published starts with empty bounds and only grows (atomic min/max), so a reader sees either
//    no sub-tree or a sub-tree with bounds that contain everything below it once the linker has finished.
//  - Bounds only ever grow until a rebuild (MoveBody uses atomic min on mins and max on maxes and walks to
//    the root), so a concurrent query may see bounds that are too wide, never too narrow for the body's
//    previous or new bounds. Removal sets a slot empty; queries then report the body or not.
//  - Published nodes are never freed (only a rebuild, not implemented yet, would retire them by generation),
//    so a reader never follows an index into a recycled node.
// Queries allocate nothing: fixed-size traversal stack (spilling to the heap only for degenerate depths).

#include "cairn/physics/broadphase/BroadPhase.h"
#include "cairn/physics/broadphase/NodeAllocator.h"

#include <atomic>
#include <memory>
#include <span>

namespace cairn
{

class QuadTree
{
public:
    /// Child slot value: a node index, a body index with cBodyFlag set, or cInvalidChild.
    static constexpr uint32_t cInvalidChild = 0xffffffffu;
    static constexpr uint32_t cBodyFlag = 0x80000000u;
    static constexpr uint32_t cInvalidNode = NodeAllocator::cInvalidIndex;

    /// One node: four child slots, each with its bounds. Every field is atomic because readers traverse
    /// while writers grow bounds and fill slots.
    struct Node
    {
        std::atomic<float>
            mMinX[4]; ///< Slot bounds; an empty slot has min = +cLargeFloat, max = -cLargeFloat
        std::atomic<float> mMinY[4];     ///< See mMinX
        std::atomic<float> mMinZ[4];     ///< See mMinX
        std::atomic<float> mMaxX[4];     ///< See mMinX
        std::atomic<float> mMaxY[4];     ///< See mMinX
        std::atomic<float> mMaxZ[4];     ///< See mMinX
        std::atomic<uint32_t> mChild[4]; ///< Tagged child: node index, cBodyFlag | body index, or invalid
        std::atomic<uint32_t> mParent;   ///< Parent node index or cInvalidNode for a root
        std::atomic<bool> mChanged;      ///< Bounds or children changed since the last rebuild (hint)
    };

    /// A prepared, not yet linked sub-tree.
    struct SubTree
    {
        uint32_t mChild = cInvalidChild; ///< What goes in the slot: a node or a single body
        AABB mBounds;                    ///< Bounds of everything in it
    };

    /// inMaxBodies: body indices must be < inMaxBodies (< cBodyFlag). inMaxNodes: node pool size.
    QuadTree(uint32_t inMaxBodies, uint32_t inMaxNodes);
    QuadTree(const QuadTree&) = delete;
    QuadTree& operator=(const QuadTree&) = delete;

    /// Builds a sub-tree of inBodies off the live tree and records each body's location and id. Bodies
    /// with invalid bounds or indices are skipped. Returns an empty SubTree (mChild invalid) when nothing
    /// valid was given or the node pool ran out (then nothing is allocated).
    SubTree BuildSubTree(std::span<const BroadPhaseBody> inBodies);
    /// Returns the nodes of an unlinked sub-tree to the pool and forgets its bodies' locations.
    void FreeSubTree(const SubTree& inSubTree);
    /// Makes a built sub-tree visible in O(1). Returns false only if the node pool is exhausted when the
    /// root is full (the sub-tree is then still owned by the caller).
    bool LinkSubTree(const SubTree& inSubTree);

    /// Removes a linked body; ignored when inBody is not in the tree (exact id).
    void RemoveBody(BodyID inBody);
    /// Grows the linked body's bounds to encapsulate inBounds (bounds only grow until a rebuild).
    void MoveBody(BodyID inBody, const AABB& inBounds);

    /// Bodies whose slot bounds overlap inBox.
    void CollideAABox(const AABB& inBox, const BroadPhaseQueryFilter& inFilter, BodyVisitor inVisitor) const;
    /// Bodies whose slot bounds overlap the sphere.
    void CollideSphere(const Vec3& inCenter, float inRadius, const BroadPhaseQueryFilter& inFilter,
                       BodyVisitor inVisitor) const;
    /// Bodies whose slot bounds contain inPoint.
    void CollidePoint(const Vec3& inPoint, const BroadPhaseQueryFilter& inFilter,
                      BodyVisitor inVisitor) const;
    /// Bodies whose slot bounds the segment enters before the visitor's current maximum fraction.
    void CastRay(const RayCast& inRay, const BroadPhaseQueryFilter& inFilter, RayBodyVisitor inVisitor) const;

    /// True when the body (exact id) is in a built or linked sub-tree.
    bool Contains(BodyID inBody) const;
    /// Current slot bounds of a body in the tree (empty if absent). For tests and statistics.
    AABB GetBodyBounds(BodyID inBody) const;
    /// Node pool usage.
    uint32_t GetNumAllocatedNodes() const { return mAllocator.GetNumAllocated(); }

private:
    static constexpr uint32_t cInvalidLocation = 0xffffffffu; ///< mBodyLocation of an absent body

    /// Body entry of the build: index into the input plus its centre.
    struct BuildItem
    {
        uint32_t mInput;
        Vec3 mCenter;
    };

    /// Recursively builds [inBegin, inEnd) (non-empty) and returns the slot value and bounds. Returns an
    /// invalid child if the pool ran out (nodes allocated so far are listed in the tree and freed by caller).
    SubTree Build(std::span<const BroadPhaseBody> inBodies, BuildItem* inBegin, BuildItem* inEnd,
                  uint32_t inParent, bool& ioOutOfNodes);
    /// Sets a slot of a node that is not published yet.
    void InitSlot(Node& ioNode, int inSlot, uint32_t inChild, const AABB& inBounds);
    /// Allocates a node with four empty slots and the given parent.
    uint32_t AllocateNode(uint32_t inParent);
    /// Grows slot inSlot of inNode by inBounds with atomic min/max.
    static void GrowSlot(Node& ioNode, int inSlot, const AABB& inBounds);
    /// Slot bounds as read now (each float atomically, relaxed).
    static AABB LoadSlot(const Node& inNode, int inSlot);
    /// Grows the slot holding inNode in its parent, and so on up to the root; marks every node changed.
    void PropagateUp(uint32_t inNode, const AABB& inBounds);
    /// Depth-first walk: inNodeTest(AABB) -> bool decides descent and leaf reports; inLeaf(BodyID) -> bool
    /// returns false to stop.
    template <class NodeTest, class LeafVisit>
    void Walk(const BroadPhaseQueryFilter& inFilter, NodeTest&& inNodeTest, LeafVisit&& inLeaf) const;

    uint32_t mMaxBodies;                                    ///< Size of the per-body arrays
    NodeAllocator mAllocator;                               ///< Hands out node indices
    std::unique_ptr<Node[]> mNodes;                         ///< Node storage, indexed by node index
    std::atomic<uint32_t> mRoot;                            ///< Current root node
    std::unique_ptr<std::atomic<uint32_t>[]> mBodyLocation; ///< Body index -> node << 2 | slot, or invalid
    std::unique_ptr<std::atomic<uint32_t>[]> mBodySequence; ///< Body index -> sequence of the stored id
    std::unique_ptr<std::atomic<uint8_t>[]> mBodyLayer;     ///< Body index -> object layer
};

} // namespace cairn
