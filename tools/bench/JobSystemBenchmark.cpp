// cairn-bench-jobs: the job system's costs and the background queue's effect on frames (Google Benchmark).
//
// jobs_overhead: schedule + run + wait of empty jobs, per job (a chain, so each waits for the one before, and
// a fan of independent jobs). jobs_parallel_for: a fixed amount of arithmetic split with ParallelFor over 1
// and 2 threads (the speed-up). jobs_frame_with_background: 200 "frames" of frame work (a ParallelFor of
// arithmetic, about 2 ms, then 1 ms idle as at 60 Hz with headroom) while a background queue runs 0.5 ms
// CPU-bound chunks without end. Modes: no background; background that stands aside for frame jobs at a lower
// OS priority (the default); background with neither (what the default protects against). Reported: frame ms
// mean and p99, and background chunks run per second (it must still progress).

#include "cairn/jobs/BackgroundQueue.h"
#include "cairn/jobs/JobSystem.h"
#include "common/BenchSpin.h"

#include <algorithm>
#include <atomic>
#include <benchmark/benchmark.h>
#include <chrono>
#include <thread>
#include <vector>

using namespace cairn::jobs;

namespace
{
using cairn::tools::Spin;

using Clock = std::chrono::steady_clock;

JobSystem::Settings Threads(int64_t inThreads)
{
    JobSystem::Settings settings;
    settings.mNumThreads = uint32_t(inThreads);
    return settings;
}

void BM_OverheadChain(benchmark::State& ioState)
{
    JobSystem jobs(Threads(ioState.range(0)));
    constexpr int cJobs = 1000;
    for (auto _ : ioState)
    {
        JobHandle previous;
        for (int i = 0; i < cJobs; ++i)
            previous = jobs.Schedule("chain", [] {}, {previous});
        jobs.Wait(previous);
    }
    ioState.counters["ns_per_job"] = benchmark::Counter(
        double(ioState.iterations()) * cJobs, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_OverheadFan(benchmark::State& ioState)
{
    JobSystem jobs(Threads(ioState.range(0)));
    constexpr int cJobs = 1000;
    std::vector<JobHandle> handles(cJobs);
    for (auto _ : ioState)
    {
        for (JobHandle& handle : handles)
            handle = jobs.Schedule("fan", [] {});
        jobs.WaitAll(handles);
    }
    ioState.counters["ns_per_job"] = benchmark::Counter(
        double(ioState.iterations()) * cJobs, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_ParallelFor(benchmark::State& ioState)
{
    JobSystem jobs(Threads(ioState.range(0)));
    constexpr uint32_t cItems = 4096;
    std::vector<float> out(cItems);
    for (auto _ : ioState)
    {
        jobs.ParallelFor(cItems, 64,
                         [&](uint32_t inBegin, uint32_t inEnd)
                         {
                             for (uint32_t i = inBegin; i < inEnd; ++i)
                                 out[i] = Spin(500, float(i));
                         });
        benchmark::DoNotOptimize(out.data());
    }
    ioState.counters["checksum"] = double(out[cItems / 2]);
}

enum BackgroundMode : int64_t
{
    cNoBackground = 0,
    cPoliteBackground = 1, ///< Stands aside for frame jobs, lower OS priority
    cRudeBackground = 2    ///< Neither
};

void BM_FrameWithBackground(benchmark::State& ioState)
{
    const BackgroundMode mode = BackgroundMode(ioState.range(0));
    JobSystem jobs(Threads(2));
    std::unique_ptr<BackgroundQueue> queue;
    std::shared_ptr<BackgroundTask> task;
    if (mode != cNoBackground)
    {
        BackgroundQueue::Settings settings;
        settings.mNumThreads = 1;
        settings.mFrameJobs = mode == cPoliteBackground ? &jobs : nullptr;
        settings.mLowerThreadPriority = mode == cPoliteBackground;
        queue = std::make_unique<BackgroundQueue>(settings);
        task = queue->Submit("endless", 0,
                             [](BackgroundTaskContext&)
                             {
                                 const auto start = Clock::now();
                                 float x = 1.0f;
                                 while (Clock::now() - start < std::chrono::microseconds(500))
                                     x = Spin(1000, x);
                                 benchmark::DoNotOptimize(x);
                                 return BackgroundStep::Continue;
                             });
    }
    constexpr int cFrames = 200;
    constexpr uint32_t cItems = 2048;
    std::vector<float> out(cItems);
    std::vector<double> frameMs;
    uint64_t chunksBefore = 0, chunksAfter = 0;
    double seconds = 0;
    for (auto _ : ioState)
    {
        frameMs.clear();
        chunksBefore = task ? task->GetChunksRun() : 0;
        const auto runStart = Clock::now();
        for (int frame = 0; frame < cFrames; ++frame)
        {
            const auto start = Clock::now();
            jobs.ParallelFor(cItems, 32,
                             [&](uint32_t inBegin, uint32_t inEnd)
                             {
                                 for (uint32_t i = inBegin; i < inEnd; ++i)
                                     out[i] = Spin(200, float(i + frame));
                             });
            frameMs.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
            std::this_thread::sleep_for(
                std::chrono::milliseconds(1)); // The rest of the frame: rendering, vsync
        }
        seconds = std::chrono::duration<double>(Clock::now() - runStart).count();
        chunksAfter = task ? task->GetChunksRun() : 0;
        ioState.SetIterationTime(seconds);
    }
    if (task) task->Cancel();
    std::sort(frameMs.begin(), frameMs.end());
    double sum = 0;
    for (double ms : frameMs)
        sum += ms;
    ioState.counters["frame_ms_mean"] = sum / double(frameMs.size());
    ioState.counters["frame_ms_p99"] = frameMs[size_t(0.99 * double(frameMs.size() - 1))];
    ioState.counters["background_chunks_per_s"] = double(chunksAfter - chunksBefore) / seconds;
    ioState.SetLabel(mode == cNoBackground       ? "no background"
                     : mode == cPoliteBackground ? "background stands aside, nice 10"
                                                 : "background ignores frames");
}

} // namespace

BENCHMARK(BM_OverheadChain)->Name("jobs_overhead_chain")->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_OverheadFan)->Name("jobs_overhead_fan")->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ParallelFor)
    ->Name("jobs_parallel_for")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_FrameWithBackground)
    ->Name("jobs_frame_with_background")
    ->Arg(cNoBackground)
    ->Arg(cPoliteBackground)
    ->Arg(cRudeBackground)
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
