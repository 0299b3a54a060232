#pragma once

// DemoRunner: one run of the streaming open-world demo in one broad-phase mode. The main thread's frame:
//   streaming focus -> balls thrown by the player -> guards and doors on their timers -> physics step (job
//   system) beside the game-object query jobs -> their moves (job threads) -> guards hit and doors at rest
//   -> AI agents (goals and the two crowds: paths on a budget here, steering on the job threads) -> navmesh
//   sync point (each profile's TileScheduler::Update) and the doors' rebuilds -> wait for the next 1/60 s
//   tick.
// The loading thread streams tiles in and out meanwhile, and background tile jobs build the navmesh.
// Threads: RunDemo on one thread; it owns everything it makes.

#include "DemoResult.h"
#include "cairn/physics/PhysicsSettings.h"
#include "cairn/physics/math/Result.h"

#include <cstdint>
#include <cstdio>
#include <string>

namespace cairn::demo
{
using namespace cairn::physics;

/// The demo's physics world holds this many bodies; a world file may fill it up to cDemoSpareBodies short
/// (the balls the player throws, and tiles still leaving while new ones stream in).
inline constexpr uint32_t cDemoMaxBodies = 65536;
inline constexpr uint32_t cDemoSpareBodies = 4096;
/// The largest values the demo takes, from its flags and its world file alike.
inline constexpr int cDemoMaxAgents = 10000;
inline constexpr int cDemoMaxCollisionSteps = 8;
inline constexpr float cDemoMaxCandidateMargin = 100.0f;
inline constexpr uint32_t cDemoMaxGameObjects = 20000;

struct DemoSettings
{
    uint64_t mSeed = 1;
    int mFrames = 1200; ///< Per mode
    int mAgents = 8;
    uint32_t mThreads = 0; ///< Job system threads (0: all cores)
    /// The main thread pinned to the first core and the job workers to the others (tools::PinnedThread,
    /// JobSystem::Settings::mPinWorkers): with idle time between paced frames, the OS woke the main thread on
    /// the worker's core, and a loop of a millisecond or two ran on one core
    bool mPinThreads = true;
    int mCollisionSteps = 1; ///< Per 1/60 s frame
    /// PhysicsSettings::mBroadPhaseCandidateMargin (m; 0: the pair search walks the static tree every step)
    float mCandidateMargin = PhysicsSettings().mBroadPhaseCandidateMargin;
    uint32_t mGameObjects = 256;   ///< Objects updated by jobs each frame
    uint32_t mGameObjectJobs = 8;  ///< K jobs per frame
    bool mRealTime = true;         ///< Wait for each 1/60 s tick (false: as fast as it goes)
    float mCollisionRadius = 3.0f; ///< World tiles with collision around the player (29 tiles)
    int mPropsPerTile = 700;
    int mDynamicPerTile = 110;
    int mBuildingsPerTile = 2; ///< Huts with a door on a timer (Buildings.h, Doors.h)
    float mPlayerSpeed = 8.0f; ///< m/s across the world
    bool mThrowBalls = true;   ///< The player throws balls that knock crates and stacks over
};

/// Runs the demo in inMode; inProgress (may be null) gets a live one-line display on a terminal, a line every
/// 300 frames otherwise. Errors: settings the physics world refuses (PhysicsSystem::Create's), before any
/// frame; what goes wrong during the run is in the result's mErrors.
Result<DemoRunResult> RunDemo(const DemoSettings& inSettings, BroadPhaseType inMode, std::FILE* inProgress);

} // namespace cairn::demo
