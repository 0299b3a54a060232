// StepScheduler's count of the updating thread's time in parallel regions (StepStatistics::mSerialMs is the
// rest): which loops and stages count, that nested ones count once, and that other threads add nothing.
// Work is a sleep, so that each region's length is known; the checks compare with the wall clock around the
// regions, never with a figure.

#include "step/StepScheduler.h"

#include "cairn/jobs/JobSystem.h"

#include <chrono>
#include <gtest/gtest.h>
#include <thread>

namespace cairn::test
{
using namespace cairn::physics;
using namespace std::chrono_literals;

namespace
{
using Clock = std::chrono::steady_clock;

uint64_t NanosecondsOf(Clock::duration inDuration)
{
    return uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(inDuration).count());
}

/// The wall time of inBody() in nanoseconds.
template <class Body> uint64_t WallNanoseconds(const Body& inBody)
{
    const Clock::time_point start = Clock::now();
    inBody();
    return NanosecondsOf(Clock::now() - start);
}

std::unique_ptr<jobs::JobSystem> TwoThreads()
{
    jobs::JobSystem::Settings settings;
    settings.mNumThreads = 2;
    return std::make_unique<jobs::JobSystem>(settings);
}
} // namespace

TEST(StepSchedulerTest, LoopOfSeveralChunksCountsAsParallelOnOneThread)
{
    StepScheduler scheduler;
    scheduler.BeginStep(nullptr);
    scheduler.ParallelFor(4, 1, 1'000'000, [](uint32_t, uint32_t) { std::this_thread::sleep_for(2ms); });
    EXPECT_GE(scheduler.GetParallelNanoseconds(), NanosecondsOf(8ms));
}

TEST(StepSchedulerTest, LoopOfOneChunkIsSerial)
{
    StepScheduler scheduler;
    scheduler.BeginStep(nullptr);
    scheduler.ParallelFor(8, 8, 1'000'000, [](uint32_t, uint32_t) { std::this_thread::sleep_for(2ms); });
    scheduler.ParallelForUnlessAlone(true, 8, 1,
                                     [](uint32_t, uint32_t) { std::this_thread::sleep_for(2ms); });
    EXPECT_EQ(scheduler.GetParallelNanoseconds(), 0u);
}

TEST(StepSchedulerTest, NestedLoopCountsOnce)
{
    StepScheduler scheduler;
    scheduler.BeginStep(nullptr);
    const uint64_t wall = WallNanoseconds(
        [&]
        {
            scheduler.ParallelFor(2, 1, 1'000'000,
                                  [&](uint32_t, uint32_t) {
                                      scheduler.ParallelFor(2, 1, 1'000'000,
                                                            [](uint32_t, uint32_t)
                                                            { std::this_thread::sleep_for(2ms); });
                                  });
        });
    EXPECT_GE(scheduler.GetParallelNanoseconds(), NanosecondsOf(8ms));
    EXPECT_LE(scheduler.GetParallelNanoseconds(), wall)
        << "the inner loops were counted beside the outer one";
}

TEST(StepSchedulerTest, OnlyTheUpdatingThreadCounts)
{
    StepScheduler scheduler;
    scheduler.BeginStep(nullptr);
    std::thread other(
        [&] {
            scheduler.ParallelFor(4, 1, 1'000'000,
                                  [](uint32_t, uint32_t) { std::this_thread::sleep_for(1ms); });
        });
    other.join();
    EXPECT_EQ(scheduler.GetParallelNanoseconds(), 0u);
}

TEST(StepSchedulerTest, BeginStepStartsTheCountAgain)
{
    StepScheduler scheduler;
    scheduler.BeginStep(nullptr);
    scheduler.ParallelFor(2, 1, 1'000'000, [](uint32_t, uint32_t) { std::this_thread::sleep_for(1ms); });
    ASSERT_GT(scheduler.GetParallelNanoseconds(), 0u);
    scheduler.BeginStep(nullptr);
    EXPECT_EQ(scheduler.GetParallelNanoseconds(), 0u);
}

/// Stage 0 has one part for any thread count (serial), stage 1 one part per thread (up to 4), each part of
/// either sleeping inSleep: the serial stage is left out of the count, on any number of threads.
void ExpectSerialStageLeftOut(jobs::JobSystem* ioJobs)
{
    StepScheduler scheduler;
    scheduler.BeginStep(ioJobs);
    constexpr auto sleep = 4ms;
    const uint64_t wall = WallNanoseconds(
        [&]
        {
            scheduler.RunStages(
                false, 2,
                [](uint32_t inStage, uint32_t inThreads)
                { return inStage == 0 ? 1u : std::min(inThreads, 4u); },
                [&](uint32_t, uint32_t, uint32_t) { std::this_thread::sleep_for(sleep); });
        });
    EXPECT_GE(scheduler.GetParallelNanoseconds(), NanosecondsOf(sleep));
    EXPECT_LE(scheduler.GetParallelNanoseconds(), wall - NanosecondsOf(sleep)) << "the serial stage counted";
}

TEST(StepSchedulerTest, StageOfOnePartIsSerialOnOneThread)
{
    ExpectSerialStageLeftOut(nullptr);
}

TEST(StepSchedulerTest, StageOfOnePartIsSerialOnTwoThreads)
{
    const std::unique_ptr<jobs::JobSystem> jobs = TwoThreads();
    ExpectSerialStageLeftOut(jobs.get());
}

TEST(StepSchedulerTest, StagesAloneAreSerial)
{
    StepScheduler scheduler;
    scheduler.BeginStep(nullptr);
    scheduler.RunStages(
        true, 2, [](uint32_t, uint32_t inThreads) { return inThreads; },
        [](uint32_t, uint32_t, uint32_t) { std::this_thread::sleep_for(1ms); });
    scheduler.RunWhole(true, [] { std::this_thread::sleep_for(1ms); });
    EXPECT_EQ(scheduler.GetParallelNanoseconds(), 0u);
    scheduler.RunWhole(false, [] { std::this_thread::sleep_for(1ms); });
    EXPECT_GE(scheduler.GetParallelNanoseconds(), NanosecondsOf(1ms));
}

} // namespace cairn::test
