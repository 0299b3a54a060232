// QuadTree::Rebuild and the reclamation of old nodes (see QuadTree.h for the threading rules).
//
// A rebuild has two phases:
//  1. Build, with no lock, concurrently with queries, moves, removes and links: walk the live tree from the
//     root, descending only into Changed nodes (all of them for a full rebuild). An unchanged node is kept
//     whole, as one object; a body of a changed node becomes one object with its exact bounds (grown by the
//     margin and stretched ahead of its motion if it moved: MovedSlot). The objects are built into new
//     private nodes with the same midpoint split as a batch add.
//  2. Commit, under the exclusive side of the modification lock (so no move, remove or link runs), in
//     O(bodies relocated + nodes kept):
//     a. kept nodes get their new parents; one that changed during phase 1 pushes its bounds up the new tree;
//     b. each relocated body that is still where phase 1 found it gets its current exact bounds in its new
//        slot and its new location; one that was removed meanwhile leaves an empty slot;
//     c. sub-trees that linkers put into the old root chain during phase 1 are linked into the new root;
//     d. the root index is swapped (release), and the replaced nodes are retired with the current epoch.
//  Queries never wait: before the swap they read the old tree, which is complete and unchanged by the commit;
//  after it the new one, which already holds every modification made before the commit.

#include "QuadTreeInternal.h"
#include "broadphase/QuadTree.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdint>

