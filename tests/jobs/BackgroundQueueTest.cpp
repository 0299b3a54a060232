// BackgroundQueue: tasks run in chunks to the end, by priority, can be cancelled queued or running, report
// failures (returned or thrown) with a reason, and stand aside while frame jobs are in flight.

#include "cairn/jobs/BackgroundQueue.h"

#include "cairn/jobs/JobSystem.h"

#include <atomic>
#include <gtest/gtest.h>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace cairn::jobs
{
namespace
{

using namespace std::chrono_literals;

/// A task that holds the queue's only thread until released, so that later submissions queue up.
struct Gate
{
    std::atomic<bool> mOpen{false};
    std::atomic<bool> mEntered{false};

    BackgroundStepFunction Step()
    {
        return [this](BackgroundTaskContext&)
        {
            mEntered.store(true, std::memory_order_release);
            while (!mOpen.load(std::memory_order_acquire))
                std::this_thread::sleep_for(1ms);
            return BackgroundStep::Done;
        };
    }
    void WaitEntered() const
    {
        while (!mEntered.load(std::memory_order_acquire))
            std::this_thread::sleep_for(1ms);
    }
};

TEST(BackgroundQueueTest, ATaskRunsChunkByChunkToTheEnd)
{
    BackgroundQueue queue;
    int chunks = 0; // Touched by the queue's thread only until the task is seen finished
    auto task = queue.Submit("count to 10", 0,
                             [&](BackgroundTaskContext& ioContext)
                             {
                                 ++chunks;
                                 ioContext.SetProgress(float(chunks) / 10.0f);
                                 return chunks == 10 ? BackgroundStep::Done : BackgroundStep::Continue;
                             });
    ASSERT_TRUE(task->Wait(10s));
    EXPECT_EQ(task->GetState(), BackgroundTaskState::Done);
    EXPECT_EQ(chunks, 10);
    EXPECT_EQ(task->GetChunksRun(), 10u);
    EXPECT_EQ(task->GetProgress(), 1.0f);
    EXPECT_EQ(task->GetError(), "");
}

TEST(BackgroundQueueTest, HigherPriorityRunsFirstAndEqualPrioritiesInOrder)
{
    BackgroundQueue queue;
    Gate gate;
    auto blocker = queue.Submit("gate", 0, gate.Step());
    gate.WaitEntered();
    std::mutex mutex;
    std::vector<std::string> order;
    auto record = [&](std::string inName)
    {
        return [&, inName](BackgroundTaskContext&)
        {
            std::lock_guard lock(mutex);
            order.push_back(inName);
            return BackgroundStep::Done;
        };
    };
    std::vector<std::shared_ptr<BackgroundTask>> tasks = {
        queue.Submit("low", 1, record("low")), queue.Submit("high-a", 5, record("high-a")),
        queue.Submit("high-b", 5, record("high-b")), queue.Submit("raised", 0, record("raised"))};
    tasks[3]->SetPriority(10); // Priorities may change while queued
    gate.mOpen.store(true, std::memory_order_release);
    for (const auto& task : tasks)
        ASSERT_TRUE(task->Wait(10s));
    const std::vector<std::string> expected = {"raised", "high-a", "high-b", "low"};
    EXPECT_EQ(order, expected);
}

TEST(BackgroundQueueTest, ARunningTaskGivesWayToAHigherOneBetweenChunks)
{
    BackgroundQueue queue;
    std::atomic<bool> urgentDone{false};
    std::atomic<int> lowChunksAfterUrgentSubmitted{0};
    std::atomic<bool> urgentSubmitted{false};
    std::atomic<bool> lowSawUrgentDone{false};
    auto low = queue.Submit("long low", 0,
                            [&](BackgroundTaskContext&)
                            {
                                std::this_thread::sleep_for(1ms);
                                if (urgentDone.load(std::memory_order_acquire))
                                {
                                    lowSawUrgentDone.store(true);
                                    return BackgroundStep::Done;
                                }
                                if (urgentSubmitted.load(std::memory_order_acquire))
                                    lowChunksAfterUrgentSubmitted.fetch_add(1);
                                return BackgroundStep::Continue;
                            });
    while (low->GetChunksRun() < 3)
        std::this_thread::sleep_for(1ms);
    auto urgent = queue.Submit("urgent", 10,
                               [&](BackgroundTaskContext&)
                               {
                                   urgentDone.store(true, std::memory_order_release);
                                   return BackgroundStep::Done;
                               });
    // Once it is queued, not before: set before, a low chunk could see the flag, end, and start another
    // before the urgent task was queued at all (a second count on a loaded machine, not a missed preemption)
    urgentSubmitted.store(true, std::memory_order_release);
    ASSERT_TRUE(urgent->Wait(10s));
    ASSERT_TRUE(low->Wait(10s));
    EXPECT_TRUE(lowSawUrgentDone.load());
    // At most the chunk that was running when it arrived
    EXPECT_LE(lowChunksAfterUrgentSubmitted.load(), 1);
    EXPECT_GE(queue.GetStats().mPreemptions, 1u);
}

TEST(BackgroundQueueTest, CancelAQueuedTaskAtOnceAndARunningOneAtItsNextChunk)
{
    BackgroundQueue queue;
    Gate gate;
    auto blocker = queue.Submit("gate", 0, gate.Step());
    gate.WaitEntered();
    std::atomic<bool> queuedRan{false};
    auto queued = queue.Submit("queued", 0,
                               [&](BackgroundTaskContext&)
                               {
                                   queuedRan.store(true);
                                   return BackgroundStep::Done;
                               });
    queued->Cancel();
    EXPECT_EQ(queued->GetState(), BackgroundTaskState::Cancelled);
    EXPECT_TRUE(queued->Wait(0ms));

    std::atomic<int> chunks{0};
    auto running = queue.Submit("endless", 0,
                                [&](BackgroundTaskContext& ioContext)
                                {
                                    chunks.fetch_add(1);
                                    return ioContext.IsCancelRequested() ? BackgroundStep::Done
                                                                         : BackgroundStep::Continue;
                                });
    gate.mOpen.store(true, std::memory_order_release);
    while (chunks.load() < 5)
        std::this_thread::sleep_for(1ms);
    running->Cancel();
    ASSERT_TRUE(running->Wait(10s));
    EXPECT_TRUE(running->GetState() == BackgroundTaskState::Cancelled ||
                running->GetState() == BackgroundTaskState::Done); // Done if it saw the request itself
    EXPECT_FALSE(queuedRan.load());
}

TEST(BackgroundQueueTest, CancellingAQueuedTaskReleasesItsCapturesAtOnce)
{
    BackgroundQueue queue;
    Gate gate;
    auto blocker = queue.Submit("gate", 0, gate.Step());
    gate.WaitEntered();
    auto captured = std::make_shared<int>(7);
    auto queued = queue.Submit("holds a capture", 0,
                               [captured](BackgroundTaskContext&) { return BackgroundStep::Done; });
    EXPECT_EQ(captured.use_count(), 2);
    queued->Cancel();
    // Before, the capture lived on in the task until a queue thread happened to sweep it out
    EXPECT_EQ(captured.use_count(), 1);
    gate.mOpen.store(true, std::memory_order_release);
    EXPECT_TRUE(blocker->Wait(10s));
}

TEST(BackgroundQueueTest, AThreadCountBeyondTheLimitIsClamped)
{
    BackgroundQueue::Settings settings;
    settings.mNumThreads = 10000;
    BackgroundQueue queue(settings);
    auto task = queue.Submit("runs", 0, [](BackgroundTaskContext&) { return BackgroundStep::Done; });
    EXPECT_TRUE(task->Wait(10s));
    EXPECT_EQ(queue.GetNumThreads(), BackgroundQueue::cMaxThreads);
}

TEST(BackgroundQueueTest, FailuresCarryTheirReason)
{
    BackgroundQueue queue;
    auto returned = queue.Submit("returns failed", 0,
                                 [](BackgroundTaskContext& ioContext)
                                 {
                                     ioContext.SetError("tile 3,4: no geometry");
                                     return BackgroundStep::Failed;
                                 });
    auto thrown = queue.Submit("throws", 0,
                               [](BackgroundTaskContext&) -> BackgroundStep
                               { throw std::runtime_error("malformed mesh"); });
    auto empty = queue.Submit("empty", 0, BackgroundStepFunction{});
    ASSERT_TRUE(returned->Wait(10s));
    ASSERT_TRUE(thrown->Wait(10s));
    ASSERT_TRUE(empty->Wait(0ms));
    EXPECT_EQ(returned->GetState(), BackgroundTaskState::Failed);
    EXPECT_EQ(returned->GetError(), "tile 3,4: no geometry");
    EXPECT_EQ(thrown->GetState(), BackgroundTaskState::Failed);
    EXPECT_NE(thrown->GetError().find("malformed mesh"), std::string::npos);
    EXPECT_EQ(empty->GetState(), BackgroundTaskState::Failed);
    EXPECT_FALSE(empty->GetError().empty());
    // The queue goes on after a failure
    auto after = queue.Submit("after", 0, [](BackgroundTaskContext&) { return BackgroundStep::Done; });
    ASSERT_TRUE(after->Wait(10s));
    EXPECT_EQ(after->GetState(), BackgroundTaskState::Done);
}

TEST(BackgroundQueueTest, StandsAsideWhileFrameJobsAreInFlight)
{
    JobSystem::Settings jobSettings;
    jobSettings.mNumThreads = 2;
    JobSystem frame(jobSettings);
    BackgroundQueue::Settings settings;
    settings.mFrameJobs = &frame;
    settings.mMaxYield =
        std::chrono::microseconds(10'000'000); // Longer than the test: only idleness frees it
    BackgroundQueue queue(settings);

    std::atomic<bool> frameMayEnd{false};
    const JobHandle frameJob = frame.Schedule("long frame job",
                                              [&]
                                              {
                                                  while (!frameMayEnd.load(std::memory_order_acquire))
                                                      std::this_thread::sleep_for(1ms);
                                              });
    std::atomic<bool> ranDuringFrame{false};
    auto task = queue.Submit("background", 0,
                             [&](BackgroundTaskContext&)
                             {
                                 if (!frameMayEnd.load(std::memory_order_acquire)) ranDuringFrame.store(true);
                                 return BackgroundStep::Done;
                             });
    std::this_thread::sleep_for(50ms);
    EXPECT_EQ(task->GetChunksRun(), 0u) << "a chunk ran while a frame job was in flight";
    frameMayEnd.store(true, std::memory_order_release);
    frame.Wait(frameJob);
    ASSERT_TRUE(task->Wait(10s));
    EXPECT_FALSE(ranDuringFrame.load());
    EXPECT_GE(queue.GetStats().mYieldsToFrame, 1u);
}

TEST(BackgroundQueueTest, DestroyingTheQueueCancelsWhatIsLeft)
{
    std::shared_ptr<BackgroundTask> running, queued;
    {
        BackgroundQueue queue;
        running = queue.Submit("endless", 0, [](BackgroundTaskContext&) { return BackgroundStep::Continue; });
        queued =
            queue.Submit("never started", -1, [](BackgroundTaskContext&) { return BackgroundStep::Done; });
        while (running->GetChunksRun() == 0)
            std::this_thread::sleep_for(1ms);
    }
    EXPECT_EQ(running->GetState(), BackgroundTaskState::Cancelled);
    EXPECT_EQ(queued->GetState(), BackgroundTaskState::Cancelled);
}

} // namespace
} // namespace cairn::jobs
