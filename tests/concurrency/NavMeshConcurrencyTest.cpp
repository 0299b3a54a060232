// The navmesh pipeline under concurrency (short enough for ThreadSanitizer): tile jobs run on two background
// threads while the physics world steps, one thread adds and removes static and dynamic boxes, another moves
// bodies by hand, and a third asks for paths, straight walks and walls. Afterwards, with every thread stopped
// and the dirty tiles rebuilt, the navmesh must equal one built from scratch over the same world, tile for
// tile.

#include "cairn/jobs/BackgroundQueue.h"
#include "cairn/navmesh/NavMeshWorld.h"
#include "cairn/navmesh/TileScheduler.h"
#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "common/MakePhysicsSystem.h"
#include "common/StaticFloor.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <gtest/gtest.h>
#include <mutex>
#include <random>
#include <thread>
#include <vector>

namespace cairn::navmesh
{
using namespace cairn::physics;
namespace
{

constexpr float cHalfWorld = 12.8f; // 2 x 2 tiles around the origin

using cairn::test::BoxBodySettings;

struct NavMeshUnderTest
{
    std::unique_ptr<NavMeshWorld> mWorld;
    std::unique_ptr<TileScheduler> mScheduler;
};

NavMeshUnderTest MakeNavMesh(PhysicsSystem& ioPhysics, jobs::BackgroundQueue& ioQueue)
{
    const AgentProfile profile;
    const TileGrid grid(-cHalfWorld, -cHalfWorld, profile.mTileSize, -5.0f, 20.0f);
    NavMeshUnderTest navMesh;
    navMesh.mWorld = std::move(NavMeshWorld::Create(grid, profile).Value());
    TileScheduler::Settings settings;
    settings.mMaxConcurrentJobs = 2;
    navMesh.mScheduler = std::make_unique<TileScheduler>(ioPhysics, *navMesh.mWorld, ioQueue, settings);
    (void)navMesh.mScheduler
        ->AddArea(AABB(Vec3(-cHalfWorld + 0.1f, -5, -cHalfWorld + 0.1f),
                       Vec3(cHalfWorld - 0.1f, 20, cHalfWorld - 0.1f)))
        .Value();
    return navMesh;
}

bool RunUntilIdle(PhysicsSystem& ioPhysics, TileScheduler& ioScheduler)
{
    for (int frame = 0; frame < 20000; ++frame)
    {
        EXPECT_TRUE(ioPhysics.Update(1.0f / 60.0f).IsOk());
        ioScheduler.Update();
        if (ioScheduler.IsIdle())
        {
            ioScheduler.Update();
            return true;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return false;
}

TEST(NavMeshConcurrencyTest, TilesBuiltWhileTheWorldChangesEqualTilesBuiltFromScratch)
{
    const std::unique_ptr<PhysicsSystem> physics = cairn::test::MakePhysicsSystem();
    BodyInterface& bodies = physics->GetBodyInterface();
    ASSERT_TRUE(bodies.CreateAndAddBody(
        BoxBodySettings(Vec3(0, -0.5f, 0), Vec3(cHalfWorld, 0.5f, cHalfWorld), MotionType::Static),
        Activation::DontActivate));
    // Pillars: level geometry the jobs read while the step runs
    for (int i = -3; i <= 3; ++i)
        for (int k = -3; k <= 3; k += 2)
            ASSERT_TRUE(bodies.CreateAndAddBody(BoxBodySettings(Vec3(3.0f * float(i), 1.0f, 3.0f * float(k)),
                                                                Vec3(0.4f, 1.0f, 0.4f), MotionType::Static),
                                                Activation::DontActivate));

    jobs::BackgroundQueue::Settings queueSettings;
    queueSettings.mNumThreads = 2;
    jobs::BackgroundQueue queue(queueSettings);
    NavMeshUnderTest live = MakeNavMesh(*physics, queue);

    std::atomic<bool> stop{false};
    std::mutex addedMutex;
    struct Added
    {
        BodyID mID;
        bool mStatic;
    };
    std::vector<Added> added; // Guarded by addedMutex: bodies the adder thread owns

    // Adds and removes boxes: static ones (level changes) and dynamic ones that fall, land and sleep
    std::thread adder(
        [&]
        {
            std::mt19937 random(7);
            std::uniform_real_distribution<float> position(-cHalfWorld + 1.0f, cHalfWorld - 1.0f);
            while (!stop.load(std::memory_order_relaxed))
            {
                const bool isStatic = random() % 2 == 0;
                const Vec3 center(position(random), isStatic ? 0.5f : 2.0f, position(random));
                Result<BodyID> id = bodies.CreateAndAddBody(
                    BoxBodySettings(center, Vec3(0.5f, 0.5f, 0.5f),
                                    isStatic ? MotionType::Static : MotionType::Dynamic),
                    isStatic ? Activation::DontActivate : Activation::Activate);
                ASSERT_TRUE(id);
                std::lock_guard lock(addedMutex);
                added.push_back({id.Value(), isStatic});
                if (added.size() > 12)
                {
                    const size_t victim = random() % added.size();
                    ASSERT_TRUE(bodies.RemoveBody(added[victim].mID).IsOk());
                    ASSERT_TRUE(bodies.DestroyBody(added[victim].mID).IsOk());
                    added.erase(added.begin() + std::ptrdiff_t(victim));
                }
                std::this_thread::sleep_for(std::chrono::milliseconds(2));
            }
        });
    // Moves the added bodies by hand (static ones too: a level editor does)
    std::thread mover(
        [&]
        {
            std::mt19937 random(11);
            std::uniform_real_distribution<float> position(-cHalfWorld + 1.0f, cHalfWorld - 1.0f);
            while (!stop.load(std::memory_order_relaxed))
            {
                BodyID id;
                {
                    std::lock_guard lock(addedMutex);
                    if (!added.empty()) id = added[random() % added.size()].mID;
                }
                // The adder may remove it meanwhile: a stale id is an error, never a crash
                if (!id.IsInvalid())
                    (void)bodies.SetPosition(id, Vec3(position(random), 1.0f, position(random)),
                                             Activation::Activate);
                std::this_thread::sleep_for(std::chrono::milliseconds(1));
            }
        });
    // Asks for paths, straight walks and walls across the level while tiles are swapped in. Each answer is
    // whole: a walk stops between its ends with a level unit normal at a hit, a wall lies within its radius
    std::atomic<int> pathsFound{0}, walksAnswered{0}, wallsFound{0}, wrongAnswers{0};
    std::thread walker(
        [&]
        {
            std::mt19937 random(13);
            std::uniform_real_distribution<float> position(-cHalfWorld + 0.5f, cHalfWorld - 0.5f);
            while (!stop.load(std::memory_order_relaxed))
            {
                const Vec3 from(position(random), 0, position(random)),
                    to(position(random), 0, position(random));
                Result<PathResult> path = live.mWorld->FindPath(from, to);
                if (path && !path.Value().mStraightPath.empty())
                    pathsFound.fetch_add(1, std::memory_order_relaxed);
                if (Result<NavRaycastHit> walk = live.mWorld->Raycast(from, to))
                {
                    const NavRaycastHit& hit = walk.Value();
                    const bool whole = hit.mFraction >= 0.0f && hit.mFraction <= 1.0f &&
                                       IsFinite(hit.mPosition) &&
                                       (hit.mHit ? std::abs(hit.mWallNormal.norm() - 1.0f) < 1.0e-3f &&
                                                       hit.mWallNormal.y() == 0.0f
                                                 : hit.mFraction == 1.0f);
                    (whole ? walksAnswered : wrongAnswers).fetch_add(1, std::memory_order_relaxed);
                }
                if (Result<NavWall> wall = live.mWorld->FindNearestWall(from, 3.0f);
                    wall && wall.Value().mFound)
                {
                    const bool whole = wall.Value().mDistance >= 0.0f && wall.Value().mDistance <= 3.0f &&
                                       IsFinite(wall.Value().mPosition);
                    (whole ? wallsFound : wrongAnswers).fetch_add(1, std::memory_order_relaxed);
                }
            }
        });

    // The game thread: steps and the sync point
    for (int frame = 0; frame < 240; ++frame)
    {
        ASSERT_TRUE(physics->Update(1.0f / 60.0f).IsOk());
        live.mScheduler->Update();
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    stop.store(true, std::memory_order_relaxed);
    adder.join();
    mover.join();
    walker.join();
    // Dynamic boxes would keep changing the navmesh as they fall asleep, each at its own pace: removed
    for (const Added& body : added)
        if (!body.mStatic)
        {
            ASSERT_TRUE(bodies.RemoveBody(body.mID).IsOk());
        }
    ASSERT_TRUE(RunUntilIdle(*physics, *live.mScheduler));
    const TileScheduler::Stats stats = live.mScheduler->GetStats();
    EXPECT_GT(stats.mRebuilds, 0u); // The world did change under the jobs
    EXPECT_EQ(stats.mJobsFailed, 0u) << stats.mLastError;
    EXPECT_GT(pathsFound.load(), 0);
    EXPECT_GT(walksAnswered.load(), 0);
    EXPECT_GT(wallsFound.load(), 0);
    EXPECT_EQ(wrongAnswers.load(), 0);
    const auto liveTiles = live.mWorld->SnapshotTiles();
    EXPECT_EQ(liveTiles.size(), 4u);
    live.mScheduler.reset();

    NavMeshUnderTest fresh = MakeNavMesh(*physics, queue);
    ASSERT_TRUE(RunUntilIdle(*physics, *fresh.mScheduler));
    const auto freshTiles = fresh.mWorld->SnapshotTiles();
    ASSERT_EQ(freshTiles.size(), liveTiles.size());
    for (const auto& [tile, data] : freshTiles)
    {
        ASSERT_TRUE(liveTiles.contains(tile));
        EXPECT_TRUE(liveTiles.at(tile) == data) << "tile " << tile.mX << "," << tile.mZ << " differs";
    }
}

} // namespace
} // namespace cairn::navmesh
