// JobSystem: prerequisites order jobs, waiting threads help, ParallelFor covers every index once and hands
// its parts to idle workers on the loop board (woken if asleep; queued as jobs when the board is taken), a
// full pool or too many dependents degrade to running in place instead of failing, and scheduling allocates
// nothing.

#include "cairn/jobs/JobSystem.h"

#include "common/AllocationCounter.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <gtest/gtest.h>
#include <random>
#include <sched.h>
#include <thread>
#include <vector>

namespace cairn::jobs
{
namespace
{

class JobSystemThreads : public ::testing::TestWithParam<uint32_t>
{
protected:
    JobSystem::Settings MakeSettings() const
    {
        JobSystem::Settings settings;
        settings.mNumThreads = GetParam();
        return settings;
    }
};

TEST_P(JobSystemThreads, ThreadCountIsTheOneAskedFor)
{
    JobSystem jobs(MakeSettings());
    EXPECT_EQ(jobs.GetNumThreads(), GetParam());
}

TEST_P(JobSystemThreads, AJobRunsAndItsEffectsAreVisibleAfterWait)
{
    JobSystem jobs(MakeSettings());
    int value = 0; // Plain: Wait orders the job's write before the read
    const JobHandle job = jobs.Schedule("set", [&] { value = 42; });
    jobs.Wait(job);
    EXPECT_TRUE(jobs.IsDone(job));
    EXPECT_EQ(value, 42);
}

TEST_P(JobSystemThreads, RandomGraphsRunEveryJobAfterItsPrerequisites)
{
    JobSystem jobs(MakeSettings());
    std::mt19937 random(11);
    for (int graph = 0; graph < 20; ++graph)
    {
        constexpr int cNumJobs = 300;
        std::vector<std::vector<int>> prerequisites(cNumJobs);
        for (int j = 1; j < cNumJobs; ++j)
        {
            const int count = std::uniform_int_distribution<int>(0, 4)(random);
            for (int k = 0; k < count; ++k)
                prerequisites[j].push_back(std::uniform_int_distribution<int>(0, j - 1)(random));
        }
        std::atomic<int> clock{0};
        std::vector<int> finishedAt(cNumJobs, -1);
        std::vector<JobHandle> handles(cNumJobs);
        for (int j = 0; j < cNumJobs; ++j)
        {
            std::vector<JobHandle> before;
            for (int p : prerequisites[j])
                before.push_back(handles[p]);
            handles[j] = jobs.Schedule(
                "node", [&, j] { finishedAt[j] = clock.fetch_add(1, std::memory_order_relaxed); }, before);
        }
        jobs.WaitAll(handles);
        for (int j = 0; j < cNumJobs; ++j)
        {
            ASSERT_GE(finishedAt[j], 0) << "job " << j << " did not run";
            for (int p : prerequisites[j])
                ASSERT_LT(finishedAt[p], finishedAt[j])
                    << "job " << j << " ran before its prerequisite " << p;
        }
    }
}

TEST_P(JobSystemThreads, FinishedAndInvalidPrerequisitesDoNotBlock)
{
    JobSystem jobs(MakeSettings());
    const JobHandle first = jobs.Schedule("first", [] {});
    jobs.Wait(first);
    bool ran = false;
    const JobHandle invalid{};
    const JobHandle outOfRange{123456789u, 0};
    const JobHandle second = jobs.Schedule("second", [&] { ran = true; }, {first, invalid, outOfRange});
    jobs.Wait(second);
    EXPECT_TRUE(ran);
    EXPECT_TRUE(jobs.IsDone(invalid));
    EXPECT_TRUE(jobs.IsDone(outOfRange));
}

TEST_P(JobSystemThreads, ManyDependentsOfOneJobAllRunAfterIt)
{
    JobSystem jobs(MakeSettings());
    std::atomic<bool> release{false};
    std::atomic<bool> firstDone{false};
    const JobHandle first = jobs.Schedule("first",
                                          [&]
                                          {
                                              while (!release.load(std::memory_order_acquire))
                                                  std::this_thread::yield();
                                              firstDone.store(true, std::memory_order_relaxed);
                                          });
    // With one thread the first job cannot start before Wait: release it from a helper thread
    std::thread releaser(
        [&]
        {
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
            release.store(true, std::memory_order_release);
        });
    constexpr int cDependents = JobSystem::cMaxDependents + 10;
    std::atomic<int> sawFirstDone{0};
    std::vector<JobHandle> handles;
    for (int i = 0; i < cDependents; ++i)
        handles.push_back(jobs.Schedule("dependent",
                                        [&]
                                        {
                                            if (firstDone.load(std::memory_order_relaxed))
                                                sawFirstDone.fetch_add(1, std::memory_order_relaxed);
                                        },
                                        {first}));
    jobs.WaitAll(handles);
    releaser.join();
    EXPECT_EQ(sawFirstDone.load(), cDependents);
    EXPECT_GE(jobs.GetStats().mDependentOverflow, 1u) << "more dependents than slots: the scheduler waited";
}

TEST_P(JobSystemThreads, ParallelForVisitsEveryIndexOnce)
{
    JobSystem jobs(MakeSettings());
    for (uint32_t count : {0u, 1u, 7u, 1000u, 100000u})
        for (uint32_t grain : {0u, 1u, 64u, 5000u, 1000000u})
        {
            std::vector<std::atomic<int>> visits(count);
            jobs.ParallelFor(count, grain,
                             [&](uint32_t inBegin, uint32_t inEnd)
                             {
                                 ASSERT_LT(inBegin, inEnd);
                                 ASSERT_LE(inEnd, count);
                                 for (uint32_t i = inBegin; i < inEnd; ++i)
                                     visits[i].fetch_add(1, std::memory_order_relaxed);
                             });
            for (uint32_t i = 0; i < count; ++i)
                ASSERT_EQ(visits[i].load(), 1) << "count " << count << " grain " << grain << " index " << i;
        }
}

/// Keeps a worker busy with a job until Release (or the end of the scope): with 2 threads the only one, so
/// that what the test schedules meanwhile stays queued.
class WorkerHeld
{
public:
    explicit WorkerHeld(JobSystem& ioJobs) : mJobs(ioJobs)
    {
        mHolder = mJobs.Schedule("holder",
                                 [this]
                                 {
                                     mHolding.store(true);
                                     while (!mRelease.load())
                                         std::this_thread::yield();
                                 });
        while (!mHolding.load())
            std::this_thread::yield();
    }
    ~WorkerHeld() { Release(); }
    void Release()
    {
        mRelease.store(true);
        mJobs.Wait(mHolder);
    }
    const JobHandle& Holder() const { return mHolder; }

private:
    JobSystem& mJobs;
    JobHandle mHolder;
    std::atomic<bool> mHolding{false}, mRelease{false};
};

TEST(JobSystemParallelForTest, TheCallerTakesItsRegionFromTheFrontAndTheOthersFromTheBack)
{
    // Two threads; the worker is held by a job, so the caller runs every chunk itself: its own region (the
    // first half) in order, then the worker's region from the back. The order proves each thread keeps to a
    // contiguous part of the data and that a thread out of work takes chunks its owner would reach last
    JobSystem::Settings settings;
    settings.mNumThreads = 2;
    JobSystem jobs(settings);
    WorkerHeld held(jobs);
    std::vector<uint32_t> order;
    const std::thread::id caller = std::this_thread::get_id();
    bool allOnCaller = true;
    jobs.ParallelFor(80, 10,
                     [&](uint32_t inBegin, uint32_t)
                     {
                         allOnCaller = allOnCaller && std::this_thread::get_id() == caller;
                         order.push_back(inBegin / 10);
                     });
    held.Release();
    EXPECT_TRUE(allOnCaller);
    EXPECT_EQ(order, (std::vector<uint32_t>{0, 1, 2, 3, 7, 6, 5, 4}));
}

TEST(JobSystemTryRunHereTest, RunsAQueuedJobOnTheCallerAndNothingElse)
{
    // Two threads, the worker held by a job: a job scheduled now stays queued, and TryRunHere runs it here
    JobSystem::Settings settings;
    settings.mNumThreads = 2;
    JobSystem jobs(settings);
    WorkerHeld held(jobs);
    std::thread::id ranOn;
    int otherRuns = 0;
    const JobHandle first = jobs.Schedule("first", [&] { ++otherRuns; });
    const JobHandle job = jobs.Schedule("job", [&] { ranOn = std::this_thread::get_id(); });
    EXPECT_FALSE(jobs.TryRunHere(held.Holder())) << "a job another thread is running";
    EXPECT_TRUE(jobs.TryRunHere(job)) << "second in the queue";
    EXPECT_TRUE(jobs.IsDone(job));
    EXPECT_EQ(ranOn, std::this_thread::get_id());
    EXPECT_EQ(otherRuns, 0) << "only the job asked for runs";
    EXPECT_FALSE(jobs.TryRunHere(job)) << "a finished job";
    held.Release();
    jobs.Wait(first);
    EXPECT_EQ(otherRuns, 1);
}

namespace
{
/// The workers asleep once inAsleep of them are (or after 2 s). Idle workers spin about cSpinMicroseconds,
/// then sleep: polled, for a loaded test machine.
uint32_t WaitForWorkersAsleep(const JobSystem& inJobs, uint32_t inAsleep)
{
    for (int i = 0; i < 2000 && inJobs.GetNumWorkersAsleep() != inAsleep; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    return inJobs.GetNumWorkersAsleep();
}
} // namespace

TEST(JobSystemSleepTest, WorkersWithoutWorkAreCountedAsleepAndABusyOneIsNot)
{
    JobSystem::Settings settings;
    settings.mNumThreads = 3;
    JobSystem jobs(settings);
    auto waitFor = [&](uint32_t inAsleep) { return WaitForWorkersAsleep(jobs, inAsleep); };
    EXPECT_EQ(waitFor(2), 2u) << "both workers sleep with nothing to do";
    // Each went to sleep once at least (a spurious wake-up may add one); none counted is a statistic that
    // counts nothing
    const uint64_t sleepsBefore = jobs.GetStats().mWorkerSleeps;
    EXPECT_GE(sleepsBefore, 2u);
    {
        WorkerHeld held(jobs); // One worker runs a job until released
        EXPECT_EQ(waitFor(1), 1u) << "the other one sleeps";
    }
    EXPECT_EQ(waitFor(2), 2u) << "the released worker sleeps again";
    EXPECT_GT(jobs.GetStats().mWorkerSleeps, sleepsBefore) << "the released worker's sleep is counted";
}

TEST(JobSystemSleepTest, AnExtendedSpinKeepsAnIdleWorkerAwakeUntilItEnds)
{
    if (std::thread::hardware_concurrency() < 2) GTEST_SKIP() << "ExtendSpin does nothing on one core";
    JobSystem::Settings settings;
    settings.mNumThreads = 2;
    JobSystem jobs(settings);
    ASSERT_EQ(WaitForWorkersAsleep(jobs, 1), 1u) << "the worker sleeps with nothing to do";
    using Clock = std::chrono::steady_clock;
    // A job on the worker extends the spin as its last act, so the worker runs out of work right after
    // (the test's atomics are sequentially consistent, the default: nothing here is about their cost)
    std::atomic<bool> running{false}, release{false};
    std::atomic<Clock::rep> extendedAt{0};
    const JobHandle job = jobs.Schedule("extends the spin",
                                        [&]
                                        {
                                            running.store(true);
                                            while (!release.load())
                                                std::this_thread::yield();
                                            // Before the call: the extension runs from a later time
                                            extendedAt.store(Clock::now().time_since_epoch().count());
                                            jobs.ExtendSpin(UINT64_MAX); // Capped: it still ends
                                        });
    while (!running.load())
        std::this_thread::yield();
    EXPECT_EQ(jobs.GetNumWorkersAsleep(), 0u);
    release.store(true);
    // Polled without pause. The worker is seen asleep after it went to sleep, never before, so the time
    // measured is never shorter than its spin, however loaded the machine: a shorter one proves that it
    // slept early (without the extension it sleeps about cSpinMicroseconds after the job)
    const Clock::time_point released = Clock::now();
    while (jobs.GetNumWorkersAsleep() == 0 && Clock::now() - released < std::chrono::seconds(5))
    {
    }
    const Clock::time_point seenAsleep = Clock::now();
    EXPECT_EQ(jobs.GetNumWorkersAsleep(), 1u) << "the worker sleeps once the extension is over";
    const Clock::time_point extended{Clock::duration(extendedAt.load())};
    EXPECT_GE(seenAsleep - extended, std::chrono::nanoseconds(JobSystem::cMaxSpinExtensionNanoseconds))
        << "the idle worker spins through the extension before it sleeps";
    jobs.Wait(job);
}

namespace
{
/// A ParallelFor of inParts chunks whose chunks each wait (up to 5 s) until every chunk has started: it
/// finishes in time only when inParts threads run it at once. Returns whether they did, and the threads seen.
bool RunPartsAtOnce(JobSystem& ioJobs, uint32_t inParts, std::vector<std::thread::id>& outThreads)
{
    std::atomic<uint32_t> started{0};
    std::atomic<bool> allMet{true};
    std::vector<std::thread::id> threads(inParts);
    ioJobs.ParallelFor(inParts, 1,
                       [&](uint32_t inBegin, uint32_t)
                       {
                           threads[inBegin] = std::this_thread::get_id();
                           started.fetch_add(1);
                           const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
                           while (started.load() < inParts)
                               if (std::chrono::steady_clock::now() > deadline)
                               {
                                   allMet.store(false);
                                   return;
                               }
                               else
                                   std::this_thread::yield();
                       });
    outThreads = threads;
    return allMet.load();
}
} // namespace

TEST(JobSystemLoopBoardTest, IdleWorkersJoinALoopWithoutAJobEach)
{
    // The loop's parts go to idle workers through the board: every part runs at once on its own thread, and
    // the queue runs no job for them
    JobSystem::Settings settings;
    settings.mNumThreads = 3;
    JobSystem jobs(settings);
    const JobSystem::Stats before = jobs.GetStats();
    std::vector<std::thread::id> threads;
    ASSERT_TRUE(RunPartsAtOnce(jobs, 3, threads)) << "the parts did not run at once";
    EXPECT_EQ(threads[0], std::this_thread::get_id()) << "the caller takes the first part";
    std::sort(threads.begin(), threads.end());
    EXPECT_EQ(std::unique(threads.begin(), threads.end()), threads.end()) << "three threads";
    const JobSystem::Stats after = jobs.GetStats();
    EXPECT_EQ(after.mJobsRun, before.mJobsRun) << "no job was queued for a part";
    EXPECT_EQ(after.mLoopPartsJoined - before.mLoopPartsJoined, 2u);
}

TEST(JobSystemLoopBoardTest, WithoutTheBoardALoopsPartsAreQueuedAsJobs)
{
    JobSystem::Settings settings;
    settings.mNumThreads = 3;
    settings.mUseLoopBoard = false;
    JobSystem jobs(settings);
    const JobSystem::Stats before = jobs.GetStats();
    std::vector<std::thread::id> threads;
    ASSERT_TRUE(RunPartsAtOnce(jobs, 3, threads)) << "the parts did not run at once";
    const JobSystem::Stats after = jobs.GetStats();
    EXPECT_EQ(after.mJobsRun - before.mJobsRun, 2u) << "a job for each part but the caller's";
    EXPECT_EQ(after.mLoopPartsJoined, before.mLoopPartsJoined);
}

TEST(JobSystemLoopBoardTest, SleepingWorkersAreWokenForALoop)
{
    JobSystem::Settings settings;
    settings.mNumThreads = 3;
    JobSystem jobs(settings);
    ASSERT_EQ(WaitForWorkersAsleep(jobs, 2), 2u);
    std::vector<std::thread::id> threads;
    EXPECT_TRUE(RunPartsAtOnce(jobs, 3, threads)) << "a sleeping worker was not woken for its part";
}

TEST(JobSystemLoopBoardTest, ALoopCountsAsFrameWorkUntilItEnds)
{
    // Background queues stand aside while frame work is in flight, and WaitIdle waits for it: a loop on the
    // board is frame work like a job
    JobSystem::Settings settings;
    settings.mNumThreads = 2;
    JobSystem jobs(settings);
    std::atomic<uint32_t> leastInFlight{UINT32_MAX};
    jobs.ParallelFor(64, 1,
                     [&](uint32_t, uint32_t)
                     {
                         uint32_t least = leastInFlight.load();
                         const uint32_t now = jobs.GetNumJobsInFlight();
                         while (now < least && !leastInFlight.compare_exchange_weak(least, now))
                         {
                         }
                     });
    EXPECT_GE(leastInFlight.load(), 1u);
    EXPECT_EQ(jobs.GetNumJobsInFlight(), 0u);
    EXPECT_TRUE(jobs.WaitForFrameIdle(std::chrono::microseconds(0)));
}

TEST(JobSystemLoopBoardTest, ALoopStartedWhileTheBoardHoldsAnotherGoesThroughTheQueue)
{
    // Loops nested in a loop's parts (the caller's and the joiners') find the board taken: they run as
    // jobs, and every index of every loop is still visited once
    JobSystem::Settings settings;
    settings.mNumThreads = 3;
    JobSystem jobs(settings);
    const JobSystem::Stats before = jobs.GetStats();
    constexpr uint32_t cOuter = 3, cInner = 300;
    std::vector<std::atomic<int>> visits(cOuter * cInner);
    jobs.ParallelFor(cOuter, 1,
                     [&](uint32_t inOuter, uint32_t)
                     {
                         jobs.ParallelFor(cInner, 10,
                                          [&](uint32_t inBegin, uint32_t inEnd)
                                          {
                                              for (uint32_t i = inBegin; i < inEnd; ++i)
                                                  visits[inOuter * cInner + i].fetch_add(1);
                                          });
                     });
    for (uint32_t i = 0; i < cOuter * cInner; ++i)
        ASSERT_EQ(visits[i].load(), 1) << "index " << i;
    EXPECT_GT(jobs.GetStats().mJobsRun, before.mJobsRun) << "the nested loops' parts were queued";
}

TEST_P(JobSystemThreads, ParallelForWithUnevenChunksVisitsEveryIndexOnce)
{
    // The first chunks are slow, so threads that finish their region take chunks from the back of the slow
    // one while its owner still takes from the front: each chunk must still run exactly once
    JobSystem jobs(MakeSettings());
    for (int round = 0; round < 20; ++round)
    {
        constexpr uint32_t cCount = 512;
        std::vector<std::atomic<int>> visits(cCount);
        jobs.ParallelFor(cCount, 4,
                         [&](uint32_t inBegin, uint32_t inEnd)
                         {
                             if (inBegin < cCount / 8)
                                 std::this_thread::sleep_for(std::chrono::microseconds(50));
                             for (uint32_t i = inBegin; i < inEnd; ++i)
                                 visits[i].fetch_add(1, std::memory_order_relaxed);
                         });
        for (uint32_t i = 0; i < cCount; ++i)
            ASSERT_EQ(visits[i].load(), 1) << "round " << round << " index " << i;
    }
}

TEST_P(JobSystemThreads, JobsCanScheduleAndWaitForJobs)
{
    JobSystem jobs(MakeSettings());
    std::atomic<int> leaves{0};
    std::vector<JobHandle> parents;
    for (int p = 0; p < 8; ++p)
        parents.push_back(jobs.Schedule(
            "parent",
            [&]
            {
                JobHandle children[8];
                for (JobHandle& child : children)
                    child = jobs.Schedule("child", [&] { leaves.fetch_add(1, std::memory_order_relaxed); });
                jobs.WaitAll(children);
                jobs.ParallelFor(
                    64, 4, [&](uint32_t inBegin, uint32_t inEnd) { leaves.fetch_add(int(inEnd - inBegin)); });
            }));
    jobs.WaitAll(parents);
    EXPECT_EQ(leaves.load(), 8 * (8 + 64));
}

TEST_P(JobSystemThreads, AWaitInsideAJobDoesNotRunAJobThatWaitsForIt)
{
    // P waits for its child Q; R, queued behind P, waits for P. Before isolation, P's wait ran R on P's own
    // stack when Q was not first in the queue, and R then waited forever for P below it
    JobSystem jobs(MakeSettings());
    for (int round = 0; round < 50; ++round)
    {
        std::atomic<int> done{0};
        const JobHandle p = jobs.Schedule("P",
                                          [&]
                                          {
                                              const JobHandle q =
                                                  jobs.Schedule("Q", [&] { done.fetch_add(1); });
                                              jobs.Wait(q);
                                              done.fetch_add(1);
                                          });
        const JobHandle r = jobs.Schedule("R",
                                          [&]
                                          {
                                              jobs.Wait(p);
                                              done.fetch_add(1);
                                          });
        jobs.Wait(r);
        EXPECT_EQ(done.load(), 3);
    }
}

TEST_P(JobSystemThreads, AJobCanWaitForASiblingThatIsNotReadyYet)
{
    // The sibling waits on a prerequisite that nobody inside the waiting job scheduled: with no other thread,
    // the wait must still run it
    JobSystem jobs(MakeSettings());
    std::atomic<int> order{0};
    int prerequisiteRan = -1, siblingRan = -1;
    const JobHandle waiter = jobs.Schedule("waiter", [&] {});
    const JobHandle prerequisite =
        jobs.Schedule("prerequisite", [&] { prerequisiteRan = order.fetch_add(1); });
    const JobHandle sibling =
        jobs.Schedule("sibling", [&] { siblingRan = order.fetch_add(1); }, {prerequisite});
    const JobHandle parent = jobs.Schedule("parent", [&] { jobs.Wait(sibling); }, {waiter});
    jobs.Wait(parent);
    EXPECT_EQ(prerequisiteRan, 0);
    EXPECT_EQ(siblingRan, 1);
}

/// P waits for X, which waits for a chain of inDepth queued-later prerequisites (X <- Y1 <- ... <- Yn, only
/// Yn runnable); R, queued before the chain, waits for P. With nothing of P's own queued, a wait that ran the
/// first queued job ran R on P's stack, and R waited forever for P below it (one thread). Checks that every
/// job ran, in every round.
void WaitThroughAChainOfPrerequisites(JobSystem& ioJobs, int inDepth)
{
    for (int round = 0; round < 20; ++round)
    {
        std::atomic<int> done{0};
        JobHandle x;
        std::atomic<bool> xScheduled{false};
        const JobHandle p = ioJobs.Schedule("P",
                                            [&]
                                            {
                                                while (!xScheduled.load())
                                                    std::this_thread::yield();
                                                ioJobs.Wait(x);
                                                done.fetch_add(1);
                                            });
        const JobHandle r = ioJobs.Schedule("R",
                                            [&]
                                            {
                                                ioJobs.Wait(p);
                                                done.fetch_add(1);
                                            });
        JobHandle below = ioJobs.Schedule("Y", [&] { done.fetch_add(1); });
        for (int level = 1; level < inDepth; ++level)
            below = ioJobs.Schedule("Y", [&] { done.fetch_add(1); }, {below});
        x = ioJobs.Schedule("X", [&] { done.fetch_add(1); }, {below});
        xScheduled.store(true);
        ioJobs.Wait(r);
        EXPECT_EQ(done.load(), 3 + inDepth) << "depth " << inDepth;
    }
}

TEST_P(JobSystemThreads, AWaitInsideAJobRunsThePrerequisitesOfWhatItWaitsFor)
{
    JobSystem jobs(MakeSettings());
    WaitThroughAChainOfPrerequisites(jobs, 1);
}

TEST_P(JobSystemThreads, AWaitInsideAJobRunsPrerequisitesOfPrerequisites)
{
    // Only the last of the chain is queued, two and more steps away from X: a wait that looked at X's direct
    // prerequisites alone found nothing of its own and fell back to R (the test hung with one thread)
    JobSystem jobs(MakeSettings());
    for (const int depth : {2, 5})
        WaitThroughAChainOfPrerequisites(jobs, depth);
}

TEST_P(JobSystemThreads, WaitIdleInsideAJobIsRefused)
{
    JobSystem jobs(MakeSettings());
    bool result = true;
    jobs.Wait(jobs.Schedule("asks for idle", [&] { result = jobs.WaitIdle(); }));
    EXPECT_FALSE(result) << "its own job is in flight: it could never be idle";
    EXPECT_TRUE(jobs.WaitIdle());
}

// A job that waits for its own handle would wait for ever: it finishes only when that wait returns. The wait
// is refused at once instead (false), and the job's wait for a job it scheduled still waits. On any thread
// count: the job may run on a worker or on the waiting caller
TEST_P(JobSystemThreads, AJobsWaitForItselfIsRefused)
{
    JobSystem jobs(MakeSettings());
    JobHandle self; // Plain: written before the release below, read after the acquire that pairs with it
    std::atomic<bool> published{false};
    bool selfWait = true, childWait = false, childRan = false;
    const JobHandle job = jobs.Schedule("waits for itself",
                                        [&]
                                        {
                                            // Acquire: pairs with the release that publishes the handle
                                            while (!published.load(std::memory_order_acquire))
                                                std::this_thread::yield();
                                            selfWait = jobs.Wait(self);
                                            childWait =
                                                jobs.Wait(jobs.Schedule("child", [&] { childRan = true; }));
                                        });
    self = job;
    published.store(true, std::memory_order_release); // Release: the handle is written before
    EXPECT_TRUE(jobs.Wait(job));
    EXPECT_FALSE(selfWait);
    EXPECT_TRUE(childWait);
    EXPECT_TRUE(childRan);
    EXPECT_TRUE(jobs.Wait(JobHandle{})); // An invalid handle counts as done: true, not refused
}

// mMaxJobs is clamped like the thread count: 2^32 - 1 slots asked for hundreds of gigabytes and aborted
TEST(JobSystemTest, AJobCountBeyondTheLimitIsClamped)
{
    JobSystem::Settings settings;
    settings.mNumThreads = 2;
    settings.mMaxJobs = 0xffffffffu;
    JobSystem jobs(settings);
    std::atomic<int> ran{0};
    std::vector<JobHandle> handles;
    for (int i = 0; i < 100; ++i)
        handles.push_back(jobs.Schedule("count", [&] { ran.fetch_add(1, std::memory_order_relaxed); }));
    EXPECT_TRUE(jobs.WaitAll(handles));
    EXPECT_EQ(ran.load(std::memory_order_relaxed), 100); // Relaxed: WaitAll ordered the jobs before
}

TEST_P(JobSystemThreads, WaitIdleRunsEverything)
{
    std::atomic<int> ran{0};
    {
        JobSystem jobs(MakeSettings());
        for (int i = 0; i < 100; ++i)
            jobs.Schedule("fire and forget", [&] { ran.fetch_add(1, std::memory_order_relaxed); });
        EXPECT_TRUE(jobs.WaitIdle());
        EXPECT_EQ(ran.load(), 100);
        EXPECT_EQ(jobs.GetNumJobsInFlight(), 0u);
        for (int i = 0; i < 50; ++i)
            jobs.Schedule("left to the destructor", [&] { ran.fetch_add(1, std::memory_order_relaxed); });
    }
    EXPECT_EQ(ran.load(), 150);
}

INSTANTIATE_TEST_SUITE_P(Threads, JobSystemThreads, ::testing::Values(1u, 2u, 4u),
                         [](const auto& inInfo) { return std::to_string(inInfo.param) + "Threads"; });

TEST(JobSystemTest, AFullPoolRunsJobsInPlace)
{
    JobSystem::Settings settings;
    settings.mNumThreads = 1; // No workers: queued jobs wait for Wait, so the pool stays full
    settings.mMaxJobs = 4;
    JobSystem jobs(settings);
    std::vector<int> order;
    std::vector<JobHandle> queued;
    for (int i = 0; i < 4; ++i)
        queued.push_back(jobs.Schedule("queued", [&, i] { order.push_back(i); }));
    // The fifth finds no slot: it runs now, after its prerequisite (which the caller runs first)
    const JobHandle inPlace = jobs.Schedule("in place", [&] { order.push_back(100); }, {queued[2]});
    EXPECT_FALSE(inPlace.IsValid());
    EXPECT_EQ(jobs.GetStats().mJobsRunInline, 1u);
    ASSERT_FALSE(order.empty());
    EXPECT_EQ(order.back(), 100);
    EXPECT_NE(std::find(order.begin(), order.end(), 2), order.end()) << "its prerequisite ran first";
    jobs.WaitAll(queued);
    EXPECT_EQ(order.size(), 5u);
}

TEST(JobSystemTest, SchedulingAndRunningAllocateNothing)
{
    JobSystem::Settings settings;
    settings.mNumThreads = 2;
    JobSystem jobs(settings);
    // Warm: threads started, every structure sized in the constructor
    jobs.Wait(jobs.Schedule("warm", [] {}));
    std::atomic<int> sum{0};
    const test::AllocationScope scope;
    for (int frame = 0; frame < 20; ++frame)
    {
        JobHandle a = jobs.Schedule("a", [&] { sum.fetch_add(1, std::memory_order_relaxed); });
        JobHandle b = jobs.Schedule("b", [&] { sum.fetch_add(1, std::memory_order_relaxed); }, {a});
        jobs.ParallelFor(1000, 100,
                         [&](uint32_t inBegin, uint32_t inEnd) { sum.fetch_add(int(inEnd - inBegin)); });
        jobs.Wait(b);
    }
    EXPECT_EQ(scope.GetCount(), 0u);
    EXPECT_EQ(sum.load(), 20 * 1002);
}

} // namespace
} // namespace cairn::jobs

namespace cairn::jobs
{
namespace
{

/// The cores the calling thread may run on.
int AllowedCores()
{
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof(set), &set) != 0) return 0;
    return CPU_COUNT(&set);
}

// With mPinWorkers each worker runs on one core (not the first the process may use, left to the caller), the
// caller keeps its cores, and without it the workers keep every core
TEST(JobSystemPinningTest, PinnedWorkersRunOnOneCoreEachAndTheCallerKeepsItsCores)
{
    const int cores = AllowedCores();
    if (cores < 2) GTEST_SKIP() << "one core: nothing to pin";
    for (bool pin : {true, false})
    {
        JobSystem::Settings settings;
        settings.mNumThreads = 2;
        settings.mPinWorkers = pin;
        JobSystem jobs(settings);
        std::atomic<int> workerCores{-1};
        const std::thread::id caller = std::this_thread::get_id();
        // Jobs until one runs on the worker (the caller may take some itself)
        for (int attempt = 0; attempt < 1000 && workerCores.load() < 0; ++attempt)
        {
            const JobHandle job = jobs.Schedule("where",
                                                [&]
                                                {
                                                    if (std::this_thread::get_id() != caller)
                                                        workerCores.store(AllowedCores());
                                                });
            std::this_thread::sleep_for(std::chrono::microseconds(200)); // Leave it to the worker
            jobs.Wait(job);
        }
        ASSERT_GE(workerCores.load(), 1) << "no job ran on the worker";
        EXPECT_EQ(workerCores.load(), pin ? 1 : cores) << (pin ? "pinned" : "not pinned");
        EXPECT_EQ(AllowedCores(), cores) << "the caller's cores";
    }
}

} // namespace
} // namespace cairn::jobs
