// The physics step finds its pairs while the broad-phase update (rebuild) runs on another thread
// (BroadPhase::CanFindPairsDuringUpdate). Every FindCollidingPairs made while an Update runs must return
// exactly the pairs of the brute-force reference: not one missed or extra because a sub-tree was being
// rebuilt, swapped in or freed. Run under ThreadSanitizer in CI.

#include "cairn/physics/broadphase/BroadPhaseBruteForce.h"
#include "cairn/physics/broadphase/BroadPhaseQuadTree.h"

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

    int roundsWithOverlap = 0;
    for (int round = 0; round < 24; ++round)
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

        // Relaxed: flags that only steer the loop below and count overlaps; the update's writes are joined
        // before the final checks
        std::atomic<bool> started{false}, updating{true};
        std::thread updater(
            [&]
            {
                started.store(true, std::memory_order_relaxed);
                // A full rebuild every fourth round: the largest swap and the most nodes retired
                if (round % 4 == 3)
                    quadTree.RebuildAll();
                else
                    quadTree.Update();
                updating.store(false, std::memory_order_relaxed);
            });
        while (!started.load(std::memory_order_relaxed))
            std::this_thread::yield();
        int searches = 0;
        bool overlapped = false;
        do
        {
            const bool updatingBefore = updating.load(std::memory_order_relaxed);
            ASSERT_EQ(FindPairs(quadTree, active), expected) << "round " << round << " search " << searches;
            overlapped = overlapped || updatingBefore;
            ++searches;
        } while (updating.load(std::memory_order_relaxed));
        updater.join();
        if (overlapped) ++roundsWithOverlap;
        EXPECT_EQ(FindPairs(quadTree, active), expected) << "round " << round << " after the update";
    }
    EXPECT_EQ(quadTree.GetRefusedStepCalls(), 0u)
        << "an update and a pair search are not the same kind of call";
    EXPECT_TRUE(quadTree.Validate());
    // The searches must really have met the updates (else the test proves nothing); printed for the record
    std::printf("[ figure   ] %d of 24 rounds began a pair search while the update ran\n", roundsWithOverlap);
    EXPECT_GT(roundsWithOverlap, 0);
}

} // namespace
} // namespace cairn
