// cairn-bench-unionfind: the lock-free union-find of the simulation islands (AtomicUnionFind) on contact
// graphs like a physics step's, on 1 and 2 threads, with Google Benchmark.
//
// Graphs: "piles", 20,000 bodies in 20 piles of 1,000 bodies; each body touches 3 bodies of its pile at most
// 16 places away in the active list (the bodies of a pile are activated together, so they sit near each other
// in index), and the contacts come in order of their first body, as the narrow phase finds them. "uniform",
// 100,000 bodies and 300,000 edges between uniformly random bodies (the stress test's graph). The threads
// take batches of 64 contacts in turn, as narrow-phase jobs would, and are released together by a barrier.
//
// Counters: ns_per_union, time of one Union on its thread (wall time x threads / unions); wall_ns_per_union,
// wall time / unions (the throughput of all threads); find_loops_per_union, links followed by the Finds of a
// Union (retries included), find_loops_per_find, the same per Find call, and retries_per_union, failed
// compare-exchanges, all three from one extra pass with the counting Union after the timed ones; finalize_us,
// the single-thread Finalize; islands, the checksum. The reference engine saw 0.9 Find loops and 0.07 us per
// Union. A Find from a body that is no longer a root follows at least one link, so the loops per Union are
// at least the share of Union ends that are not roots: 1.66 on the piles graph and 1.60 on the uniform one
// (each body has about 6 contact ends), whatever the algorithm.

#include "common/BenchThreads.h"
#include "islands/AtomicUnionFind.h"

#include <algorithm>
#include <barrier>
#include <benchmark/benchmark.h>
#include <chrono>
#include <random>
#include <string>
#include <thread>
#include <utility>
#include <vector>

using namespace cairn;
using namespace cairn::physics;

