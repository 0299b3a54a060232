// The quad-tree broad phase's "no missed collisions" stress, short run (see common/NoMissStress.h): part of
// the test command and run under ThreadSanitizer in CI. The 2-million-check run is tests/long/.

#include "cairn/physics/broadphase/BroadPhaseQuadTree.h"
#include "common/NoMissStress.h"

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
    test::ExpectNoMisses(result, config, broadPhase.GetBodyCount());
    EXPECT_TRUE(broadPhase.Validate());
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
