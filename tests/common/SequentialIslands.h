#pragma once

// The islands of a contact graph from a plain sequential union-find: the reference the lock-free
// AtomicUnionFind is checked against, in the unit tests and in the concurrency stress test.

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <utility>
#include <vector>

namespace cairn::test
{

using Edge = std::pair<uint32_t, uint32_t>;

/// Island per body, numbered in order of each island's lowest body (as AtomicUnionFind::Finalize numbers
/// them).
inline std::vector<uint32_t> SequentialIslands(uint32_t inNumBodies, const std::vector<Edge>& inEdges)
{
    std::vector<uint32_t> parent(inNumBodies);
    std::iota(parent.begin(), parent.end(), 0u);
    auto find = [&](uint32_t inBody)
    {
        while (parent[inBody] != inBody)
            inBody = parent[inBody] = parent[parent[inBody]]; // Path halving
        return inBody;
    };
    for (auto [a, b] : inEdges)
    {
        const uint32_t rootA = find(a);
        const uint32_t rootB = find(b);
        parent[std::max(rootA, rootB)] = std::min(rootA, rootB); // The lower root stays: the lowest body
    }
    std::vector<uint32_t> island(inNumBodies);
    uint32_t numIslands = 0;
    for (uint32_t i = 0; i < inNumBodies; ++i)
        island[i] = find(i) == i ? numIslands++ : island[find(i)];
    return island;
}

} // namespace cairn::test
