#pragma once

// Pieces shared by QuadTree.cpp (live tree) and QuadTreeRebuild.cpp (rebuild): the traversal stack, the
// atomic min/max and the build item. Private to the physics library.

#include "broadphase/BroadPhaseOverlap.h"
#include "broadphase/QuadTree.h"

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include <vector>

namespace cairn::physics::quadtree
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
    return (int(inBox.mMin.x() > inBox.mMax.x()) | int(inBox.mMin.y() > inBox.mMax.y()) |
            int(inBox.mMin.z() > inBox.mMax.z())) != 0;
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

/// The four slot bounds of a node as read now, one SIMD lane per slot, for branch-free 4-wide tests. The
/// floats are read one by one from the atomics (acquire, as LoadSlot) straight into registers: storing them
/// to memory and loading 16 bytes back stalls on store forwarding, which cost a quarter of a box query.
struct SlotBounds4
{
#if defined(__SSE2__)
    __m128 mMinX, mMinY, mMinZ, mMaxX, mMaxY, mMaxZ;

    explicit SlotBounds4(const QuadTree::Node& inNode)
        : mMinX(Load4(inNode.mMinX)), mMinY(Load4(inNode.mMinY)), mMinZ(Load4(inNode.mMinZ)),
          mMaxX(Load4(inNode.mMaxX)), mMaxY(Load4(inNode.mMaxY)), mMaxZ(Load4(inNode.mMaxZ))
    {
    }

    /// One slot's bounds (a query hit's; rare next to the 4-wide tests, so the stores are fine).
    AABB Slot(int inSlot) const
    {
        alignas(16) float rows[6][4];
        _mm_store_ps(rows[0], mMinX);
        _mm_store_ps(rows[1], mMinY);
        _mm_store_ps(rows[2], mMinZ);
        _mm_store_ps(rows[3], mMaxX);
        _mm_store_ps(rows[4], mMaxY);
        _mm_store_ps(rows[5], mMaxZ);
        return AABB(Vec3(rows[0][inSlot], rows[1][inSlot], rows[2][inSlot]),
                    Vec3(rows[3][inSlot], rows[4][inSlot], rows[5][inSlot]));
    }

    /// The same bounds grown by inExtent on every side (swept boxes). Empty slots stay empty.
    SlotBounds4 Grown(const Vec3& inExtent) const
    {
        SlotBounds4 grown = *this;
        grown.mMinX = _mm_sub_ps(mMinX, _mm_set1_ps(inExtent.x()));
        grown.mMinY = _mm_sub_ps(mMinY, _mm_set1_ps(inExtent.y()));
        grown.mMinZ = _mm_sub_ps(mMinZ, _mm_set1_ps(inExtent.z()));
        grown.mMaxX = _mm_add_ps(mMaxX, _mm_set1_ps(inExtent.x()));
        grown.mMaxY = _mm_add_ps(mMaxY, _mm_set1_ps(inExtent.y()));
        grown.mMaxZ = _mm_add_ps(mMaxZ, _mm_set1_ps(inExtent.z()));
        return grown;
    }

private:
    static __m128 Load4(const std::atomic<float> (&inValues)[4])
    {
#if defined(__x86_64__) && !defined(__SANITIZE_THREAD__)
        // One aligned 16-byte load for the four slots. On x86 every load has acquire order (TSO) and an
        // aligned 4-byte element is read whole, so this reads what four acquire loads would, without 4 loads
        // and 3 shuffles a row (the SIMD test was spending most of its time assembling its inputs); the fence
        // keeps the compiler from moving later loads (the children) above it, as acquire would.
        // ThreadSanitizer builds take the portable path below, so the protocol is still checked with real
        // atomic loads.
        static_assert(sizeof(std::atomic<float>) == sizeof(float) && std::atomic<float>::is_always_lock_free);
        const __m128 values = _mm_load_ps(reinterpret_cast<const float*>(&inValues[0]));
        std::atomic_signal_fence(std::memory_order_acquire);
        return values;
#else
        // Acquire: pairs with the releases of GrowSlot, exactly as LoadSlot does per slot
        return _mm_setr_ps(
            inValues[0].load(std::memory_order_acquire), inValues[1].load(std::memory_order_acquire),
            inValues[2].load(std::memory_order_acquire), inValues[3].load(std::memory_order_acquire));
#endif
    }
#else
    float mMinX[4], mMinY[4], mMinZ[4], mMaxX[4], mMaxY[4], mMaxZ[4];

