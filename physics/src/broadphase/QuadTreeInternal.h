#pragma once

// Pieces shared by QuadTree.cpp (live tree) and QuadTreeRebuild.cpp (rebuild): the traversal stack, the
// atomic min/max and the build item. Private to the physics library.

#include "cairn/physics/broadphase/QuadTree.h"

#include <vector>

namespace cairn::quadtree
{

/// Lowers ioValue to inValue if smaller. Release on success: see GrowSlot.
inline void AtomicMin(std::atomic<float>& ioValue, float inValue)
{
    float current = ioValue.load(std::memory_order_relaxed); // Only a first guess for the exchange
    // Release on success (see QuadTree::GrowSlot); relaxed on failure: we only retry with the fresh value
    while (inValue < current && !ioValue.compare_exchange_weak(current, inValue, std::memory_order_release,
                                                               std::memory_order_relaxed))
    {
    }
}

/// Raises ioValue to inValue if larger. Same orders as AtomicMin.
inline void AtomicMax(std::atomic<float>& ioValue, float inValue)
{
    float current = ioValue.load(std::memory_order_relaxed); // Only a first guess for the exchange
    // Release on success (see QuadTree::GrowSlot); relaxed on failure: we only retry with the fresh value
    while (inValue > current && !ioValue.compare_exchange_weak(current, inValue, std::memory_order_release,
                                                               std::memory_order_relaxed))
    {
    }
}

/// True when min > max on some axis (an empty slot). Not AABB::IsEmpty: no Eigen reduction in the hot loop.
inline bool IsEmptyBox(const AABB& inBox)
{
    return (inBox.mMin.x() > inBox.mMax.x()) | (inBox.mMin.y() > inBox.mMax.y()) |
           (inBox.mMin.z() > inBox.mMax.z());
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
    static constexpr uint32_t cFixed = 256; ///< Entries before spilling (3 per level of a 4-wide tree)
    uint32_t mFixed[cFixed];                ///< Stack storage
    uint32_t mSize = 0;                     ///< Entries used in mFixed
    std::vector<uint32_t> mSpill;           ///< Overflow; empty (never allocates) in normal trees
};

/// An object to place in a tree being built: a body (cBodyFlag | index) or a kept node, with its bounds.
struct BuildItem
{
    uint32_t mChild;       ///< cBodyFlag | body index, or a node index
    AABB mBounds;          ///< What its slot gets
    Vec3 mCenter;          ///< Centre of mBounds (the split key)
    uint32_t mOldLocation; ///< Rebuild: where a body was found (node << 2 | slot); unused otherwise
};

} // namespace cairn::quadtree