namespace cairn::physics
{

using quadtree::BuildItem;
using quadtree::NodeStack;

namespace
{

/// Union of a node's four slot bounds as read now.
AABB UnionOfSlots(const QuadTree::Node& inNode)
{
    AABB bounds;
    for (int s = 0; s < 4; ++s)
    {
        // Acquire: pairs with the releases of GrowSlot
        const AABB slot(Vec3(inNode.mMinX[s].load(std::memory_order_acquire),
                             inNode.mMinY[s].load(std::memory_order_acquire),
                             inNode.mMinZ[s].load(std::memory_order_acquire)),
                        Vec3(inNode.mMaxX[s].load(std::memory_order_acquire),
                             inNode.mMaxY[s].load(std::memory_order_acquire),
                             inNode.mMaxZ[s].load(std::memory_order_acquire)));
        if (!quadtree::IsEmptyBox(slot)) bounds.Encapsulate(slot);
    }
    return bounds;
}

} // namespace

AABB QuadTree::MovedSlot(const AABB& inBounds, const AABB& inOldSlot, uint8_t inStretchedSides,
                         uint8_t& outStretchedSides) const
{
    const float margin =
        std::min(mMovedSlotMargin, cMovedSlotMarginShare * (inBounds.mMax - inBounds.mMin).minCoeff());
    AABB slot = inBounds.Expanded(margin);
    outStretchedSides = 0;
    if (mMovedSlotReach == 0.0f) return slot;
    for (int axis = 0; axis < 3; ++axis)
    {
        const uint8_t minSide = uint8_t(1u << (2 * axis)), maxSide = uint8_t(2u << (2 * axis));
        // Room left above the body means it moved towards min, and the other way round. An empty slot (the
        // body removed meanwhile) leaves no room on either side: its min is +large and its max -large. Room
        // under a quarter of the margin is taken for rounding (bounds + margin - bounds is not the margin
        // far from the origin), not for a move
        const float leftAbove =
            (inStretchedSides & maxSide) != 0 ? 0.0f : inOldSlot.mMax[axis] - inBounds.mMax[axis] - margin;
        const float leftBelow =
            (inStretchedSides & minSide) != 0 ? 0.0f : inBounds.mMin[axis] - inOldSlot.mMin[axis] - margin;
        const float minRoom = 0.25f * margin;
        if (leftAbove > minRoom)
        {
            slot.mMin[axis] -= std::min(mMovedSlotReach * leftAbove, cMaxMovedSlotReach);
            outStretchedSides |= minSide;
        }
        if (leftBelow > minRoom)
        {
            slot.mMax[axis] += std::min(mMovedSlotReach * leftBelow, cMaxMovedSlotReach);
            outStretchedSides |= maxSide;
        }
    }
    return slot;
}

QuadTree::RebuildStats QuadTree::Rebuild(bool inFull)
{
    RebuildStats stats;
    // Acquire: we read the tree below the root
    const uint32_t oldRoot = mRoot.load(std::memory_order_acquire);
    // Relaxed: a hint; a change we miss now is seen by the next rebuild
    if (!inFull && !GetNode(oldRoot).mChanged.load(std::memory_order_relaxed)) return stats;
    // Reclamation lags (a query thread descheduled inside its read section holds the epoch back): another
    // rebuild would retire another tree's worth of nodes and could leave batches without room. The current
    // tree stays valid, only looser; try again at the next update. Relaxed: only this thread changes the
    // count upwards, and a stale low value only lets one more rebuild through
    if (mNumRetired.load(std::memory_order_relaxed) > mAllocator.GetCapacity() / 4)
    {
        stats.mDeferred = true;
        return stats;
    }

    // Phase 1: collect objects (no lock)
    ++mRebuildStamp;
    if (mRebuildMark.size() < mAllocator.GetHighWater()) mRebuildMark.resize(mAllocator.GetHighWater(), 0);
    quadtree::RebuildScratch& scratch = *mRebuildScratch;
    std::vector<BuildItem>& items = scratch.mItems;
    items.clear();
    std::vector<uint32_t> replaced; // Handed to the retired list, so not scratch
    NodeStack stack;
    stack.Push(oldRoot);
    mRebuildMark[oldRoot] = mRebuildStamp;
    replaced.push_back(oldRoot);
    uint32_t nodeIndex;
    while (stack.Pop(nodeIndex))
    {
        const Node& node = GetNode(nodeIndex);
        for (int s = 0; s < 4; ++s)
        {
            // Acquire: pairs with the release exchange in LinkSubTree
            const uint32_t child = node.mChild[s].load(std::memory_order_acquire);
            if (child == cInvalidChild) continue;
            if ((child & cBodyFlag) != 0)
            {
                AABB bounds;
                QuadTreeBodyTable::Entry& entry = mBodies[child & ~cBodyFlag];
                uint8_t stretchedSides = 0;
                if (!QuadTreeBodyTable::LoadBounds(entry, bounds))
                    bounds = LoadSlot(node, s); // Being moved: the commit sets the exact bounds
                // A body that moved since the last rebuild (its slot is loose) gets a slot grown by the
                // margin, and stretched ahead of its motion: while it stays inside, its moves write nothing
                // to the tree (see MoveBody). Relaxed: the bit is only read here to choose; the commit
                // handles moves made meanwhile
                else if (mMovedSlotMargin > 0.0f && ((node.mLoose.load(std::memory_order_relaxed) >> s) & 1u))
                    bounds = MovedSlot(bounds, LoadSlot(node, s), entry.mSlotReachSides, stretchedSides);
                // Written here, not by the commit: a rebuild that gives up later (out of nodes) leaves flags
                // that describe slots it did not make, which only makes the next stretch shorter or wrongly
                // sided (speed, never containment: the commit checks every slot). Only when they change: the
                // update runs beside the pair search, which reads these entries
                if (entry.mSlotReachSides != stretchedSides) entry.mSlotReachSides = stretchedSides;
                items.push_back({child, bounds, nodeIndex << 2 | uint32_t(s)});
                continue;
            }
            const Node& childNode = GetNode(child);
            if (child >= mRebuildMark.size()) mRebuildMark.resize(mAllocator.GetHighWater(), 0);
            mRebuildMark[child] = mRebuildStamp;
            // Relaxed: a hint; a node that changes after this read is handled by the commit (step a)
            if (!inFull && !childNode.mChanged.load(std::memory_order_relaxed))
            {
                // Kept whole, unless it is empty (then it is retired like a changed node)
                const AABB bounds = UnionOfSlots(childNode);
                if (!bounds.IsEmpty())
                {
                    items.push_back({child, bounds, QuadTreeBodyTable::cInvalidLocation});
                    continue;
                }
            }
            replaced.push_back(child);
            stack.Push(child);
        }
    }

    // Build the new tree (no lock): relocations and re-parentings are applied by the commit
    std::vector<quadtree::Relocation>& relocations = scratch.mRelocations;
    std::vector<quadtree::Reparent>& reparents = scratch.mReparents;
    std::vector<uint32_t>& newNodes = scratch.mNewNodes;
    relocations.clear();
    reparents.clear();
    newNodes.clear();
    const SubTree built =
        BuildNodes(items, 0, newNodes,
                   [&](const BuildItem& inItem, uint32_t inNode, int inSlot)
                   {
                       if ((inItem.mChild & cBodyFlag) != 0)
                           relocations.push_back({inItem.mChild & ~cBodyFlag, inItem.mOldLocation,
                                                  inNode << 2 | uint32_t(inSlot), inItem.mBounds});
                       else
                           reparents.push_back({inItem.mChild, inNode});
                   });
    auto freeNew = [&](const std::vector<uint32_t>& inNodes)
    {
        for (uint32_t node : inNodes)
            mAllocator.Free(node); // Never published
    };
    if (built.mChild == cInvalidChild)
    {
        freeNew(newNodes);
        stats.mOutOfNodes = true;
        return stats;
    }

    // Phase 2: commit
    const auto commitStart = std::chrono::steady_clock::now();
    {
        std::unique_lock lock(mModificationLock);
        // Nodes for the new root levels that the sub-trees linked during the build may need, allocated before
        // anything live changes, so that running out of nodes can still abort cleanly
        std::vector<uint32_t> spares;
        const uint32_t numLate = CountLateSubTrees(oldRoot);
        for (uint32_t i = 0; i < (numLate + 2) / 3 + 1; ++i)
        {
            const uint32_t spare = AllocateNode(cInvalidNode);
            if (spare == cInvalidNode)
            {
                lock.unlock();
                freeNew(spares);
                freeNew(newNodes);
                stats.mOutOfNodes = true;
                return stats;
            }
            spares.push_back(spare);
        }

        // a. Kept nodes hang below the new tree now
        for (const quadtree::Reparent& reparent : reparents)
            // Release: a mover walking up (acquire) after the swap finds its new parent's initialised slots
            GetNode(reparent.mNode).mParent.store(reparent.mParent, std::memory_order_release);
        for (const quadtree::Reparent& reparent : reparents)
        {
            const Node& kept = GetNode(reparent.mNode);
            // Relaxed: modifiers are excluded; their writes happened before they released the lock we hold
            if (kept.mChanged.load(std::memory_order_relaxed))
                PropagateUp(reparent.mNode, UnionOfSlots(kept));
        }

        // b. Bodies move to their new leaves with their current bounds. Their table entries are scattered
        // (the new tree's order is spatial): each is fetched a few relocations ahead, so the misses overlap
        // and the exclusive section, which modifiers wait for, is shorter
        constexpr size_t cAhead = 8;
        for (size_t i = 0; i < relocations.size(); ++i)
        {
            if (i + cAhead < relocations.size()) __builtin_prefetch(&mBodies[relocations[i + cAhead].mBody]);
            const quadtree::Relocation& relocation = relocations[i];
            QuadTreeBodyTable::Entry& entry = mBodies[relocation.mBody];
            const uint32_t newNode = relocation.mNewLocation >> 2;
            const int newSlot = int(relocation.mNewLocation & 3);
            // Relaxed: modifiers are excluded (see above)
            if (entry.mLocation.load(std::memory_order_relaxed) == relocation.mOldLocation &&
                entry.mTree.load(std::memory_order_relaxed) == mTreeId)
            {
                AABB exact;
                QuadTreeBodyTable::LoadBounds(entry, exact); // No writer can be inside: always consistent
                // Not the slot's bounds (grown by the margin, read while a move was being written, or moved
                // during the build): the slot is loose, so queries test the exact bounds, and if the body
                // left it, it and the private ancestors grow to the current bounds (an exact slot, the common
                // case without a margin, costs no atomic write: the commit is what modifiers wait for)
                const AABB& built = relocation.mBuiltBounds;
                if (exact.mMin != built.mMin || exact.mMax != built.mMax)
                {
                    // Relaxed: the node is private until the swap below (release) publishes it, so no other
                    // core holds its line (MoveBody's read before the write is for published nodes)
                    Node& node = GetNode(newNode);
                    node.mLoose.fetch_or(uint8_t(1u << newSlot), std::memory_order_relaxed);
                    if (!built.Contains(exact))
                    {
                        GrowSlot(node, newSlot, exact);
                        PropagateUp(newNode, exact);
                    }
                }
                // Release: a modifier that acquires the location sees the new node's contents
                entry.mLocation.store(relocation.mNewLocation, std::memory_order_release);
                ++stats.mRelocatedBodies;
            }
            else
            {
                ClearSlot(GetNode(newNode), newSlot); // Removed during the build
                MarkChangedUp(newNode);
            }
        }

        // c. Sub-trees linked during the build
        uint32_t newRoot = built.mChild;
        newRoot = LinkLateSubTrees(oldRoot, newRoot, spares, replaced);

        // d. Swap; the old nodes are retired, not freed: queries may still be in them
        // Release: readers that acquire the root see the whole new tree
        mRoot.store(newRoot, std::memory_order_release);
        lock.unlock();
        freeNew(spares); // The ones not used
    }
    stats.mCommitMicroseconds =
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - commitStart).count();
    stats.mRebuilt = true;
    stats.mKeptNodes = uint32_t(reparents.size());
    stats.mNewNodes = uint32_t(newNodes.size());
    stats.mRetiredNodes = uint32_t(replaced.size());
    mNumRetired.fetch_add(uint32_t(replaced.size()), std::memory_order_relaxed); // Statistic only
    mRetired.push_back({mBodies.GetReclaimer().GetEpoch(), std::move(replaced)});
    return stats;
}

