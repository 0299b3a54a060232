// The quad-tree broad phase's "no missed collisions" stress, long run: at least 2 million checks with zero
// misses (issue 3, done-when 2). Label "long": not part of the default test command; run it with
// `ctest --test-dir build/release -L long` (or under TSan with the tsan preset).

#include "cairn/physics/broadphase/BroadPhaseQuadTree.h"
#include "common/NoMissStress.h"

#include <cstdio>
#include <gtest/gtest.h>

namespace cairn
{
namespace
{

TEST(BroadPhaseQuadTreeNoMissLongTest, TwoMillionChecks)
{
    test::NoMissStressConfig config;
    config.mNumPermanent = 8000;
    config.mNumChurned = 2000;
    config.mTargetChecks = 2000000;
    config.mMinDuration = std::chrono::milliseconds(5000);
    config.mMaxDuration = std::chrono::milliseconds(30 * 60 * 1000);
    BroadPhaseQuadTree broadPhase(config.mNumPermanent + config.mNumChurned, LayerSetup::CreateDefault());
    const test::NoMissStressResult result =
        test::RunNoMissStress(broadPhase, config, [&] { broadPhase.RebuildAll(); });
    EXPECT_GE(result.mChecks, config.mTargetChecks);
    EXPECT_EQ(result.mMisses, 0u);
    EXPECT_EQ(result.mRefusedBatches, 0u);
    EXPECT_GT(result.mUpdates, 16u);
    EXPECT_TRUE(broadPhase.Validate());
    EXPECT_EQ(broadPhase.GetBodyCount(), config.mNumPermanent + config.mNumChurned);
    std::printf(
        "[ figure   ] %llu checks, %llu misses, %llu moves, %llu churn batches, %llu updates in %.1f s\n",
        (unsigned long long)result.mChecks, (unsigned long long)result.mMisses,
        (unsigned long long)result.mMoves, (unsigned long long)result.mChurnBatches,
        (unsigned long long)result.mUpdates, result.mSeconds);
}

} // namespace
} // namespace cairn
