// cairn-bench-crowd: a crowd walking on the navmesh of a physics world, for 100, 1,000 and 10,000 agents
// (issue 32's figures).
//  The world: a 665.6 m square of ground (52 x 52 tiles of 12.8 m) with crates on it (one per 105 m^2), its
//  navmesh built by the tile pipeline once, before the runs.
//  crowd_N        N agents (radius 0.6 m) placed at random in a square round the centre sized for 42 m^2 an
//                 agent (a 204.8 m square for 1,000), so that N grows as an open world's population does:
//                 with the area. Each is given a random goal on the navmesh 10-60 m away, a new one on
//                 arrival.
//  crowd_10000_dense  10,000 agents in the 1,000's square: ten times as dense (4.2 m^2 an agent).
//  600 frames of 1/60 s on a job system of --threads threads (2 by default, 1 also with --threads 1,2).
// Prints per frame (p50, p99, max): the crowd's work on the calling thread alone (path requests and results,
// the snapshot) and in its parallel parts (corridor checks; steering beside the path queue's budget, on the
// job threads, the caller taking part); paths served and failed, the path wait in frames (p99, max),
// arrivals, replans, and agents stuck (Moving under 0.2 m/s for 5 s or more at the end). The figures are the
// crowd's own: the physics world does not step.

#include "cairn/jobs/BackgroundQueue.h"
#include "cairn/jobs/JobSystem.h"
#include "cairn/navmesh/Crowd.h"
#include "cairn/navmesh/TileScheduler.h"
#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "common/BenchOptions.h"
#include "common/FrameTimes.h"
#include "common/MachineInfo.h"
#include "common/PhysicsSystemOrExit.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <thread>
#include <vector>

using namespace cairn;
using namespace cairn::physics;
using namespace cairn::navmesh;

