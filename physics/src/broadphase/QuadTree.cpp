#include "broadphase/QuadTree.h"

#include "QuadTreeInternal.h"
#include "broadphase/BroadPhaseOverlap.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cstddef>
#include <type_traits>

namespace cairn::physics
{

using quadtree::BuildItem;
using quadtree::IsEmptyBox;
using quadtree::NodeStack;

QuadTree::QuadTree(QuadTreeBodyTable& ioBodies, uint8_t inTreeId, uint32_t inMaxNodes,
                   uint32_t inRebuildReserve)
    : mBodies(ioBodies), mTreeId(inTreeId), mRebuildReserve(inRebuildReserve),
      mAllocator(std::clamp(inMaxNodes, 1u, 1u << 30)),
      mChunks(
          std::make_unique<std::atomic<Node*>[]>((mAllocator.GetCapacity() + cChunkSize - 1) >> cChunkShift))
{
    // Construction is single-threaded; the object is published to other threads by whoever shares it
    const uint32_t numChunks = (mAllocator.GetCapacity() + cChunkSize - 1) >> cChunkShift;
    for (uint32_t i = 0; i < numChunks; ++i)
        mChunks[i].store(nullptr, std::memory_order_relaxed);
    mRoot.store(AllocateNode(cInvalidNode), std::memory_order_relaxed); // Construction: see above
    mRebuildScratch = std::make_unique<quadtree::RebuildScratch>();
}

QuadTree::~QuadTree()
{
    const uint32_t numChunks = (mAllocator.GetCapacity() + cChunkSize - 1) >> cChunkShift;
    for (uint32_t i = 0; i < numChunks; ++i)
        delete[] mChunks[i].load(std::memory_order_relaxed); // No other thread may use a dying tree
}

uint32_t QuadTree::AllocateNode(uint32_t inParent, uint32_t inKeepFree)
{
    const uint32_t index = mAllocator.Allocate(inKeepFree);
    if (index == cInvalidNode) return cInvalidNode;
    std::atomic<Node*>& chunk = mChunks[index >> cChunkShift];
    // Acquire: if another thread installed the chunk, see its initialisation
    if (chunk.load(std::memory_order_acquire) == nullptr)
    {
        Node* fresh = new Node[cChunkSize]; // Only when the high-water mark enters a new chunk
        Node* expected = nullptr;
        // Release on success: publishes the constructed chunk; acquire on failure: we use the winner's
        if (!chunk.compare_exchange_strong(expected, fresh, std::memory_order_release,
                                           std::memory_order_acquire))
            delete[] fresh;
    }
    ResetNode(index, inParent);
    return index;
}

void QuadTree::ResetNode(uint32_t inNode, uint32_t inParent)
{
    Node& node = GetNode(inNode);
    // Relaxed everywhere: the node is private until a release compare-exchange publishes it
    for (int s = 0; s < 4; ++s)
        InitSlot(node, s, cInvalidChild, AABB::Empty());
    node.mParent.store(inParent, std::memory_order_relaxed);
    node.mChanged.store(false, std::memory_order_relaxed);
    node.mLoose.store(0, std::memory_order_relaxed);
}

void QuadTree::InitSlot(Node& ioNode, int inSlot, uint32_t inChild, const AABB& inBounds)
{
    // Relaxed: only called on nodes not yet reachable by readers; the publishing release orders these
    ioNode.mMinX[inSlot].store(inBounds.mMin.x(), std::memory_order_relaxed);
    ioNode.mMinY[inSlot].store(inBounds.mMin.y(), std::memory_order_relaxed);
    ioNode.mMinZ[inSlot].store(inBounds.mMin.z(), std::memory_order_relaxed);
    ioNode.mMaxX[inSlot].store(inBounds.mMax.x(), std::memory_order_relaxed);
    ioNode.mMaxY[inSlot].store(inBounds.mMax.y(), std::memory_order_relaxed);
    ioNode.mMaxZ[inSlot].store(inBounds.mMax.z(), std::memory_order_relaxed);
    ioNode.mChild[inSlot].store(inChild, std::memory_order_relaxed);
}

void QuadTree::GrowSlot(Node& ioNode, int inSlot, const AABB& inBounds)
{
    // Maxes first, then mins, each with release: a reader that acquires a new min also sees the new maxes (a
    // slot filled from empty never looks like a box that is only partly there), and a reader that acquires
    // any grown value sees the loose bit that MoveBody set before growing
    quadtree::AtomicMax(ioNode.mMaxX[inSlot], inBounds.mMax.x());
    quadtree::AtomicMax(ioNode.mMaxY[inSlot], inBounds.mMax.y());
    quadtree::AtomicMax(ioNode.mMaxZ[inSlot], inBounds.mMax.z());
    quadtree::AtomicMin(ioNode.mMinX[inSlot], inBounds.mMin.x());
    quadtree::AtomicMin(ioNode.mMinY[inSlot], inBounds.mMin.y());
    quadtree::AtomicMin(ioNode.mMinZ[inSlot], inBounds.mMin.z());
}

void QuadTree::ClearSlot(Node& ioNode, int inSlot)
{
    // Relaxed: a reader seeing any mix of old and empty bounds reports the body or not, both allowed; the
    // slot's writers are serialised (one body's operations, or the rebuild commit under the exclusive lock)
    ioNode.mMinX[inSlot].store(cLargeFloat, std::memory_order_relaxed);
    ioNode.mMinY[inSlot].store(cLargeFloat, std::memory_order_relaxed);
    ioNode.mMinZ[inSlot].store(cLargeFloat, std::memory_order_relaxed);
    ioNode.mMaxX[inSlot].store(-cLargeFloat, std::memory_order_relaxed);
    ioNode.mMaxY[inSlot].store(-cLargeFloat, std::memory_order_relaxed);
    ioNode.mMaxZ[inSlot].store(-cLargeFloat, std::memory_order_relaxed);
    // Relaxed: a leaf slot is never refilled before a rebuild, which swaps in new nodes
    ioNode.mChild[inSlot].store(cInvalidChild, std::memory_order_relaxed);
}

QuadTree::SubTree QuadTree::BuildSubTree(std::span<const BroadPhaseBody> inBodies)
{
    // Off the hot path (loading thread): the item list is this thread's, kept for its capacity. A fresh one
    // per batch cost a page fault every 4 KB (0.64 MB for a 20,000-body batch) and its unmapping; nodes come
    // from the pool
    thread_local std::vector<BuildItem> items;
    items.clear();
    items.reserve(inBodies.size());
    for (const BroadPhaseBody& body : inBodies)
    {
        const uint32_t index = body.mID.GetIndex();
        if (index >= mBodies.GetMaxBodies() || index >= cBodyFlag || !IsValidBroadPhaseBounds(body.mBounds) ||
            body.mLayer >= cMaxObjectLayers)
        {
            assert(false && "QuadTree: invalid body");
            continue;
        }
        // Claim the index, so that a body already present (or twice in this batch) is not added again.
        // Relaxed: the caller serialises operations on one body; the claim only detects double adds
        uint32_t expected = QuadTreeBodyTable::cInvalidLocation;
        if (!mBodies[index].mLocation.compare_exchange_strong(expected, QuadTreeBodyTable::cPendingLocation,
                                                              std::memory_order_relaxed))
            continue;
        QuadTreeBodyTable::Entry& entry = mBodies[index];
        // Relaxed: read by queries only after the sub-tree is published by a release exchange
        mBodies.Sequence(index).store(body.mID.GetSequence(), std::memory_order_relaxed);
        entry.mLayer.store(body.mLayer, std::memory_order_relaxed);
        entry.mTree.store(mTreeId, std::memory_order_relaxed); // As above
        QuadTreeBodyTable::StoreBounds(entry, body.mBounds);
        items.push_back({cBodyFlag | index, body.mBounds, QuadTreeBodyTable::cInvalidLocation});
    }
    if (items.empty()) return {};

    std::vector<uint32_t> newNodes;
    // The link's spare root first, so that a batch gets everything it needs or nothing; rebuilds keep a
    // reserve that batches may not take
    const uint32_t spareRoot = AllocateNode(cInvalidNode, mRebuildReserve);
    if (spareRoot != cInvalidNode) newNodes.push_back(spareRoot);
    const SubTree tree = spareRoot == cInvalidNode
                             ? SubTree{}
                             : BuildNodes(items, mRebuildReserve, newNodes,
                                          [&](const BuildItem& inItem, uint32_t inNode, int inSlot)
                                          {
                                              // Release: Remove/Move of this body (acquire) see the node
                                              // contents
                                              mBodies[inItem.mChild & ~cBodyFlag].mLocation.store(
                                                  inNode << 2 | uint32_t(inSlot), std::memory_order_release);
                                          });
    if (tree.mChild != cInvalidChild)
    {
        SubTree result = tree;
        result.mNumBodies = uint32_t(items.size());
        result.mSpareRoot = spareRoot;
        return result;
    }
    // Out of nodes: give everything back
    for (uint32_t node : newNodes)
        mAllocator.Free(node); // Never published
    for (const BuildItem& item : items)
        // Relaxed: never published
        mBodies[item.mChild & ~cBodyFlag].mLocation.store(QuadTreeBodyTable::cInvalidLocation,
                                                          std::memory_order_relaxed);
    return {};
}

void QuadTree::FreeSubTree(const SubTree& inSubTree)
{
    if (inSubTree.mSpareRoot != cInvalidNode) mAllocator.Free(inSubTree.mSpareRoot); // Never published
    if (inSubTree.mChild == cInvalidChild) return;
    // Iterative, so that deep trees cannot overflow the thread's stack; nodes are private (never linked)
    NodeStack stack;
    stack.Push(inSubTree.mChild);
    uint32_t nodeIndex;
    while (stack.Pop(nodeIndex))
    {
        Node& node = GetNode(nodeIndex);
        for (int s = 0; s < 4; ++s)
        {
            const uint32_t child = node.mChild[s].load(std::memory_order_relaxed); // Private node
            if (child == cInvalidChild) continue;
            if ((child & cBodyFlag) != 0)
                mBodies[child & ~cBodyFlag].mLocation.store(QuadTreeBodyTable::cInvalidLocation,
                                                            std::memory_order_relaxed); // Never published
            else
                stack.Push(child);
        }
        mAllocator.Free(nodeIndex);
    }
}

QuadTree::SubTree QuadTree::BuildSecondLeaf(uint32_t inIndex, const AABB& inBounds, uint32_t& outLocation)
{
    outLocation = QuadTreeBodyTable::cInvalidLocation;
    if (inIndex >= mBodies.GetMaxBodies() || inIndex >= cBodyFlag || !IsValidBroadPhaseBounds(inBounds))
    {
        assert(false && "QuadTree: invalid body");
        return {};
    }
    // No claim of the table entry: the body stays where the entry says until AdoptSecondLeaf
    BuildItem item{cBodyFlag | inIndex, inBounds, QuadTreeBodyTable::cInvalidLocation};
    std::vector<uint32_t> newNodes;
    // The spare root first, as BuildSubTree does: rebuilds keep a reserve that this may not take
    const uint32_t spareRoot = AllocateNode(cInvalidNode, mRebuildReserve);
    if (spareRoot == cInvalidNode) return {};
    newNodes.push_back(spareRoot);
    SubTree tree = BuildNodes(std::span(&item, 1), mRebuildReserve, newNodes,
                              [&](const BuildItem&, uint32_t inNode, int inSlot)
                              { outLocation = inNode << 2 | uint32_t(inSlot); });
    if (tree.mChild == cInvalidChild)
    {
        for (uint32_t node : newNodes)
            mAllocator.Free(node); // Never published
        outLocation = QuadTreeBodyTable::cInvalidLocation;
        return {};
    }
    tree.mNumBodies = 1;
    tree.mSpareRoot = spareRoot;
    return tree;
}

void QuadTree::AdoptSecondLeaf([[maybe_unused]] const MoveScope& inScope, uint32_t inIndex,
                               uint32_t inLocation)
{
    assert(&inScope.GetTree() == this);
    if (inIndex >= mBodies.GetMaxBodies()) return;
    QuadTreeBodyTable::Entry& entry = mBodies[inIndex];
    // Relaxed: read with the location by this body's serialised operations, after its release below
    entry.mTree.store(mTreeId, std::memory_order_relaxed);
    // Release: a later operation on the body (acquire, FindLocation) sees the leaf's node, and the tree id
    entry.mLocation.store(inLocation, std::memory_order_release);
}

void QuadTree::LinkSubTree(const SubTree& inSubTree)
{
    if (inSubTree.mChild == cInvalidChild) return;
    const MoveScope scope(*this); // Keeps out of a rebuild commit only
    LinkSubTreeHeld(scope, inSubTree);
}

void QuadTree::LinkSubTreeHeld([[maybe_unused]] const MoveScope& inScope, const SubTree& inSubTree)
{
    assert(&inScope.GetTree() == this);
    if (inSubTree.mChild == cInvalidChild) return;
    mNumBodies.fetch_add(inSubTree.mNumBodies, std::memory_order_relaxed); // Before the link: see mNumBodies
    const uint32_t subNode = inSubTree.mChild;
    for (;;)
    {
        // Acquire: we read the root's slots and may make it the child of a new root
        const uint32_t rootIndex = mRoot.load(std::memory_order_acquire);
        Node& root = GetNode(rootIndex);
        for (int s = 0; s < 4; ++s)
        {
            // Relaxed: only a hint to skip full slots; the exchange below decides
            if (root.mChild[s].load(std::memory_order_relaxed) != cInvalidChild) continue;
            // Relaxed: the sub-tree is private until the release exchange below publishes it
            GetNode(subNode).mParent.store(rootIndex, std::memory_order_relaxed);
            uint32_t expected = cInvalidChild;
            // Release on success: publishes the sub-tree's nodes to readers that acquire the slot; relaxed on
            // failure: another linker took the slot, try the next one
            if (root.mChild[s].compare_exchange_strong(expected, subNode, std::memory_order_release,
                                                       std::memory_order_relaxed))
            {
                GrowSlot(root, s, inSubTree.mBounds);                 // Max first, then min (see GrowSlot)
                root.mChanged.store(true, std::memory_order_relaxed); // Rebuild hint only
                // The root may have been replaced meanwhile: keep the new parents' bounds and flags right
                PropagateUp(rootIndex, inSubTree.mBounds);
                if (inSubTree.mSpareRoot != cInvalidNode) mAllocator.Free(inSubTree.mSpareRoot); // Unused
                return;
            }
        }

        // Root full: a new root (the batch's spare) holding the old one (unbounded: its bounds are not
        // tracked upwards) and ours
        const uint32_t newRootIndex = inSubTree.mSpareRoot;
        ResetNode(newRootIndex, cInvalidNode); // A failed exchange below may have filled it before
        Node& newRoot = GetNode(newRootIndex);
        InitSlot(newRoot, 0, rootIndex, AABB(Vec3::Constant(-cLargeFloat), Vec3::Constant(cLargeFloat)));
        InitSlot(newRoot, 1, subNode, inSubTree.mBounds);
        newRoot.mChanged.store(true, std::memory_order_relaxed);                 // Private node
        GetNode(subNode).mParent.store(newRootIndex, std::memory_order_relaxed); // Still private
        uint32_t expected = rootIndex;
        // Release on success: publishes the new root and the sub-tree; relaxed on failure: we retry from a
        // fresh acquire load of the root
        if (mRoot.compare_exchange_strong(expected, newRootIndex, std::memory_order_release,
                                          std::memory_order_relaxed))
        {
            // Release: a mover walking up (acquire) finds the new root's fully initialised slots
            root.mParent.store(newRootIndex, std::memory_order_release);
            return;
        }
    }
}

void QuadTree::MarkChanged(Node& ioNode)
{
    // Relaxed: a rebuild hint. Read first: a move that stays inside its bounds then writes nothing on its way
    // to the root, and the top nodes' cache lines stay shared with the query threads (they were invalidated
    // by every move before, a cache miss per query on each)
    if (!ioNode.mChanged.load(std::memory_order_relaxed))
        ioNode.mChanged.store(true, std::memory_order_relaxed);
}

void QuadTree::PropagateUp(uint32_t inNode, const AABB& inBounds)
{
    uint32_t nodeIndex = inNode;
    for (;;)
    {
        // Acquire: pairs with the release store of a new root's index in LinkSubTree
        const uint32_t parentIndex = GetNode(nodeIndex).mParent.load(std::memory_order_acquire);
        if (parentIndex == cInvalidNode) return;
        Node& parent = GetNode(parentIndex);
        int slot = -1;
        for (int s = 0; s < 4; ++s)
            // Relaxed: a node's slot in its parent never changes while linked, and the parent link was
            // acquired above
            if (parent.mChild[s].load(std::memory_order_relaxed) == nodeIndex) slot = s;
        if (slot < 0) return; // Cannot happen for a linked node; be safe
        GrowSlot(parent, slot, inBounds);
        MarkChanged(parent);
        nodeIndex = parentIndex;
    }
}

void QuadTree::MarkChangedUp(uint32_t inNode)
{
    for (uint32_t n = inNode; n != cInvalidNode;)
    {
        Node& node = GetNode(n);
        MarkChanged(node);
        n = node.mParent.load(std::memory_order_acquire); // Pairs with the release in LinkSubTree
    }
}

bool QuadTree::RemoveBody(BodyID inBody)
{
    if (inBody.GetIndex() >= mBodies.GetMaxBodies()) return false;
    const MoveScope scope(*this); // Keeps out of a rebuild commit only
    return RemoveBodyHeld(scope, inBody);
}

bool QuadTree::RemoveBodyHeld([[maybe_unused]] const MoveScope& inScope, BodyID inBody)
{
    assert(&inScope.GetTree() == this);
    const uint32_t index = inBody.GetIndex();
    if (index >= mBodies.GetMaxBodies()) return false;
    QuadTreeBodyTable::Entry& entry = mBodies[index];
    const uint32_t location = FindLocation(inBody);
    if (location == QuadTreeBodyTable::cInvalidLocation) return false;
    const uint32_t nodeIndex = location >> 2;
    const int slot = int(location & 3);
    Node& node = GetNode(nodeIndex);
    // Relaxed: the location is only read by this body's serialised operations and the rebuild commit (which
    // runs under the exclusive lock, so after we release ours)
    entry.mLocation.store(QuadTreeBodyTable::cInvalidLocation, std::memory_order_relaxed);
    ClearSlot(node, slot);
    MarkChangedUp(nodeIndex);
    mNumBodies.fetch_sub(1, std::memory_order_relaxed); // After the unlink: see mNumBodies
    return true;
}

void QuadTree::MoveBody(BodyID inBody, const AABB& inBounds)
{
    const MoveScope scope(*this); // Keeps out of a rebuild commit only
    MoveBodyHeld(scope, inBody, inBounds);
}

bool QuadTree::MoveBodyHeld([[maybe_unused]] const MoveScope& inScope, BodyID inBody, const AABB& inBounds)
{
    assert(&inScope.GetTree() == this);
    const uint32_t index = inBody.GetIndex();
    if (index >= mBodies.GetMaxBodies() || !IsValidBroadPhaseBounds(inBounds)) return false;
    QuadTreeBodyTable::Entry& entry = mBodies[index];
    const uint32_t location = FindLocation(inBody);
    if (location == QuadTreeBodyTable::cInvalidLocation) return false;
    const uint32_t nodeIndex = location >> 2;
    const int slot = int(location & 3);
    Node& node = GetNode(nodeIndex);
    QuadTreeBodyTable::StoreBounds(entry, inBounds);
    // Relaxed: ordered before the release of GrowSlot's first exchange, which readers acquire. Only when not
    // yet set (only this body's serialised operations set it; a bit already set was published by an earlier
    // growth): a write would take the node's cache line away from every core that queries through it
    const uint8_t looseBit = uint8_t(1u << slot);
    if ((node.mLoose.load(std::memory_order_relaxed) & looseBit) == 0)
        node.mLoose.fetch_or(looseBit, std::memory_order_relaxed);
    // Inside its slot (grown by the last rebuild when the body had moved): nothing above changes. Only this
    // body's serialised operations grow its slot, and each of them returned after growing every ancestor,
    // so the ancestors contain the slot already. Writing nothing keeps the nodes' cache lines shared, and
    // the node unchanged for the rebuild
    if (LoadSlot(node, slot).Contains(inBounds)) return true;
    GrowSlot(node, slot, inBounds);
    MarkChanged(node);
    // Always walk to the root (no early out when a parent already contains the box): another mover may have
    // grown a slot below without having reached the parent yet, and our bounds must be visible when we return
    PropagateUp(nodeIndex, inBounds);
    return true;
}

void QuadTree::SetBodyLayer(BodyID inBody, ObjectLayer inLayer)
{
    const uint32_t index = inBody.GetIndex();
    if (index >= mBodies.GetMaxBodies() || inLayer >= cMaxObjectLayers) return;
    QuadTreeBodyTable::Entry& entry = mBodies[index];
    // Relaxed: same-body operations are serialised; a query sees the old or the new layer
    if (mBodies.Sequence(index).load(std::memory_order_relaxed) == inBody.GetSequence())
        entry.mLayer.store(inLayer, std::memory_order_relaxed);
}

bool QuadTree::Contains(BodyID inBody) const
{
    return FindLocation(inBody) != QuadTreeBodyTable::cInvalidLocation;
}

uint32_t QuadTree::FindLocation(BodyID inBody) const
{
    const uint32_t index = inBody.GetIndex();
    if (index >= mBodies.GetMaxBodies()) return QuadTreeBodyTable::cInvalidLocation;
    // Relaxed: same-body operations are serialised by the caller (or this is a snapshot for tests/statistics)
    if (mBodies.Sequence(index).load(std::memory_order_relaxed) != inBody.GetSequence())
        return QuadTreeBodyTable::cInvalidLocation;
    const QuadTreeBodyTable::Entry& entry = mBodies[index];
    // Acquire: pairs with the release in BuildSubTree and the rebuild commit, so the node is seen initialised
    const uint32_t location = entry.mLocation.load(std::memory_order_acquire);
    // Relaxed: written with the location by the same serialised operations, before its release
    if (location >= QuadTreeBodyTable::cPendingLocation ||
        entry.mTree.load(std::memory_order_relaxed) != mTreeId)
        return QuadTreeBodyTable::cInvalidLocation;
    return location;
}

void QuadTree::PrefetchNodeOf(uint32_t inIndex) const
{
    if (inIndex >= mBodies.GetMaxBodies()) return;
    const QuadTreeBodyTable::Entry& entry = mBodies[inIndex];
    // Relaxed: only an address to prefetch; a stale or foreign location costs a useless fetch, nothing else
    const uint32_t location = entry.mLocation.load(std::memory_order_relaxed);
    if (location >= QuadTreeBodyTable::cPendingLocation ||
        entry.mTree.load(std::memory_order_relaxed) != mTreeId)
        return;
    const uint32_t node = location >> 2;
    if (node >= mAllocator.GetCapacity()) return;
    // Relaxed: a chunk is never freed while the tree lives; an unset one is skipped
    const Node* chunk = mChunks[node >> cChunkShift].load(std::memory_order_relaxed);
    if (chunk == nullptr) return;
    const char* bytes = reinterpret_cast<const char*>(&chunk[node & (cChunkSize - 1)]);
    __builtin_prefetch(bytes, 1); // For writing: a move grows the slot
    __builtin_prefetch(bytes + 64, 1);
}

AABB QuadTree::GetBodySlotBounds(BodyID inBody) const
{
    EpochReclaimer::ReadScope scope(mBodies.GetReclaimer());
    const uint32_t location = FindLocation(inBody);
    if (location == QuadTreeBodyTable::cInvalidLocation) return AABB::Empty();
    return LoadSlot(GetNode(location >> 2), int(location & 3));
}

AABB QuadTree::GetBodyBounds(BodyID inBody) const
{
    if (!Contains(inBody)) return AABB::Empty();
    AABB exact;
    if (QuadTreeBodyTable::LoadBounds(mBodies[inBody.GetIndex()], exact)) return exact;
    return GetBodySlotBounds(inBody); // A move is being written: its slot contains the old bounds
}

bool QuadTree::ReportsTransitLeaf(uint64_t inTransit, const MultiTreeQuery* inMulti, ObjectLayerMask inMask,
                                  bool inCheckLayers) const
{
    const QuadTreeBodyTable::Transit transit = QuadTreeBodyTable::UnpackTransit(inTransit);
    // Either layer passes the filter: queries that run while the body's published layer changes find it
    if (inCheckLayers && !IsInLayerMask(inMask, transit.mOldLayer) &&
        !IsInLayerMask(inMask, transit.mNewLayer))
        return false;
    // One leaf, or a walk that cannot meet the other leaf in this query: this leaf is the body
    const uint32_t both = 1u << transit.mOldTree | 1u << transit.mNewTree;
    if (transit.mOldTree == transit.mNewTree || inMulti == nullptr || (inMulti->mTrees & both) != both)
        return true;
    // The query walks both trees: the leaf its entry epoch picks, so that it reports the body once
    const bool takesNew = QuadTreeBodyTable::IsAtOrPastFlip(inMulti->mEpoch, transit.mFlip);
    return (mTreeId == transit.mNewTree) == takesNew;
}

template <class Test4, class Test, class LeafVisit>
bool QuadTree::Walk(ObjectLayerMask inMask, const MultiTreeQuery* inMulti, Test4&& inTest4, Test&& inTest,
                    LeafVisit&& inLeaf) const
{
    if (mNumBodies.load(std::memory_order_relaxed) == 0) return true; // See mNumBodies
    if (inMulti != nullptr) return WalkInSection(inMask, inMulti, inTest4, inTest, inLeaf);
    EpochReclaimer::ReadScope scope(mBodies.GetReclaimer());
    return WalkInSection(inMask, inMulti, inTest4, inTest, inLeaf);
}

template <class Test4, class Test, class LeafVisit>
bool QuadTree::WalkInSection(ObjectLayerMask inMask, const MultiTreeQuery* inMulti, Test4&& inTest4,
                             Test&& inTest, LeafVisit&& inLeaf) const
{
    const bool checkLayers = inMask != cAllObjectLayers;
    NodeStack stack;
    // Acquire: pairs with the release exchange or store that published the root and everything below it
    stack.Push(mRoot.load(std::memory_order_acquire));
    uint32_t nodeIndex;
    float fractions[4] = {0, 0, 0, 0}; // Ray entry fractions of the slots (casts only)
    while (stack.Pop(nodeIndex))
    {
        const Node& node = GetNode(nodeIndex);
        const quadtree::SlotBounds4 slots(node);
        // One branch-free 4-wide test for the node, then only the slots that passed
        for (uint32_t hits = inTest4(slots, fractions); hits != 0; hits &= hits - 1)
        {
            const int s = std::countr_zero(hits);
            // Acquire: pairs with the release exchange in LinkSubTree that published a sub-tree here
            const uint32_t child = node.mChild[s].load(std::memory_order_acquire);
            if (child == cInvalidChild) continue;
            if ((child & cBodyFlag) == 0)
            {
                // Queries are bound by node misses: start fetching both cache lines of the child now, so that
                // the misses of the siblings pushed with it overlap
                const Node& childNode = GetNode(child);
                __builtin_prefetch(&childNode);
                __builtin_prefetch(reinterpret_cast<const char*>(&childNode) + 64);
                stack.Push(child);
                continue;
            }
            const uint32_t index = child & ~cBodyFlag;
            const QuadTreeBodyTable::Entry& entry = mBodies[index];
            float fraction = fractions[s];
            bool haveExact = false;
            AABB exact;
            // Relaxed: MoveBody set the bit before the release of the growth we may have acquired above
            if ((node.mLoose.load(std::memory_order_relaxed) >> s) & 1u)
            {
                // The slot may be wider than the body: test its exact bounds (the slot, which contains the
                // old bounds, was already tested when a move is being written)
                haveExact = QuadTreeBodyTable::LoadBounds(entry, exact);
                if (haveExact && !inTest(exact, fraction)) continue;
            }
            // Acquire: a layer that a change stored (release) before it publishes the body comes with the
            // transit record stored before it (read below); else written before the sub-tree was published
            // (acquired above). A concurrent re-add of the index is reported with its old or new id, both
            // allowed
            const ObjectLayer layer = checkLayers ? entry.mLayer.load(std::memory_order_acquire) : 0;
            // The body changing layers, if any (one at a time): a load of a word that changes only then
            if (const uint64_t transit = mBodies.LoadTransit();
                QuadTreeBodyTable::TransitBody(transit) == index) [[unlikely]]
            {
                if (!ReportsTransitLeaf(transit, inMulti, inMask, checkLayers)) continue;
            }
            else if (checkLayers && !IsInLayerMask(inMask, layer))
                continue;
            // Relaxed: written before the sub-tree was published (acquired above)
            const BodyID id(index, mBodies.Sequence(index).load(std::memory_order_relaxed));
            if constexpr (std::is_invocable_v<LeafVisit&, BodyID, float, const AABB&>)
            {
                // A slot that is not loose holds the body's exact bounds
                if (!inLeaf(id, fraction, haveExact ? exact : slots.Slot(s))) return false;
            }
            else if (!inLeaf(id, fraction))
                return false;
        }
    }
    return true;
}

void QuadTree::CollideAABox(const AABB& inBox, ObjectLayerMask inMask, BodyVisitor inVisitor,
                            const MultiTreeQuery* inMulti) const
{
    Walk(
        inMask, inMulti,
        [&](const quadtree::SlotBounds4& inSlots, float(&)[4])
        { return quadtree::OverlapMask(inSlots, inBox); },
        [&](const AABB& inBody, float&) { return AABBsOverlap(inBody, inBox); },
        [&](BodyID inID, float)
        {
            inVisitor(inID);
            return true;
        });
}

void QuadTree::CollideAABoxWithBounds(const AABB& inBox, ObjectLayerMask inMask,
                                      FunctionRef<void(BodyID, const AABB&)> inVisitor,
                                      const MultiTreeQuery* inMulti) const
{
    Walk(
        inMask, inMulti,
        [&](const quadtree::SlotBounds4& inSlots, float(&)[4])
        { return quadtree::OverlapMask(inSlots, inBox); },
        [&](const AABB& inBody, float&) { return AABBsOverlap(inBody, inBox); },
        [&](BodyID inID, float, const AABB& inBounds)
        {
            inVisitor(inID, inBounds);
            return true;
        });
}

void QuadTree::CollideSphere(const Vec3& inCenter, float inRadius, ObjectLayerMask inMask,
                             BodyVisitor inVisitor, const MultiTreeQuery* inMulti) const
{
    Walk(
        inMask, inMulti,
        [&](const quadtree::SlotBounds4& inSlots, float(&)[4])
        { return quadtree::SphereMask(inSlots, inCenter, inRadius); },
        [&](const AABB& inBody, float&) { return SphereOverlapsAABB(inCenter, inRadius, inBody); },
        [&](BodyID inID, float)
        {
            inVisitor(inID);
            return true;
        });
}

void QuadTree::CollidePoint(const Vec3& inPoint, ObjectLayerMask inMask, BodyVisitor inVisitor,
                            const MultiTreeQuery* inMulti) const
{
    const AABB point(inPoint, inPoint);
    Walk(
        inMask, inMulti,
        [&](const quadtree::SlotBounds4& inSlots, float(&)[4])
        { return quadtree::OverlapMask(inSlots, point); },
        [&](const AABB& inBody, float&) { return AABBContains(inBody, inPoint); },
        [&](BodyID inID, float)
        {
            inVisitor(inID);
            return true;
        });
}

bool QuadTree::CastRay(const RayCast& inRay, ObjectLayerMask inMask, float& ioMaxFraction,
                       RayBodyVisitor inVisitor, const MultiTreeQuery* inMulti) const
{
    const Vec3 invDirection = SafeReciprocal(inRay.mDirection);
    return Walk(
        inMask, inMulti,
        [&](const quadtree::SlotBounds4& inSlots, float(&outFractions)[4])
        { return quadtree::RayMask(inSlots, inRay.mOrigin, invDirection, ioMaxFraction, outFractions); },
        [&](const AABB& inBody, float& outFraction)
        {
            outFraction = inBody.RayEntryFraction(inRay.mOrigin, invDirection, ioMaxFraction);
            return outFraction <= ioMaxFraction;
        },
        [&](BodyID inID, float inFraction)
        {
            // Slots of this node were tested against the range before the visitor may have shrunk it
            if (inFraction > ioMaxFraction) return true;
            // The visitor can only shrink the range, as in the other broad phases
            ioMaxFraction = std::min(ioMaxFraction, inVisitor(inID, inFraction));
            return ioMaxFraction >= 0.0f;
        });
}

bool QuadTree::CastAABox(const AABB& inBox, const Vec3& inDisplacement, ObjectLayerMask inMask,
                         float& ioMaxFraction, RayBodyVisitor inVisitor, const MultiTreeQuery* inMulti) const
{
    // The box centre is cast against slots grown by the box half extents (see SweptAABox)
    const SweptAABox sweep(inBox, inDisplacement);
    return Walk(
        inMask, inMulti,
        [&](const quadtree::SlotBounds4& inSlots, float(&outFractions)[4])
        {
            // Empty slots stay empty when grown (min > max by about 2 * cLargeFloat)
            return quadtree::RayMask(inSlots.Grown(sweep.mHalfExtent), sweep.mCenter, sweep.mInvDisplacement,
                                     ioMaxFraction, outFractions);
        },
        [&](const AABB& inBody, float& outFraction)
        {
            outFraction = sweep.EntryFraction(inBody, ioMaxFraction);
            return outFraction <= ioMaxFraction;
        },
        [&](BodyID inID, float inFraction)
        {
            if (inFraction > ioMaxFraction) return true; // See CastRay
            ioMaxFraction = std::min(ioMaxFraction, inVisitor(inID, inFraction));
            return ioMaxFraction >= 0.0f;
        });
}

QuadTree::MemoryStats QuadTree::GetMemoryStats() const
{
    MemoryStats stats;
    stats.mNodesInUse = mAllocator.GetNumAllocated();
    stats.mNodesRetired = mNumRetired.load(std::memory_order_relaxed); // Statistic only
    stats.mNodeBytesInUse = size_t(stats.mNodesInUse) * sizeof(Node);
    const uint32_t numChunks = (mAllocator.GetCapacity() + cChunkSize - 1) >> cChunkShift;
    for (uint32_t i = 0; i < numChunks; ++i)
        if (mChunks[i].load(std::memory_order_relaxed) != nullptr) // Statistic only
            stats.mNodeBytesBacked += size_t(cChunkSize) * sizeof(Node);
    return stats;
}

int64_t QuadTree::Validate() const
{
    // Single-threaded (tests): relaxed loads throughout
    int64_t bodies = 0;
    NodeStack stack;
    const uint32_t root = mRoot.load(std::memory_order_relaxed);
    if (GetNode(root).mParent.load(std::memory_order_relaxed) != cInvalidNode) return -1;
    stack.Push(root);
    uint32_t nodeIndex;
    while (stack.Pop(nodeIndex))
    {
        const Node& node = GetNode(nodeIndex);
        for (int s = 0; s < 4; ++s)
        {
            const uint32_t child = node.mChild[s].load(std::memory_order_relaxed);
            const AABB slot = LoadSlot(node, s);
            if (child == cInvalidChild) continue;
            if ((child & cBodyFlag) != 0)
            {
                const uint32_t index = child & ~cBodyFlag;
                if (mBodies[index].mLocation.load(std::memory_order_relaxed) !=
                    (nodeIndex << 2 | uint32_t(s)))
                    return -1;
                AABB exact;
                if (!QuadTreeBodyTable::LoadBounds(mBodies[index], exact) || !slot.Contains(exact)) return -1;
                ++bodies;
                continue;
            }
            const Node& childNode = GetNode(child);
            if (childNode.mParent.load(std::memory_order_relaxed) != nodeIndex) return -1;
            for (int c = 0; c < 4; ++c)
            {
                const AABB childSlot = LoadSlot(childNode, c);
                if (childNode.mChild[c].load(std::memory_order_relaxed) != cInvalidChild &&
                    !IsEmptyBox(childSlot) && !slot.Contains(childSlot))
                    return -1;
            }
            stack.Push(child);
        }
    }
    return bodies;
}

} // namespace cairn::physics
