#pragma once

// Where a thread's wall time went: to tell a frame that ran slowly from one whose thread was taken off its
// core by the hypervisor. Linux: a thread's CPU clock counts only the time it ran, and with paravirtual steal
// accounting (KVM guests) that leaves out the time the host gave the vCPU to someone else; getrusage counts
// the times the guest switched the thread out (it blocked, or was preempted). So in a window with no switch,
// wall time beyond the thread's CPU time is time the host took the vCPU (or spent in interrupts); with a
// switch, the guest's own scheduling may account for it, and the two can not be told apart.

#include "FrameTimes.h"

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <limits>
#include <sys/resource.h>
#include <unistd.h>

namespace cairn::tools
{

/// The calling thread's CPU clock and context-switch count at one moment.
struct ThreadCpuSample
{
    double mCpuMs = 0.0;
    int64_t mSwitches = 0; ///< Voluntary and involuntary
    bool mValid = false;   ///< False when either could not be read
};

/// Samples the calling thread. Take it right before the window's first wall-clock read and right after its
/// last, so the window's own bookkeeping stays out of it.
inline ThreadCpuSample SampleThisThreadCpu()
{
    ThreadCpuSample sample;
    rusage usage{};
    timespec cpu{};
    if (getrusage(RUSAGE_THREAD, &usage) != 0 || clock_gettime(CLOCK_THREAD_CPUTIME_ID, &cpu) != 0)
        return sample;
    sample.mCpuMs = double(cpu.tv_sec) * 1.0e3 + double(cpu.tv_nsec) / 1.0e6;
    sample.mSwitches = int64_t(usage.ru_nvcsw) + int64_t(usage.ru_nivcsw);
    sample.mValid = true;
    return sample;
}

/// Of inWallMs between two samples of one thread, the milliseconds it was off its core while the guest never
/// switched it out: the host took its vCPU. NaN when that can not be told: a switch in between (the wait may
/// be the guest's) or a sample that failed.
inline double HostTakenMs(const ThreadCpuSample& inBefore, const ThreadCpuSample& inAfter, double inWallMs)
{
    if (!inBefore.mValid || !inAfter.mValid || inAfter.mSwitches != inBefore.mSwitches)
        return std::numeric_limits<double>::quiet_NaN();
    // The CPU clock is read just outside the wall window, so it can run a few microseconds ahead of it
    const double offCore = inWallMs - (inAfter.mCpuMs - inBefore.mCpuMs);
    return offCore > 0.0 ? offCore : 0.0;
}

/// A stretch of work on one thread: its wall time and the host's share of it (HostTakenMs).
struct TimedWork
{
    double mWallMs = 0.0;
    double mHostTakenMs = 0.0;
};

/// Runs inWork on the calling thread, timed, with the samples right outside the wall clock's reads.
template <class Work> TimedWork TimeOnThisThread(Work&& inWork)
{
    const ThreadCpuSample before = SampleThisThreadCpu();
    const auto start = std::chrono::steady_clock::now();
    inWork();
    const double wallMs = MillisecondsSince(start);
    const ThreadCpuSample after = SampleThisThreadCpu();
    return {wallMs, HostTakenMs(before, after, wallMs)};
}

/// Time the host took from all of this machine's vCPUs since boot, in milliseconds, as the guest counts it
/// (the steal column of /proc/stat, in clock ticks); NaN where it is not counted.
inline double GuestStealMs()
{
    std::FILE* file = std::fopen("/proc/stat", "r");
    if (file == nullptr) return std::numeric_limits<double>::quiet_NaN();
    unsigned long long user = 0, nice = 0, system = 0, idle = 0, iowait = 0, irq = 0, softirq = 0, steal = 0;
    const int read = std::fscanf(file, "cpu %llu %llu %llu %llu %llu %llu %llu %llu", &user, &nice, &system,
                                 &idle, &iowait, &irq, &softirq, &steal);
    std::fclose(file);
    const long ticksPerSecond = sysconf(_SC_CLK_TCK);
    if (read != 8 || ticksPerSecond <= 0) return std::numeric_limits<double>::quiet_NaN();
    return double(steal) * 1000.0 / double(ticksPerSecond);
}

} // namespace cairn::tools
