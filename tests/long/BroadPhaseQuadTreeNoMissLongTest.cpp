// The quad-tree broad phase's "no missed collisions" stress, long run: at least 2 million checks with zero
// misses (issue 3, done-when 2). Label "long": not part of the default test command; run it with
// `ctest --test-dir build/release -L long` (or under TSan with the tsan preset).

#include "broadphase/BroadPhaseQuadTree.h"
#include "common/NoMissStress.h"

#include <gtest/gtest.h>

namespace cairn
{
using namespace cairn::physics;
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
    test::ExpectNoMisses(result, config, broadPhase.GetBodyCount());
    EXPECT_TRUE(broadPhase.Validate());
}

} // namespace
} // namespace cairn
