// AtomicUnionFind on one thread: the same islands as an obviously correct sequential union-find on random
// graphs (a rapidcheck property, shrunk to a minimal graph on a difference), islands numbered in order of
// their lowest body with ascending body lists, self links, empty graphs, out-of-range indices, and Reset
// reusing its storage. The concurrent interleavings are in tests/concurrency/AtomicUnionFindStressTest.cpp.

#include "islands/AtomicUnionFind.h"

#include "common/AllocationCounter.h"
#include "common/SequentialIslands.h"
#include "common/TestRandom.h"

#include <algorithm>
#include <gtest/gtest.h>
#include <numeric>
#include <rapidcheck/gtest.h>
#include <string>
#include <utility>
#include <vector>

namespace cairn
{
using namespace cairn::physics;
namespace
{

using cairn::test::Edge;

/// The first difference between the finalized islands and the reference, or "" when they agree. Also checks
/// that each island lists exactly its bodies, ascending, and that islands are ordered by their lowest body.
std::string FindMismatch(const AtomicUnionFind& inUnionFind, const std::vector<uint32_t>& inReference)
{
    const uint32_t n = uint32_t(inReference.size());
    const uint32_t numIslands = n == 0 ? 0 : *std::max_element(inReference.begin(), inReference.end()) + 1;
    if (inUnionFind.GetNumBodies() != n) return "body count";
    if (inUnionFind.GetNumIslands() != numIslands)
        return "island count " + std::to_string(inUnionFind.GetNumIslands()) +
               " != " + std::to_string(numIslands);
    for (uint32_t i = 0; i < n; ++i)
        if (inUnionFind.GetIsland(i) != inReference[i]) return "island of body " + std::to_string(i);
    uint32_t numListed = 0;
    for (uint32_t island = 0; island < numIslands; ++island)
    {
        const std::span<const uint32_t> bodies = inUnionFind.GetBodies(island);
        if (bodies.empty()) return "empty island " + std::to_string(island);
        if (island > 0 && bodies[0] <= inUnionFind.GetBodies(island - 1)[0])
            return "islands not ordered by lowest body at " + std::to_string(island);
        for (size_t k = 0; k < bodies.size(); ++k)
        {
            if (inUnionFind.GetIsland(bodies[k]) != island) return "body listed in the wrong island";
            if (k > 0 && bodies[k - 1] >= bodies[k])
                return "bodies not ascending in island " + std::to_string(island);
            if (inUnionFind.Find(bodies[k]) != bodies[0]) return "root is not the lowest body";
        }
        numListed += uint32_t(bodies.size());
    }
    return numListed == n ? "" : "listed body count";
}

std::vector<Edge> RandomEdges(uint32_t inNumBodies, uint32_t inNumEdges, uint32_t inSeed)
{
    test::TestRandom random(inSeed);
    std::vector<Edge> edges;
    for (uint32_t e = 0; e < inNumEdges; ++e)
        edges.emplace_back(random.Index(inNumBodies), random.Index(inNumBodies));
    return edges;
}

RC_GTEST_PROP(AtomicUnionFind, MatchesSequentialUnionFindOnRandomGraphs, ())
{
    const uint32_t n = *rc::gen::inRange<uint32_t>(0, 65);
    std::vector<Edge> edges;
    if (n > 0)
        edges = *rc::gen::container<std::vector<Edge>>(
            rc::gen::pair(rc::gen::inRange<uint32_t>(0, n), rc::gen::inRange<uint32_t>(0, n)));
    AtomicUnionFind unionFind;
    unionFind.Reset(n);
    for (auto [a, b] : edges)
        unionFind.Union(a, b);
    unionFind.Finalize();
    RC_ASSERT(FindMismatch(unionFind, test::SequentialIslands(n, edges)) == "");
}

TEST(AtomicUnionFind, MatchesSequentialUnionFindOnLargeRandomGraphs)
{
    // From mostly singletons to one giant island, where long paths and root changes are common
    for (uint32_t numEdges : {1000u, 5000u, 10000u, 30000u})
    {
        const std::vector<Edge> edges = RandomEdges(10000, numEdges, numEdges);
        AtomicUnionFind unionFind;
        unionFind.Reset(10000);
        for (auto [a, b] : edges)
            unionFind.Union(a, b);
        unionFind.Finalize();
        EXPECT_EQ(FindMismatch(unionFind, test::SequentialIslands(10000, edges)), "") << numEdges << " edges";
    }
}

TEST(AtomicUnionFind, NumbersIslandsByTheirLowestBodyWhateverTheUnionOrder)
{
    // Islands {0}, {1, 4}, {2, 3, 5}: ids follow the lowest bodies 0, 1, 2 in every order of the same edges
    std::vector<Edge> edges = {{5, 3}, {4, 1}, {2, 5}};
    const std::vector<uint32_t> expected = {0, 1, 2, 2, 1, 2};
    std::sort(edges.begin(), edges.end());
    do
    {
        AtomicUnionFind unionFind;
        unionFind.Reset(6);
        for (auto [a, b] : edges)
            unionFind.Union(b, a); // Reversed pairs too: the order inside a pair must not matter either
        unionFind.Finalize();
        ASSERT_EQ(FindMismatch(unionFind, expected), "");
        const std::span<const uint32_t> third = unionFind.GetBodies(2);
        EXPECT_EQ(std::vector<uint32_t>(third.begin(), third.end()), (std::vector<uint32_t>{2, 3, 5}));
    } while (std::next_permutation(edges.begin(), edges.end()));
}

TEST(AtomicUnionFind, SelfLinksChangeNothing)
{
    AtomicUnionFind unionFind;
    unionFind.Reset(8);
    for (uint32_t i = 0; i < 8; ++i)
        unionFind.Union(i, i);
    unionFind.Union(6, 2);
    unionFind.Union(6, 6);
    unionFind.Finalize();
    EXPECT_EQ(FindMismatch(unionFind, {0, 1, 2, 3, 4, 5, 2, 6}), "");
}

TEST(AtomicUnionFind, EmptyGraphs)
{
    AtomicUnionFind unionFind;
    unionFind.Reset(0);
    unionFind.Finalize();
    EXPECT_EQ(unionFind.GetNumIslands(), 0u);
    EXPECT_EQ(FindMismatch(unionFind, {}), "");

    // Bodies without contacts: one island each
    unionFind.Reset(5);
    unionFind.Finalize();
    EXPECT_EQ(FindMismatch(unionFind, {0, 1, 2, 3, 4}), "");
}

TEST(AtomicUnionFind, ResetReusesItsStorageAndForgetsThePreviousStep)
{
    AtomicUnionFind unionFind;
    unionFind.Reset(2000);
    for (uint32_t i = 1; i < 2000; ++i)
        unionFind.Union(i - 1, i);
    unionFind.Finalize();
    ASSERT_EQ(unionFind.GetNumIslands(), 1u);

    // Same or smaller sizes: no allocation in Reset, Union or Finalize, and no trace of the earlier links
    for (uint32_t n : {2000u, 700u, 0u, 1999u})
    {
        const std::vector<Edge> edges = RandomEdges(std::max(n, 1u), n / 2, n);
        test::AllocationScope allocations;
        unionFind.Reset(n);
        EXPECT_EQ(unionFind.GetNumIslands(), 0u) << "results of the previous step must not show";
        for (auto [a, b] : edges)
            unionFind.Union(a, b);
        unionFind.Finalize();
        EXPECT_EQ(allocations.GetCount(), 0u) << n << " bodies";
        EXPECT_EQ(FindMismatch(unionFind, test::SequentialIslands(n, edges)), "");
    }

    // Growing works too
    unionFind.Reset(5000);
    unionFind.Union(4999, 0);
    unionFind.Finalize();
    EXPECT_EQ(unionFind.GetNumIslands(), 4999u);
    EXPECT_EQ(unionFind.GetIsland(4999), 0u);
}

TEST(AtomicUnionFind, CountingUnionGivesTheSameIslands)
{
    const std::vector<Edge> edges = RandomEdges(5000, 8000, 7);
    AtomicUnionFind unionFind;
    unionFind.Reset(5000);
    AtomicUnionFind::Statistics statistics;
    uint64_t numUnions = 0;
    for (auto [a, b] : edges)
    {
        unionFind.Union(a, b, statistics);
        numUnions += a != b ? 1 : 0;
    }
    unionFind.Finalize();
    EXPECT_EQ(FindMismatch(unionFind, test::SequentialIslands(5000, edges)), "");
    EXPECT_EQ(statistics.mNumUnions, numUnions);
    EXPECT_GE(statistics.mNumFinds, 2 * numUnions);
    EXPECT_GT(statistics.mFindLoops, 0u);
}

TEST(AtomicUnionFind, OutOfRangeIndicesAreRejected)
{
    AtomicUnionFind unionFind;
    unionFind.Reset(4);
#ifdef NDEBUG
    // Release: ignored, nothing outside the links is touched
    unionFind.Union(0, 4);
    unionFind.Union(1000000, 1);
    EXPECT_EQ(unionFind.Find(4), 4u);
    unionFind.Union(3, 2);
    unionFind.Finalize();
    EXPECT_EQ(FindMismatch(unionFind, {0, 1, 2, 2}), "");
#else
    EXPECT_DEATH(unionFind.Union(0, 4), "out of range");
    EXPECT_DEATH(unionFind.Find(4), "out of range");
#endif
}

} // namespace
} // namespace cairn
