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

/// The four slot bounds of a node as read now, one SIMD lane per slot, for branch-free 4-wide tests.
struct SlotBounds4
{
    Eigen::Array4f mMinX, mMinY, mMinZ, mMaxX, mMaxY, mMaxZ;

    explicit SlotBounds4(const QuadTree::Node& inNode)
    {
        // Acquire on every float: pairs with the releases of GrowSlot, exactly as LoadSlot does per slot
        auto load4 = [](const std::atomic<float>(&inValues)[4])
        {
            return Eigen::Array4f(
                inValues[0].load(std::memory_order_acquire), inValues[1].load(std::memory_order_acquire),
                inValues[2].load(std::memory_order_acquire), inValues[3].load(std::memory_order_acquire));
        };
        mMinX = load4(inNode.mMinX);
        mMinY = load4(inNode.mMinY);
        mMinZ = load4(inNode.mMinZ);
        mMaxX = load4(inNode.mMaxX);
        mMaxY = load4(inNode.mMaxY);
        mMaxZ = load4(inNode.mMaxZ);
    }
};

/// Lanes set in a 4-lane boolean array, as bits 0..3.
inline uint32_t ToMask(const Eigen::Array<bool, 4, 1>& inLanes)
{
    return uint32_t(inLanes[0]) | uint32_t(inLanes[1]) << 1 | uint32_t(inLanes[2]) << 2 |
           uint32_t(inLanes[3]) << 3;
}

/// Slots whose bounds overlap inBox (closed intervals, the same comparisons as AABBsOverlap). Empty slots
/// fail for any query below cLargeFloat; the walk skips invalid children anyway.
inline uint32_t OverlapMask(const SlotBounds4& inSlots, const AABB& inBox)
{
    return ToMask((inSlots.mMinX <= inBox.mMax.x()) && (inSlots.mMaxX >= inBox.mMin.x()) &&
                  (inSlots.mMinY <= inBox.mMax.y()) && (inSlots.mMaxY >= inBox.mMin.y()) &&
                  (inSlots.mMinZ <= inBox.mMax.z()) && (inSlots.mMaxZ >= inBox.mMin.z()));
}

/// Slots whose bounds are within inRadius of inCenter (the same arithmetic as SphereOverlapsAABB).
inline uint32_t SphereMask(const SlotBounds4& inSlots, const Vec3& inCenter, float inRadius)
{
    const Eigen::Array4f dx = inSlots.mMinX.max(inCenter.x()).min(inSlots.mMaxX) - inCenter.x();
    const Eigen::Array4f dy = inSlots.mMinY.max(inCenter.y()).min(inSlots.mMaxY) - inCenter.y();
    const Eigen::Array4f dz = inSlots.mMinZ.max(inCenter.z()).min(inSlots.mMaxZ) - inCenter.z();
    return ToMask(dx * dx + dy * dy + dz * dz <= inRadius * inRadius) &
           ToMask((inSlots.mMinX <= inSlots.mMaxX) && (inSlots.mMinY <= inSlots.mMaxY) &&
                  (inSlots.mMinZ <= inSlots.mMaxZ));
}

/// Slots whose bounds the ray enters at or before inMaxFraction; outFractions gets the entry fractions. The
/// same operations, in the same order per lane, as AABB::RayEntryFraction, so the fractions are
/// bit-identical.
inline uint32_t RayMask(const SlotBounds4& inSlots, const Vec3& inOrigin, const Vec3& inInvDirection,
                        float inMaxFraction, Eigen::Array4f& outFractions)
{
    Eigen::Array4f tMin = Eigen::Array4f::Zero();
    Eigen::Array4f tMax = Eigen::Array4f::Constant(inMaxFraction);
    auto axis = [&](const Eigen::Array4f& inMin, const Eigen::Array4f& inMax, float inO, float inInv)
    {
        Eigen::Array4f t1 = (inMin - inO) * inInv;
        Eigen::Array4f t2 = (inMax - inO) * inInv;
        // 0 * inf gives NaN when the origin lies on a slab plane of a parallel ray; treat it as inside
        t1 = t1.isNaN().select(Eigen::Array4f::Constant(-cLargeFloat), t1);
        t2 = t2.isNaN().select(Eigen::Array4f::Constant(cLargeFloat), t2);
        tMin = tMin.max(t1.min(t2));
        tMax = tMax.min(t1.max(t2));
    };
    axis(inSlots.mMinX, inSlots.mMaxX, inOrigin.x(), inInvDirection.x());
    axis(inSlots.mMinY, inSlots.mMaxY, inOrigin.y(), inInvDirection.y());
    axis(inSlots.mMinZ, inSlots.mMaxZ, inOrigin.z(), inInvDirection.z());
    outFractions = tMin;
    return ToMask(tMin <= tMax) &
           ToMask((inSlots.mMinX <= inSlots.mMaxX) && (inSlots.mMinY <= inSlots.mMaxY) &&
                  (inSlots.mMinZ <= inSlots.mMaxZ));
}

/// An object to place in a tree being built: a body (cBodyFlag | index) or a kept node, with its bounds.
struct BuildItem
{
    uint32_t mChild;       ///< cBodyFlag | body index, or a node index
    AABB mBounds;          ///< What its slot gets
    Vec3 mCenter;          ///< Centre of mBounds (the split key)
    uint32_t mOldLocation; ///< Rebuild: where a body was found (node << 2 | slot); unused otherwise
};

} // namespace cairn::quadtree
