// RadixSort against std::stable_sort: the same order for any keys (duplicates included), any key width and
// any count, so the step's sorts give the results the comparison sorts gave.

#include "math/RadixSort.h"

#include <algorithm>
#include <cstdint>
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>
#include <vector>

namespace cairn::test
{
using namespace cairn::physics;
namespace
{
struct Keyed
{
    uint64_t mKey;
    uint32_t mInputPosition; ///< Tells a stable order from another
    bool operator==(const Keyed&) const = default;
};

std::vector<Keyed> StableSorted(std::vector<Keyed> inItems)
{
    std::stable_sort(inItems.begin(), inItems.end(),
                     [](const Keyed& inL, const Keyed& inR) { return inL.mKey < inR.mKey; });
    return inItems;
}

uint64_t KeyOf(const Keyed& inItem)
{
    return inItem.mKey;
}
} // namespace

RC_GTEST_PROP(RadixSortTest, OrdersAsStableSortForAnyKeysAndWidths, ())
{
    const int keyBits = *rc::gen::inRange(1, 65);
    const uint64_t mask = keyBits == 64 ? ~uint64_t(0) : (uint64_t(1) << keyBits) - 1;
    // Few distinct keys half of the time, so that equal keys (the stability) are tested
    const bool fewKeys = *rc::gen::arbitrary<bool>();
    const auto raw = *rc::gen::container<std::vector<uint64_t>>(rc::gen::arbitrary<uint64_t>());
    std::vector<Keyed> items;
    for (uint32_t i = 0; i < raw.size(); ++i)
        items.push_back({(fewKeys ? raw[i] % 5 : raw[i]) & mask, i});
    const std::vector<Keyed> expected = StableSorted(items);
    std::vector<Keyed> scratch;
    RadixSort(std::span<Keyed>(items), scratch, KeyOf, keyBits);
    RC_ASSERT(items == expected);
}

TEST(RadixSortTest, SortsThousandsOfHashedKeysAndKeepsEqualKeysInInputOrder)
{
    std::vector<Keyed> items;
    uint64_t state = 0x9e3779b97f4a7c15ull;
    for (uint32_t i = 0; i < 5000; ++i)
    {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        items.push_back({i % 7 == 0 ? 42u : state, i}); // Every seventh key equal
    }
    const std::vector<Keyed> expected = StableSorted(items);
    std::vector<Keyed> scratch;
    RadixSort(std::span<Keyed>(items), scratch, KeyOf, 64);
    EXPECT_EQ(items, expected);
    EXPECT_EQ(scratch.size(), items.size()) << "the scratch buffer is kept for its capacity";
}
// The solve order's sort: high halves forced to a few values, so that the runs the fix-up re-sorts are long
RC_GTEST_PROP(RadixSortTest, ByHighHalfOrdersAsTheFullComparison, ())
{
    const auto raw = *rc::gen::container<std::vector<uint64_t>>(rc::gen::arbitrary<uint64_t>());
    std::vector<Keyed> items;
    for (uint32_t i = 0; i < raw.size(); ++i)
        items.push_back({(raw[i] % 3) << 32 | (raw[i] >> 40), uint32_t(raw[i] % 7) * 1000 + i});
    // Key, then a tie-break that is not the input order (as the cache index is not)
    auto less = [](const Keyed& inL, const Keyed& inR)
    { return inL.mKey < inR.mKey || (inL.mKey == inR.mKey && inL.mInputPosition > inR.mInputPosition); };
    std::vector<Keyed> expected = items;
    std::sort(expected.begin(), expected.end(), less);
    std::vector<Keyed> scratch;
    RadixSortByHighHalf(std::span<Keyed>(items), scratch, KeyOf, less);
    RC_ASSERT(items == expected);
}

} // namespace cairn::test
