// BroadPhaseSortAndSweep under the same "no missed collisions" stress as the quad tree
// (common/NoMissStress.h), for ThreadSanitizer and for the "old or new state, never neither" contract of its
// single reader-writer lock.

#include "cairn/physics/broadphase/BroadPhaseSortAndSweep.h"
#include "common/NoMissStress.h"

#include <gtest/gtest.h>

namespace cairn
{
namespace
{

TEST(BroadPhaseReferenceConcurrencyTest, MovedBodiesAreAlwaysFound)
{
    test::NoMissStressConfig config;
    config.mTargetChecks = 50000;
    config.mMinDuration = std::chrono::milliseconds(1000);
    config.mMaxDuration = std::chrono::milliseconds(20000);
    BroadPhaseSortAndSweep broadPhase(config.mNumPermanent + config.mNumChurned, LayerSetup::CreateDefault());
    // Sort and sweep has no separate full rebuild: every 16th update is an ordinary one
    const test::NoMissStressResult result =
        test::RunNoMissStress(broadPhase, config, [&] { broadPhase.Update(); });
    test::ExpectNoMisses(result, config, broadPhase.GetBodyCount());
    EXPECT_TRUE(broadPhase.Validate());
}

} // namespace
} // namespace cairn
