#include "DemoRunner.h"

#include "Agents.h"
#include "Doors.h"
#include "GameObjects.h"
#include "Guards.h"
#include "HutLadders.h"
#include "Projectiles.h"
#include "TileStreamer.h"
#include "WorldGenerator.h"
#include "cairn/jobs/BackgroundQueue.h"
#include "cairn/jobs/JobSystem.h"
#include "cairn/navmesh/NavMeshPreview.h"
#include "cairn/navmesh/NavMeshWorld.h"
#include "cairn/navmesh/TileScheduler.h"
#include "cairn/physics/PhysicsSystem.h"
#include "common/FrameTimes.h"
#include "common/PinnedThread.h"
#include "common/ThreadCpuClock.h"
#include "common/ThreadSwitches.h"

#include <DetourNavMesh.h>
#include <chrono>
#include <map>
#include <optional>
#include <thread>
#include <unistd.h>

namespace cairn::demo
{
using namespace cairn::physics;

namespace
{
using Clock = std::chrono::steady_clock;

/// The navmesh of each agent profile (human, then large), built from the one physics world by a scheduler
/// each, on the same background queue; an invoker each at the player keeps the agents' area built.
struct NavMeshProfiles
{
    NavMeshProfiles(PhysicsSystem& ioPhysics, jobs::BackgroundQueue& ioQueue)
    {
        navmesh::AgentProfile large;
        large.mRadius = 1.5f;
        const navmesh::AgentProfile profiles[2] = {navmesh::AgentProfile(), large};
        navmesh::TileScheduler::Settings settings;
        settings.mMaxConcurrentJobs = 2;
        settings.mDropDelayFrames = 180;
        for (int p = 0; p < 2; ++p)
        {
            const navmesh::TileGrid grid(0.0f, 0.0f, profiles[p].mTileSize, -50.0f, 100.0f);
            mNavMeshes[p] = std::move(navmesh::NavMeshWorld::Create(grid, profiles[p]).Value());
            mSchedulers[p] =
                std::make_unique<navmesh::TileScheduler>(ioPhysics, *mNavMeshes[p], ioQueue, settings);
        }
    }
    ~NavMeshProfiles()
    {
        for (auto& scheduler : mSchedulers)
            scheduler.reset(); // Its jobs read the navmesh
    }
    /// The sync point: tiles handed in are published, new jobs started.
    void Update()
    {
        for (auto& scheduler : mSchedulers)
            scheduler->Update();
    }
    bool IsIdle() const { return mSchedulers[0]->IsIdle() && mSchedulers[1]->IsIdle(); }
    /// The agents' area round inPlayer is kept built (an invoker per profile, added on the first call).
    Status Focus(const Vec3& inPlayer, float inRadius)
    {
        for (int p = 0; p < 2; ++p)
        {
            if (!mInvokers[p])
            {
                Result<navmesh::TileScheduler::InvokerID> invoker =
                    mSchedulers[p]->AddInvoker(inPlayer, inRadius);
                if (!invoker) return invoker.GetError();
                mInvokers[p] = invoker.Value();
            }
            else if (Status moved = mSchedulers[p]->MoveInvoker(*mInvokers[p], inPlayer); !moved)
                return moved;
        }
        return Status::Ok();
    }

