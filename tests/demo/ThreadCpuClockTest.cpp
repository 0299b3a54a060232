// The demo's attribution of slow frames to the host: a thread's CPU clock against the wall clock, trusted
// only when the guest did not switch the thread out in between.

#include "common/ThreadCpuClock.h"

#include <chrono>
#include <cmath>
#include <gtest/gtest.h>
#include <thread>

namespace cairn::tools
{
namespace
{

ThreadCpuSample Sample(double inCpuMs, int64_t inSwitches)
{
    return {inCpuMs, inSwitches, true};
}

TEST(ThreadCpuClockTest, TheHostsShareIsTheWallTimeTheThreadDidNotRunWithoutASwitch)
{
    EXPECT_DOUBLE_EQ(HostTakenMs(Sample(10.0, 4), Sample(10.5, 4), 2.0), 1.5);
    // The CPU clock is read just outside the wall window: a little ahead is no time taken, not a negative one
    EXPECT_EQ(HostTakenMs(Sample(10.0, 4), Sample(12.01, 4), 2.0), 0.0);
    // A switch (blocked, or preempted by the guest): the wait may be the guest's, so it is not told
    EXPECT_TRUE(std::isnan(HostTakenMs(Sample(10.0, 4), Sample(10.5, 5), 2.0)));
    ThreadCpuSample failed = Sample(10.5, 4);
    failed.mValid = false;
    EXPECT_TRUE(std::isnan(HostTakenMs(Sample(10.0, 4), failed, 2.0)));
    EXPECT_TRUE(std::isnan(HostTakenMs(failed, Sample(10.5, 4), 2.0)));
}

TEST(ThreadCpuClockTest, ABusyThreadsClockFollowsTheWallClockAndASleepIsASwitch)
{
    using Clock = std::chrono::steady_clock;
    const ThreadCpuSample busyStart = SampleThisThreadCpu();
    const Clock::time_point start = Clock::now();
    volatile uint64_t spin = 0;
    while (Clock::now() - start < std::chrono::milliseconds(20))
        spin = spin + 1;
    const double busyWallMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    const ThreadCpuSample busyEnd = SampleThisThreadCpu();
    ASSERT_TRUE(busyStart.mValid && busyEnd.mValid);
    const double busyCpuMs = busyEnd.mCpuMs - busyStart.mCpuMs;
    EXPECT_GT(busyCpuMs, 0.0);
    EXPECT_LE(busyCpuMs, busyWallMs + 1.0); // A thread can not run longer than the wall clock
    const double taken = HostTakenMs(busyStart, busyEnd, busyWallMs);
    if (!std::isnan(taken)) // NaN if the guest preempted the spinner
    {
        EXPECT_LE(taken, busyWallMs);
    }

    const ThreadCpuSample sleepStart = SampleThisThreadCpu();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const ThreadCpuSample sleepEnd = SampleThisThreadCpu();
    EXPECT_GT(sleepEnd.mSwitches, sleepStart.mSwitches); // Sleeping gives up the core
    EXPECT_LT(sleepEnd.mCpuMs - sleepStart.mCpuMs, 10.0);
    EXPECT_TRUE(std::isnan(HostTakenMs(sleepStart, sleepEnd, 20.0)));
}

TEST(ThreadCpuClockTest, TimeOnThisThreadTimesTheWork)
{
    int calls = 0;
    const TimedWork sleeping = TimeOnThisThread(
        [&]
        {
            ++calls;
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        });
    EXPECT_EQ(calls, 1);
    EXPECT_GE(sleeping.mWallMs, 5.0);
    EXPECT_TRUE(std::isnan(sleeping.mHostTakenMs)); // A sleep switches the thread out: not told
}

TEST(ThreadCpuClockTest, GuestStealOnlyGrows)
{
    const double first = GuestStealMs();
    const double second = GuestStealMs();
    if (std::isnan(first)) GTEST_SKIP() << "this kernel does not count steal time";
    EXPECT_GE(first, 0.0);
    EXPECT_GE(second, first);
}

} // namespace
} // namespace cairn::tools