uint32_t QuadTree::CountLateSubTrees(uint32_t inOldRoot) const
{
    uint32_t count = 0;
    // Relaxed: called under the commit's exclusive lock, which excludes every other writer
    for (uint32_t chainNode = mRoot.load(std::memory_order_relaxed);;)
    {
        const Node& node = GetNode(chainNode);
        const bool isOldRoot = chainNode == inOldRoot;
        for (int s = isOldRoot ? 0 : 1; s < 4; ++s)
        {
            const uint32_t child = node.mChild[s].load(std::memory_order_relaxed); // Writers excluded
            count += child != cInvalidChild && (child & cBodyFlag) == 0 && !IsMarked(child) ? 1 : 0;
        }
        if (isOldRoot) return count;
        chainNode = node.mChild[0].load(std::memory_order_relaxed); // The previous root
    }
}

uint32_t QuadTree::LinkLateSubTrees(uint32_t inOldRoot, uint32_t inNewRoot, std::vector<uint32_t>& ioSpares,
                                    std::vector<uint32_t>& ioRetired)
{
    // Linkers only ever put sub-trees into the current root; a full root gets a new root whose slot 0 is the
    // previous root. So everything linked since phase 1 is in the chain from the live root down to inOldRoot.
    uint32_t newRoot = inNewRoot;
    // Relaxed: modifiers (the only writers of the root besides us) are excluded by the commit's lock
    uint32_t chainNode = mRoot.load(std::memory_order_relaxed);
    for (;;)
    {
        const Node& node = GetNode(chainNode);
        const bool isOldRoot = chainNode == inOldRoot;
        if (!isOldRoot) ioRetired.push_back(chainNode);
        for (int s = isOldRoot ? 0 : 1; s < 4; ++s)
        {
            const uint32_t child = node.mChild[s].load(std::memory_order_relaxed); // Writers excluded
            if (child == cInvalidChild || (child & cBodyFlag) != 0 || IsMarked(child)) continue;
            const AABB bounds = LoadSlot(node, s);
            // Put it in a free slot of the new root, or give the new root a parent first
            Node* root = &GetNode(newRoot);
            int freeSlot = -1;
            for (int r = 0; r < 4 && freeSlot < 0; ++r)
                if (root->mChild[r].load(std::memory_order_relaxed) == cInvalidChild) freeSlot = r; // Private
            if (freeSlot < 0)
            {
                // Never empty: the commit reserved a level for every 3 late sub-trees
                const uint32_t above = ioSpares.back();
                ioSpares.pop_back();
                InitSlot(GetNode(above), 0, newRoot, UnionOfSlots(*root));
                GetNode(newRoot).mParent.store(above, std::memory_order_relaxed); // Private until the swap
                newRoot = above;
                root = &GetNode(newRoot);
                freeSlot = 1;
            }
            InitSlot(*root, freeSlot, child, bounds);
            // Release: a mover walking up after the swap sees the new root's slot
            GetNode(child).mParent.store(newRoot, std::memory_order_release);
        }
        if (isOldRoot) break;
        chainNode = node.mChild[0].load(std::memory_order_relaxed); // The previous root
    }
    return newRoot;
}

