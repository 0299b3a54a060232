// Crowd filters under concurrency (short enough for ThreadSanitizer): a crowd steps on job threads while its
// filters' excluded areas change between Updates, more sets of them than the world has marks for (so marks
// are taken over and every polygon marked again), tiles are rebuilt and published, and another thread asks
// the same world for paths, straight walks and walls all along. After every Update, no agent whose filter
// excludes the water stands in it.

#include "cairn/jobs/BackgroundQueue.h"
#include "cairn/jobs/JobSystem.h"
#include "cairn/navmesh/Crowd.h"
#include "cairn/navmesh/NavMeshWorld.h"
#include "cairn/navmesh/TileScheduler.h"
#include "cairn/physics/PhysicsSystem.h"
#include "common/MakePhysicsSystem.h"
#include "common/StaticFloor.h"

#include <DetourNavMesh.h>
#include <atomic>
#include <chrono>
#include <gtest/gtest.h>
#include <random>
#include <thread>

namespace cairn::navmesh
{
using namespace cairn::physics;
namespace
{

constexpr float cRiverWorldHalf = 12.8f; // 2 x 2 tiles around the origin
constexpr uint8_t cWater = 5;
constexpr uint64_t cNoSwimming = uint64_t(1) << cWater;

using cairn::test::BoxBodySettings;

TEST(CrowdFilterConcurrencyTest, AgentsStayOutOfExcludedAreasWhileTheSetsChangeAndOthersQuery)
{
    const std::unique_ptr<PhysicsSystem> physics = cairn::test::MakePhysicsSystem();
    BodyInterface& bodies = physics->GetBodyInterface();
    // Two banks, a river between them at z in [-1, 1] and a bridge at x in [8, 10]
    ASSERT_TRUE(
        bodies.CreateAndAddBody(BoxBodySettings(Vec3(0, -0.5f, -6), Vec3(10, 0.5f, 5), MotionType::Static),
                                Activation::DontActivate));
    ASSERT_TRUE(bodies.CreateAndAddBody(
        BoxBodySettings(Vec3(0, -0.5f, 6), Vec3(10, 0.5f, 5), MotionType::Static), Activation::DontActivate));
    BodyCreationSettings water = BoxBodySettings(Vec3(-1, -0.5f, 0), Vec3(9, 0.5f, 1), MotionType::Static);
    water.mNavMeshArea = cWater;
    ASSERT_TRUE(bodies.CreateAndAddBody(water, Activation::DontActivate));
    ASSERT_TRUE(bodies.CreateAndAddBody(
        BoxBodySettings(Vec3(9, -0.5f, 0), Vec3(1, 0.5f, 1), MotionType::Static), Activation::DontActivate));

    const AgentProfile profile;
    const TileGrid grid(-cRiverWorldHalf, -cRiverWorldHalf, profile.mTileSize, -5.0f, 20.0f);
    const std::unique_ptr<NavMeshWorld> world = std::move(NavMeshWorld::Create(grid, profile).Value());
    jobs::BackgroundQueue::Settings queueSettings;
    queueSettings.mNumThreads = 1;
    jobs::BackgroundQueue queue(queueSettings);
    TileScheduler scheduler(*physics, *world, queue, TileScheduler::Settings{});
    (void)scheduler
        .AddArea(AABB(Vec3(-cRiverWorldHalf + 0.1f, -5, -cRiverWorldHalf + 0.1f),
                      Vec3(cRiverWorldHalf - 0.1f, 20, cRiverWorldHalf - 0.1f)))
        .Value();
    auto frame = [&]
    {
        ASSERT_TRUE(physics->Update(1.0f / 60.0f).IsOk());
        scheduler.Update();
    };
    for (int wait = 0; wait < 20000 && !(scheduler.IsIdle() && world->GetNumTiles() == 4); ++wait)
    {
        frame();
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    ASSERT_EQ(world->GetNumTiles(), 4);

    jobs::JobSystem jobSystem(jobs::JobSystem::Settings{2});
    std::unique_ptr<Crowd> crowd = Crowd::Create(*world).Value();
    std::mt19937 random(5);
    std::uniform_real_distribution<float> along(-9.0f, 9.0f), across(2.0f, 9.0f);
    std::vector<Crowd::AgentID> agents;
    for (int i = 0; i < 24; ++i)
    {
        const float side = i % 2 == 0 ? -1.0f : 1.0f;
        const Crowd::AgentID agent = crowd
                                         ->AddAgent(Vec3(along(random), 0, side * across(random)),
                                                    AgentParams{.mFilter = uint8_t(i % 3)})
                                         .Value();
        ASSERT_TRUE(crowd->SetTarget(agent, Vec3(along(random), 0, -side * across(random))).IsOk());
        agents.push_back(agent);
    }

    // Another thread's queries on the same world all along: paths, straight walks and walls, across the river
    std::atomic<bool> stop{false};
    std::atomic<int> answered{0};
    std::thread asker(
        [&]
        {
            PathFilter noSwimming;
            noSwimming.mExcludedAreas = cNoSwimming;
            std::mt19937 askRandom(9);
            std::uniform_real_distribution<float> x(-9.0f, 6.0f); // Never over the bridge
            while (!stop.load(std::memory_order_relaxed))
            {
                const Vec3 from(x(askRandom), 0, -5), to(x(askRandom), 0, 5);
                const Result<PathResult> path = world->FindPath(from, to, noSwimming);
                const Result<NavRaycastHit> walk = world->Raycast(from, to, noSwimming);
                const Result<NavWall> wall = world->FindNearestWall(from, 3.0f, noSwimming);
                // Straight across the river is never a clear walk for one that may not swim
                if (path && walk && wall)
                {
                    EXPECT_TRUE(walk.Value().mHit);
                    answered.fetch_add(1, std::memory_order_relaxed); // A count only
                }
            }
        });

    // Filters 1 and 2 change every few Updates, to sets of excluded areas (the water's always with filter 1)
    // that outnumber the world's marks: marks are let go, taken over and every polygon marked again
    BodyID rebuilt;
    int wrongInWater = 0;
    for (int update = 0; update < 240; ++update)
    {
        if (update % 8 == 0)
        {
            const uint64_t other = uint64_t(1) << (10 + update / 8 % 40);
            PathFilter first, second;
            first.mExcludedAreas = cNoSwimming | other;
            second.mExcludedAreas = update % 16 == 0 ? cNoSwimming : other;
            ASSERT_TRUE(crowd->SetFilter(1, first).IsOk());
            ASSERT_TRUE(crowd->SetFilter(2, second).IsOk());
        }
        // A crate on the south bank comes and goes: its tile is rebuilt and published with the marks
        if (update % 30 == 0)
        {
            if (!rebuilt.IsInvalid())
            {
                ASSERT_TRUE(bodies.RemoveBody(rebuilt).IsOk());
                ASSERT_TRUE(bodies.DestroyBody(rebuilt).IsOk());
                rebuilt = {};
            }
            else
                rebuilt = bodies
                              .CreateAndAddBody(BoxBodySettings(Vec3(-4, 0.5f, -4), Vec3(0.5f, 0.5f, 0.5f),
                                                                MotionType::Static),
                                                Activation::DontActivate)
                              .Value();
        }
        frame();
        ASSERT_TRUE(crowd->Update(1.0f / 60.0f, &jobSystem).IsOk());
        for (const Crowd::AgentID agent : agents)
        {
            const int filter = (int(agent) & ((1 << Crowd::cAgentSlotBits) - 1)) % 3;
            if ((crowd->GetFilter(filter).Value().mExcludedAreas & cNoSwimming) == 0) continue;
            const std::vector<uint64_t> corridor = crowd->GetCorridor(agent).Value();
            if (corridor.empty()) continue;
            world->Read(
                [&](const dtNavMesh& inNavMesh)
                {
                    const dtMeshTile* tile = nullptr;
                    const dtPoly* polygon = nullptr;
                    if (dtStatusSucceed(inNavMesh.getTileAndPolyByRef(corridor[0], &tile, &polygon)))
                        wrongInWater += polygon->getArea() == cWater ? 1 : 0;
                });
        }
    }
    stop.store(true, std::memory_order_relaxed);
    asker.join();
    EXPECT_EQ(wrongInWater, 0);
    EXPECT_GT(answered.load(), 0);
    EXPECT_GT(crowd->GetStatistics().mPathsApplied, 24u);
}

} // namespace
} // namespace cairn::navmesh
