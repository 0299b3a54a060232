#pragma once

// World-wide settings, fixed when the PhysicsSystem is created. Plain value type.

#include "cairn/physics/math/Math.h"
#include "cairn/physics/math/Result.h"
#include "cairn/physics/solver/SolverSettings.h"

#include <cstdint>

namespace cairn::physics
{

enum class BroadPhaseType : uint8_t
{
    BruteForce,          ///< The reference: every query tests every body (tests only)
    QuadTree,            ///< Lock-free quad trees, one per broad-phase layer: the default
    QuadTreeGlobalMutex, ///< The same trees behind one global reader-writer mutex (the "before" mode)
};

/// Where WorldQuery reads the bodies it tests.
enum class QueryReads : uint8_t
{
    PublishedPoses, ///< No lock: never waits for the step (the default)
    BodyLocks,      ///< Each body under its read lock: waits for the step (the "before" mode, for measuring)
};

struct PhysicsSettings
{
    static constexpr uint32_t cMaxBodiesLimit =
        1u << 22; ///< Largest mMaxBodies (the array is allocated at once)

    uint32_t mMaxBodies = 65536;              ///< Fixed capacity of the body array
    Vec3 mGravity = Vec3(0.0f, -9.81f, 0.0f); ///< m/s^2
    SolverSettings mSolver;                   ///< Iterations, slop, restitution threshold
    float mSpeculativeDistance = 0.02f;       ///< m: contacts start this far before touching
    bool mAllowSleeping = true;
    float mTimeBeforeSleep = 0.5f; ///< s an island must stay slow before it sleeps
    float mSleepVelocity = 0.05f;  ///< m/s: the fastest point of a body must stay below this
    BroadPhaseType mBroadPhase = BroadPhaseType::QuadTree;
    /// Read-write mutexes guarding the bodies (body i by mutex i % this): a power of two from 1 to 32. 32 as
    /// in the reference engine's "after"; 1 is its "before" (one lock for every body), for measuring
    uint32_t mNumBodyMutexes = 32;
    /// A body pair whose relative pose moved less than this (m, and radians) since its manifolds were made
    /// takes them over instead of colliding its shapes again; 0 turns the reuse off. Jolt's defaults: small
    /// enough that a contact point moves by at most a few millimetres on a metre-sized body
    float mPairCacheMaxDeltaPosition = 0.001f;
    float mPairCacheMaxDeltaAngle = 2.0f * cPi / 180.0f;
    /// One body pair's manifolds whose normals are within 5 degrees of each other (a shape across several
    /// triangles of a mesh or height field, a compound's parts on one floor) become one manifold of at most
    /// four points, as with Jolt's mUseManifoldReduction; off: one manifold per triangle or part
    bool mMergeManifolds = true;
    /// With a job system of two or more threads and a broad phase that allows it, a step whose active bodies
    /// times its helper threads (the job system's threads less the updating one) reach this rebuilds the
    /// broad phase on another thread while it finds its pairs and contacts: from 1,024 active bodies on 2
    /// threads, 342 on 4, 69 on 16. Below, a small scene's rebuild is short and the step does it first,
    /// itself: on 2 threads running it beside cost more than it saved (the step's only helper taken for it, a
    /// worker woken for it, pair queries on the tree not yet rebuilt; the demo's 0.2 ms physics frames were
    /// 15-25 % slower with it, the 1,240- and 2,000-body benchmarks 3-6 % faster). The bar falls with the
    /// helpers: beside, the update takes one helper of many from the step's loops; done first, it is a serial
    /// stretch that no thread count shortens. 0: beside whenever it may
    uint32_t mUpdateBesideStepMinActiveBodies = 1024;
    /// The step's loops over bodies, pairs and joints are cut so that each of the job system's threads has at
    /// least this many chunks to take, where the items allow (a chunk keeps a few microseconds of work): a
    /// thread that took a costly chunk then finds the others took the rest, instead of the loop waiting on
    /// its one chunk. A chunk is never larger than the loop's own grain, so on 2 threads the costliest loops
    /// are cut as before. No result depends on it. 0: every loop keeps its own grain whatever the thread
    /// count, for measuring
    uint32_t mMinChunksPerThread = 4;
    /// Quad-tree broad phase: the pair search remembers the static bodies (those of trees that did not
    /// change) within this margin (m) of each active body and reuses them while the body stays inside it; 0
    /// turns it off. Larger keeps candidates longer but more of them (see BroadPhaseQuadTree)
    float mBroadPhaseCandidateMargin = 0.25f;
    /// Where WorldQuery reads bodies: their published poses, with no lock (the default), or each under its
    /// body lock, waiting for the step (the reference engine's "before", for measuring)
    QueryReads mQueryReads = QueryReads::PublishedPoses;
};

/// Ok, or an InvalidArgument error naming the first field out of its documented range (NaN, infinity, a
/// negative distance, an iteration count over 1000, a body mutex count that is not a power of two up to 32).
Status ValidateSettings(const PhysicsSettings& inSettings);

} // namespace cairn::physics
