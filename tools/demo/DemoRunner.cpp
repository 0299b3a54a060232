#include "DemoRunner.h"

#include "Agents.h"
#include "GameObjects.h"
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
#include "common/ThreadCpuClock.h"

#include <chrono>
#include <thread>
#include <unistd.h>

namespace cairn::demo
{
using namespace cairn::physics;

namespace
{
using Clock = std::chrono::steady_clock;
using tools::MillisecondsSince;

/// Runs frames of physics and the navmesh sync point (no measuring) until inDone or inMaxSeconds.
template <class Done>
bool RunUntil(PhysicsSystem& ioPhysics, jobs::JobSystem& ioJobs, navmesh::TileScheduler& ioScheduler,
              const Done& inDone, double inMaxSeconds)
{
    const Clock::time_point start = Clock::now();
    while (!inDone())
    {
        if (MillisecondsSince(start) > inMaxSeconds * 1000.0) return false;
        (void)ioPhysics.Update(1.0f / 60.0f, 1, ioJobs);
        ioScheduler.Update();
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
    worldSettings.mPlayerSpeed = inSettings.mPlayerSpeed;
    const WorldGenerator generator(worldSettings);

    const navmesh::AgentProfile profile;
    const navmesh::TileGrid grid(0.0f, 0.0f, profile.mTileSize, -50.0f, 100.0f);
    std::unique_ptr<navmesh::NavMeshWorld> navMesh =
        std::move(navmesh::NavMeshWorld::Create(grid, profile).Value());
    navmesh::TileScheduler::Settings schedulerSettings;
    schedulerSettings.mMaxConcurrentJobs = 2;
    schedulerSettings.mDropDelayFrames = 180;
    auto scheduler =
        std::make_unique<navmesh::TileScheduler>(physics, *navMesh, background, schedulerSettings);

    // Game objects before the streamer: the streamer counts the bodies it finds as not its own
    auto gameObjects =
        std::make_unique<GameObjects>(physics, generator, inSettings.mGameObjects, inSettings.mSeed);
    auto streamer = std::make_unique<TileStreamer>(physics, generator, inSettings.mCollisionRadius);

    // The loading screen: the tiles around the start, before the clock runs
    const float speed = worldSettings.mPlayerSpeed;
    const float lookAhead = generator.GetSettings().mTileSize / speed; // Seconds to cross one tile
    streamer->SetFocus(generator.GetPlayerPosition(0.0f), generator.GetPlayerPosition(lookAhead));
    if (!RunUntil(
            physics, frameJobs, *scheduler, [&] { return streamer->IsSettled(); }, 60.0))
        result.mErrors.push_back("the start area did not load within 60 s");
    auto agents = std::make_unique<Agents>(physics, generator, *streamer, *navMesh, *scheduler,
                                           inSettings.mAgents, inSettings.mSeed + 1);

    Projectiles projectiles(physics, generator, inSettings.mSeed + 2);
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
        agents->Update(dt, player);
        scheduler->Update();
        result.mFrameMs.push_back(MillisecondsSince(frameStart));

        if (IsProgressFrame(inProgress, liveProgress, frame, inSettings.mFrames))
        {
            const TileStreamer::Stats streaming = streamer->GetStats();
            std::fprintf(inProgress,
                         "%s  %-12s frame %5d/%d  physics %6.2f ms  world tiles %2zu  bodies %5u static %4u "
                         "dynamic  navmesh tiles %3d%s",
                         liveProgress ? "\r" : "", result.mModeName.c_str(), frame + 1, inSettings.mFrames,
                         result.mPhysicsMs.back(), streamer->GetLoadedTiles().size(), streaming.mStaticBodies,
                         streaming.mDynamicBodies, navMesh->GetNumTiles(), liveProgress ? "   " : "\n");
            std::fflush(inProgress);
        }
        if (inSettings.mRealTime)
            std::this_thread::sleep_until(begin + std::chrono::microseconds(int64_t(16667.0 * (frame + 1))));
    }
    if (liveProgress) std::fprintf(inProgress, "\n");
    result.mGuestStealMs = tools::GuestStealMs() - stealBefore; // NaN where the guest does not count it
    result.mFrames = inSettings.mFrames;
    projectiles.RemoveAll(); // Before the streamer counts the world's bodies

    // Invariants: every tile the agents asked for gets built; no body lost or duplicated by streaming
    if (!RunUntil(
            physics, frameJobs, *scheduler, [&] { return scheduler->IsIdle() && streamer->IsSettled(); },
            30.0))
        result.mErrors.push_back("the navmesh or the streaming did not settle within 30 s after the run");
    result.mTilesRequestedNeverBuilt = scheduler->CountNeededNeverPublished();
    result.mLostOrDuplicatedBodies = streamer->CountLostOrDuplicated();

    const navmesh::TileScheduler::Stats navStats = scheduler->GetStats();
    result.mNavTilesBuilt = navStats.mTilesPublished;
    navMesh->Read([&](const dtNavMesh& inNavMesh) { result.mNavMeshObj = navmesh::NavMeshToObj(inNavMesh); });
    result.mNavTileLatencyFrames = navStats.mFirstPublishFrames;
    if (navStats.mJobsFailed > 0) result.mErrors.push_back("navmesh: " + navStats.mLastError);
    const Agents::Stats& agentStats = agents->GetStats();
    result.mPathQueries = agentStats.mPathQueries;
    result.mPathsFound = agentStats.mPathsFound;
    result.mPathsPartial = agentStats.mPathsPartial;
    result.mPathsFailed = agentStats.mPathsFailed;
    result.mPathQueryMicrosMean =
        agentStats.mPathQueries == 0 ? 0.0 : agentStats.mPathMicros / double(agentStats.mPathQueries);
    result.mAgentDistanceMetres = agentStats.mDistance;
    result.mAgentCatchUps = agentStats.mCatchUps;
    result.mPathsThroughWalls = agentStats.mPathsThroughWalls;
    for (const std::string& error : agentStats.mErrors)
        result.mErrors.push_back("agents: " + error);
    result.mQueries = gameObjects->GetNumQueries();
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
    scheduler.reset();
    result.mLostOrDuplicatedBodies += streamer->UnloadAllAndCheck();
    streamer.reset();
    gameObjects.reset();
    return result;
}

} // namespace cairn::demo
