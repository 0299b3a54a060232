// cairn-bench-stages: what the step's two ways of sharing work cost per hand-off, on 1, 2, ... threads, with
// Google Benchmark. A colored island's solve is a stage per color per pass, and every stage ends with all
// threads meeting (a settled pyramid: 16 colors and 13 passes, about 200 stages a step); the rest of the step
// is loops handed to the job system (StepScheduler::ParallelFor), a dozen or more a step. What a hand-off
// costs, paid that many times a step, decides how far a small step scales with threads.
//
// stages: 1,024 stages of StepScheduler::RunStages in a row, each of one part per thread. loops: 1,024
// StepScheduler::ParallelFor loops in a row, each of one chunk per thread, with workers awake (as within a
// step); loops_queued: the same with the job system's loop board off (a queued job per part), what the board
// saves. The work of a stage or loop (the Arg: 0, the bare hand-off; 4,000 and 16,000 ns, about what a color
// of a settled pyramid's velocity pass takes on one thread) is arithmetic shared evenly between its parts.
// Counters: ns_per_stage, wall time / stages (or loops); overhead_ns_per_stage, ns_per_stage less the work
// over the threads (what a thread would take for its share with no hand-off); efficiency, that share /
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

/// One result a part, each on its own cache line: the parts share nothing but the hand-off.
struct alignas(64) PartResult
{
    float mValue = 1.0f;
};

enum class HandOff
{
    Stages,
    Loops,
    QueuedLoops ///< Loops with JobSystem::Settings::mUseLoopBoard off: a queued job per part
};

/// Runs cStages stages or loops of inWorkNanoseconds each on inThreads threads and sets the counters.
void MeasureHandOffs(benchmark::State& ioState, HandOff inHandOff)
{
    const double workNanoseconds = double(ioState.range(0));
    const uint32_t threads = uint32_t(ioState.range(1));
    jobs::JobSystem::Settings settings;
    settings.mNumThreads = threads;
    settings.mUseLoopBoard = inHandOff != HandOff::QueuedLoops;
    jobs::JobSystem jobSystem(settings);
    StepScheduler scheduler;
    scheduler.BeginStep(&jobSystem);
    const uint32_t parts = scheduler.GetNumThreads();
    const uint32_t iterationsPerPart = uint32_t(workNanoseconds / NanosecondsPerIteration() / parts);
    const std::unique_ptr<PartResult[]> results = std::make_unique<PartResult[]>(parts);
    auto runPart = [&](uint32_t inPart)
    { results[inPart].mValue = Spin(iterationsPerPart, results[inPart].mValue); };
    // A loop's cost estimate high enough that a sleeping worker is woken too: the first loop of a run may
    // find one asleep, and the measure is the hand-off to every thread
    constexpr uint32_t cWakeAnyWorkerNanoseconds = 1'000'000;
    double totalSeconds = 0.0;
    for (auto _ : ioState)
    {
        const Clock::time_point start = Clock::now();
        if (inHandOff == HandOff::Stages)
            scheduler.RunStages(
                false, cStages, [](uint32_t, uint32_t inThreads) { return inThreads; },
                [&](uint32_t, uint32_t inPart, uint32_t) { runPart(inPart); });
        else
            for (uint32_t loop = 0; loop < cStages; ++loop)
                scheduler.ParallelFor(parts, 1, cWakeAnyWorkerNanoseconds,
                                      [&](uint32_t inBegin, uint32_t inEnd)
                                      {
                                          for (uint32_t part = inBegin; part < inEnd; ++part)
                                              runPart(part);
                                      });
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

void BM_Stages(benchmark::State& ioState)
{
    MeasureHandOffs(ioState, HandOff::Stages);
}

void BM_Loops(benchmark::State& ioState)
{
    MeasureHandOffs(ioState, HandOff::Loops);
}

void BM_QueuedLoops(benchmark::State& ioState)
{
    MeasureHandOffs(ioState, HandOff::QueuedLoops);
}

/// Work per stage or loop, then threads: CAIRN_BENCH_THREADS (default 1,2; the 16-core run asks for
/// 1,2,4,8,16).
void WorkAndThreads(benchmark::internal::Benchmark* ioBenchmark)
{
    for (const int64_t work : {0, 4000, 16000})
        for (const int threads : tools::BenchThreadCounts("CAIRN_BENCH_THREADS", {1, 2}))
            ioBenchmark->Args({work, threads});
}

} // namespace

BENCHMARK(BM_Stages)->Name("stages")->Apply(WorkAndThreads)->UseManualTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Loops)->Name("loops")->Apply(WorkAndThreads)->UseManualTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_QueuedLoops)
    ->Name("loops_queued")
    ->Apply(WorkAndThreads)
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
