#pragma once

// What one run of the demo measured: plain data, filled by DemoRunner on the main thread after the run, read
// by DemoReport to print the summary and write the Markdown report.

#include "cairn/physics/StepStatistics.h"
#include "common/SpikeAttribution.h"

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace cairn::demo
{
using namespace cairn::physics;

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
    uint64_t mQueries = 0;         ///< Ray casts and shape queries made by game-object jobs
    double mQueryMicrosMean = 0.0; ///< Over all queries
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
    uint64_t mPathQueries = 0;
    uint64_t mPathsFound = 0;   ///< Reaching the goal
    uint64_t mPathsPartial = 0; ///< Ending short of it
    uint64_t mPathsFailed = 0;  ///< No path (mostly: no navmesh there yet)
    double mPathQueryMicrosMean = 0.0;
    int mAgents = 0;
    double mAgentDistanceMetres = 0.0; ///< Walked by all agents along their paths
    uint64_t mAgentCatchUps = 0;       ///< Agents put back beside the player after falling too far behind
    /// Invariants (the demo test checks them)
    uint32_t mLostOrDuplicatedBodies = 0;
    uint32_t mTilesRequestedNeverBuilt = 0;
    uint32_t mPathsThroughWalls = 0;
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
