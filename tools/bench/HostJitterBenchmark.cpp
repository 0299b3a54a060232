// cairn-bench-host: how steady this machine is, measured without the engine. The same piece of work (a
// pointer chase through a buffer larger than the core's L2, as a tree walk misses, then dependent arithmetic)
// is done once a frame, paced at 60 Hz as the demo's physics step is, and timed on its thread. Every frame
// does exactly the same work, so what varies from frame to frame is the machine: the summary uses the demo's
// measures (p99 and max against the mean, the frames over 3x and the host's share of them, ThreadCpuClock.h)
// so that the demo's physics figures can be read against it. The chase and the arithmetic are also timed
// apart: a slow chase with steady arithmetic is the memory system slowing, both slow is the core.
//
// Threads: the main thread only.

#include "common/FrameTimes.h"
#include "common/MachineInfo.h"
#include "common/SpikeAttribution.h"
#include "common/ThreadCpuClock.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <numeric>
#include <random>
#include <thread>
#include <vector>

namespace
{

using Clock = std::chrono::steady_clock;
using namespace cairn::tools;

struct Settings
{
    int mFrames = 1200;
    uint32_t mBufferMegabytes = 8;
    uint32_t mChaseSteps = 1000;
    uint32_t mArithmeticSteps = 20000;
    bool mFast = false;
};

/// A single cycle through every slot of the buffer in a random order, so that the prefetchers can not guess
/// the chase's next address.
std::vector<uint32_t> MakeChase(uint32_t inSlots, uint64_t inSeed)
{
    std::vector<uint32_t> order(inSlots);
    std::iota(order.begin(), order.end(), 0u);
    std::shuffle(order.begin(), order.end(), std::mt19937_64(inSeed));
    std::vector<uint32_t> next(inSlots);
    for (uint32_t i = 0; i < inSlots; ++i)
        next[order[i]] = order[(i + 1) % inSlots];
    return next;
}

struct FrameSample
{
    double mWallMs = 0.0;
    double mHostTakenMs = 0.0;
    double mChaseMs = 0.0;
    double mArithmeticMs = 0.0;
};

struct Work
{
    const std::vector<uint32_t>& mChase;
    uint32_t mChaseSteps;
    uint32_t mArithmeticSteps;
    uint32_t mAt = 0;       ///< Where the chase goes on from: each frame walks new slots
    uint64_t mState = 1;    ///< The arithmetic's state, carried over so nothing can be folded away
    uint64_t mChecksum = 0; ///< Printed, so the work is observable

    FrameSample Run()
    {
        FrameSample sample;
        const TimedWork timed = TimeOnThisThread(
            [&]
            {
                const Clock::time_point start = Clock::now();
                uint32_t at = mAt;
                for (uint32_t i = 0; i < mChaseSteps; ++i)
                    at = mChase[at];
                const Clock::time_point chased = Clock::now();
                uint64_t x = mState ^ at;
                for (uint32_t i = 0; i < mArithmeticSteps; ++i)
                {
                    x ^= x << 13; // xorshift64: each step needs the one before
                    x ^= x >> 7;
                    x ^= x << 17;
                }
                sample.mChaseMs = std::chrono::duration<double, std::milli>(chased - start).count();
                sample.mArithmeticMs = MillisecondsSince(chased);
                mAt = at;
                mState = x | 1;
                mChecksum += x;
            });
        sample.mWallMs = timed.mWallMs;
        sample.mHostTakenMs = timed.mHostTakenMs;
        return sample;
    }
};

/// Prints the summary of inMs on one line, and returns it.
TimingSummary PrintLine(const char* inName, const std::vector<double>& inMs)
{
    const TimingSummary s = Summarize(inMs);
    std::printf("%-14s avg %.3f  p50 %.3f  p99 %.3f  max %.3f  p99/avg %.2fx  max/avg %.2fx\n", inName,
                s.mMean, s.mP50, s.mP99, s.mMax, s.mP99 / s.mMean, s.mMax / s.mMean);
    return s;
}

} // namespace

int main(int inArgc, char** inArgv)
{
    Settings settings;
    CLI::App app{"cairn-bench-host: the same work every 1/60 s, timed: how steady this machine is"};
    app.add_option("--frames", settings.mFrames, "Frames")->check(CLI::Range(10, 1000000));
    app.add_option("--buffer-mb", settings.mBufferMegabytes,
                   "Size of the chased buffer, MB (twice that while made)")
        ->check(CLI::Range(1, 1024));
    app.add_option("--chase", settings.mChaseSteps, "Pointer-chase steps a frame")
        ->check(CLI::Range(0, 100000000));
    app.add_option("--arithmetic", settings.mArithmeticSteps, "Arithmetic steps a frame")
        ->check(CLI::Range(0, 1000000000));
    app.add_flag("--fast", settings.mFast, "Do not wait for each 1/60 s tick (frames back to back)");
    CLI11_PARSE(app, inArgc, inArgv);

    const uint32_t slots = uint32_t(uint64_t(settings.mBufferMegabytes) * 1024 * 1024 / sizeof(uint32_t));
    const std::vector<uint32_t> chase = MakeChase(slots, 1);
    Work work{chase, settings.mChaseSteps, settings.mArithmeticSteps};
    std::printf(
        "cairn-bench-host: %d frames of the same work (a %u-step chase through %u MB, %u arithmetic steps)"
        "%s; %s\n",
        settings.mFrames, settings.mChaseSteps, settings.mBufferMegabytes, settings.mArithmeticSteps,
        settings.mFast ? ", back to back" : " at 60 Hz", DescribeMachine().c_str());

    std::vector<double> wall, hostTaken, chaseMs, arithmeticMs;
    for (std::vector<double>* series : {&wall, &hostTaken, &chaseMs, &arithmeticMs})
        series->reserve(size_t(settings.mFrames));
    const double stealBefore = GuestStealMs();
    const Clock::time_point begin = Clock::now();
    for (int frame = 0; frame < settings.mFrames; ++frame)
    {
        const FrameSample sample = work.Run();
        wall.push_back(sample.mWallMs);
        hostTaken.push_back(sample.mHostTakenMs);
        chaseMs.push_back(sample.mChaseMs);
        arithmeticMs.push_back(sample.mArithmeticMs);
        if (!settings.mFast)
            std::this_thread::sleep_until(begin + std::chrono::microseconds(int64_t(16667.0 * (frame + 1))));
    }
    const double steal = GuestStealMs() - stealBefore;

    const TimingSummary summary = PrintLine("work ms/frame", wall);
    if (settings.mChaseSteps > 0) PrintLine("  of it chase", chaseMs); // A part with no steps times the clock
    if (settings.mArithmeticSteps > 0) PrintLine("  arithmetic", arithmeticMs);
    const SpikeAttribution spikes = AttributeSpikes(wall, hostTaken, cSpikeRatio);
    std::printf(
        "spikes         frames over %gx avg %zu  of which the host's %zu  share unknown %zu  max/avg less "
        "the host's time %.2fx  guest steal ms %.0f\n",
        cSpikeRatio, spikes.mSpikes, spikes.mSpikesByHost, spikes.mSpikesUnknown,
        spikes.mMaxLessHostMs / summary.mMean, steal);
    std::printf("checksum       %llu\n", static_cast<unsigned long long>(work.mChecksum));
    return 0;
}
