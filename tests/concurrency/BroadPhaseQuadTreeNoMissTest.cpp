// The quad-tree broad phase's "no missed collisions" stress, short run (see common/NoMissStress.h): part of
// the test command and run under ThreadSanitizer in CI. The 2-million-check run is tests/long/.

#include "cairn/physics/broadphase/BroadPhaseQuadTree.h"
#include "common/NoMissStress.h"

#include <cstdio>
#include <gtest/gtest.h>

namespace cairn
{
namespace
{

void RunShort(BroadPhaseQuadTree::LockMode inMode)
{
    test::NoMissStressConfig config;
    config.mTargetChecks = 50000;
    config.mMinDuration = std::chrono::milliseconds(1000);
    config.mMaxDuration = std::chrono::milliseconds(20000);
    BroadPhaseQuadTree broadPhase(config.mNumPermanent + config.mNumChurned, LayerSetup::CreateDefault(),
                                  inMode);
    const test::NoMissStressResult result =
        test::RunNoMissStress(broadPhase, config, [&] { broadPhase.RebuildAll(); });
    EXPECT_EQ(result.mMisses, 0u);
    EXPECT_EQ(result.mRefusedBatches, 0u);
    EXPECT_GT(result.mChecks, 0u);
    EXPECT_GT(result.mMoves, 0u);
    EXPECT_GT(result.mChurnBatches, 0u);
    EXPECT_GT(result.mUpdates, 16u); // At least one full rebuild ran
    EXPECT_TRUE(broadPhase.Validate());
    EXPECT_EQ(broadPhase.GetBodyCount(), config.mNumPermanent + config.mNumChurned);
    std::printf(
        "[ figure   ] %llu checks, %llu misses, %llu moves, %llu churn batches, %llu updates in %.1f s\n",
        (unsigned long long)result.mChecks, (unsigned long long)result.mMisses,
        (unsigned long long)result.mMoves, (unsigned long long)result.mChurnBatches,
        (unsigned long long)result.mUpdates, result.mSeconds);
}

TEST(BroadPhaseQuadTreeNoMissTest, LockFreeShortRun)
{
    RunShort(BroadPhaseQuadTree::LockMode::LockFree);
}

TEST(BroadPhaseQuadTreeNoMissTest, GlobalMutexShortRun)
{
    RunShort(BroadPhaseQuadTree::LockMode::GlobalMutex);
}

} // namespace
} // namespace cairn