    explicit SlotBounds4(const QuadTree::Node& inNode)
    {
        for (int s = 0; s < 4; ++s)
        {
            const AABB slot = QuadTree::LoadSlot(inNode, s); // Acquire, see there
            mMinX[s] = slot.mMin.x();
            mMinY[s] = slot.mMin.y();
            mMinZ[s] = slot.mMin.z();
            mMaxX[s] = slot.mMax.x();
            mMaxY[s] = slot.mMax.y();
            mMaxZ[s] = slot.mMax.z();
        }
    }

    AABB Slot(int inSlot) const
    {
        return AABB(Vec3(mMinX[inSlot], mMinY[inSlot], mMinZ[inSlot]),
                    Vec3(mMaxX[inSlot], mMaxY[inSlot], mMaxZ[inSlot]));
    }

    /// The same bounds grown by inExtent on every side (swept boxes). Empty slots stay empty.
    SlotBounds4 Grown(const Vec3& inExtent) const
    {
        SlotBounds4 grown = *this;
        for (int s = 0; s < 4; ++s)
        {
            grown.mMinX[s] -= inExtent.x();
            grown.mMinY[s] -= inExtent.y();
            grown.mMinZ[s] -= inExtent.z();
            grown.mMaxX[s] += inExtent.x();
            grown.mMaxY[s] += inExtent.y();
            grown.mMaxZ[s] += inExtent.z();
        }
        return grown;
    }
#endif
};

// The masks below have an SSE version (x86-64 always has SSE2) and a scalar one with the shared exact tests.
// Both give the same bits: the SSE versions use the same comparisons and, for rays, the same operations in
// the same order as AABB::RayEntryFraction. (Eigen's boolean arrays were tried first: turning their lanes
// into a mask cost a third of a box query.)
#if defined(__SSE2__)

/// Lanes of a non-empty slot (min <= max on every axis).
inline __m128 NonEmptyLanes(const SlotBounds4& inSlots)
{
    return _mm_and_ps(
        _mm_and_ps(_mm_cmple_ps(inSlots.mMinX, inSlots.mMaxX), _mm_cmple_ps(inSlots.mMinY, inSlots.mMaxY)),
        _mm_cmple_ps(inSlots.mMinZ, inSlots.mMaxZ));
}

/// Slots whose bounds overlap inBox (closed intervals, the comparisons of AABBsOverlap). Empty slots fail for
/// any query below cLargeFloat; the walk skips invalid children anyway.
inline uint32_t OverlapMask(const SlotBounds4& inSlots, const AABB& inBox)
{
    const __m128 x = _mm_and_ps(_mm_cmple_ps(inSlots.mMinX, _mm_set1_ps(inBox.mMax.x())),
                                _mm_cmpge_ps(inSlots.mMaxX, _mm_set1_ps(inBox.mMin.x())));
    const __m128 y = _mm_and_ps(_mm_cmple_ps(inSlots.mMinY, _mm_set1_ps(inBox.mMax.y())),
                                _mm_cmpge_ps(inSlots.mMaxY, _mm_set1_ps(inBox.mMin.y())));
    const __m128 z = _mm_and_ps(_mm_cmple_ps(inSlots.mMinZ, _mm_set1_ps(inBox.mMax.z())),
                                _mm_cmpge_ps(inSlots.mMaxZ, _mm_set1_ps(inBox.mMin.z())));
    return uint32_t(_mm_movemask_ps(_mm_and_ps(_mm_and_ps(x, y), z)));
}

/// Slots whose bounds are within inRadius of inCenter (the arithmetic of SphereOverlapsAABB).
inline uint32_t SphereMask(const SlotBounds4& inSlots, const Vec3& inCenter, float inRadius)
{
    auto axis = [](__m128 inMin, __m128 inMax, float inC)
    {
        const __m128 c = _mm_set1_ps(inC);
        const __m128 d = _mm_sub_ps(c, _mm_min_ps(_mm_max_ps(c, inMin), inMax));
        return _mm_mul_ps(d, d);
    };
    const __m128 distanceSq = _mm_add_ps(_mm_add_ps(axis(inSlots.mMinX, inSlots.mMaxX, inCenter.x()),
                                                    axis(inSlots.mMinY, inSlots.mMaxY, inCenter.y())),
                                         axis(inSlots.mMinZ, inSlots.mMaxZ, inCenter.z()));
    return uint32_t(_mm_movemask_ps(
        _mm_and_ps(_mm_cmple_ps(distanceSq, _mm_set1_ps(inRadius * inRadius)), NonEmptyLanes(inSlots))));
}

