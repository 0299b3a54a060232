// The demo's count of the times another task took a navigation thread's core: the job workers found by their
// names, and each thread's count of involuntary switches read from any thread.

#include "common/ThreadSwitches.h"

#include "cairn/jobs/BackgroundQueue.h"
#include "cairn/jobs/JobSystem.h"

#include <algorithm>
#include <gtest/gtest.h>
#include <optional>

namespace cairn::tools
{
namespace
{

TEST(ThreadSwitchesTest, TheJobWorkersAndBackgroundThreadsAreFoundByTheirNames)
{
#if !defined(__linux__)
    GTEST_SKIP() << "thread names and /proc are Linux's";
#endif
    const size_t workersBefore = FindThreadsNamed(jobs::JobSystem::cWorkerThreadNamePrefix).size();
    const size_t backgroundBefore = FindThreadsNamed("cairn-bg").size();
    {
        jobs::JobSystem::Settings settings;
        settings.mNumThreads = 3; // The caller and two workers
        jobs::JobSystem jobSystem(settings);
        jobs::BackgroundQueue::Settings queueSettings;
        queueSettings.mNumThreads = 2;
        jobs::BackgroundQueue background(queueSettings);
        const std::vector<int> workers = FindThreadsNamed(jobs::JobSystem::cWorkerThreadNamePrefix);
        EXPECT_EQ(workers.size(), workersBefore + 2);
        EXPECT_EQ(FindThreadsNamed("cairn-bg").size(), backgroundBefore + 2);
        // This thread is not a worker
        EXPECT_EQ(std::count(workers.begin(), workers.end(), CurrentThreadId()), 0);
    }
    EXPECT_EQ(FindThreadsNamed(jobs::JobSystem::cWorkerThreadNamePrefix).size(), workersBefore);
    EXPECT_EQ(FindThreadsNamed("cairn-bg").size(), backgroundBefore);
}

TEST(ThreadSwitchesTest, AThreadsCountIsReadFromAnyThreadAndAGoneThreadHasNone)
{
#if !defined(__linux__)
    GTEST_SKIP() << "/proc is Linux's";
#endif
    const int self = CurrentThreadId();
    const int64_t before = InvoluntarySwitches(self);
    ASSERT_GE(before, 0);
    EXPECT_GE(InvoluntarySwitches(self), before); // A count: it never goes back

    jobs::JobSystem::Settings settings;
    settings.mNumThreads = 2;
    std::optional<jobs::JobSystem> jobSystem(std::in_place, settings);
    const std::vector<int> workers = FindThreadsNamed(jobs::JobSystem::cWorkerThreadNamePrefix);
    ASSERT_FALSE(workers.empty());
    std::vector<int> watched = workers;
    watched.push_back(self);
    EXPECT_GE(InvoluntarySwitches(watched), before);
    jobSystem.reset(); // Its workers end
    for (int worker : workers)
        EXPECT_EQ(InvoluntarySwitches(worker), -1);
    EXPECT_EQ(InvoluntarySwitches(watched), -1); // One gone: the sum can not be told
    EXPECT_EQ(InvoluntarySwitches(-5), -1);
}

} // namespace
} // namespace cairn::tools
