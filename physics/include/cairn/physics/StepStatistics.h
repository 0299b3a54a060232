#pragma once

// What the last PhysicsSystem::Update did and how long each phase took: counts and milliseconds, summed over
// its collision steps. Plain value type; PhysicsSystem::GetLastStepStatistics returns a copy.

#include <cstdint>

namespace cairn::physics
{

/// What the last Update did and how long each phase took (summed over its collision steps).
struct StepStatistics
{
    uint32_t mNumActiveBodies = 0;
    uint32_t mNumBodyPairs = 0; ///< Broad-phase pairs
    uint32_t mNumReusedBodyPairs =
        0; ///< Pairs that took last step's manifolds over (see mPairCacheMaxDelta*)
    uint32_t mNumManifolds = 0;
    uint32_t mNumContactPoints = 0;
    uint32_t mNumWarmStartedPoints = 0; ///< Contact points that took over last step's impulses
    uint32_t mNumIslands = 0;
    uint32_t mLargestIsland = 0;      ///< Bodies
    uint32_t mNumColoredIslands = 0;  ///< Islands colored for the parallel or wide solver
    uint32_t mNumColoringsReused = 0; ///< ... of which took the previous step's coloring (mReuseColorings)
    /// Collision steps whose constraints (at least one) came with the same keys in the same order as in the
    /// one before, so that its solve order was taken over instead of sorted (mReuseColorings)
    uint32_t mNumSolveOrdersReused = 0;
    uint32_t mNumLinearCastsMovedBack = 0; ///< LinearCast bodies stopped short of what they would touch
    /// The broad-phase update's own time. With a job system of two or more threads it may run beside the
    /// forces, the pairs, the narrow phase, the islands, the solve and the linear casts (see PhysicsStep), so
    /// it overlaps their times and the phases add up to more than mTotalMs
    double mBroadPhaseUpdateMs = 0.0;
    double mNarrowPhaseMs = 0.0; ///< Forces, pairs and the narrow phase, from the step's start (see above)
    double mIslandsMs = 0.0;
    double mSolveMs = 0.0;      ///< Velocity and position iterations plus integration
    double mContinuousMs = 0.0; ///< The linear casts (MotionQuality::LinearCast bodies)
    double mFinishMs = 0.0;     ///< Bounds update, broad-phase notify and sleeping
    double mTotalMs = 0.0;
    /// The updating thread's time outside the step's parallel loops and stages: what more threads cannot
    /// shorten. A loop counts as parallel when it has more items than a chunk, even when it ran on one
    /// thread, so on one thread mSerialMs / mTotalMs is the step's serial (Amdahl) fraction; with more
    /// threads a growing share shows the phase that stops the scaling. Per phase (each a part of that phase's
    /// time above; the linear casts are serial whole), then the step's
    double mNarrowPhaseSerialMs = 0.0;
    double mIslandsSerialMs = 0.0;
    double mSolveSerialMs = 0.0;
    double mFinishSerialMs = 0.0; ///< Includes waiting for a broad-phase update that runs beside
    double mSerialMs = 0.0;
    /// Time the update's threads spent blocked on the engine's locks (LockWaits): taking every body mutex at
    /// the start, the broad-phase update's rebuild commit, and with the global-mutex broad phase its mutex
    /// (in the pair search and the bounds notify too). A slow step with no wait here lost its time elsewhere
    double mLockWaitMs = 0.0;
};

} // namespace cairn::physics
