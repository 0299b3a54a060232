// QuadTree::BuildNodes: the build of private nodes over a list of items, shared by batch adds
// (BuildSubTree) and rebuilds (Rebuild). Threads: any, no lock. It writes only nodes it has just allocated,
// which no other thread can reach until the caller publishes them (QuadTree.h says how); what inOnLeaf does
// with each placed item is the caller's affair.

#include "QuadTreeInternal.h"
#include "broadphase/QuadTree.h"

#include <algorithm>
#include <array>
#include <cstddef>
#include <utility>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace cairn::physics
{

using quadtree::BuildItem;

QuadTree::SubTree QuadTree::BuildNodes(std::span<BuildItem> ioItems, uint32_t inKeepFree,
                                       std::vector<uint32_t>& ioNewNodes, LeafCallback inOnLeaf)
{
    if (ioItems.empty())
    {
        SubTree empty;
        empty.mChild = AllocateNode(cInvalidNode, inKeepFree);
        if (empty.mChild != cInvalidNode) ioNewNodes.push_back(empty.mChild);
        return empty;
    }
    return BuildRange(ioItems.data(), ioItems.data() + ioItems.size(), cInvalidNode, inKeepFree, ioNewNodes,
                      inOnLeaf);
}

QuadTree::SubTree QuadTree::BuildRange(BuildItem* inBegin, BuildItem* inEnd, uint32_t inParent,
                                       uint32_t inKeepFree, std::vector<uint32_t>& ioNewNodes,
                                       LeafCallback inOnLeaf)
{
    SubTree result;
    const uint32_t nodeIndex = AllocateNode(inParent, inKeepFree);
    if (nodeIndex == cInvalidNode) return result;
    ioNewNodes.push_back(nodeIndex);
    result.mChild = nodeIndex;
    Node& node = GetNode(nodeIndex);

    // Bounds of the doubled centres (min + max) of [inB, inE), with min/max on plain floats (the AABB helpers
    // go through Eigen reductions, which dominated the build)
    auto centreBounds = [](const BuildItem* inB, const BuildItem* inE)
    {
#if defined(__SSE2__)
        // Four lanes at once: min.xyz and max.xyz each read with one 16-byte load that runs one float past
        // (into max.x and mOldLocation, both inside the item); lane 3 is ignored. The scalar loop spent a
        // third of the build here
        static_assert(offsetof(BuildItem, mBounds) + sizeof(AABB) + sizeof(uint32_t) <= sizeof(BuildItem));
        __m128 lo = _mm_set1_ps(cLargeFloat), hi = _mm_set1_ps(-cLargeFloat);
        // Lane 3 of the max row is mOldLocation's bits, a NaN or a denormal as a float: zeroed, so that lane
        // adds max.x and 0 (denormal operands can be slow, and NaN ones raise the invalid flag)
        const __m128 xyzMask = _mm_castsi128_ps(_mm_set_epi32(0, -1, -1, -1));
        for (const BuildItem* it = inB; it != inE; ++it)
        {
            const __m128 centre2 = _mm_add_ps(_mm_loadu_ps(it->mBounds.mMin.data()),
                                              _mm_and_ps(_mm_loadu_ps(it->mBounds.mMax.data()), xyzMask));
            lo = _mm_min_ps(lo, centre2);
            hi = _mm_max_ps(hi, centre2);
        }
        alignas(16) float loOut[4], hiOut[4];
        _mm_store_ps(loOut, lo);
        _mm_store_ps(hiOut, hi);
        return AABB(Vec3(loOut[0], loOut[1], loOut[2]), Vec3(hiOut[0], hiOut[1], hiOut[2]));
#else
        Vec3 lo = Vec3::Constant(cLargeFloat), hi = Vec3::Constant(-cLargeFloat);
        for (const BuildItem* it = inB; it != inE; ++it)
        {
            const Vec3 centre2 = it->mBounds.mMin + it->mBounds.mMax;
            lo = lo.cwiseMin(centre2);
            hi = hi.cwiseMax(centre2);
        }
        return AABB(lo, hi);
#endif
    };
    // Splits [inB, inE) at the midpoint of the longest axis of the centres (inCentres: their bounds);
    // halves when degenerate
    auto splitWith = [](BuildItem* inB, BuildItem* inE, const AABB& inCentres) -> BuildItem*
    {
        if (inE - inB < 2) return inE;
        const Vec3 size = inCentres.mMax - inCentres.mMin;
        int axis = 0;
        if (size.y() > size[axis]) axis = 1;
        if (size.z() > size[axis]) axis = 2;
        BuildItem* mid = inB + (inE - inB) / 2;
        if (size[axis] > 0.0f)
        {
            const float splitValue = 0.5f * (inCentres.mMin[axis] + inCentres.mMax[axis]);
            BuildItem* p =
                std::partition(inB, inE,
                               [&](const BuildItem& inItem) {
                                   return inItem.mBounds.mMin[axis] + inItem.mBounds.mMax[axis] < splitValue;
                               });
            // Rounding can put everything on one side; fall back to halves then
            if (p != inB && p != inE) return p;
        }
        return mid;
    };
    auto split = [&](BuildItem* inB, BuildItem* inE) { return splitWith(inB, inE, centreBounds(inB, inE)); };

    // The node's slots as ranges of items: each becomes one slot, or several when pulled up (see below)
    using Range = std::pair<BuildItem*, BuildItem*>;
    std::array<Range, 4> ranges;
    int numRanges = 0;
    const ptrdiff_t count = inEnd - inBegin;
    if (count <= 4)
    {
        for (BuildItem* it = inBegin; it != inEnd; ++it)
            ranges[numRanges++] = {it, it + 1};
    }
    else
    {
        // Objects much larger than the spread of the centres (a 64 m ground slab among 1 m crates) get a slot
        // of their own here, up to two: pushed down, each would widen every node on its way to a leaf, and
        // every query near them would walk those nodes. One pass: centres and the two largest objects
        const AABB centres = centreBounds(inBegin, inEnd);
        const float wideLimit =
            0.25f * (centres.mMax - centres.mMin).maxCoeff(); // Half the spread: centres are doubled
        BuildItem* largest[2] = {nullptr, nullptr};
        float largestSize[2] = {wideLimit, wideLimit};
        for (BuildItem* it = inBegin; it != inEnd; ++it)
        {
            const Vec3 extent = it->mBounds.mMax - it->mBounds.mMin;
            const float size = std::max(extent.x(), std::max(extent.y(), extent.z()));
            if (size <= largestSize[1]) continue;
            if (size > largestSize[0])
            {
                largest[1] = largest[0];
                largestSize[1] = largestSize[0];
                largest[0] = it;
                largestSize[0] = size;
            }
            else
            {
                largest[1] = it;
                largestSize[1] = size;
            }
        }
        BuildItem* rest = inBegin;
        if (largest[0] != nullptr)
        {
            // The item at inBegin moves to largest[0]'s place: follow it if it is the second largest
            if (largest[1] == rest) largest[1] = largest[0];
            std::swap(*rest, *largest[0]);
            ++rest;
            if (largest[1] != nullptr)
            {
                std::swap(*rest, *largest[1]);
                ++rest;
            }
        }
        for (BuildItem* it = inBegin; it != rest; ++it)
            ranges[numRanges++] = {it, it + 1};
        // The rest: split at the midpoint of the longest axis of the centres, then each half again
        ranges[numRanges++] = {rest, inEnd};
        // Breadth first: the rest, then each of its halves (the first split reuses the centre bounds above)
        bool topSplit = true;
        for (int next = numRanges - 1; numRanges < 4 && next < numRanges;)
        {
            const auto [begin, end] = ranges[next];
            if (end - begin <= 4) // Fits a leaf: more parts would only add half-empty nodes
            {
                ++next;
                continue;
            }
            BuildItem* mid = topSplit && rest == inBegin ? splitWith(begin, end, centres) : split(begin, end);
            ranges[next] = {begin, mid};
            ranges[numRanges++] = {mid, end};
            if (topSplit)
                topSplit = false; // Its lower half, now at [next], is split next
            else
                ++next;
        }
    }

    // Neighbouring parts that would both become leaf nodes (2 to 4 items) and fit one leaf together are
    // merged: the midpoint splits know nothing of counts, and half-empty leaves were a third of the nodes
    // Insertion sort by position: neighbours in the array are neighbours in space (each split is a partition)
    for (int i = 1; i < numRanges; ++i)
        for (int j = i; j > 0 && ranges[j].first < ranges[j - 1].first; --j)
            std::swap(ranges[j], ranges[j - 1]);
    for (int r = 0; r + 1 < numRanges;)
    {
        const ptrdiff_t a = ranges[r].second - ranges[r].first,
                        b = ranges[r + 1].second - ranges[r + 1].first;
        if (a >= 2 && b >= 2 && a + b <= 4)
        {
            ranges[r].second = ranges[r + 1].second;
            for (int k = r + 1; k + 1 < numRanges; ++k)
                ranges[k] = ranges[k + 1];
            --numRanges;
        }
        else
            ++r;
    }

    // Groups of a few items are pulled up into the slots that the splits left empty, smallest first, when all
    // of their items fit: a node holding two bodies costs 128 bytes and a step of every query that reaches it
    // Insertion sort by size (std::sort on 4 elements trips GCC 12's -Warray-bounds)
    for (int i = 1; i < numRanges; ++i)
        for (int j = i;
             j > 0 && ranges[j].second - ranges[j].first < ranges[j - 1].second - ranges[j - 1].first; --j)
            std::swap(ranges[j], ranges[j - 1]);
    int freeSlots = 4 - numRanges;
    int slot = 0;
    auto fillSlot = [&](const BuildItem& inItem)
    {
        InitSlot(node, slot, inItem.mChild, inItem.mBounds);
        result.mBounds.Encapsulate(inItem.mBounds);
        inOnLeaf(inItem, nodeIndex, slot);
        ++slot;
    };
    for (int r = 0; r < numRanges; ++r)
    {
        auto [begin, end] = ranges[r];
        const int n = int(end - begin);
        if (n == 1 || n - 1 <= freeSlots)
        {
            freeSlots -= n - 1;
            for (const BuildItem* it = begin; it != end; ++it)
                fillSlot(*it);
            continue;
        }
        const SubTree child = BuildRange(begin, end, nodeIndex, inKeepFree, ioNewNodes, inOnLeaf);
        if (child.mChild == cInvalidChild) return SubTree{}; // Out of nodes: the caller frees ioNewNodes
        InitSlot(node, slot++, child.mChild, child.mBounds);
        result.mBounds.Encapsulate(child.mBounds);
    }
    return result;
}

} // namespace cairn::physics