namespace
{

using Clock = std::chrono::steady_clock;
using Edge = std::pair<uint32_t, uint32_t>;

enum GraphKind : int64_t
{
    cPiles = 0,
    cUniform = 1
};

struct Graph
{
    uint32_t mNumBodies = 0;
    std::vector<Edge> mEdges;
};

Graph MakePiles()
{
    constexpr uint32_t cPileSize = 1000;
    Graph graph{20000, {}};
    std::mt19937 random(11);
    std::uniform_int_distribution<uint32_t> offset(1, 16);
    for (uint32_t body = 0; body < graph.mNumBodies; ++body)
    {
        const uint32_t pileEnd = (body / cPileSize + 1) * cPileSize;
        for (int contact = 0; contact < 3; ++contact)
        {
            const uint32_t step = offset(random);
            graph.mEdges.emplace_back(body, body + step < pileEnd ? body + step : body - step);
        }
    }
    return graph;
}

Graph MakeUniform()
{
    Graph graph{100000, {}};
    std::mt19937 random(12);
    std::uniform_int_distribution<uint32_t> body(0, graph.mNumBodies - 1);
    for (uint32_t e = 0; e < 300000; ++e)
        graph.mEdges.emplace_back(body(random), body(random));
    return graph;
}

const Graph& GetGraph(int64_t inKind)
{
    static const Graph piles = MakePiles();
    static const Graph uniform = MakeUniform();
    return inKind == cPiles ? piles : uniform;
}

/// Thread inThread of inNumThreads links its batches of the edges.
template <class UnionFunction>
void UnionShare(const std::vector<Edge>& inEdges, uint32_t inThread, uint32_t inNumThreads,
                const UnionFunction& inUnion)
{
    constexpr size_t cBatch = 64;
    for (size_t begin = inThread * cBatch; begin < inEdges.size(); begin += inNumThreads * cBatch)
        for (size_t e = begin; e < std::min(begin + cBatch, inEdges.size()); ++e)
            inUnion(inEdges[e].first, inEdges[e].second);
}

double SecondsSince(Clock::time_point inStart)
{
    return std::chrono::duration<double>(Clock::now() - inStart).count();
}

void BM_Union(benchmark::State& ioState)
{
    const Graph& graph = GetGraph(ioState.range(0));
    const uint32_t numThreads = uint32_t(ioState.range(1));
    AtomicUnionFind unionFind;
    std::vector<AtomicUnionFind::Statistics> statistics(numThreads);

    // The calling thread is thread 0; the others wait at the barrier for each pass. Plain flags: the barrier
    // orders their writes before the workers read them
    std::barrier barrier(numThreads);
    bool stop = false;
    bool counting = false;
    auto pass = [&](uint32_t inThread)
    {
        if (counting)
            UnionShare(graph.mEdges, inThread, numThreads,
                       [&](uint32_t inA, uint32_t inB) { unionFind.Union(inA, inB, statistics[inThread]); });
        else
            UnionShare(graph.mEdges, inThread, numThreads,
                       [&](uint32_t inA, uint32_t inB) { unionFind.Union(inA, inB); });
    };
    std::vector<std::thread> workers;
    for (uint32_t t = 1; t < numThreads; ++t)
        workers.emplace_back(
            [&, t]
            {
                for (;;)
                {
                    barrier.arrive_and_wait();
                    if (stop) return;
                    pass(t);
                    barrier.arrive_and_wait();
                }
            });
    auto runPass = [&]
    {
        const Clock::time_point start = Clock::now();
        barrier.arrive_and_wait();
        pass(0);
        barrier.arrive_and_wait();
        return SecondsSince(start);
    };

    double unionSeconds = 0;
    double finalizeSeconds = 0;
    for (auto _ : ioState)
    {
        unionFind.Reset(graph.mNumBodies);
        const double seconds = runPass();
        const Clock::time_point finalizeStart = Clock::now();
        unionFind.Finalize();
        finalizeSeconds += SecondsSince(finalizeStart);
        unionSeconds += seconds;
        ioState.SetIterationTime(seconds);
    }
    const uint32_t numIslands = unionFind.GetNumIslands();

    counting = true;
    unionFind.Reset(graph.mNumBodies);
    runPass();
    stop = true;
    barrier.arrive_and_wait();
    for (std::thread& worker : workers)
        worker.join();
    unionFind.Finalize();
    if (unionFind.GetNumIslands() != numIslands)
        ioState.SkipWithError("the counting pass found other islands");

    AtomicUnionFind::Statistics total;
    for (const AtomicUnionFind::Statistics& threadStatistics : statistics)
    {
        total.mNumUnions += threadStatistics.mNumUnions;
        total.mNumFinds += threadStatistics.mNumFinds;
        total.mFindLoops += threadStatistics.mFindLoops;
        total.mRetries += threadStatistics.mRetries;
    }
    const double unions = double(ioState.iterations()) * double(graph.mEdges.size());
    ioState.counters["ns_per_union"] = unionSeconds * 1e9 * numThreads / unions;
    ioState.counters["wall_ns_per_union"] = unionSeconds * 1e9 / unions;
    ioState.counters["find_loops_per_union"] = double(total.mFindLoops) / double(total.mNumUnions);
    ioState.counters["find_loops_per_find"] = double(total.mFindLoops) / double(total.mNumFinds);
    ioState.counters["retries_per_union"] = double(total.mRetries) / double(total.mNumUnions);
    ioState.counters["finalize_us"] = finalizeSeconds * 1e6 / double(ioState.iterations());
    ioState.counters["islands"] = numIslands;
    ioState.SetLabel(std::string(ioState.range(0) == cPiles ? "piles 20k bodies 60k contacts"
                                                            : "uniform 100k bodies 300k edges") +
                     ", " + std::to_string(numThreads) + " thread(s)");
}

} // namespace

// Threads: CAIRN_BENCH_THREADS (default 1,2; the 16-core run asks for 1,2,4,8,16)
BENCHMARK(BM_Union)
    ->Name("uf_union")
    ->Apply(
        [](benchmark::internal::Benchmark* ioBenchmark)
        {
            for (const int64_t graph : {cPiles, cUniform})
                for (const int threads : tools::BenchThreadCounts("CAIRN_BENCH_THREADS", {1, 2}))
                    ioBenchmark->Args({graph, threads});
        })
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