/// Slots whose bounds the ray enters at or before inMaxFraction; outFractions gets the entry fractions.
inline uint32_t RayMask(const SlotBounds4& inSlots, const Vec3& inOrigin, const Vec3& inInvDirection,
                        float inMaxFraction, float (&outFractions)[4])
{
    __m128 tMin = _mm_setzero_ps();
    __m128 tMax = _mm_set1_ps(inMaxFraction);
    auto axis = [&](__m128 inMin, __m128 inMax, float inO, float inInv)
    {
        const __m128 o = _mm_set1_ps(inO), inv = _mm_set1_ps(inInv);
        __m128 t1 = _mm_mul_ps(_mm_sub_ps(inMin, o), inv);
        __m128 t2 = _mm_mul_ps(_mm_sub_ps(inMax, o), inv);
        // 0 * inf gives NaN when the origin lies on a slab plane of a parallel ray; treat it as inside
        const __m128 nan1 = _mm_cmpunord_ps(t1, t1), nan2 = _mm_cmpunord_ps(t2, t2);
        t1 = _mm_or_ps(_mm_andnot_ps(nan1, t1), _mm_and_ps(nan1, _mm_set1_ps(-cLargeFloat)));
        t2 = _mm_or_ps(_mm_andnot_ps(nan2, t2), _mm_and_ps(nan2, _mm_set1_ps(cLargeFloat)));
        tMin = _mm_max_ps(tMin, _mm_min_ps(t1, t2));
        tMax = _mm_min_ps(tMax, _mm_max_ps(t1, t2));
    };
    axis(inSlots.mMinX, inSlots.mMaxX, inOrigin.x(), inInvDirection.x());
    axis(inSlots.mMinY, inSlots.mMaxY, inOrigin.y(), inInvDirection.y());
    axis(inSlots.mMinZ, inSlots.mMaxZ, inOrigin.z(), inInvDirection.z());
    _mm_storeu_ps(outFractions, tMin);
    return uint32_t(_mm_movemask_ps(_mm_and_ps(_mm_cmple_ps(tMin, tMax), NonEmptyLanes(inSlots))));
}

#else

inline uint32_t OverlapMask(const SlotBounds4& inSlots, const AABB& inBox)
{
    uint32_t mask = 0;
    for (int s = 0; s < 4; ++s)
        mask |= uint32_t(AABBsOverlap(inSlots.Slot(s), inBox)) << s;
    return mask;
}

inline uint32_t SphereMask(const SlotBounds4& inSlots, const Vec3& inCenter, float inRadius)
{
    uint32_t mask = 0;
    for (int s = 0; s < 4; ++s)
    {
        const AABB slot = inSlots.Slot(s);
        mask |= uint32_t(!IsEmptyBox(slot) && SphereOverlapsAABB(inCenter, inRadius, slot)) << s;
    }
    return mask;
}

inline uint32_t RayMask(const SlotBounds4& inSlots, const Vec3& inOrigin, const Vec3& inInvDirection,
                        float inMaxFraction, float (&outFractions)[4])
{
    uint32_t mask = 0;
    for (int s = 0; s < 4; ++s)
    {
        const AABB slot = inSlots.Slot(s);
        outFractions[s] = slot.RayEntryFraction(inOrigin, inInvDirection, inMaxFraction);
        mask |= uint32_t(!IsEmptyBox(slot) && outFractions[s] <= inMaxFraction) << s;
    }
    return mask;
}

#endif

/// An object to place in a tree being built: a body (cBodyFlag | index) or a kept node, with its bounds.
struct BuildItem
{
    uint32_t mChild;       ///< cBodyFlag | body index, or a node index
    AABB mBounds;          ///< What its slot gets; the split key is twice its centre, min + max (no
                           ///< stored centre: 32-byte items move faster through the partitions)
    uint32_t mOldLocation; ///< Rebuild: where a body was found (node << 2 | slot); unused otherwise
};

/// A body that a rebuild moves to a new leaf.
struct Relocation
{
    uint32_t mBody, mOldLocation, mNewLocation;
    AABB mBuiltBounds; ///< What the new slot holds: the exact bounds phase 1 read, grown if it had moved
};

/// A kept node and its parent in the new tree.
struct Reparent
{
    uint32_t mNode, mParent;
};

/// The rebuild's working arrays, kept from one rebuild to the next (update thread only): as fresh vectors
/// they were allocated and page-faulted in every rebuild (1.4 MB for the shared world's full rebuild).
struct RebuildScratch
{
    std::vector<BuildItem> mItems;
    std::vector<Relocation> mRelocations;
    std::vector<Reparent> mReparents;
    std::vector<uint32_t> mNewNodes;
};

} // namespace cairn::physics::quadtree
