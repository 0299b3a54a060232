// The published poses' "no miss" stress, long run (see common/PublishedPoseStress.h): at least 2 million
// conclusive checks with zero misses, stale ids, duplicates or torn poses, with the step alone and on a job
// system of 2 threads. Label "long": not part of the default test command; run it with
// `ctest --test-dir build/release -L long`.

#include "common/PublishedPoseStress.h"

#include <gtest/gtest.h>
#include <string>

namespace cairn
{
using namespace cairn::physics;
namespace
{

/// The step's job-system threads: 0 steps on the step thread alone.
class PublishedPoseNoMissLongTest : public ::testing::TestWithParam<uint32_t>
{
};

TEST_P(PublishedPoseNoMissLongTest, TwoMillionChecks)
{
    test::PublishedPoseStressConfig config;
    config.mJobThreads = GetParam();
    config.mTargetChecks = 2000000;
    config.mMinUpdates = 10000; // The pistons' squeeze many times over, and hundreds of churn batches
    config.mMinDuration = std::chrono::milliseconds(30000);
    config.mMaxDuration = std::chrono::milliseconds(30 * 60 * 1000);
    const test::PublishedPoseStressResult result = test::RunPublishedPoseStress(config);
    test::ExpectNoMissedPublishedPoses(result, config.mTargetChecks);
}

INSTANTIATE_TEST_SUITE_P(Steps, PublishedPoseNoMissLongTest, ::testing::Values(0u, 2u),
                         [](const auto& inInfo) {
                             return inInfo.param == 0 ? std::string("NoJobSystem")
                                                      : std::to_string(inInfo.param) + "JobThreads";
                         });

} // namespace
} // namespace cairn
