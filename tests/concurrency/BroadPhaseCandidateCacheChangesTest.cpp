// The pair search's static candidate cache while another thread adds and removes static bodies (a streamed
// tile coming and going): a static whose add finished before a pair search began must be reported by it, and
// one whose remove finished before must not, even when the search serves the body from its cache. Adds and
// removes that overlap a search may be seen either way. Run under ThreadSanitizer in CI (the cache's entries
// are written by the search's range threads, the change counts by the modifier).

#include "broadphase/BroadPhaseQuadTree.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <gtest/gtest.h>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

namespace cairn
{
using namespace cairn::physics;
namespace
{

constexpr uint32_t cSide = 10;                ///< Resting boxes on a cSide x cSide grid of tiles
constexpr uint32_t cBoxes = cSide * cSide;    ///< One toggled static per box
constexpr uint32_t cFirstToggled = 1000;      ///< Body index of box 0's toggled static
constexpr uint32_t cSearchesPerChange = 3;    ///< Walked, filled, served from the cache
constexpr uint32_t cChanges = 3 * cBoxes + 7; ///< Each toggled static added and removed about 1.5 times

AABB Box(const Vec3& inCenter, float inHalfExtent)
{
    return AABB::FromCenterExtent(inCenter, Vec3::Constant(inHalfExtent));
}

/// Change k toggles the static of box k % cBoxes: its even changes add it, its odd ones remove it. True when
/// that static is present once the first inChangesDone changes have finished.
bool PresentAfter(uint32_t inBox, uint32_t inChangesDone)
{
    if (inChangesDone <= inBox) return false;
    const uint32_t changesOfBox = (inChangesDone - inBox - 1) / cBoxes + 1;
    return changesOfBox % 2 == 1;
}

TEST(BroadPhaseCandidateCacheChangesTest, StaticsAddedOrRemovedBeforeASearchAreSeenByIt)
{
    BroadPhaseQuadTree broadPhase(4096, LayerSetup::CreateDefault());
    std::vector<BroadPhaseBody> tiles, boxes;
    std::vector<BodyID> active;
    for (uint32_t i = 0; i < cBoxes; ++i)
    {
        const Vec3 center(float(i % cSide) * 2.0f, 0.0f, float(i / cSide) * 2.0f);
        tiles.push_back({BodyID(i, 1), Box(center - Vec3(0, 0.5f, 0), 0.5f), Layers::cStatic});
        boxes.push_back({BodyID(500 + i, 1), Box(center + Vec3(0, 0.2f, 0), 0.2f), Layers::cMoving});
        active.push_back(boxes.back().mID);
    }
    // Far away statics, so that the static tree is large enough to be served from the cache
    for (uint32_t i = 0; i < BroadPhaseQuadTree::cMinCachedTreeBodies; ++i)
        tiles.push_back(
            {BodyID(2000 + i, 1), Box(Vec3(500.0f + float(i), 0.0f, 500.0f), 0.4f), Layers::cStatic});
    broadPhase.AddBodiesFinalize(broadPhase.AddBodiesPrepare(tiles));
    broadPhase.AddBodiesFinalize(broadPhase.AddBodiesPrepare(boxes));
    broadPhase.Update();

    // Release/acquire: a search that reads a count sees the changes it counts (and their change counts)
    std::atomic<uint32_t> changesDone{0};
    // Relaxed: the modifier paces itself on it; nothing else is published through it
    std::atomic<uint32_t> searchesDone{0};
    std::thread modifier(
        [&]
        {
            for (uint32_t change = 0; change < cChanges; ++change)
            {
                // Let the last change be walked, filled into the cache and served from it, then change a
                // static during the next search
                const uint32_t target = (change + 1) * cSearchesPerChange;
                while (searchesDone.load(std::memory_order_relaxed) < target)
                    std::this_thread::yield();
                const uint32_t box = change % cBoxes;
                const BodyID id(cFirstToggled + box, 1 + change / cBoxes);
                if (!PresentAfter(box, change))
                {
                    const BroadPhaseBody body{id, Box(boxes[box].mBounds.Center(), 0.05f), Layers::cStatic};
                    broadPhase.AddBodiesFinalize(broadPhase.AddBodiesPrepare(std::span(&body, 1)));
                }
                else
                {
                    // Removed with the sequence it was added with
                    const BodyID added(id.GetIndex(), 1 + (change - cBoxes) / cBoxes);
                    broadPhase.RemoveBodies(std::span(&added, 1));
                }
                changesDone.store(change + 1, std::memory_order_release);
            }
        });

    // The searching thread plays the step: it searches on two range threads and rebuilds now and then
    auto runRanges = [&](uint32_t inCount, FunctionRef<void(uint32_t, uint32_t)> inBody)
    {
        std::thread helper([&] { inBody(inCount / 2, inCount); });
        inBody(0, inCount / 2);
        helper.join();
    };
    const ParallelRanges ranges = runRanges;
    uint32_t checkedSearches = 0, wrong = 0;
    for (uint32_t search = 0; changesDone.load(std::memory_order_acquire) < cChanges; ++search)
    {
        const uint32_t before = changesDone.load(std::memory_order_acquire);
        std::mutex mutex;
        std::vector<std::pair<uint32_t, uint32_t>> pairs;
        broadPhase.FindCollidingPairs(
            active, LayerSetup::CreateDefault(),
            [&](BodyID inActive, BodyID inOther)
            {
                const std::lock_guard lock(mutex);
                pairs.emplace_back(inActive.GetIndex(), inOther.GetIndex());
            },
            &ranges);
        const uint32_t after = changesDone.load(std::memory_order_acquire);
        searchesDone.store(search + 1, std::memory_order_relaxed);
        if (search % 16 == 15) broadPhase.Update();
        std::sort(pairs.begin(), pairs.end());
        // Changes before .. after (the one running at the start to the one running at the end) may overlap
        // the search: their boxes are not checked
        if (after - before + 1 >= cBoxes) continue;
        ++checkedSearches;
        for (uint32_t box = 0; box < cBoxes; ++box)
        {
            bool touched = false;
            for (uint32_t change = before; change <= after; ++change)
                touched |= change % cBoxes == box;
            const uint32_t self = boxes[box].mID.GetIndex();
            const bool tile = std::binary_search(pairs.begin(), pairs.end(), std::pair(self, box));
            const bool toggled =
                std::binary_search(pairs.begin(), pairs.end(), std::pair(self, cFirstToggled + box));
            if (!tile || (!touched && toggled != PresentAfter(box, before))) ++wrong;
        }
    }
    modifier.join();
    EXPECT_EQ(wrong, 0u) << "boxes whose pairs missed a finished change (or their tile)";
    const BroadPhaseQuadTree::CandidateCacheStats stats = broadPhase.GetCandidateCacheStats();
    std::printf("[ figure   ] %u checked searches; cache: %llu reused, %llu refilled\n", checkedSearches,
                static_cast<unsigned long long>(stats.mReused),
                static_cast<unsigned long long>(stats.mRefilled));
    EXPECT_GT(checkedSearches, cChanges) << "the searches must be checked, else the test proves nothing";
    EXPECT_GT(stats.mReused, uint64_t(cChanges) * cBoxes / 2) << "and the cache must serve them";
}

} // namespace
} // namespace cairn
