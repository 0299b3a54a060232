// The job system under concurrent use, for ThreadSanitizer: several threads schedule job graphs into one pool
// and wait on them while the pool's workers run them, several run loops into it at once (the loop board and
// the queue), and a background queue takes submissions, cancellations and priority changes from several
// threads while frame jobs come and go.

#include "cairn/jobs/BackgroundQueue.h"
#include "cairn/jobs/JobSystem.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <gtest/gtest.h>
#include <numeric>
#include <random>
#include <thread>
#include <vector>

namespace cairn::jobs
{
namespace
{

using namespace std::chrono_literals;

TEST(JobSystemConcurrencyTest, ThreadsScheduleAndWaitOnGraphsAtOnce)
{
    JobSystem::Settings settings;
    settings.mNumThreads = 3;
    settings.mMaxJobs = 256; // Small, so that the pool also runs full and jobs run in place
    JobSystem jobs(settings);
    constexpr int cSchedulers = 3;
    std::atomic<int> violations{0};
    std::atomic<int> jobsRun{0};
    std::vector<std::thread> schedulers;
    for (int t = 0; t < cSchedulers; ++t)
        schedulers.emplace_back(
            [&, t]
            {
                std::mt19937 random(100 + t);
                for (int graph = 0; graph < 20; ++graph)
                {
                    constexpr int cNumJobs = 60;
                    std::vector<std::atomic<bool>> finished(cNumJobs);
                    std::vector<JobHandle> handles(cNumJobs);
                    for (int j = 0; j < cNumJobs; ++j)
                    {
                        JobHandle before[2];
                        int count = 0;
                        std::vector<int> prerequisites;
                        for (int k = 0; k < 2 && j > 0; ++k)
                        {
                            const int p = std::uniform_int_distribution<int>(0, j - 1)(random);
                            prerequisites.push_back(p);
                            before[count++] = handles[p];
                        }
                        const int a = prerequisites.empty() ? -1 : prerequisites[0];
                        const int b = prerequisites.size() < 2 ? -1 : prerequisites[1];
                        handles[j] = jobs.Schedule(
                            "graph node",
                            [&, j, a, b]
                            {
                                // Relaxed loads suffice: the job system must order prerequisites' writes
                                // before this job, and TSan checks that it does (the plain counter below)
                                if ((a >= 0 && !finished[a].load(std::memory_order_relaxed)) ||
                                    (b >= 0 && !finished[b].load(std::memory_order_relaxed)))
                                    violations.fetch_add(1);
                                finished[j].store(true, std::memory_order_relaxed);
                                jobsRun.fetch_add(1, std::memory_order_relaxed);
                            },
                            std::span<const JobHandle>(before, count));
                    }
                    jobs.WaitAll(handles);
                }
            });
    for (std::thread& scheduler : schedulers)
        scheduler.join();
    EXPECT_EQ(violations.load(), 0);
    EXPECT_EQ(jobsRun.load(), cSchedulers * 20 * 60);
}

TEST(JobSystemConcurrencyTest, PlainDataWrittenByAPrerequisiteIsSeenByItsDependent)
{
    JobSystem::Settings settings;
    settings.mNumThreads = 3;
    JobSystem jobs(settings);
    for (int round = 0; round < 200; ++round)
    {
        std::vector<int> data(64, 0); // Plain memory: a missing happens-before is a TSan report
        const JobHandle writer = jobs.Schedule("write", [&] { std::fill(data.begin(), data.end(), round); });
        int sum = 0;
        const JobHandle reader =
            jobs.Schedule("read", [&] { sum = std::accumulate(data.begin(), data.end(), 0); }, {writer});
        jobs.Wait(reader);
        ASSERT_EQ(sum, 64 * round);
    }
}

TEST(JobSystemConcurrencyTest, LoopsFromSeveralThreadsSeeEveryPartsPlainWrites)
{
    // Three threads run loops into one pool at once: one holds the loop board, the others queue their parts
    // as jobs, and the board changes hands hundreds of times. Each loop's parts write plain memory that its
    // caller reads after the loop: a joiner's part not ordered before the caller's return (or a board's
    // function and context rewritten while a joiner still reads them) is a TSan report.
    // The callers go on past their 300 rounds until a worker has joined a loop: on a loaded machine the
    // workers may get no core while the first rounds run, and the board's joiners are what this tests
    JobSystem::Settings settings;
    settings.mNumThreads = 3;
    JobSystem jobs(settings);
    const auto deadline = std::chrono::steady_clock::now() + 60s;
    auto joined = [&] { return jobs.GetStats().mLoopPartsJoined > 0; };
    auto caller = [&](int inSeed)
    {
        std::vector<int> data(48, 0);
        for (int round = 1;
             round <= 300 || (!joined() && round <= 100000 && std::chrono::steady_clock::now() < deadline);
             ++round)
        {
            jobs.ParallelFor(uint32_t(data.size()), 1 + uint32_t(round % 5),
                             [&](uint32_t inBegin, uint32_t inEnd)
                             {
                                 for (uint32_t i = inBegin; i < inEnd; ++i)
                                     data[i] = round * inSeed;
                             });
            ASSERT_EQ(std::accumulate(data.begin(), data.end(), 0), int(data.size()) * round * inSeed);
        }
    };
    std::thread first(caller, 1), second(caller, 2);
    caller(3);
    first.join();
    second.join();
    EXPECT_TRUE(joined()) << "no loop went through the board";
}

TEST(JobSystemConcurrencyTest, BackgroundQueueUnderConcurrentSubmitCancelAndFrames)
{
    JobSystem::Settings jobSettings;
    jobSettings.mNumThreads = 2;
    JobSystem frame(jobSettings);
    BackgroundQueue::Settings settings;
    settings.mNumThreads = 2;
    settings.mFrameJobs = &frame;
    settings.mMaxYield = std::chrono::microseconds(500);
    BackgroundQueue queue(settings);

    std::atomic<bool> stop{false};
    std::thread frames(
        [&]
        {
            while (!stop.load(std::memory_order_relaxed))
            {
                std::atomic<int> sum{0};
                frame.ParallelFor(2000, 100,
                                  [&](uint32_t inBegin, uint32_t inEnd)
                                  { sum.fetch_add(int(inEnd - inBegin)); });
                std::this_thread::sleep_for(200us);
            }
        });
    std::vector<std::shared_ptr<BackgroundTask>> all[3];
    std::vector<std::thread> submitters;
    for (int t = 0; t < 3; ++t)
        submitters.emplace_back(
            [&, t]
            {
                std::mt19937 random(7 + t);
                for (int i = 0; i < 40; ++i)
                {
                    auto counter = std::make_shared<int>(0); // Plain: owned by the running chunk
                    const int chunks = 1 + int(random() % 5);
                    auto task = queue.Submit("task", int(random() % 4),
                                             [counter, chunks](BackgroundTaskContext& ioContext)
                                             {
                                                 ++*counter;
                                                 ioContext.SetProgress(float(*counter) / float(chunks));
                                                 return *counter >= chunks ? BackgroundStep::Done
                                                                           : BackgroundStep::Continue;
                                             });
                    all[t].push_back(task);
                    if (random() % 4 == 0) task->Cancel();
                    if (random() % 4 == 0) task->SetPriority(int(random() % 8));
                }
            });
    for (std::thread& submitter : submitters)
        submitter.join();
    for (auto& tasks : all)
        for (const auto& task : tasks)
        {
            ASSERT_TRUE(task->Wait(30s)) << "a task never finished";
            EXPECT_TRUE(task->GetState() == BackgroundTaskState::Done ||
                        task->GetState() == BackgroundTaskState::Cancelled);
        }
    stop.store(true, std::memory_order_relaxed);
    frames.join();
}

} // namespace
} // namespace cairn::jobs