    std::unique_ptr<navmesh::NavMeshWorld> mNavMeshes[2];
    std::unique_ptr<navmesh::TileScheduler> mSchedulers[2];
    std::optional<navmesh::TileScheduler::InvokerID> mInvokers[2];
};

/// The human navmesh's polygons as outlines in the ground plane, each with its tile's build latency.
std::vector<DemoRunResult::MapPolygon> NavMap(const navmesh::NavMeshWorld& inNavMesh,
                                              const navmesh::TileScheduler::Stats& inStats)
{
    std::map<std::pair<int32_t, int32_t>, int> latency; // The last first-publication of each tile
    for (size_t i = 0; i < inStats.mFirstPublishTiles.size() && i < inStats.mFirstPublishFrames.size(); ++i)
        latency[{inStats.mFirstPublishTiles[i].mX, inStats.mFirstPublishTiles[i].mZ}] =
            int(inStats.mFirstPublishFrames[i]);
    std::vector<DemoRunResult::MapPolygon> polygons;
    inNavMesh.Read(
        [&](const dtNavMesh& inDetour)
        {
            for (int t = 0; t < inDetour.getMaxTiles(); ++t)
            {
                const dtMeshTile* tile = inDetour.getTile(t);
                if (tile == nullptr || tile->header == nullptr) continue;
                const auto found = latency.find({tile->header->x, tile->header->y});
                for (int p = 0; p < tile->header->polyCount; ++p)
                {
                    const dtPoly& poly = tile->polys[p];
                    if (poly.getType() != DT_POLYTYPE_GROUND) continue;
                    DemoRunResult::MapPolygon polygon;
                    polygon.mLatencyFrames = found == latency.end() ? -1 : found->second;
                    for (int v = 0; v < poly.vertCount; ++v)
                    {
                        const float* vertex = &tile->verts[3 * poly.verts[v]];
                        polygon.mOutline.push_back({vertex[0], vertex[2]});
                    }
                    polygons.push_back(std::move(polygon));
                }
            }
        });
    return polygons;
}

/// Runs frames of physics and the navmesh sync point (no measuring) until inDone or inMaxSeconds.
template <class Done>
bool RunUntil(PhysicsSystem& ioPhysics, jobs::JobSystem& ioJobs, NavMeshProfiles& ioNavMeshes,
              const Done& inDone, double inMaxSeconds)
{
    const Clock::time_point start = Clock::now();
    while (!inDone())
    {
        if (tools::MillisecondsSince(start) > inMaxSeconds * 1000.0) return false;
        (void)ioPhysics.Update(1.0f / 60.0f, 1, ioJobs);
        ioNavMeshes.Update();
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return true;
}

/// A terminal gets a live line rewritten every 15 frames; a log file or a pipe gets a plain line every 300
/// frames (5 s at 60 Hz), since carriage returns would leave dozens of overwritten lines in it.
bool IsProgressFrame(std::FILE* inProgress, bool inLive, int inFrame, int inFrames)
{
    if (inProgress == nullptr) return false;
    const int period = inLive ? 15 : 300;
    return inFrame % period == 0 || inFrame + 1 == inFrames;
}
} // namespace

Result<DemoRunResult> RunDemo(const DemoSettings& inSettings, BroadPhaseType inMode, std::FILE* inProgress)
{
    DemoRunResult result;
    result.mModeName = inMode == BroadPhaseType::QuadTreeGlobalMutex ? "global mutex" : "lock-free";
    result.mAgents = inSettings.mAgents;

    PhysicsSettings physicsSettings;
    physicsSettings.mMaxBodies = cDemoMaxBodies;
    physicsSettings.mBroadPhase = inMode;
    physicsSettings.mBroadPhaseCandidateMargin = inSettings.mCandidateMargin;
    // The reference engine's "before": one read-write mutex around the broad phase and one for every body,
    // which queries take to read a body, so they wait for the step (its "after": the lock-free trees, 32 body
    // mutexes, and queries on published poses that take none)
    if (inMode == BroadPhaseType::QuadTreeGlobalMutex)
    {
        physicsSettings.mNumBodyMutexes = 1;
        physicsSettings.mQueryReads = QueryReads::BodyLocks;
    }
    Result<std::unique_ptr<PhysicsSystem>> physicsWorld = PhysicsSystem::Create(physicsSettings);
    if (!physicsWorld) return physicsWorld.GetError();
    PhysicsSystem& physics = *physicsWorld.Value();
    jobs::JobSystem::Settings jobSettings;
    jobSettings.mNumThreads = inSettings.mThreads;
    jobSettings.mPinWorkers = inSettings.mPinThreads;
    jobs::JobSystem frameJobs(jobSettings);
    result.mThreads = frameJobs.GetNumThreads();
    jobs::BackgroundQueue::Settings queueSettings;
    queueSettings.mNumThreads = 1;
    queueSettings.mFrameJobs = &frameJobs;
    queueSettings.mIdleScheduling = inSettings.mRealTime; // Frames leave idle time only when paced
    jobs::BackgroundQueue background(queueSettings);

    WorldSettings worldSettings;
    worldSettings.mSeed = inSettings.mSeed;
    worldSettings.mPropsPerTile = inSettings.mPropsPerTile;
    worldSettings.mDynamicPerTile = inSettings.mDynamicPerTile;
    worldSettings.mBuildingsPerTile = inSettings.mBuildingsPerTile;
    worldSettings.mPlayerSpeed = inSettings.mPlayerSpeed;
    const WorldGenerator generator(worldSettings);

    NavMeshProfiles navMeshes(physics, background);
    const float navMeshRadius = Agents::NavMeshRadius(inSettings.mAgents);

    // Game objects before the streamer: the streamer counts the bodies it finds as not its own
    auto gameObjects = std::make_unique<GameObjects>(physics, generator, inSettings.mGameObjects,
                                                     inSettings.mSeed, inSettings.mPlayerSpeed);
    auto streamer = std::make_unique<TileStreamer>(physics, generator, inSettings.mCollisionRadius);

    // The main thread on the first core, the job workers on the others (see PinnedThread); pinned after the
    // loading and background threads are made, which would otherwise inherit its one core
    const tools::PinnedThread pinnedMain(inSettings.mPinThreads);

    // The loading screen: the tiles around the start, before the clock runs
    const float speed = worldSettings.mPlayerSpeed;
    const float lookAhead = generator.GetSettings().mTileSize / speed; // Seconds to cross one tile
    streamer->SetFocus(generator.GetPlayerPosition(0.0f), generator.GetPlayerPosition(lookAhead));
    if (!RunUntil(
            physics, frameJobs, navMeshes, [&] { return streamer->IsSettled(); }, 60.0))
        result.mErrors.push_back("the start area did not load within 60 s");
    // The huts' ladders, then the agents' navmesh round the start, of both profiles
    auto ladders = std::make_unique<HutLadders>(*streamer, generator, *navMeshes.mSchedulers[0]);
    ladders->Update();
    if (Status focused = navMeshes.Focus(generator.GetPlayerPosition(0.0f), navMeshRadius); !focused)
        result.mErrors.push_back("navmesh invoker: " + focused.GetError().mMessage);
    if (!RunUntil(
            physics, frameJobs, navMeshes, [&] { return navMeshes.IsIdle(); }, 60.0))
        result.mErrors.push_back("the start area's navmesh was not built within 60 s");
    const Agents::Profile human{navMeshes.mNavMeshes[0].get(), navMeshes.mNavMeshes[0]->GetProfile().mRadius};
    const Agents::Profile large{navMeshes.mNavMeshes[1].get(), navMeshes.mNavMeshes[1]->GetProfile().mRadius};
    auto agents = std::make_unique<Agents>(physics, generator, *streamer, human, large, inSettings.mAgents,
                                           inSettings.mSeed + 1);
    std::vector<int> navigationThreads = tools::FindThreadsNamed(jobs::JobSystem::cWorkerThreadNamePrefix);
    navigationThreads.push_back(tools::CurrentThreadId());
    agents->WatchThreads(std::move(navigationThreads));

    Projectiles projectiles(physics, generator, inSettings.mSeed + 2);
    Guards guards(physics, generator);
    Doors doors(physics, *streamer, {navMeshes.mNavMeshes[0].get(), navMeshes.mNavMeshes[1].get()},
                {navMeshes.mSchedulers[0].get(), navMeshes.mSchedulers[1].get()});
    const float dt = 1.0f / 60.0f;
    const Clock::time_point begin = Clock::now();
    const double stealBefore = tools::GuestStealMs();
    const bool liveProgress = inProgress != nullptr && isatty(fileno(inProgress)) == 1;
    for (int frame = 0; frame < inSettings.mFrames; ++frame)
    {
        const Clock::time_point frameStart = Clock::now();
        const float seconds = float(frame) * dt;
        const Vec3 player = generator.GetPlayerPosition(seconds);

        const tools::TimedWork streaming = tools::TimeOnThisThread(
            [&] { streamer->SetFocus(player, generator.GetPlayerPosition(seconds + lookAhead)); });
        result.mMainThreadStreamMs.push_back(streaming.mWallMs);
        result.mMainThreadStreamHostTakenMs.push_back(streaming.mHostTakenMs);

        if (inSettings.mThrowBalls) projectiles.Update(frame, player);
        guards.Update(frame, seconds, player, projectiles, inSettings.mThrowBalls);
        doors.Command(seconds);
        ladders->Update();

        // A frame pipeline: the game objects' queries and the step are two jobs that run at once (each waits
        // only for jobs it scheduled itself, so neither runs the other's work on its stack); the queries
        // first, so that this thread takes them and a worker the step. The objects' moves follow the step.
        // The step is timed on the thread that runs it
        struct Stepping
        {
            tools::TimedWork mTimed;
            Status mStatus;
        } stepping;
        const uint64_t waitedBefore = gameObjects->GetLockWaitNanosTotal();
        const jobs::JobHandle frameWork[] = {
            frameJobs.Schedule(
                "game-object queries", [&gameObjects, &frameJobs, &inSettings, &player, dt]
                { gameObjects->UpdateQueries(frameJobs, inSettings.mGameObjectJobs, player, dt); }),
            frameJobs.Schedule("physics step",
                               [&stepping, &physics, &frameJobs, dt, steps = inSettings.mCollisionSteps]
                               {
                                   stepping.mTimed = tools::TimeOnThisThread(
                                       [&] { stepping.mStatus = physics.Update(dt, steps, frameJobs); });
                               })};
        frameJobs.WaitAll(frameWork); // Orders the jobs' writes before the reads below
        result.mGameObjectLockWaitUs.push_back(double(gameObjects->GetLockWaitNanosTotal() - waitedBefore) /
                                               1000.0);
        if (!stepping.mStatus)
            result.mErrors.push_back("physics update: " + stepping.mStatus.GetError().mMessage);
        result.mPhysicsMs.push_back(stepping.mTimed.mWallMs);
        result.mPhysicsHostTakenMs.push_back(stepping.mTimed.mHostTakenMs);
        result.mSteps.push_back(physics.GetLastStepStatistics());
        gameObjects->ApplyMoves(frameJobs, inSettings.mGameObjectJobs);
        doors.AfterStep();
        guards.AfterStep(frame, projectiles);
        if (Status focused = navMeshes.Focus(player, navMeshRadius); !focused && result.mErrors.size() < 20)
            result.mErrors.push_back("navmesh invoker: " + focused.GetError().mMessage);
        agents->Update(dt, player, frameJobs);
        navMeshes.Update();
        doors.AfterNavMeshUpdate();
        result.mFrameMs.push_back(tools::MillisecondsSince(frameStart));

        if (IsProgressFrame(inProgress, liveProgress, frame, inSettings.mFrames))
        {
            const TileStreamer::Stats streaming = streamer->GetStats();
            std::fprintf(inProgress,
                         "%s  %-12s frame %5d/%d  physics %6.2f ms  world tiles %2zu  bodies %5u static %4u "
                         "dynamic  navmesh tiles %3d%s",
                         liveProgress ? "\r" : "", result.mModeName.c_str(), frame + 1, inSettings.mFrames,
                         result.mPhysicsMs.back(), streamer->GetLoadedTiles().size(), streaming.mStaticBodies,
                         streaming.mDynamicBodies, navMeshes.mNavMeshes[0]->GetNumTiles(),
                         liveProgress ? "   " : "\n");
            std::fflush(inProgress);
        }
        if (inSettings.mRealTime)
            std::this_thread::sleep_until(begin + std::chrono::microseconds(int64_t(16667.0 * (frame + 1))));
    }
    if (liveProgress) std::fprintf(inProgress, "\n");
    result.mGuestStealMs = tools::GuestStealMs() - stealBefore; // NaN where the guest does not count it
    result.mFrames = inSettings.mFrames;
    result.mGuardStats = guards.GetStats();
    for (const std::string& error : result.mGuardStats.mErrors)
        result.mErrors.push_back("guards: " + error);
    guards.RemoveAll(); // Before the streamer counts the world's bodies
    projectiles.RemoveAll();

    // Invariants: every tile the agents asked for gets built; no body lost or duplicated by streaming
    if (!RunUntil(
            physics, frameJobs, navMeshes, [&] { return navMeshes.IsIdle() && streamer->IsSettled(); }, 30.0))
        result.mErrors.push_back("the navmesh or the streaming did not settle within 30 s after the run");
    for (const auto& scheduler : navMeshes.mSchedulers)
    {
        result.mTilesRequestedNeverBuilt += scheduler->CountNeededNeverPublished();
        const navmesh::TileScheduler::Stats navStats = scheduler->GetStats();
        result.mNavTilesBuilt += navStats.mTilesPublished;
        result.mNavTileLatencyFrames.insert(result.mNavTileLatencyFrames.end(),
                                            navStats.mFirstPublishFrames.begin(),
                                            navStats.mFirstPublishFrames.end());
        if (navStats.mJobsFailed > 0) result.mErrors.push_back("navmesh: " + navStats.mLastError);
    }
    result.mLostOrDuplicatedBodies = streamer->CountLostOrDuplicated();
    navMeshes.mNavMeshes[0]->Read([&](const dtNavMesh& inNavMesh)
                                  { result.mNavMeshObj = navmesh::NavMeshToObj(inNavMesh); });
    result.mNavMap = NavMap(*navMeshes.mNavMeshes[0], navMeshes.mSchedulers[0]->GetStats());
    doors.AfterNavMeshUpdate(); // The rebuilds the settling above published
    result.mDoorStats = doors.GetStats();
    for (const std::string& error : result.mDoorStats.mErrors)
        result.mErrors.push_back("doors: " + error);
    agents->FinishStats();
    result.mAgentStats = agents->GetStats();
    result.mLaddersMost = ladders->GetMostLadders();
    const HutLadders::States ladderStates = ladders->CountStates();
    result.mLaddersJoined = ladderStates.mJoined;
    result.mLaddersWaiting = ladderStates.mWaiting;
    result.mLaddersDead = ladderStates.mDead;
    if (result.mLaddersDead > 0)
        result.mErrors.push_back("ladders: " + std::to_string(result.mLaddersDead) +
                                 " with a foot that joins no navmesh, or left out of their tile");
    if (ladders->GetNumRefused() > 0)
        result.mErrors.push_back("ladders: " + std::to_string(ladders->GetNumRefused()) + " refused");
    for (const std::string& error : result.mAgentStats.mErrors)
        result.mErrors.push_back("agents: " + error);
    if (result.mAgentStats.mInsideStatic > 0)
        result.mErrors.push_back("agents: " + std::to_string(result.mAgentStats.mInsideStatic) +
                                 " checks found an agent inside a static body");
    if (result.mAgentStats.mOffNavMeshOverOneSecond > 0)
        result.mErrors.push_back("agents: " + std::to_string(result.mAgentStats.mOffNavMeshOverOneSecond) +
                                 " times an agent was off the navmesh for over 1 s");
    if (result.mAgentStats.mNonClimberLadderFrames > 0)
        result.mErrors.push_back("agents: " + std::to_string(result.mAgentStats.mNonClimberLadderFrames) +
                                 " frames an agent that may not climb was on a ladder");
    if (result.mAgentStats.mCorridorsThroughGone > 0)
        result.mErrors.push_back("agents: " + std::to_string(result.mAgentStats.mCorridorsThroughGone) +
                                 " corridors went through a polygon that was gone");
    result.mQueries = gameObjects->GetNumQueries();
    result.mCharacterWalks = gameObjects->GetNumWalks();
    result.mCharacterPutBack = gameObjects->GetNumPutBack();
    if (const uint64_t queryErrors = gameObjects->GetNumQueryErrors(); queryErrors > 0)
        result.mErrors.push_back("game objects: " + std::to_string(queryErrors) + " world queries failed");
    result.mQueryMicrosMean = gameObjects->GetQueryMicrosMean();
    result.mQueryMicrosPerThread = gameObjects->GetQueryMicrosPerThread();
    result.mBroadPhaseLockWaitMicrosPerThreadFrame =
        gameObjects->GetLockWaitMicrosPerThreadFrame(LockKind::BroadPhase);
    result.mBodyLockWaitMicrosPerThreadFrame = gameObjects->GetLockWaitMicrosPerThreadFrame(LockKind::Body);
    result.mMoveLockWaitMicrosPerThreadFrame = gameObjects->GetMoveLockWaitMicrosPerThreadFrame();
    const TileStreamer::Stats streaming = streamer->GetStats();
    result.mStreamInMs = streaming.mStreamInMs;
    result.mStreamLinkMs = streaming.mStreamLinkMs;
    result.mStreamOutMs = streaming.mStreamOutMs;
    result.mTilesStreamedIn = streaming.mTilesIn;
    result.mTilesStreamedOut = streaming.mTilesOut;
    result.mStaticBodiesPeak = streaming.mStaticPeak;
    result.mDynamicBodiesPeak = streaming.mDynamicPeak;
    for (const std::string& error : streaming.mErrors)
        result.mErrors.push_back("streaming: " + error);

    // Tear down in dependency order: agents (invokers), the scheduler (its jobs read the world), then the
    // streamer, whose unload checks every body it made once more
    agents.reset();
    ladders.reset(); // Withdrawn from the human scheduler
    for (auto& scheduler : navMeshes.mSchedulers)
        scheduler.reset();
    result.mLostOrDuplicatedBodies += streamer->UnloadAllAndCheck();
    streamer.reset();
    gameObjects.reset();
    return result;
}

} // namespace cairn::demo
