// QuadTree and NodeAllocator under concurrency (short enough for ThreadSanitizer):
//  - NodeAllocator: threads allocate and free indices; no index is ever handed to two owners at once.
//  - Moves vs queries: body i always contains its fixed point p_i while mover threads grow it at random;
//    query threads check that CollidePoint(p_i) finds body i: zero misses.
//  - Links vs queries: adder threads link batches concurrently (filling root slots and replacing the root);
//    once a batch's LinkSubTree has returned, every query must find its bodies.

#include "broadphase/QuadTree.h"

#include <atomic>
#include <chrono>
#include <gtest/gtest.h>
#include <random>
#include <thread>
#include <vector>

namespace cairn
{
using namespace cairn::physics;
namespace
{

using Clock = std::chrono::steady_clock;
constexpr auto cDuration = std::chrono::milliseconds(500);

TEST(QuadTreeConcurrency, NodeAllocatorNeverHandsOutAnIndexTwice)
{
    constexpr uint32_t cCapacity = 64;
    NodeAllocator allocator(cCapacity);
    std::vector<std::atomic<int>> owner(cCapacity);
    std::atomic<int> errors = 0;
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t)
        threads.emplace_back(
            [&, t]
            {
                std::vector<uint32_t> held;
                std::mt19937 random(t);
                for (int i = 0; i < 20000; ++i)
                {
                    if (held.size() < 20 && (held.empty() || random() % 2 == 0))
                    {
                        const uint32_t index = allocator.Allocate();
                        if (index == NodeAllocator::cInvalidIndex) continue;
                        if (owner[index].exchange(t + 1) != 0) ++errors;
                        held.push_back(index);
                    }
                    else
                    {
                        const uint32_t index = held.back();
                        held.pop_back();
                        if (owner[index].exchange(0) != t + 1) ++errors;
                        allocator.Free(index);
                    }
                }
                for (uint32_t index : held)
                {
                    owner[index].store(0);
                    allocator.Free(index);
                }
            });
    for (std::thread& thread : threads)
        thread.join();
    EXPECT_EQ(errors.load(), 0);
    EXPECT_EQ(allocator.GetNumAllocated(), 0u);
    // Every index is free again exactly once
    std::vector<bool> seen(cCapacity, false);
    for (uint32_t i = 0; i < cCapacity; ++i)
    {
        const uint32_t index = allocator.Allocate();
        ASSERT_NE(index, NodeAllocator::cInvalidIndex);
        ASSERT_FALSE(seen[index]);
        seen[index] = true;
    }
    EXPECT_EQ(allocator.Allocate(), NodeAllocator::cInvalidIndex);
}

TEST(QuadTreeConcurrency, MovedBodiesAreAlwaysFoundAtTheirFixedPoint)
{
    constexpr uint32_t cNumBodies = 512;
    QuadTreeBodyTable bodies(cNumBodies);
    QuadTree tree(bodies, 0, 4096);
    std::mt19937 setup(7);
    std::uniform_real_distribution<float> coordinate(-50.0f, 50.0f);
    std::vector<Vec3> points(cNumBodies);
    std::vector<BroadPhaseBody> batch;
    for (uint32_t i = 0; i < cNumBodies; ++i)
    {
        points[i] = Vec3(coordinate(setup), coordinate(setup), coordinate(setup));
        batch.push_back({BodyID(i, 1), AABB::FromCenterExtent(points[i], Vec3::Constant(0.5f)), 0});
    }
    // Two batches so the tree has several levels and root slots
    tree.LinkSubTree(tree.BuildSubTree(std::span(batch).first(cNumBodies / 2)));
    tree.LinkSubTree(tree.BuildSubTree(std::span(batch).subspan(cNumBodies / 2)));

    std::atomic<bool> stop = false;
    std::atomic<uint64_t> misses = 0, queries = 0, moves = 0;
    std::vector<std::thread> threads;
    constexpr int cMovers = 2;
    for (int m = 0; m < cMovers; ++m)
        threads.emplace_back(
            [&, m]
            {
                // Each mover owns the bodies i % cMovers == m: same-body moves are serialised
                std::mt19937 random(100 + m);
                std::uniform_real_distribution<float> extent(0.0f, 3.0f);
                while (!stop.load(std::memory_order_relaxed))
                {
                    const uint32_t i = (random() % (cNumBodies / cMovers)) * cMovers + m;
                    const Vec3 lo(extent(random), extent(random), extent(random));
                    const Vec3 hi(extent(random), extent(random), extent(random));
                    tree.MoveBody(BodyID(i, 1), AABB(points[i] - lo, points[i] + hi));
                    moves.fetch_add(1, std::memory_order_relaxed);
                }
            });
    for (int q = 0; q < 2; ++q)
        threads.emplace_back(
            [&, q]
            {
                std::mt19937 random(200 + q);
                while (!stop.load(std::memory_order_relaxed))
                {
                    const uint32_t i = random() % cNumBodies;
                    bool found = false;
                    tree.CollidePoint(points[i], cAllObjectLayers,
                                      [&](BodyID inID) { found |= inID == BodyID(i, 1); });
                    if (!found) misses.fetch_add(1, std::memory_order_relaxed);
                    queries.fetch_add(1, std::memory_order_relaxed);
                }
            });
    const auto end = Clock::now() + cDuration;
    while (Clock::now() < end)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    stop = true;
    for (std::thread& thread : threads)
        thread.join();
    EXPECT_EQ(misses.load(), 0u);
    EXPECT_GT(queries.load(), 0u);
    EXPECT_GT(moves.load(), 0u);
}

TEST(QuadTreeConcurrency, LinkedBatchesAreFoundByLaterQueries)
{
    constexpr uint32_t cBatch = 16;
    constexpr int cAdders = 2;
    constexpr uint32_t cBatchesPerAdder = 60;
    constexpr uint32_t cNumBodies = cBatch * cBatchesPerAdder * cAdders;
    QuadTreeBodyTable bodies(cNumBodies);
    QuadTree tree(bodies, 0, 4 * cNumBodies);
    std::vector<Vec3> points(cNumBodies);
    std::mt19937 setup(9);
    std::uniform_real_distribution<float> coordinate(-50.0f, 50.0f);
    for (Vec3& p : points)
        p = Vec3(coordinate(setup), coordinate(setup), coordinate(setup));
    std::vector<std::atomic<bool>> linked(cNumBodies);

    std::atomic<int> addersDone = 0;
    std::atomic<uint64_t> misses = 0, checks = 0;
    std::vector<std::thread> threads;
    for (int a = 0; a < cAdders; ++a)
        threads.emplace_back(
            [&, a]
            {
                for (uint32_t b = 0; b < cBatchesPerAdder; ++b)
                {
                    const uint32_t first = (a * cBatchesPerAdder + b) * cBatch;
                    std::vector<BroadPhaseBody> batch;
                    for (uint32_t i = first; i < first + cBatch; ++i)
                        batch.push_back(
                            {BodyID(i, 1), AABB::FromCenterExtent(points[i], Vec3::Constant(0.5f)), 0});
                    const QuadTree::SubTree sub = tree.BuildSubTree(batch);
                    if (sub.mChild == QuadTree::cInvalidChild)
                        misses.fetch_add(1000000); // Pool exhausted: test bug
                    tree.LinkSubTree(sub);
                    for (uint32_t i = first; i < first + cBatch; ++i)
                        linked[i].store(true, std::memory_order_release);
                }
                addersDone.fetch_add(1);
            });
    threads.emplace_back(
        [&]
        {
            std::mt19937 random(300);
            while (addersDone.load() < cAdders)
            {
                const uint32_t i = random() % cNumBodies;
                if (!linked[i].load(std::memory_order_acquire)) continue;
                bool found = false;
                tree.CollidePoint(points[i], cAllObjectLayers,
                                  [&](BodyID inID) { found |= inID == BodyID(i, 1); });
                if (!found) misses.fetch_add(1, std::memory_order_relaxed);
                checks.fetch_add(1, std::memory_order_relaxed);
            }
        });
    for (std::thread& thread : threads)
        thread.join();
    EXPECT_EQ(misses.load(), 0u);
    // Afterwards everything is there exactly once
    for (uint32_t i = 0; i < cNumBodies; ++i)
    {
        int count = 0;
        tree.CollidePoint(points[i], cAllObjectLayers, [&](BodyID inID) { count += inID == BodyID(i, 1); });
        ASSERT_EQ(count, 1) << i;
    }
}

} // namespace
} // namespace cairn
