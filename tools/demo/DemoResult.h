#pragma once

// What one run of the demo measured: plain data, filled by DemoRunner on the main thread after the run, read
// by DemoReport to print the summary and write the Markdown report.

#include "cairn/physics/StepStatistics.h"
#include "cairn/physics/math/Math.h"
#include "common/SpikeAttribution.h"

#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace cairn::demo
{
using namespace cairn::physics;

/// What the demo's agents did and cost (Agents' figures, for the report).
struct AgentStats
{
    /// Per frame: the navigation work on the main thread (the crowds' path budgets, results and
    /// corridor checks, goals set, the demo's bookkeeping), ms
    std::vector<double> mMainThreadMs;
    /// Per frame: the navigation work spread over the job threads (goal picking and the crowds'
    /// steering), wall time with the main thread taking part, ms
    std::vector<double> mJobThreadsMs;
    std::vector<double> mGoalPickingMs; ///< Per frame: of mJobThreadsMs, the goals' picking
    /// Per frame: the times another task (a kernel thread, another process) took the core of a thread doing
    /// the navigation work while it could still run; -1 where that could not be read
    std::vector<int64_t> mOtherTaskSwitches;
    uint64_t mGoalsSet = 0;
    uint64_t mGoalsNotFound = 0; ///< No navmesh point to head for (the navmesh not built there yet)
    uint64_t mArrivals = 0;
    uint64_t mGoalTimeouts = 0;   ///< Wander goals not reached in 15 s, given up for another
    uint64_t mPathsRequested = 0; ///< Through the crowds' queues, replans included
    uint64_t mPathsServed = 0;    ///< Found (whole or partial)
    uint64_t mPathsFailed = 0;
    uint64_t mReplans = 0;     ///< Corridors cut by a tile change, asked again
    uint64_t mLinksTaken = 0;  ///< Off-mesh links (the huts' ladders) agents started to climb
    uint64_t mNonClimbers = 0; ///< Agents that may not climb (the human crowd's no-climbing filter)
    /// Agent-frames of those on a ladder (an invariant: none)
    uint64_t mNonClimberLadderFrames = 0;
    uint64_t mPathWaitP99Frames = 0;
    uint64_t mPathWaitMaxFrames = 0;
    uint64_t mCatchUps = 0;    ///< Put back by the player after falling 50 m behind
    uint64_t mStuck = 0;       ///< Moved under 1 m in 5 s while heading for a goal (a new one is picked)
    double mDistance = 0.0;    ///< Metres walked by all agents
    uint64_t mAgentFrames = 0; ///< Agents times frames
    uint64_t mOffNavMeshFrames = 0;
    uint32_t mLongestOffNavMeshFrames = 0;
    uint64_t mOffNavMeshOverOneSecond = 0; ///< Spells of more than 60 frames (an invariant: none)
    uint64_t mOverlapChecks = 0;           ///< Agent-frames checked for overlaps (every 10th frame)
    uint64_t mOverlapping = 0; ///< Of those, agents overlapping another by more than 10 % of a radius
    uint64_t mInsideStaticChecks = 0;
    uint64_t mInsideStatic = 0;         ///< An invariant: none
    uint64_t mCorridorsThroughGone = 0; ///< Corridors holding a polygon the navmesh lost: none
    /// Of some agents, a point every quarter second; a NaN point where the agent was put back (no walk)
    std::vector<std::vector<Vec3>> mTrails;
    std::vector<float> mTrailRadii;
    std::vector<std::string> mErrors;
};

/// The error lines a feature's figures keep (DoorStats, GuardStats): enough to tell what went wrong, and a
/// fault repeated every frame does not grow the report
constexpr size_t cMaxStatsErrors = 20;

/// What the huts' doors did to the navmesh (Doors' figures, for the report).
struct DoorStats
{
    uint64_t mDoorsSeen = 0; ///< Doors streamed in during the run
    uint64_t mCommands = 0;  ///< Opens and closes on the doors' timers
    uint64_t mRests = 0;     ///< Times a door came to rest (fell asleep), after a command or a knock
    /// Tiles published from a build that started after a door came to rest over them, both profiles: the
    /// door-caused rebuilds
    uint64_t mRebuilds = 0;
    /// Per rebuild: frames from the step the door fell asleep in to the sync point that published the tile
    std::vector<uint32_t> mLatencyFrames;
    uint64_t mDroppedBeforeRebuild = 0; ///< Tiles no invoker kept any more before their rebuild came
    /// Paths through a doorway once its door's tiles were rebuilt (human profile), by the hinge's angle then:
    /// a closed door must block the path, an open one let it through
    uint64_t mClosedChecks = 0;
    uint64_t mClosedBlocked = 0;
    uint64_t mOpenChecks = 0;
    uint64_t mOpenPassable = 0;
    /// Checks not made: the door moved again before its tiles were published, stood ajar, or a path end was
    /// off the navmesh (a neighbouring tile not built)
    uint64_t mChecksSkipped = 0;
    std::vector<std::string> mErrors;
};

/// What the guards that go limp when hit did (Guards' figures, for the report).
struct GuardStats
{
    uint64_t mPlaced = 0; ///< Guards stood on the path
    uint64_t mShots = 0;  ///< Aimed balls
    uint64_t mHits = 0;   ///< Guards a ball reached, made ragdolls
    uint64_t mAtRest = 0; ///< Ragdolls that came to rest (every part asleep)
    uint64_t mRemovedBeforeRest = 0;
    std::vector<double> mMakeMs;        ///< Per hit: Ragdoll::Create (23 bodies in one batch, 22 joints), ms
    std::vector<double> mSecondsToRest; ///< Per ragdoll at rest: from the hit
    std::vector<std::string> mErrors;
};

/// Summary of a series of samples (milliseconds unless said otherwise).
struct SampleSummary
{
    double mMean = 0.0;
    double mP50 = 0.0;
    double mP99 = 0.0;
    double mMax = 0.0;
    size_t mCount = 0;
};

SampleSummary Summarize(std::vector<double> inSamples);

/// Each phase of the physics step over a run's frames, summarized as the whole step is (ms per frame).
struct PhaseSummaries
{
    SampleSummary mBroadPhaseUpdate;
    SampleSummary mNarrowPhase; ///< Pairs + narrow phase
    SampleSummary mIslands;
    SampleSummary mSolve;
    SampleSummary mFinish;
    SampleSummary mLockWait; ///< The step's threads blocked on locks (not a phase: inside the others)
};

PhaseSummaries SummarizePhases(const std::vector<StepStatistics>& inSteps);

struct DemoRunResult
{
    std::string mModeName; ///< "lock-free" or "global mutex"
    int mFrames = 0;
    uint32_t mThreads = 0;          ///< Job system threads
    std::vector<double> mPhysicsMs; ///< Per frame: PhysicsSystem::Update wall time
    /// Per frame: of mPhysicsMs, the time the updating thread was off its core while the guest never switched
    /// it out, so the host had taken its vCPU (tools::HostTakenMs); NaN when the thread was switched out (it
    /// blocked, or the guest preempted it): then it can not be told. Only the updating thread is watched: a
    /// job thread that loses its core while the updating thread spins for it is not seen.
    std::vector<double> mPhysicsHostTakenMs;
    /// Time the host took from all vCPUs over the frames, as the guest counts it (10 ms ticks); NaN if it
    /// does not
    double mGuestStealMs = 0.0;
    std::vector<double>
        mFrameMs; ///< Per frame: the whole main-thread frame (physics, game objects, AI, sync)
    /// Per frame, the step's statistics (PhysicsSystem::GetLastStepStatistics): the phases of the summary
    /// (SummarizePhases) and frames.csv, where a slow frame's time went
    std::vector<StepStatistics> mSteps;
    /// Game-object query jobs: mean microseconds per query, per job-system thread (index = thread slot)
    std::vector<double> mQueryMicrosPerThread;
    uint64_t mQueries = 0;          ///< Ray casts and shape queries made by game-object jobs
    uint64_t mCharacterWalks = 0;   ///< Frames a game object walked as a character (one query each)
    uint64_t mCharacterPutBack = 0; ///< Times a game object fell 3 m behind its spot and was put back there
    double mQueryMicrosMean = 0.0;  ///< Over all queries
    /// Game-object query jobs (during the step): microseconds per frame each thread spent waiting for the
    /// broad phase's locks (LockWaits), in the order of mQueryMicrosPerThread
    std::vector<double> mBroadPhaseLockWaitMicrosPerThreadFrame;
    std::vector<double> mBodyLockWaitMicrosPerThreadFrame; ///< The same for the body locks
    /// Game-object move jobs (after the step): microseconds per frame each thread waited for any lock
    std::vector<double> mMoveLockWaitMicrosPerThreadFrame;
    std::vector<double> mGameObjectLockWaitUs; ///< Per frame: the query jobs' lock waits, all threads
    /// Streaming, measured on the loading thread per world tile
    std::vector<double> mStreamInMs;                  ///< Create + prepare + finalize of one tile's bodies
    std::vector<double> mStreamLinkMs;                ///< The finalize (broad-phase link) alone
    std::vector<double> mStreamOutMs;                 ///< Remove + destroy of one tile's bodies
    std::vector<double> mMainThreadStreamMs;          ///< Per frame: time the main thread spent on streaming
    std::vector<double> mMainThreadStreamHostTakenMs; ///< Per frame: the host's share of it (as for physics)
    uint32_t mTilesStreamedIn = 0;
    uint32_t mTilesStreamedOut = 0;
    uint32_t mStaticBodiesPeak = 0;
    uint32_t mDynamicBodiesPeak = 0;
    /// Navmesh
    uint64_t mNavTilesBuilt = 0;
    std::vector<uint32_t> mNavTileLatencyFrames; ///< Request to publication, per tile
    int mAgents = 0;
    AgentStats mAgentStats;
    DoorStats mDoorStats;
    GuardStats mGuardStats;
    uint32_t mLaddersMost = 0; ///< Most hut ladders (off-mesh links) declared at once
    /// At the run's end, the ladders declared: joined to the navmesh at both feet, waiting for their tiles,
    /// and dead (a foot that joins no navmesh, or left out of its tile: an invariant, none)
    uint32_t mLaddersJoined = 0;
    uint32_t mLaddersWaiting = 0;
    uint32_t mLaddersDead = 0;
    /// The final navmesh of the human profile, for the map: each polygon's outline (x, z) and the build
    /// latency of its tile in frames (-1: not known, a tile built before the run)
    struct MapPolygon
    {
        std::vector<std::pair<float, float>> mOutline;
        int mLatencyFrames = -1;
    };
    std::vector<MapPolygon> mNavMap;
    /// Invariants (the demo test checks them)
    uint32_t mLostOrDuplicatedBodies = 0;
    uint32_t mTilesRequestedNeverBuilt = 0;
    std::vector<std::string> mErrors; ///< Anything that went wrong, one line each
    std::string mNavMeshObj;          ///< The navmesh at the end of the run, as Wavefront OBJ text
};

/// The physics frames over inRatio times their mean, and how many of them the host's taking the updating
/// thread's vCPU (mPhysicsHostTakenMs) accounts for.
tools::SpikeAttribution AttributePhysicsSpikes(const DemoRunResult& inRun, double inRatio);

/// The game-object query jobs' lock waits of every kind, per thread (the sum of the per-kind series).
std::vector<double> LockWaitMicrosPerThreadFrame(const DemoRunResult& inRun);
/// The game-object query jobs' lock waits per query, µs (all threads and frames; NaN without queries).
double QueryLockWaitMicrosPerQuery(const DemoRunResult& inRun);

} // namespace cairn::demo
