#include "cairn/physics/broadphase/QuadTree.h"

#include "cairn/physics/broadphase/BroadPhaseOverlap.h"

#include <algorithm>
#include <cassert>
#include <vector>

namespace cairn
{

namespace
{

/// Lowers ioValue to inValue if smaller. Relaxed load: the compare-exchange re-reads on failure.
void AtomicMin(std::atomic<float>& ioValue, float inValue, std::memory_order inOrder)
{
    float current = ioValue.load(std::memory_order_relaxed); // Only a first guess for the exchange
    // inOrder on success (see callers); relaxed on failure: we only retry with the fresh value
    while (inValue < current &&
           !ioValue.compare_exchange_weak(current, inValue, inOrder, std::memory_order_relaxed))
    {
    }
}

/// Raises ioValue to inValue if larger. Same orders as AtomicMin.
void AtomicMax(std::atomic<float>& ioValue, float inValue, std::memory_order inOrder)
{
    float current = ioValue.load(std::memory_order_relaxed); // Only a first guess for the exchange
    // inOrder on success (see callers); relaxed on failure: we only retry with the fresh value
    while (inValue > current &&
           !ioValue.compare_exchange_weak(current, inValue, inOrder, std::memory_order_relaxed))
    {
    }
}

/// Traversal stack: fixed-size array, spilling to the heap only for pathological depths (the tree grows a
/// level every three add batches until a rebuild).
class NodeStack
{
public:
    void Push(uint32_t inNode)
    {
        if (mSize < cFixed)
            mFixed[mSize++] = inNode;
        else
            mSpill.push_back(inNode);
    }
    bool Pop(uint32_t& outNode)
    {
        if (!mSpill.empty())
        {
            outNode = mSpill.back();
            mSpill.pop_back();
            return true;
        }
        if (mSize == 0) return false;
        outNode = mFixed[--mSize];
        return true;
    }

private:
    static constexpr uint32_t cFixed = 512; ///< Entries before spilling
    uint32_t mFixed[cFixed];                ///< Stack storage
    uint32_t mSize = 0;                     ///< Entries used in mFixed
    std::vector<uint32_t> mSpill;           ///< Overflow; empty (never allocates) in normal trees
};

/// True when min > max on some axis (an empty slot). Not AABB::IsEmpty: no Eigen reduction in the hot loop.
bool IsEmptyBox(const AABB& inBox)
{
    return inBox.mMin.x() > inBox.mMax.x() || inBox.mMin.y() > inBox.mMax.y() ||
           inBox.mMin.z() > inBox.mMax.z();
}

} // namespace

QuadTree::QuadTree(uint32_t inMaxBodies, uint32_t inMaxNodes)
    : mMaxBodies(std::min(inMaxBodies, cBodyFlag)), mAllocator(std::min(inMaxNodes, 1u << 30)),
      mNodes(std::make_unique<Node[]>(mAllocator.GetCapacity())),
      mBodyLocation(std::make_unique<std::atomic<uint32_t>[]>(mMaxBodies)),
      mBodySequence(std::make_unique<std::atomic<uint32_t>[]>(mMaxBodies)),
      mBodyLayer(std::make_unique<std::atomic<uint8_t>[]>(mMaxBodies))
{
    assert(inMaxNodes > 0 && inMaxNodes <= (1u << 30));
    // Construction is single-threaded; the object is published to other threads by whoever shares it
    for (uint32_t i = 0; i < mMaxBodies; ++i)
        mBodyLocation[i].store(cInvalidLocation, std::memory_order_relaxed);
    mRoot.store(AllocateNode(cInvalidNode), std::memory_order_relaxed); // Construction: see above
}

uint32_t QuadTree::AllocateNode(uint32_t inParent)
{
    const uint32_t index = mAllocator.Allocate();
    if (index == cInvalidNode) return cInvalidNode;
    Node& node = mNodes[index];
    // Relaxed everywhere: the node is private until a release compare-exchange publishes it
    for (int s = 0; s < 4; ++s)
        InitSlot(node, s, cInvalidChild, AABB::Empty());
    node.mParent.store(inParent, std::memory_order_relaxed);
    node.mChanged.store(false, std::memory_order_relaxed);
    return index;
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
    // Maxes first (relaxed), then mins with release: a reader that acquires a new min also sees the new max,
    // so a slot being filled from empty never looks like a box that is only partly there
    AtomicMax(ioNode.mMaxX[inSlot], inBounds.mMax.x(), std::memory_order_relaxed);
    AtomicMax(ioNode.mMaxY[inSlot], inBounds.mMax.y(), std::memory_order_relaxed);
    AtomicMax(ioNode.mMaxZ[inSlot], inBounds.mMax.z(), std::memory_order_relaxed);
    AtomicMin(ioNode.mMinX[inSlot], inBounds.mMin.x(), std::memory_order_release);
    AtomicMin(ioNode.mMinY[inSlot], inBounds.mMin.y(), std::memory_order_release);
    AtomicMin(ioNode.mMinZ[inSlot], inBounds.mMin.z(), std::memory_order_release);
}

AABB QuadTree::LoadSlot(const Node& inNode, int inSlot)
{
    AABB box;
    // Acquire on the mins: pairs with the release in GrowSlot (maxes were written before the mins)
    box.mMin = Vec3(inNode.mMinX[inSlot].load(std::memory_order_acquire),
                    inNode.mMinY[inSlot].load(std::memory_order_acquire),
                    inNode.mMinZ[inSlot].load(std::memory_order_acquire));
    // Relaxed: ordered after the min loads by their acquire
    box.mMax = Vec3(inNode.mMaxX[inSlot].load(std::memory_order_relaxed),
                    inNode.mMaxY[inSlot].load(std::memory_order_relaxed),
                    inNode.mMaxZ[inSlot].load(std::memory_order_relaxed));
    return box;
}

QuadTree::SubTree QuadTree::BuildSubTree(std::span<const BroadPhaseBody> inBodies)
{
    // Off the hot path (loading thread): the item list may use the heap; nodes come from the pool
    std::vector<BuildItem> items;
    items.reserve(inBodies.size());
    for (uint32_t i = 0; i < uint32_t(inBodies.size()); ++i)
    {
        const BroadPhaseBody& body = inBodies[i];
        if (body.mID.GetIndex() >= mMaxBodies || !IsValidBroadPhaseBounds(body.mBounds) ||
            body.mLayer >= cMaxObjectLayers)
        {
            assert(false && "QuadTree: invalid body");
            continue;
        }
        items.push_back({i, body.mBounds.Center()});
    }
    if (items.empty()) return {};

    bool outOfNodes = false;
    SubTree tree = Build(inBodies, items.data(), items.data() + items.size(), cInvalidNode, outOfNodes);
    if (outOfNodes)
    {
        FreeSubTree(tree);
        return {};
    }
    return tree;
}

QuadTree::SubTree QuadTree::Build(std::span<const BroadPhaseBody> inBodies, BuildItem* inBegin,
                                  BuildItem* inEnd, uint32_t inParent, bool& ioOutOfNodes)
{
    SubTree result;
    const uint32_t nodeIndex = AllocateNode(inParent);
    if (nodeIndex == cInvalidNode)
    {
        ioOutOfNodes = true;
        return result;
    }
    result.mChild = nodeIndex;
    Node& node = mNodes[nodeIndex];

    // Splits [inB, inE) at the midpoint of the longest axis of the centres; halves when degenerate
    auto split = [](BuildItem* inB, BuildItem* inE) -> BuildItem*
    {
        if (inE - inB < 2) return inE;
        AABB centres;
        for (BuildItem* it = inB; it != inE; ++it)
            centres.Encapsulate(it->mCenter);
        const Vec3 size = centres.Size();
        int axis = 0;
        if (size.y() > size[axis]) axis = 1;
        if (size.z() > size[axis]) axis = 2;
        BuildItem* mid = inB + (inE - inB) / 2;
        if (size[axis] > 0.0f)
        {
            const float splitValue = centres.Center()[axis];
            BuildItem* p = std::partition(
                inB, inE, [&](const BuildItem& inItem) { return inItem.mCenter[axis] < splitValue; });
            // Rounding can put everything on one side; fall back to halves then
            if (p != inB && p != inE) return p;
        }
        return mid;
    };

    BuildItem* bounds[5];
    const ptrdiff_t count = inEnd - inBegin;
    if (count <= 4)
    {
        for (int g = 0; g < 5; ++g)
            bounds[g] = inBegin + std::min<ptrdiff_t>(g, count);
    }
    else
    {
        bounds[0] = inBegin;
        bounds[2] = split(inBegin, inEnd);
        bounds[1] = split(inBegin, bounds[2]);
        bounds[3] = split(bounds[2], inEnd);
        bounds[4] = inEnd;
    }

    for (int g = 0; g < 4; ++g)
    {
        const ptrdiff_t n = bounds[g + 1] - bounds[g];
        if (n == 0) continue;
        if (n == 1)
        {
            const BroadPhaseBody& body = inBodies[bounds[g]->mInput];
            const uint32_t index = body.mID.GetIndex();
            InitSlot(node, g, cBodyFlag | index, body.mBounds);
            result.mBounds.Encapsulate(body.mBounds);
            // Relaxed: read by queries only after the sub-tree is published by a release exchange
            mBodySequence[index].store(body.mID.GetSequence(), std::memory_order_relaxed);
            mBodyLayer[index].store(body.mLayer, std::memory_order_relaxed); // Same as above
            // Release: Remove/Move of this body (acquire) see the node contents written above
            mBodyLocation[index].store(nodeIndex << 2 | uint32_t(g), std::memory_order_release);
        }
        else
        {
            const SubTree child = Build(inBodies, bounds[g], bounds[g + 1], nodeIndex, ioOutOfNodes);
            if (child.mChild == cInvalidChild) return result; // Out of nodes: caller frees what was built
            InitSlot(node, g, child.mChild, child.mBounds);
            result.mBounds.Encapsulate(child.mBounds);
            if (ioOutOfNodes) return result;
        }
    }
    return result;
}

void QuadTree::FreeSubTree(const SubTree& inSubTree)
{
    if (inSubTree.mChild == cInvalidChild || (inSubTree.mChild & cBodyFlag) != 0) return;
    // Iterative, so that deep trees cannot overflow the thread's stack; nodes are private (never linked)
    NodeStack stack;
    stack.Push(inSubTree.mChild);
    uint32_t nodeIndex;
    while (stack.Pop(nodeIndex))
    {
        Node& node = mNodes[nodeIndex];
        for (int s = 0; s < 4; ++s)
        {
            const uint32_t child = node.mChild[s].load(std::memory_order_relaxed); // Private node
            if (child == cInvalidChild) continue;
            if ((child & cBodyFlag) != 0)
                mBodyLocation[child & ~cBodyFlag].store(cInvalidLocation,
                                                        std::memory_order_relaxed); // Never published
            else
                stack.Push(child);
        }
        mAllocator.Free(nodeIndex);
    }
}

bool QuadTree::LinkSubTree(const SubTree& inSubTree)
{
    if (inSubTree.mChild == cInvalidChild) return true;
    const uint32_t subNode = inSubTree.mChild;
    for (;;)
    {
        // Acquire: we read the root's slots and may make it the child of a new root
        const uint32_t rootIndex = mRoot.load(std::memory_order_acquire);
        Node& root = mNodes[rootIndex];
        for (int s = 0; s < 4; ++s)
        {
            // Relaxed: only a hint to skip full slots; the exchange below decides
            if (root.mChild[s].load(std::memory_order_relaxed) != cInvalidChild) continue;
            // Relaxed: the sub-tree is private until the release exchange below publishes it
            mNodes[subNode].mParent.store(rootIndex, std::memory_order_relaxed);
            uint32_t expected = cInvalidChild;
            // Release on success: publishes the sub-tree's nodes to readers that acquire the slot; relaxed on
            // failure: another linker took the slot, try the next one
            if (root.mChild[s].compare_exchange_strong(expected, subNode, std::memory_order_release,
                                                       std::memory_order_relaxed))
            {
                GrowSlot(root, s, inSubTree.mBounds);
                root.mChanged.store(true, std::memory_order_relaxed); // Rebuild hint only
                // The root may have been replaced meanwhile: its slot in the new root is unbounded, but keep
                // the parents' changed flags right
                PropagateUp(rootIndex, inSubTree.mBounds);
                return true;
            }
        }

        // Root full: a new root holding the old one (unbounded: its bounds are not tracked upwards) and ours
        const uint32_t newRootIndex = AllocateNode(cInvalidNode);
        if (newRootIndex == cInvalidNode) return false;
        Node& newRoot = mNodes[newRootIndex];
        InitSlot(newRoot, 0, rootIndex, AABB(Vec3::Constant(-cLargeFloat), Vec3::Constant(cLargeFloat)));
        InitSlot(newRoot, 1, subNode, inSubTree.mBounds);
        newRoot.mChanged.store(true, std::memory_order_relaxed);                // Private node
        mNodes[subNode].mParent.store(newRootIndex, std::memory_order_relaxed); // Still private
        uint32_t expected = rootIndex;
        // Release on success: publishes the new root and the sub-tree; relaxed on failure: we retry from a
        // fresh acquire load of the root
        if (mRoot.compare_exchange_strong(expected, newRootIndex, std::memory_order_release,
                                          std::memory_order_relaxed))
        {
            // Release: a mover walking up (acquire) finds the new root's fully initialised slots
            root.mParent.store(newRootIndex, std::memory_order_release);
            return true;
        }
        mAllocator.Free(newRootIndex); // Never published
    }
}

void QuadTree::PropagateUp(uint32_t inNode, const AABB& inBounds)
{
    uint32_t nodeIndex = inNode;
    for (;;)
    {
        // Acquire: pairs with the release store of a new root's index in LinkSubTree
        const uint32_t parentIndex = mNodes[nodeIndex].mParent.load(std::memory_order_acquire);
        if (parentIndex == cInvalidNode) return;
        Node& parent = mNodes[parentIndex];
        int slot = -1;
        for (int s = 0; s < 4; ++s)
            // Relaxed: a node's slot in its parent never changes once linked, and the parent link was
            // acquired above
            if (parent.mChild[s].load(std::memory_order_relaxed) == nodeIndex) slot = s;
        if (slot < 0) return; // Cannot happen for a linked node; be safe
        GrowSlot(parent, slot, inBounds);
        parent.mChanged.store(true, std::memory_order_relaxed); // Rebuild hint only
        nodeIndex = parentIndex;
    }
}

void QuadTree::RemoveBody(BodyID inBody)
{
    const uint32_t index = inBody.GetIndex();
    if (index >= mMaxBodies) return;
    // Relaxed: same-body operations are serialised by the caller
    if (mBodySequence[index].load(std::memory_order_relaxed) != inBody.GetSequence()) return;
    // Acquire: pairs with the release in Build, so the node is seen initialised
    const uint32_t location = mBodyLocation[index].exchange(cInvalidLocation, std::memory_order_acquire);
    if (location == cInvalidLocation) return;
    const uint32_t nodeIndex = location >> 2;
    const int slot = int(location & 3);
    Node& node = mNodes[nodeIndex];
    // Relaxed: a reader seeing any mix of old and empty bounds reports the body or not, both allowed; only
    // this thread writes the slot of this body
    node.mMinX[slot].store(cLargeFloat, std::memory_order_relaxed);
    node.mMinY[slot].store(cLargeFloat, std::memory_order_relaxed);
    node.mMinZ[slot].store(cLargeFloat, std::memory_order_relaxed);
    node.mMaxX[slot].store(-cLargeFloat, std::memory_order_relaxed);
    node.mMaxY[slot].store(-cLargeFloat, std::memory_order_relaxed);
    node.mMaxZ[slot].store(-cLargeFloat, std::memory_order_relaxed);
    // Relaxed: leaf slots are never reused before a rebuild, so no reader or writer depends on the order
    node.mChild[slot].store(cInvalidChild, std::memory_order_relaxed);
    // Mark the path changed (for the future rebuild)
    for (uint32_t n = nodeIndex; n != cInvalidNode;)
    {
        mNodes[n].mChanged.store(true, std::memory_order_relaxed); // Hint only
        n = mNodes[n].mParent.load(std::memory_order_acquire);     // Pairs with the release in LinkSubTree
    }
}

void QuadTree::MoveBody(BodyID inBody, const AABB& inBounds)
{
    const uint32_t index = inBody.GetIndex();
    if (index >= mMaxBodies || !IsValidBroadPhaseBounds(inBounds)) return;
    // Relaxed: same-body operations are serialised by the caller
    if (mBodySequence[index].load(std::memory_order_relaxed) != inBody.GetSequence()) return;
    // Acquire: pairs with the release in Build, so the node is seen initialised
    const uint32_t location = mBodyLocation[index].load(std::memory_order_acquire);
    if (location == cInvalidLocation) return;
    const uint32_t nodeIndex = location >> 2;
    Node& node = mNodes[nodeIndex];
    GrowSlot(node, int(location & 3), inBounds);
    node.mChanged.store(true, std::memory_order_relaxed); // Rebuild hint only
    // Always walk to the root (no early out when a parent already contains the box): another mover may have
    // grown a slot below without having reached the parent yet, and our bounds must be visible when we return
    PropagateUp(nodeIndex, inBounds);
}

bool QuadTree::Contains(BodyID inBody) const
{
    const uint32_t index = inBody.GetIndex();
    // Relaxed: a snapshot for tests and statistics
    return index < mMaxBodies && mBodyLocation[index].load(std::memory_order_relaxed) != cInvalidLocation &&
           mBodySequence[index].load(std::memory_order_relaxed) == inBody.GetSequence();
}

AABB QuadTree::GetBodyBounds(BodyID inBody) const
{
    if (!Contains(inBody)) return AABB::Empty();
    // Acquire: pairs with the release in Build
    const uint32_t location = mBodyLocation[inBody.GetIndex()].load(std::memory_order_acquire);
    if (location == cInvalidLocation) return AABB::Empty();
    return LoadSlot(mNodes[location >> 2], int(location & 3));
}

template <class NodeTest, class LeafVisit>
void QuadTree::Walk(const BroadPhaseQueryFilter& inFilter, NodeTest&& inNodeTest, LeafVisit&& inLeaf) const
{
    NodeStack stack;
    // Acquire: pairs with the release exchange that published the root and everything below it
    stack.Push(mRoot.load(std::memory_order_acquire));
    uint32_t nodeIndex;
    while (stack.Pop(nodeIndex))
    {
        const Node& node = mNodes[nodeIndex];
        for (int s = 0; s < 4; ++s)
        {
            const AABB box = LoadSlot(node, s);
            if (IsEmptyBox(box) || !inNodeTest(box)) continue;
            // Acquire: pairs with the release exchange in LinkSubTree that published a sub-tree here
            const uint32_t child = node.mChild[s].load(std::memory_order_acquire);
            if (child == cInvalidChild) continue;
            if ((child & cBodyFlag) == 0)
            {
                stack.Push(child);
                continue;
            }
            const uint32_t index = child & ~cBodyFlag;
            // Relaxed: written before the sub-tree was published (acquired above); a concurrent re-add of
            // the index is reported with its old or new id, both allowed
            if (!IsInLayerMask(inFilter.mObjectLayers, mBodyLayer[index].load(std::memory_order_relaxed)))
                continue;
            const BodyID id(index, mBodySequence[index].load(std::memory_order_relaxed)); // As above
            if (!inLeaf(id)) return;
        }
    }
}

void QuadTree::CollideAABox(const AABB& inBox, const BroadPhaseQueryFilter& inFilter,
                            BodyVisitor inVisitor) const
{
    Walk(
        inFilter, [&](const AABB& inNode) { return AABBsOverlap(inNode, inBox); },
        [&](BodyID inID)
        {
            inVisitor(inID);
            return true;
        });
}

void QuadTree::CollideSphere(const Vec3& inCenter, float inRadius, const BroadPhaseQueryFilter& inFilter,
                             BodyVisitor inVisitor) const
{
    Walk(
        inFilter, [&](const AABB& inNode) { return SphereOverlapsAABB(inCenter, inRadius, inNode); },
        [&](BodyID inID)
        {
            inVisitor(inID);
            return true;
        });
}

void QuadTree::CollidePoint(const Vec3& inPoint, const BroadPhaseQueryFilter& inFilter,
                            BodyVisitor inVisitor) const
{
    Walk(
        inFilter, [&](const AABB& inNode) { return AABBContains(inNode, inPoint); },
        [&](BodyID inID)
        {
            inVisitor(inID);
            return true;
        });
}

void QuadTree::CastRay(const RayCast& inRay, const BroadPhaseQueryFilter& inFilter,
                       RayBodyVisitor inVisitor) const
{
    const Vec3 invDirection = SafeReciprocal(inRay.mDirection);
    float maxFraction = 1.0f;
    float fraction = 0.0f; // Entry fraction of the slot last accepted by the node test
    Walk(
        inFilter,
        [&](const AABB& inNode)
        {
            fraction = inNode.RayEntryFraction(inRay.mOrigin, invDirection, maxFraction);
            return fraction <= maxFraction;
        },
        [&](BodyID inID)
        {
            // The visitor can only shrink the range, as in the other broad phases
            maxFraction = std::min(maxFraction, inVisitor(inID, fraction));
            return maxFraction >= 0.0f;
        });
}

} // namespace cairn
