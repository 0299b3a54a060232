// AtomicUnionFind under concurrency (short enough for ThreadSanitizer): 2, 4 and 8 threads, released
// together, link random contact graphs of 100,000 bodies and 300,000 edges (uniform random edges; chains
// linked in ascending, descending and shuffled order; a few giant clusters among many singletons and small
// groups; many groups of 8 bodies whose edges sit together, so that the threads collide on the same roots),
// each thread taking every n-th edge. After the join, the islands must equal those of a sequential
// union-find, body for body (ids are canonical, so they do not depend on timing). Another run calls Find
// while Unions run: a Find returns a body of the same final island with an index no higher than its input.
// Checked against broken Unions: with no retry after a failed compare-exchange, or a plain store instead of
// it, the groups and clusters runs lost links in each of 12 release runs tried.

#include "common/SequentialIslands.h"
#include "islands/AtomicUnionFind.h"

#include <algorithm>
#include <atomic>
#include <gtest/gtest.h>
#include <latch>
#include <numeric>
#include <random>
#include <thread>
#include <utility>
#include <vector>

namespace cairn
{
using namespace cairn::physics;
namespace
{

using cairn::test::Edge;

constexpr uint32_t cNumBodies = 100000;
constexpr uint32_t cNumEdges = 300000;

// Collisions between the threads' compare-exchanges are rare events: repeat each run, except under
// ThreadSanitizer, which is slow and checks the accesses of one run anyway
#if defined(__SANITIZE_THREAD__)
constexpr int cRounds = 1;
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
constexpr int cRounds = 1;
#else
constexpr int cRounds = 5;
#endif
#else
constexpr int cRounds = 5;
#endif

struct Graph
{
    const char* mName;
    std::vector<Edge> mEdges;
};

Graph UniformGraph()
{
    std::mt19937 random(1);
    std::uniform_int_distribution<uint32_t> body(0, cNumBodies - 1);
    Graph graph{"uniform", {}};
    for (uint32_t e = 0; e < cNumEdges; ++e)
        graph.mEdges.emplace_back(body(random), body(random));
    return graph;
}

/// Chains of 1 to 4000 bodies, consecutive in index in the first half of the bodies and scattered in the
/// second. Each chain is linked in ascending, descending or shuffled order, then all its links come twice
/// more (pairs swapped, and shuffled among all chains), with self links filling up to cNumEdges.
Graph ChainGraph()
{
    std::mt19937 random(2);
    std::vector<uint32_t> order(cNumBodies);
    std::iota(order.begin(), order.end(), 0u);
    std::shuffle(order.begin() + cNumBodies / 2, order.end(), random);
    Graph graph{"chains", {}};
    std::uniform_int_distribution<uint32_t> length(1, 4000);
    for (uint32_t start = 0; start < cNumBodies;)
    {
        const uint32_t end = std::min(cNumBodies, start + length(random));
        std::vector<Edge> chain;
        for (uint32_t i = start + 1; i < end; ++i)
            chain.emplace_back(order[i - 1], order[i]);
        switch (random() % 3)
        {
        case 0:
            break;
        case 1:
            std::reverse(chain.begin(), chain.end());
            break;
        default:
            std::shuffle(chain.begin(), chain.end(), random);
        }
        graph.mEdges.insert(graph.mEdges.end(), chain.begin(), chain.end());
        start = end;
    }
    const size_t numChainEdges = graph.mEdges.size();
    for (size_t e = numChainEdges; e-- > 0;)
        graph.mEdges.emplace_back(graph.mEdges[e].second, graph.mEdges[e].first);
    std::vector<Edge> shuffled(graph.mEdges.begin(), graph.mEdges.begin() + numChainEdges);
    std::shuffle(shuffled.begin(), shuffled.end(), random);
    graph.mEdges.insert(graph.mEdges.end(), shuffled.begin(), shuffled.end());
    while (graph.mEdges.size() < cNumEdges)
    {
        const uint32_t body = random() % cNumBodies;
        graph.mEdges.emplace_back(body, body);
    }
    return graph;
}

/// Four clusters of 10,000 scattered bodies with 70,000 random edges each, 30,000 bodies in groups of three
/// and 30,000 singletons, all edges shuffled.
Graph ClusterGraph()
{
    std::mt19937 random(3);
    std::vector<uint32_t> bodies(cNumBodies);
    std::iota(bodies.begin(), bodies.end(), 0u);
    std::shuffle(bodies.begin(), bodies.end(), random);
    Graph graph{"clusters", {}};
    constexpr uint32_t cClusterSize = 10000;
    std::uniform_int_distribution<uint32_t> member(0, cClusterSize - 1);
    for (uint32_t e = 0; e < 280000; ++e)
    {
        const uint32_t* cluster = bodies.data() + (e % 4) * cClusterSize;
        graph.mEdges.emplace_back(cluster[member(random)], cluster[member(random)]);
    }
    for (uint32_t i = 4 * cClusterSize; i < 4 * cClusterSize + 30000; i += 3)
    {
        graph.mEdges.emplace_back(bodies[i], bodies[i + 1]);
        graph.mEdges.emplace_back(bodies[i + 2], bodies[i + 1]);
    }
    std::shuffle(graph.mEdges.begin(), graph.mEdges.end(), random);
    return graph;
}

/// Groups of 8 scattered bodies with 24 random edges each, a group's edges next to each other: the threads,
/// taking every n-th edge, link inside the same few sets at once, so their compare-exchanges collide often.
Graph GroupGraph()
{
    std::mt19937 random(4);
    std::vector<uint32_t> bodies(cNumBodies);
    std::iota(bodies.begin(), bodies.end(), 0u);
    std::shuffle(bodies.begin(), bodies.end(), random);
    Graph graph{"groups", {}};
    constexpr uint32_t cGroupSize = 8;
    for (uint32_t group = 0; group < cNumBodies; group += cGroupSize)
        for (uint32_t e = 0; e < cNumEdges / (cNumBodies / cGroupSize); ++e)
            graph.mEdges.emplace_back(bodies[group + random() % cGroupSize],
                                      bodies[group + random() % cGroupSize]);
    return graph;
}

const std::vector<Graph>& Graphs()
{
    static const std::vector<Graph> graphs = {UniformGraph(), ChainGraph(), ClusterGraph(), GroupGraph()};
    return graphs;
}

/// Runs inWork(thread) on inNumThreads threads released together, and joins them.
template <class Work> void RunTogether(uint32_t inNumThreads, const Work& inWork)
{
    std::latch start(inNumThreads);
    std::vector<std::thread> threads;
    for (uint32_t t = 0; t < inNumThreads; ++t)
        threads.emplace_back(
            [&, t]
            {
                start.arrive_and_wait();
                inWork(t);
            });
    for (std::thread& thread : threads)
        thread.join();
}

/// Thread inThread of inNumThreads links every inNumThreads-th edge, as contacts would arrive.
void UnionShare(AtomicUnionFind& ioUnionFind, const std::vector<Edge>& inEdges, uint32_t inThread,
                uint32_t inNumThreads)
{
    for (size_t e = inThread; e < inEdges.size(); e += inNumThreads)
        ioUnionFind.Union(inEdges[e].first, inEdges[e].second);
}

TEST(AtomicUnionFindStress, ConcurrentUnionsGiveTheSequentialIslands)
{
    AtomicUnionFind unionFind;
    for (const Graph& graph : Graphs())
    {
        ASSERT_GE(graph.mEdges.size(), cNumEdges);
        const std::vector<uint32_t> reference = test::SequentialIslands(cNumBodies, graph.mEdges);
        const uint32_t numIslands = *std::max_element(reference.begin(), reference.end()) + 1;
        for (uint32_t numThreads : {2u, 4u, 8u})
            for (int round = 0; round < cRounds; ++round)
            {
                unionFind.Reset(cNumBodies);
                RunTogether(numThreads, [&](uint32_t inThread)
                            { UnionShare(unionFind, graph.mEdges, inThread, numThreads); });
                unionFind.Finalize();
                uint32_t numWrong = 0;
                for (uint32_t i = 0; i < cNumBodies; ++i)
                    numWrong += unionFind.GetIsland(i) != reference[i] ? 1 : 0;
                EXPECT_EQ(unionFind.GetNumIslands(), numIslands)
                    << graph.mName << ", " << numThreads << " threads, round " << round;
                EXPECT_EQ(numWrong, 0u) << "bodies in the wrong island: " << graph.mName << ", " << numThreads
                                        << " threads, round " << round;
            }
    }
}

TEST(AtomicUnionFindStress, FindDuringUnionsStaysInTheSetAndNeverGoesUp)
{
    const Graph& graph = Graphs()[0];
    constexpr size_t cMaxSamples = 50000;
    AtomicUnionFind unionFind;
    for (uint32_t numThreads : {2u, 4u, 8u})
    {
        // Half the threads link, the other half ask for roots until the linking is over
        const uint32_t numUnionThreads = numThreads / 2;
        std::atomic<uint32_t> numLinking{numUnionThreads};
        std::vector<std::vector<Edge>> samples(numThreads - numUnionThreads); // (body, root found)
        std::atomic<uint32_t> numAbove{0};
        unionFind.Reset(cNumBodies);
        RunTogether(numThreads,
                    [&](uint32_t inThread)
                    {
                        if (inThread < numUnionThreads)
                        {
                            UnionShare(unionFind, graph.mEdges, inThread, numUnionThreads);
                            // Release: pairs with the finders' acquire, only to end their loop
                            numLinking.fetch_sub(1, std::memory_order_release);
                            return;
                        }
                        std::vector<Edge>& mySamples = samples[inThread - numUnionThreads];
                        mySamples.reserve(cMaxSamples);
                        std::mt19937 random(inThread);
                        // Acquire: see above; a late stop only means a few more Finds
                        while (numLinking.load(std::memory_order_acquire) > 0 || mySamples.empty())
                        {
                            const uint32_t body = random() % cNumBodies;
                            const uint32_t root = unionFind.Find(body);
                            if (root > body)
                                numAbove.fetch_add(1, std::memory_order_relaxed); // Read after join
                            if (mySamples.size() < cMaxSamples) mySamples.emplace_back(body, root);
                        }
                    });
        unionFind.Finalize();
        EXPECT_EQ(numAbove.load(std::memory_order_relaxed), 0u) << numThreads << " threads";
        const std::vector<uint32_t> reference = test::SequentialIslands(cNumBodies, graph.mEdges);
        for (uint32_t i = 0; i < cNumBodies; ++i)
            ASSERT_EQ(unionFind.GetIsland(i), reference[i])
                << "body " << i << ", " << numThreads << " threads";
        uint32_t numOutside = 0;
        for (const std::vector<Edge>& threadSamples : samples)
            for (auto [body, root] : threadSamples)
                numOutside +=
                    root >= cNumBodies || unionFind.GetIsland(root) != unionFind.GetIsland(body) ? 1 : 0;
        EXPECT_EQ(numOutside, 0u) << numThreads << " threads";
    }
}

} // namespace
} // namespace cairn
