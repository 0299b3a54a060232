// cairn-bench-stages: what a stage of StepScheduler::RunStages costs, on 1, 2, ... threads, with Google
// Benchmark. A colored island's solve is a stage per color per pass, and every stage ends with all threads
// meeting (a settled pyramid: 16 colors and 13 passes, about 200 stages a step), so the meeting's cost, paid
// some 200 times a step, decides how far that solve scales with threads.
//
// stages: 1,024 stages in a row, each of one part per thread; a stage's work (the Arg: 0, the bare meeting;
// 4,000 and 16,000 ns, about what a color of a settled pyramid's velocity pass takes on one thread) is
// arithmetic shared evenly between its parts.
// Counters: ns_per_stage, wall time / stages; overhead_ns_per_stage, ns_per_stage less the stage's work over
// the threads (what a thread would take for its share with no meeting); efficiency, that share /
// ns_per_stage.

#include "cairn/jobs/JobSystem.h"
#include "common/BenchSpin.h"
#include "common/BenchThreads.h"
#include "step/StepScheduler.h"

#include <algorithm>
#include <benchmark/benchmark.h>
#include <chrono>
#include <memory>

using namespace cairn;
using namespace cairn::physics;

namespace
{
using tools::Spin;

using Clock = std::chrono::steady_clock;
constexpr uint32_t cStages = 1024;

/// Spin's nanoseconds per iteration on this machine, measured once on one thread.
double NanosecondsPerIteration()
{
    static const double cached = []
    {
        constexpr uint32_t iterations = 20'000'000;
        const Clock::time_point start = Clock::now();
        benchmark::DoNotOptimize(Spin(iterations, 1.0f));
        return std::chrono::duration<double, std::nano>(Clock::now() - start).count() / iterations;
    }();
    return cached;
}

void BM_Stages(benchmark::State& ioState)
{
    const double workNanoseconds = double(ioState.range(0));
    const uint32_t threads = uint32_t(ioState.range(1));
    jobs::JobSystem::Settings settings;
    settings.mNumThreads = threads;
    jobs::JobSystem jobSystem(settings);
    StepScheduler scheduler;
    scheduler.BeginStep(&jobSystem);
    const uint32_t parts = scheduler.GetNumThreads();
    const uint32_t iterationsPerPart = uint32_t(workNanoseconds / NanosecondsPerIteration() / parts);
    // One result a part, each on its own cache line: the parts share nothing but the meeting
    struct alignas(64) PartResult
    {
        float mValue = 1.0f;
    };
    const std::unique_ptr<PartResult[]> results = std::make_unique<PartResult[]>(parts);
    double totalSeconds = 0.0;
    for (auto _ : ioState)
    {
        const Clock::time_point start = Clock::now();
        scheduler.RunStages(
            false, cStages, [](uint32_t, uint32_t inThreads) { return inThreads; },
            [&](uint32_t, uint32_t inPart, uint32_t)
            { results[inPart].mValue = Spin(iterationsPerPart, results[inPart].mValue); });
        const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
        ioState.SetIterationTime(seconds);
        totalSeconds += seconds;
    }
    benchmark::DoNotOptimize(results[0].mValue);
    const double nsPerStage = totalSeconds * 1.0e9 / (double(ioState.iterations()) * cStages);
    const double share = iterationsPerPart * NanosecondsPerIteration();
    ioState.counters["ns_per_stage"] = nsPerStage;
    ioState.counters["overhead_ns_per_stage"] = nsPerStage - share;
    ioState.counters["efficiency"] = share / nsPerStage;
    ioState.SetLabel(std::to_string(parts) + " threads");
}

} // namespace

// Threads: CAIRN_BENCH_THREADS (default 1,2; the 16-core run asks for 1,2,4,8,16)
BENCHMARK(BM_Stages)
    ->Name("stages")
    ->Apply(
        [](benchmark::internal::Benchmark* ioBenchmark)
        {
            for (const int64_t work : {0, 4000, 16000})
                for (const int threads : tools::BenchThreadCounts("CAIRN_BENCH_THREADS", {1, 2}))
                    ioBenchmark->Args({work, threads});
        })
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
