// StepScheduler's count of the updating thread's time in parallel regions (StepStatistics::mSerialMs is the
// rest): which loops and stages count, that nested ones count once, and that other threads add nothing.
// Work is a sleep, so that each region's length is known; the checks compare with the wall clock around the
// regions, never with a figure. And how GrainFor cuts a loop for the thread count.

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

/// Says it has inThreads threads and runs everything on the caller: GrainFor reads only the thread count.
class ClaimedThreads final : public jobs::JobInterface
{
public:
    explicit ClaimedThreads(uint32_t inThreads) : mThreads(inThreads) {}
    uint32_t GetNumThreads() const override { return mThreads; }
    void ParallelFor(uint32_t inCount, uint32_t inGrain, RangeFunction inFunction, void* inContext) override
    {
        for (uint32_t begin = 0; begin < inCount; begin += inGrain)
            inFunction(begin, std::min(inCount, begin + inGrain), inContext);
    }
    jobs::TaskHandle StartTask(const char*, TaskFunction inFunction, void* inContext) override
    {
        inFunction(inContext);
        return {1};
    }
    void FinishTask(jobs::TaskHandle) override {}

private:
    const uint32_t mThreads;
};

/// inLoop's grain for inCount items on inThreads claimed threads, at least inMinChunksPerThread chunks each.
uint32_t GrainOn(uint32_t inThreads, uint32_t inMinChunksPerThread, size_t inCount, StepCosts::Loop inLoop)
{
    ClaimedThreads jobs(inThreads);
    StepScheduler scheduler;
    scheduler.BeginStep(&jobs, inMinChunksPerThread);
    return scheduler.GrainFor(inCount, inLoop);
}
} // namespace

TEST(StepSchedulerTest, GrainIsTheLoopsOwnOnOneThreadOrWhenTurnedOff)
{
    constexpr StepCosts::Loop loop{64, 300};
    StepScheduler scheduler;
    scheduler.BeginStep(nullptr, 4);
    EXPECT_EQ(scheduler.GrainFor(1000, loop), 64u) << "no job system";
    EXPECT_EQ(GrainOn(1, 4, 1000, loop), 64u) << "one thread";
    EXPECT_EQ(GrainOn(16, 0, 1000, loop), 64u) << "turned off";
}

TEST(StepSchedulerTest, GrainGivesEachThreadSeveralChunksWhereTheItemsAllow)
{
    // 1,000 bodies' pair walks (300 ns each) on 16 threads: 64 chunks wanted, 16 bodies each (63 chunks)
    EXPECT_EQ(GrainOn(16, 4, 1000, {64, 300}), 16u);
    // On 2 threads the loop's own 16 chunks are already more than 8
    EXPECT_EQ(GrainOn(2, 4, 1000, {64, 300}), 64u);
    // 1,000 cheap items (30 ns): no chunk under cMinChunkNanoseconds of work, so 134 a chunk (8 chunks)
    EXPECT_EQ(GrainOn(16, 4, 1000, {256, 30}), 134u);
    // Ten items stay one chunk, a loop of one thread
    EXPECT_EQ(GrainOn(16, 4, 10, {256, 30}), 134u);
}

TEST(StepSchedulerTest, GrainIsNeverCoarserThanTheLoopsNorFinerThanTheLeastWork)
{
    for (const uint32_t threads : {2u, 3u, 8u, 16u, 64u})
        for (const size_t count : {size_t(0), size_t(1), size_t(100), size_t(5'000), size_t(1'000'000)})
            for (const StepCosts::Loop loop : {StepCosts::Loop{1, 5'000}, StepCosts::Loop{32, 425},
                                               StepCosts::Loop{256, 30}, StepCosts::Loop{512, 7}})
            {
                const uint32_t grain = GrainOn(threads, 4, count, loop);
                SCOPED_TRACE(testing::Message() << threads << " threads, " << count << " items of grain "
                                                << loop.mGrain << " at " << loop.mItemNanoseconds << " ns");
                EXPECT_GE(grain, 1u);
                EXPECT_LE(grain, loop.mGrain);
                if (grain < loop.mGrain)
                {
                    EXPECT_GE(uint64_t(grain) * loop.mItemNanoseconds, StepScheduler::cMinChunkNanoseconds);
                }
                EXPECT_LE(grain, GrainOn(threads / 2, 4, count, loop)) << "more threads, never coarser";
            }
}

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
