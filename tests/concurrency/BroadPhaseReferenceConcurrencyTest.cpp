// BroadPhaseSortAndSweep under concurrent use, for ThreadSanitizer and for the "old or new state, never
// neither" contract: 2 query threads, 1 mover (which also plays the physics step: Update +
// FindCollidingPairs) and 1 add/remove thread run for ~1 second. Every body i owns a fixed point p_i that all
// of its bounds contain, however it is moved, so a point query at p_i of a body that is never removed must
// always find it: 0 misses expected.

#include "cairn/physics/broadphase/BroadPhaseSortAndSweep.h"

#include <atomic>
#include <chrono>
#include <gtest/gtest.h>
#include <random>
#include <thread>

namespace cairn
{
namespace
{

constexpr uint32_t cNumPermanent = 1500; ///< Bodies 0..cNumPermanent-1: moved, never removed
constexpr uint32_t cNumChurned = 500;    ///< The rest: removed and re-added by the add/remove thread
constexpr uint32_t cNumBodies = cNumPermanent + cNumChurned;
constexpr auto cDuration = std::chrono::milliseconds(1000);

/// Random bounds that contain inPoint: up to 3 m on each side, so moves range from tiny (in place in the
/// snapshot) to large (dirty list).
AABB BoundsAround(const Vec3& inPoint, std::mt19937& ioRandom)
{
    std::uniform_real_distribution<float> extent(0.0f, 3.0f);
    const Vec3 below(extent(ioRandom), extent(ioRandom), extent(ioRandom));
    const Vec3 above(extent(ioRandom), extent(ioRandom), extent(ioRandom));
    return {inPoint - below, inPoint + above};
}

TEST(BroadPhaseReferenceConcurrencyTest, MovedBodiesAreAlwaysFound)
{
    const LayerSetup layers = LayerSetup::CreateDefault();
    BroadPhaseSortAndSweep broadPhase(cNumBodies, layers);

    // Fixed points in a 200 m square; permanent bodies alternate static/moving so both layers are exercised
    std::mt19937 setupRandom(11);
    std::uniform_real_distribution<float> coordinate(0.0f, 200.0f);
    std::vector<Vec3> points(cNumBodies);
    std::vector<BroadPhaseBody> bodies(cNumBodies);
    for (uint32_t i = 0; i < cNumBodies; ++i)
    {
        points[i] = Vec3(coordinate(setupRandom), coordinate(setupRandom) * 0.1f, coordinate(setupRandom));
        const ObjectLayer layer = i % 2 == 0 ? Layers::cMoving : Layers::cStatic;
        bodies[i] = {BodyID(i, 1), BoundsAround(points[i], setupRandom), layer};
    }
    broadPhase.AddBodiesFinalize(broadPhase.AddBodiesPrepare(bodies));
    broadPhase.Update();

    std::atomic<bool> stop{false};
    std::atomic<uint64_t> misses{0}, queries{0}, moves{0}, churns{0}, steps{0};

    // Query threads: point queries at permanent bodies' points, plus box queries and rays for load
    auto queryThread = [&](uint32_t inSeed)
    {
        std::mt19937 random(inSeed);
        std::uniform_int_distribution<uint32_t> pick(0, cNumPermanent - 1);
        uint64_t count = 0;
        while (!stop.load(std::memory_order_relaxed)) // Relaxed: only a stop flag, no data published with it
        {
            const uint32_t i = pick(random);
            const BodyID wanted(i, 1);
            bool found = false;
            broadPhase.CollidePoint(points[i], {}, [&](BodyID inID) { found |= inID == wanted; });
            if (!found) misses.fetch_add(1, std::memory_order_relaxed);
            int boxHits = 0;
            broadPhase.CollideAABox(AABB::FromCenterExtent(points[i], Vec3::Constant(4.0f)), {},
                                    [&](BodyID) { ++boxHits; });
            broadPhase.CastRay({points[i] - Vec3(10, 0, 0), Vec3(20, 0, 0)}, {},
                               [&](BodyID, float) { return 1.0f; });
            // The body itself lies within 4 m of its point
            if (boxHits == 0) misses.fetch_add(1, std::memory_order_relaxed);
            ++count;
        }
        queries.fetch_add(count, std::memory_order_relaxed);
    };

    // Mover and physics step: batches of random moves of all bodies (notifies of churned bodies that are not
    // present are ignored), an Update and a pair search every few batches
    auto moverThread = [&]
    {
        std::mt19937 random(21);
        std::uniform_int_distribution<uint32_t> pick(0, cNumBodies - 1);
        std::vector<BroadPhaseBody> batch;
        std::vector<BodyID> active;
        for (uint32_t i = 0; i < cNumBodies; i += 2)
            active.push_back(BodyID(i, 1));
        uint64_t count = 0;
        for (uint64_t round = 0; !stop.load(std::memory_order_relaxed); ++round)
        {
            batch.clear();
            for (int k = 0; k < 64; ++k)
            {
                const uint32_t i = pick(random);
                batch.push_back({BodyID(i, 1), BoundsAround(points[i], random), bodies[i].mLayer});
            }
            broadPhase.NotifyBodiesAABBChanged(batch);
            count += batch.size();
            if (round % 8 == 0)
            {
                broadPhase.Update();
                uint64_t pairs = 0;
                broadPhase.FindCollidingPairs(active, layers, [&](BodyID, BodyID) { ++pairs; });
                steps.fetch_add(1, std::memory_order_relaxed);
            }
        }
        moves.fetch_add(count, std::memory_order_relaxed);
    };

    // Add/remove: churned bodies removed in small batches and re-added (sometimes through an aborted batch
    // first)
    auto churnThread = [&]
    {
        std::mt19937 random(31);
        std::uniform_int_distribution<uint32_t> pick(cNumPermanent, cNumBodies - 1);
        std::vector<BodyID> removed;
        std::vector<BroadPhaseBody> added;
        uint64_t count = 0;
        while (!stop.load(std::memory_order_relaxed))
        {
            removed.clear();
            added.clear();
            for (int k = 0; k < 16; ++k)
            {
                const uint32_t i = pick(random);
                removed.push_back(BodyID(i, 1));
                added.push_back({BodyID(i, 1), BoundsAround(points[i], random), bodies[i].mLayer});
            }
            broadPhase.RemoveBodies(removed);
            if (count % 4 == 0) broadPhase.AddBodiesAbort(broadPhase.AddBodiesPrepare(added));
            broadPhase.AddBodiesFinalize(broadPhase.AddBodiesPrepare(added));
            ++count;
        }
        churns.fetch_add(count, std::memory_order_relaxed);
    };

    std::thread threads[] = {std::thread(queryThread, 1u), std::thread(queryThread, 2u),
                             std::thread(moverThread), std::thread(churnThread)};
    std::this_thread::sleep_for(cDuration);
    stop.store(true, std::memory_order_relaxed);
    for (std::thread& thread : threads)
        thread.join();

    EXPECT_EQ(misses.load(), 0u);
    EXPECT_GT(queries.load(), 0u);
    EXPECT_GT(moves.load(), 0u);
    EXPECT_GT(churns.load(), 0u);
    EXPECT_GT(steps.load(), 0u);
    EXPECT_TRUE(broadPhase.Validate());
    // Every churned body was re-added after its last removal
    EXPECT_EQ(broadPhase.GetBodyCount(), cNumBodies);
    std::printf("[ figure   ] queries %llu, moves %llu, churn batches %llu, steps %llu\n",
                (unsigned long long)queries.load(), (unsigned long long)moves.load(),
                (unsigned long long)churns.load(), (unsigned long long)steps.load());
}

} // namespace
} // namespace cairn