namespace
{
constexpr int cTilesPerSide = 26;        // Each side of the origin
constexpr float cAreaPerAgent = 41.94f;  ///< m^2: 1,000 agents in a 204.8 m square
constexpr float cAreaPerCrate = 104.86f; ///< m^2: 400 crates in a 204.8 m square
constexpr int cFrames = 600;

struct World
{
    std::unique_ptr<PhysicsSystem> mPhysics;
    std::unique_ptr<NavMeshWorld> mNavMesh;
};

/// The ground and crates, and their navmesh built by the tile pipeline (once, before the runs).
World MakeWorld()
{
    World world;
    PhysicsSettings settings;
    settings.mMaxBodies = 8192;
    world.mPhysics = tools::CreatePhysicsSystemOrExit("cairn-bench-crowd", settings);
    BodyInterface& bodies = world.mPhysics->GetBodyInterface();
    const AgentProfile profile;
    const float half = float(cTilesPerSide) * profile.mTileSize;
    BodyCreationSettings ground;
    ground.mShape = BoxShape::Create(Vec3(half, 0.5f, half)).Value();
    ground.mPosition = Vec3(0, -0.5f, 0);
    ground.mMotionType = MotionType::Static;
    ground.mObjectLayer = Layers::cStatic;
    (void)bodies.CreateAndAddBody(ground, Activation::DontActivate);
    std::mt19937 random(17);
    std::uniform_real_distribution<float> coordinate(-half + 3.0f, half - 3.0f), size(0.5f, 2.0f);
    const int crates = int(4.0f * half * half / cAreaPerCrate);
    for (int i = 0; i < crates; ++i)
    {
        BodyCreationSettings crate = ground;
        crate.mShape = BoxShape::Create(Vec3(size(random), 1.0f, size(random))).Value();
        crate.mPosition = Vec3(coordinate(random), 1.0f, coordinate(random));
        (void)bodies.CreateAndAddBody(crate, Activation::DontActivate);
    }
    const TileGrid grid(-half, -half, profile.mTileSize, -5.0f, 20.0f);
    world.mNavMesh = NavMeshWorld::Create(grid, profile).Value();
    // One tile at a time: the tiles are published in the same order every run, and Detour's tile slots,
    // polygon references and links follow that order, and the crowd's paths follow them. Built two at once,
    // a loaded machine finished them in another order and the runs served different paths
    jobs::BackgroundQueue::Settings queueSettings;
    queueSettings.mNumThreads = 1;
    jobs::BackgroundQueue queue(queueSettings);
    TileScheduler::Settings schedulerSettings;
    schedulerSettings.mMaxConcurrentJobs = 1;
    TileScheduler scheduler(*world.mPhysics, *world.mNavMesh, queue, schedulerSettings);
    (void)scheduler.AddArea(AABB(Vec3(-half + 0.1f, -5, -half + 0.1f), Vec3(half - 0.1f, 20, half - 0.1f)));
    while (!scheduler.IsIdle())
    {
        scheduler.Update();
        std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    scheduler.Update();
    return world;
}

/// A goal 10-60 m from inFrom on the navmesh, by the seed.
std::optional<Vec3> GoalNear(const NavMeshWorld& inWorld, const Vec3& inFrom, uint64_t inSeed)
{
    Result<Vec3> goal = inWorld.FindRandomPointAround(inFrom, 40.0f, inSeed);
    if (!goal || (goal.Value() - inFrom).norm() < 10.0f) return std::nullopt;
    return goal.Value();
}

/// inAgents agents in a square of inSide metres round the centre.
void Run(const World& inWorld, const char* inName, int inAgents, float inSide, uint32_t inThreads)
{
    jobs::JobSystem jobSystem(jobs::JobSystem::Settings{inThreads});
    Crowd::Settings settings;
    settings.mMaxAgents = inAgents;
    std::unique_ptr<Crowd> crowd = Crowd::Create(*inWorld.mNavMesh, settings).Value();
    const float half = std::min(0.5f * inSide, float(cTilesPerSide) * AgentProfile().mTileSize - 2.0f);
    std::mt19937 random{uint32_t(inAgents)};
    std::uniform_real_distribution<float> coordinate(-half, half);
    uint64_t seed = 1;
    while (int(crowd->GetAgents().size()) < inAgents)
    {
        Result<Crowd::AgentID> agent = crowd->AddAgent(Vec3(coordinate(random), 0, coordinate(random)));
        if (!agent) continue;
        if (std::optional<Vec3> goal =
                GoalNear(*inWorld.mNavMesh, crowd->GetPosition(agent.Value()).Value(), seed++))
            (void)crowd->SetTarget(agent.Value(), *goal);
    }
    std::vector<double> serialMs, moveMs, updateMs;
    std::vector<float> slowSeconds(size_t(inAgents), 0.0f);
    uint64_t arrivals = 0;
    for (int frame = 0; frame < cFrames; ++frame)
    {
        (void)crowd->Update(1.0f / 60.0f, &jobSystem);
        serialMs.push_back(crowd->GetStatistics().mLastSerialMs);
        moveMs.push_back(crowd->GetStatistics().mLastMoveMs);
        updateMs.push_back(crowd->GetStatistics().mLastSerialMs + crowd->GetStatistics().mLastMoveMs);
        for (Crowd::AgentID agent : crowd->GetAgents())
        {
            const AgentState state = crowd->GetState(agent).Value();
            const bool slow = state == AgentState::Moving && crowd->GetVelocity(agent).Value().norm() < 0.2f;
            slowSeconds[agent] = slow ? slowSeconds[agent] + 1.0f / 60.0f : 0.0f;
            if (state != AgentState::Arrived && state != AgentState::NoPath && state != AgentState::Idle)
                continue;
            arrivals += state == AgentState::Arrived ? 1 : 0;
            if (std::optional<Vec3> goal =
                    GoalNear(*inWorld.mNavMesh, crowd->GetPosition(agent).Value(), seed++))
                (void)crowd->SetTarget(agent, *goal);
        }
    }
    int stuck = 0;
    for (float seconds : slowSeconds)
        stuck += seconds >= 5.0f ? 1 : 0;
    const PathRequestQueue::Statistics paths = crowd->GetPathQueue().GetStatistics();
    uint64_t finished = 0, below = 0;
    for (uint64_t count : paths.mWaitHistogram)
        finished += count;
    int waitP99 = 0;
    for (; waitP99 < 65 && below + paths.mWaitHistogram[size_t(waitP99)] < (finished * 99 + 99) / 100;
         ++waitP99)
        below += paths.mWaitHistogram[size_t(waitP99)];
    const tools::TimingSummary serial = tools::Summarize(serialMs), move = tools::Summarize(moveMs),
                               update = tools::Summarize(updateMs);
    std::printf("%s (%.0f m square, %.1f m^2 an agent) threads=%u: calling thread alone p50 %.3f p99 %.3f "
                "max %.3f ms | "
                "parallel parts p50 %.3f p99 %.3f max %.3f ms | whole update p50 %.3f p99 %.3f ms | paths "
                "served %llu "
                "failed %llu, wait p99 %d%s max %llu frames | arrivals %llu, replans %llu, stuck %d\n",
                inName, 2.0 * half, 4.0 * half * half / inAgents, inThreads, serial.mP50, serial.mP99,
                serial.mMax, move.mP50, move.mP99, move.mMax, update.mP50, update.mP99,
                static_cast<unsigned long long>(paths.mServed),
                static_cast<unsigned long long>(paths.mFailed), waitP99, waitP99 == 64 ? "+" : "",
                static_cast<unsigned long long>(paths.mWaitUpdatesMax),
                static_cast<unsigned long long>(arrivals),
                static_cast<unsigned long long>(crowd->GetStatistics().mReplans), stuck);
}
} // namespace

int main(int inArgc, char** inArgv)
{
    tools::BenchOptions options;
    options.mThreads = {2};
    if (auto stop = tools::ParseBenchOptions(inArgc, inArgv, "cairn-bench-crowd: a crowd on the navmesh",
                                             {"crowd_100", "crowd_1000", "crowd_10000", "crowd_10000_dense"},
                                             options, true))
        return *stop;
    std::printf("cairn-bench-crowd: %s\n", tools::DescribeMachine().c_str());
    const World world = MakeWorld();
    std::printf("navmesh: %d tiles\n", world.mNavMesh->GetNumTiles());
    struct Case
    {
        const char* mName;
        int mAgents;
        float mSide;
    };
    const float side1000 = std::sqrt(1000.0f * cAreaPerAgent);
    const Case cases[] = {{"crowd_100", 100, std::sqrt(100.0f * cAreaPerAgent)},
                          {"crowd_1000", 1000, side1000},
                          {"crowd_10000", 10000, std::sqrt(10000.0f * cAreaPerAgent)},
                          {"crowd_10000_dense", 10000, side1000}};
    for (const Case& benchmark : cases)
    {
        if (!options.mOnly.empty() && options.mOnly != benchmark.mName) continue;
        for (uint32_t threads : options.mThreads)
            Run(world, benchmark.mName, benchmark.mAgents, benchmark.mSide, threads);
    }
    return 0;
}
