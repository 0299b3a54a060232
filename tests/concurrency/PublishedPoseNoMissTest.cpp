// The published poses' "no miss" stress, short run (see common/PublishedPoseStress.h for the threads and what
// each check proves): while the world steps back to back (alone, or on a job system of 2 threads), bodies are
// moved by hand, churned bodies are added and removed, and two threads query points inside moving bodies, a
// query never misses a body whose published pose did not change during it, never reports a stale id, never
// reports a body twice and never sees a torn pose. Part of the test command and run under ThreadSanitizer in
// CI; the 2-million-check run is tests/long/PublishedPoseNoMissLongTest.cpp.

#include "common/PublishedPoseStress.h"

#include <gtest/gtest.h>
#include <string>

namespace cairn
{
using namespace cairn::physics;
namespace
{

/// The step's job-system threads: 0 steps on the step thread alone.
class PublishedPoseNoMissTest : public ::testing::TestWithParam<uint32_t>
{
};

TEST_P(PublishedPoseNoMissTest, QueriesInsideMovingBodiesNeverMissThemWhileTheWorldSteps)
{
    test::PublishedPoseStressConfig config;
    config.mJobThreads = GetParam();
    // About 1 s in Release; a ThreadSanitizer run stops at the time cap with fewer checks (some 100,000 in
    // 8 s, about 90 updates: full rebuilds and paddle turns included). The cap is short because its 5 threads
    // share CI's 2 cores with the other concurrency tests, whose own time limits they would eat into
    config.mTargetChecks = 50000;
    config.mMinDuration = std::chrono::milliseconds(1000);
    config.mMaxDuration = std::chrono::milliseconds(test::cSlowBuild ? 8000 : 30000);
    const test::PublishedPoseStressResult result = test::RunPublishedPoseStress(config);
    test::ExpectNoMissedPublishedPoses(result, test::cSlowBuild ? 5000 : config.mTargetChecks);
}

INSTANTIATE_TEST_SUITE_P(Steps, PublishedPoseNoMissTest, ::testing::Values(0u, 2u),
                         [](const auto& inInfo) {
                             return inInfo.param == 0 ? std::string("NoJobSystem")
                                                      : std::to_string(inInfo.param) + "JobThreads";
                         });

} // namespace
} // namespace cairn
