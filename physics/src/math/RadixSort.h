#pragma once

// A stable least-significant-digit radix sort on an unsigned key of up to 64 bits, 8 bits a pass, for the
// physics step's large sorts: thousands of constraints by hashed keys, where std::sort's compares, half of
// them mispredicted, cost several times more than the passes here. All digit counts are taken in one read
// of the items; a pass whose digit is the same for every item is skipped, so small keys cost few passes.
// Stable: items with equal keys keep their input order. Single-threaded; allocates only when ioScratch
// grows.

#include <algorithm>
#include <array>
#include <cassert>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace cairn::physics
{

/// Sorts ioItems by inKeyOf(item) (a uint64_t below 2^inKeyBits), using ioScratch as the second buffer.
template <class Item, class KeyOf>
void RadixSort(std::span<Item> ioItems, std::vector<Item>& ioScratch, const KeyOf& inKeyOf, int inKeyBits)
{
    constexpr int cDigitBits = 8;
    constexpr uint32_t cBuckets = 1u << cDigitBits;
    const size_t count = ioItems.size();
    if (count < 2) return;
    assert(count <= UINT32_MAX && "RadixSort: the digit counts are 32-bit");
    const int passes = std::clamp((inKeyBits + cDigitBits - 1) / cDigitBits, 1, 8);
    std::array<std::array<uint32_t, cBuckets>, 8> counts{};
    for (const Item& item : ioItems)
    {
        const uint64_t key = inKeyOf(item);
        for (int pass = 0; pass < passes; ++pass)
            ++counts[pass][(key >> (pass * cDigitBits)) & (cBuckets - 1)];
    }
    ioScratch.resize(count);
    Item* source = ioItems.data();
    Item* target = ioScratch.data();
    for (int pass = 0; pass < passes; ++pass)
    {
        std::array<uint32_t, cBuckets>& start = counts[pass];
        const int shift = pass * cDigitBits;
        if (start[(inKeyOf(source[0]) >> shift) & (cBuckets - 1)] == count) continue; // One digit for all
        uint32_t sum = 0;
        for (uint32_t& bucket : start)
            sum += std::exchange(bucket, sum);
        for (size_t i = 0; i < count; ++i)
            target[start[(inKeyOf(source[i]) >> shift) & (cBuckets - 1)]++] = source[i];
        std::swap(source, target);
    }
    if (source != ioItems.data()) std::copy(source, source + count, ioItems.data());
}

/// Sorts ioItems by inLess, a strict total order whose first criterion is inKeyOf(item), a uint64_t:
/// RadixSort on the key's high 32 bits (half the passes of the whole key), then each run of items whose high
/// halves are equal sorted by inLess. For hashed keys such runs are rare and short; the result is std::sort's
/// by inLess.
template <class Item, class KeyOf, class Less>
void RadixSortByHighHalf(std::span<Item> ioItems, std::vector<Item>& ioScratch, const KeyOf& inKeyOf,
                         const Less& inLess)
{
    auto highHalf = [&](const Item& inItem) { return uint64_t(inKeyOf(inItem)) >> 32; };
    RadixSort(ioItems, ioScratch, highHalf, 32);
    for (size_t first = 0; first < ioItems.size();)
    {
        size_t last = first + 1;
        while (last < ioItems.size() && highHalf(ioItems[last]) == highHalf(ioItems[first]))
            ++last;
        if (last - first > 1) std::sort(ioItems.begin() + first, ioItems.begin() + last, inLess);
        first = last;
    }
}

} // namespace cairn::physics
