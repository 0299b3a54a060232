// The physics step finds its pairs while the broad-phase update (rebuild) runs on another thread
// (BroadPhase::CanFindPairsDuringUpdate). Every FindCollidingPairs made while an Update runs must return
// exactly the pairs of the brute-force reference: not one missed or extra because a sub-tree was being
// rebuilt, swapped in or freed. Run under ThreadSanitizer in CI.

#include "broadphase/BroadPhaseBruteForce.h"
#include "broadphase/BroadPhaseQuadTree.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <gtest/gtest.h>
#include <random>
#include <thread>
#include <utility>
#include <vector>

namespace cairn
{
using namespace cairn::physics;
namespace
{

using PairList = std::vector<std::pair<uint32_t, uint32_t>>;

PairList FindPairs(const BroadPhase& inBroadPhase, std::span<const BodyID> inActive)
{
    PairList pairs;
    inBroadPhase.FindCollidingPairs(inActive, LayerSetup::CreateDefault(),
                                    [&](BodyID inA, BodyID inB) {
                                        pairs.emplace_back(std::min(inA.GetIndex(), inB.GetIndex()),
                                                           std::max(inA.GetIndex(), inB.GetIndex()));
                                    });
    std::sort(pairs.begin(), pairs.end());
    return pairs;
}

TEST(BroadPhasePairsDuringUpdateTest, PairsFoundWhileTheTreeIsRebuiltAreExact)
{
    BroadPhaseQuadTree quadTree(3000, LayerSetup::CreateDefault());
    ASSERT_TRUE(quadTree.CanFindPairsDuringUpdate());
    BroadPhaseBruteForce reference;
    std::mt19937 random(11);
    std::uniform_real_distribution<float> coordinate(0.0f, 60.0f), size(0.3f, 2.5f), step(-0.6f, 0.6f);
    std::vector<BroadPhaseBody> bodies;
    std::vector<BodyID> active;
    for (uint32_t i = 0; i < 3000; ++i)
    {
        const Vec3 min(coordinate(random), coordinate(random) * 0.1f, coordinate(random));
        const bool moving = i % 3 != 0;
        bodies.push_back({BodyID(i, 1), AABB(min, min + Vec3(size(random), size(random), size(random))),
                          moving ? Layers::cMoving : Layers::cStatic});
        if (moving) active.push_back(bodies.back().mID);
    }
    for (BroadPhase* broadPhase : std::initializer_list<BroadPhase*>{&quadTree, &reference})
        broadPhase->AddBodiesFinalize(broadPhase->AddBodiesPrepare(bodies));
    quadTree.Update();

    // Rounds until 3 of them had a search that overlapped the update (at least 12, at most 60): on a loaded
    // machine a round's update can run while the searching thread is descheduled
    int rounds = 0, roundsWithOverlap = 0;
    for (; rounds < 60 && (rounds < 12 || roundsWithOverlap < 3); ++rounds)
    {
        // Move the moving bodies (as the step's end does), so the next Update has changed parts to rebuild
        std::vector<BroadPhaseBody> moved;
        for (BroadPhaseBody& body : bodies)
            if (body.mLayer == Layers::cMoving)
            {
                const Vec3 delta(step(random), step(random) * 0.2f, step(random));
                body.mBounds = AABB(body.mBounds.mMin + delta, body.mBounds.mMax + delta);
                moved.push_back(body);
            }
        quadTree.NotifyBodiesAABBChanged(moved);
        reference.NotifyBodiesAABBChanged(moved);
        const PairList expected = FindPairs(reference, active);

        // A searching thread compares pair searches with the reference from before the update until after
        // it. Relaxed: the phase only steers the loop and classifies the searches; the searcher is joined
        // before its counters are read
        enum Phase : int
        {
            cBefore,
            cUpdating,
            cDone
        };
        std::atomic<int> phase{cBefore}, searches{0};
        int wrong = 0, overlapping = 0;
        std::thread searcher(
            [&]
            {
                for (bool last = false; !last;)
                {
                    last = phase.load(std::memory_order_relaxed) == cDone; // One full search after the update
                    const int before = phase.load(std::memory_order_relaxed);
                    if (FindPairs(quadTree, active) != expected) ++wrong;
                    const int after = phase.load(std::memory_order_relaxed);
                    // Began before the update ended and ended after it began
                    if (before != cDone && after != cBefore) ++overlapping;
                    searches.fetch_add(1, std::memory_order_relaxed);
                }
            });
        while (searches.load(std::memory_order_relaxed) == 0)
            std::this_thread::yield();
        phase.store(cUpdating, std::memory_order_relaxed);
        // A full rebuild every fourth round: the largest swap and the most nodes retired
        if (rounds % 4 == 3)
            quadTree.RebuildAll();
        else
            quadTree.Update();
        phase.store(cDone, std::memory_order_relaxed);
        searcher.join();
        ASSERT_EQ(wrong, 0) << "round " << rounds << ": " << wrong << " of " << searches.load()
                            << " pair searches differed from the reference";
        if (overlapping > 0) ++roundsWithOverlap;
    }
    EXPECT_EQ(quadTree.GetRefusedStepCalls(), 0u)
        << "an update and a pair search are not the same kind of call";
    EXPECT_TRUE(quadTree.Validate());
    // The searches must really have met the updates, else the test proves nothing; printed for the record
    std::printf("[ figure   ] %d of %d rounds had a pair search during the update\n", roundsWithOverlap,
                rounds);
    EXPECT_GT(roundsWithOverlap, 0);
}

} // namespace
} // namespace cairn