void QuadTree::CollectGarbage()
{
    // Two steps of the epoch, each followed by freeing what became safe: the last update's retirees (stamped
    // with the epoch after its second step) are then freed here, one update later, when no reader lags. The
    // epoch is the trees' shared one (QuadTreeBodyTable): the other trees' collections and layer changes
    // advance it too, which only frees sooner what is safe to free
    for (int step = 0; step < 2; ++step)
    {
        mBodies.TryAdvanceEpoch();
        FreeReclaimableNodes();
    }
}

void QuadTree::FreeReclaimableNodes()
{
    // The nodes that became safe are marked as bits and go back to the free list from the highest index down,
    // so that the list hands them out in ascending order: the next build writes (and later queries read)
    // nodes that neighbour each other in memory. One pass over the marked words instead of sorting the
    // indices: an update after a full rebuild frees thousands of nodes, and the sort was most of its cost
    size_t kept = 0;
    size_t lowWord = SIZE_MAX, highWord = 0;
    uint32_t numFreed = 0;
    for (size_t i = 0; i < mRetired.size(); ++i)
    {
        RetiredBatch& batch = mRetired[i];
        if (!mBodies.GetReclaimer().IsSafeToFree(batch.mEpoch))
        {
            if (kept != i) mRetired[kept] = std::move(batch); // A self-move would empty the list
            ++kept;
            continue;
        }
        for (uint32_t node : batch.mNodes)
        {
            const size_t word = node >> 6;
            if (word >= mFreeMarks.size()) mFreeMarks.resize(word + 1, 0);
            mFreeMarks[word] |= uint64_t(1) << (node & 63);
            lowWord = std::min(lowWord, word);
            highWord = std::max(highWord, word);
        }
        numFreed += uint32_t(batch.mNodes.size());
    }
    mRetired.resize(kept);
    if (lowWord == SIZE_MAX) return;
    for (size_t word = highWord + 1; word-- > lowWord;)
    {
        for (uint64_t bits = mFreeMarks[word]; bits != 0;)
        {
            const int bit = 63 - std::countl_zero(bits);
            mAllocator.Free(uint32_t(word << 6) | uint32_t(bit));
            bits &= ~(uint64_t(1) << bit);
        }
        mFreeMarks[word] = 0;
    }
    mNumRetired.fetch_sub(numFreed, std::memory_order_relaxed); // Statistic only
}

} // namespace cairn::physics
