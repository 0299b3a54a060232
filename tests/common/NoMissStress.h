#pragma once

// The "no missed collisions" stress of the broad phase (issue 3, done-when 2), shared by the short run in the
// concurrency suite (under ThreadSanitizer in CI) and the long run (2 million checks, label "long").
//
// Every permanent body i owns a fixed point p_i that all of its bounds contain, however it is moved. While
//  - a mover thread moves the permanent bodies continuously (NotifyBodiesAABBChanged, batches of 32),
//  - a churn thread removes and re-adds batches of other bodies (some through an aborted batch first),
//  - a step thread runs Update (incremental rebuilds; a full rebuild every 16th) and FindCollidingPairs,
// query threads pick a random permanent body i and check that a point query at p_i reports body i exactly
// once, and that a 1 m box around p_i reports it too. Each such query is a "check"; a miss is any check that
// fails. Threads own disjoint bodies, as the BroadPhase contract requires.

#include "cairn/physics/broadphase/BroadPhase.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <gtest/gtest.h>
#include <random>
#include <thread>
#include <vector>

namespace cairn::test
{
using namespace cairn::physics;

struct NoMissStressConfig
{
    uint32_t mNumPermanent = 1500;               ///< Moved, never removed
    uint32_t mNumChurned = 500;                  ///< Removed and re-added
    uint32_t mNumQueryThreads = 2;               ///< Threads doing checks
    uint64_t mTargetChecks = 100000;             ///< Stop once this many checks are done...
    std::chrono::milliseconds mMinDuration{500}; ///< ...and at least this long has passed,
    /// ...and the step thread has updated this often (a full rebuild every 16th: under ThreadSanitizer,
    /// beside other stress tests, a run that stopped on checks and time alone had done 15),
    uint64_t mMinUpdates = 17;
    std::chrono::milliseconds mMaxDuration{60000}; ///< or when this has passed
};

struct NoMissStressResult
{
    uint64_t mChecks = 0;
    uint64_t mMisses = 0;
    uint64_t mMoves = 0;
    uint64_t mChurnBatches = 0;
    uint64_t mRefusedBatches = 0; ///< AddBodiesPrepare returned nullptr (out of capacity)
    uint64_t mUpdates = 0;
    uint64_t mPairSearches = 0;
    double mSeconds = 0;
};

/// Random bounds containing inPoint: up to 3 m on each side.
inline AABB BoundsAround(const Vec3& inPoint, std::mt19937& ioRandom)
{
    std::uniform_real_distribution<float> extent(0.0f, 3.0f);
    const Vec3 below(extent(ioRandom), extent(ioRandom), extent(ioRandom));
    const Vec3 above(extent(ioRandom), extent(ioRandom), extent(ioRandom));
    return {inPoint - below, inPoint + above};
}

/// Runs the stress on an empty broad phase made for at least mNumPermanent + mNumChurned bodies.
/// inFullRebuild: called by the step thread every 16th update instead of Update (may be null).
template <class FullRebuild>
NoMissStressResult RunNoMissStress(BroadPhase& ioBroadPhase, const NoMissStressConfig& inConfig,
                                   FullRebuild&& inFullRebuild)
{
    const uint32_t numBodies = inConfig.mNumPermanent + inConfig.mNumChurned;
    const LayerSetup layers = LayerSetup::CreateDefault();

    // Fixed points in a 200 m square; bodies alternate static/moving so both trees are exercised
    std::mt19937 setupRandom(11);
    std::uniform_real_distribution<float> coordinate(0.0f, 200.0f);
    std::vector<Vec3> points(numBodies);
    std::vector<BroadPhaseBody> bodies(numBodies);
    for (uint32_t i = 0; i < numBodies; ++i)
    {
        points[i] = Vec3(coordinate(setupRandom), coordinate(setupRandom) * 0.1f, coordinate(setupRandom));
        const ObjectLayer layer = i % 2 == 0 ? Layers::cMoving : Layers::cStatic;
        bodies[i] = {BodyID(i, 1), BoundsAround(points[i], setupRandom), layer};
    }
    ioBroadPhase.AddBodiesFinalize(ioBroadPhase.AddBodiesPrepare(bodies));
    ioBroadPhase.Update();

    // Relaxed everywhere below: a stop flag and counters, no data is published through them
    std::atomic<bool> stop{false};
    std::atomic<uint64_t> checks{0}, misses{0}, moves{0}, churns{0}, updates{0}, pairSearches{0},
        refusedBatches{0};

    auto queryThread = [&](uint32_t inSeed)
    {
        std::mt19937 random(inSeed);
        std::uniform_int_distribution<uint32_t> pick(0, inConfig.mNumPermanent - 1);
        uint64_t count = 0, missed = 0;
        while (!stop.load(std::memory_order_relaxed))
        {
            const uint32_t i = pick(random);
            const BodyID wanted(i, 1);
            int found = 0;
            ioBroadPhase.CollidePoint(points[i], {}, [&](BodyID inID) { found += inID == wanted ? 1 : 0; });
            missed += found == 1 ? 0 : 1;
            found = 0;
            ioBroadPhase.CollideAABox(AABB::FromCenterExtent(points[i], Vec3::Constant(0.5f)), {},
                                      [&](BodyID inID) { found += inID == wanted ? 1 : 0; });
            missed += found == 1 ? 0 : 1;
            count += 2;
            if ((count & 1023) == 0) checks.fetch_add(1024, std::memory_order_relaxed);
        }
        checks.fetch_add(count & 1023, std::memory_order_relaxed);
        misses.fetch_add(missed, std::memory_order_relaxed);
    };

    auto moverThread = [&]
    {
        std::mt19937 random(21);
        std::uniform_int_distribution<uint32_t> pick(0, inConfig.mNumPermanent - 1);
        std::vector<BroadPhaseBody> batch;
        uint64_t count = 0;
        while (!stop.load(std::memory_order_relaxed))
        {
            batch.clear();
            for (int k = 0; k < 32; ++k)
            {
                const uint32_t i = pick(random);
                batch.push_back({BodyID(i, 1), BoundsAround(points[i], random), bodies[i].mLayer});
            }
            ioBroadPhase.NotifyBodiesAABBChanged(batch);
            count += batch.size();
        }
        moves.fetch_add(count, std::memory_order_relaxed);
    };

    auto stepThread = [&]
    {
        std::vector<BodyID> active;
        // A step's worth of active bodies (the moving half of the first 1,000)
        for (uint32_t i = 0; i < std::min(inConfig.mNumPermanent, 1000u); i += 2)
            active.push_back(BodyID(i, 1));
        uint64_t count = 0, pairs = 0;
        while (!stop.load(std::memory_order_relaxed))
        {
            if (count % 16 == 15)
                inFullRebuild();
            else
                ioBroadPhase.Update();
            ioBroadPhase.FindCollidingPairs(active, layers, [&](BodyID, BodyID) { ++pairs; });
            ++count;
            updates.fetch_add(1, std::memory_order_relaxed); // Paces the churn thread
        }
        pairSearches.fetch_add(count, std::memory_order_relaxed);
    };

    auto churnThread = [&]
    {
        std::mt19937 random(31);
        std::uniform_int_distribution<uint32_t> pick(inConfig.mNumPermanent, numBodies - 1);
        std::vector<BodyID> removed;
        std::vector<BroadPhaseBody> added;
        std::vector<bool> chosen(numBodies, false);
        uint64_t count = 0, refused = 0, lastUpdates = 0, batchesSinceUpdate = 0;
        while (!stop.load(std::memory_order_relaxed))
        {
            removed.clear();
            added.clear();
            for (int k = 0; k < 16; ++k)
            {
                const uint32_t i = pick(random);
                if (chosen[i]) continue; // Once per batch
                chosen[i] = true;
                removed.push_back(BodyID(i, 1));
                added.push_back({BodyID(i, 1), BoundsAround(points[i], random), bodies[i].mLayer});
            }
            for (const BodyID id : removed)
                chosen[id.GetIndex()] = false;
            ioBroadPhase.RemoveBodies(removed);
            if (count % 4 == 0) ioBroadPhase.AddBodiesAbort(ioBroadPhase.AddBodiesPrepare(added));
            BroadPhase::AddState state = ioBroadPhase.AddBodiesPrepare(added);
            if (state == nullptr)
                ++refused; // Out of capacity: the test fails (the pools are sized for far more than this)
            else
                ioBroadPhase.AddBodiesFinalize(state);
            ++count;
            // A streaming rate: at most 4 batches per update of the step thread, as a loader finalizes a few
            // batches per frame. Every link between two updates adds a root level that queries walk until
            // the next rebuild, so a loop linking thousands of batches per update (easily reached under
            // ThreadSanitizer, where an update takes tens of ms) would measure nothing useful
            const uint64_t updatesNow = updates.load(std::memory_order_relaxed);
            if (updatesNow != lastUpdates)
            {
                lastUpdates = updatesNow;
                batchesSinceUpdate = 0;
            }
            ++batchesSinceUpdate;
            while (batchesSinceUpdate >= 4 && !stop.load(std::memory_order_relaxed) &&
                   updates.load(std::memory_order_relaxed) == lastUpdates)
                std::this_thread::sleep_for(std::chrono::microseconds(200));
        }
        churns.fetch_add(count, std::memory_order_relaxed);
        refusedBatches.fetch_add(refused, std::memory_order_relaxed);
    };

    const auto start = std::chrono::steady_clock::now();
    std::vector<std::thread> threads;
    for (uint32_t q = 0; q < inConfig.mNumQueryThreads; ++q)
        threads.emplace_back(queryThread, 100 + q);
    threads.emplace_back(moverThread);
    threads.emplace_back(stepThread);
    threads.emplace_back(churnThread);
    for (;;)
    {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        const auto elapsed = std::chrono::steady_clock::now() - start;
        if (elapsed >= inConfig.mMaxDuration) break;
        if (elapsed >= inConfig.mMinDuration &&
            checks.load(std::memory_order_relaxed) >= inConfig.mTargetChecks &&
            updates.load(std::memory_order_relaxed) >= inConfig.mMinUpdates)
            break;
    }
    stop.store(true, std::memory_order_relaxed);
    for (std::thread& thread : threads)
        thread.join();

    NoMissStressResult result;
    result.mChecks = checks.load();
    result.mMisses = misses.load();
    result.mMoves = moves.load();
    result.mChurnBatches = churns.load();
    result.mRefusedBatches = refusedBatches.load();
    result.mUpdates = updates.load();
    result.mPairSearches = pairSearches.load();
    result.mSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

/// The checks every run of the stress makes (gtest expectations), and its figures on stdout.
inline void ExpectNoMisses(const NoMissStressResult& inResult, const NoMissStressConfig& inConfig,
                           size_t inBodyCountAfter)
{
    EXPECT_EQ(inResult.mMisses, 0u);
    EXPECT_EQ(inResult.mRefusedBatches, 0u);
    EXPECT_GE(inResult.mChecks, std::min<uint64_t>(inConfig.mTargetChecks, 1));
    EXPECT_GT(inResult.mMoves, 0u);
    EXPECT_GT(inResult.mChurnBatches, 0u);
    EXPECT_GT(inResult.mUpdates, 16u); // At least one full rebuild ran
    // Every churned body was re-added after its last removal
    EXPECT_EQ(inBodyCountAfter, inConfig.mNumPermanent + inConfig.mNumChurned);
    std::printf(
        "[ figure   ] %llu checks, %llu misses, %llu moves, %llu churn batches, %llu updates in %.1f s\n",
        (unsigned long long)inResult.mChecks, (unsigned long long)inResult.mMisses,
        (unsigned long long)inResult.mMoves, (unsigned long long)inResult.mChurnBatches,
        (unsigned long long)inResult.mUpdates, inResult.mSeconds);
}

} // namespace cairn::test
