#pragma once

// Agents: the demo's AI, a crowd per agent profile (humans, radius 0.6 m, and one agent in ten large, 1.5 m),
// each on its own navmesh built from the same physics world. The agents steer with avoidance along path
// corridors (navmesh::Crowd) and ask for paths through each crowd's budgeted queue. Each has a place by the
// player (spread over a disc of 10 m^2 an agent) and walks the navmesh: most wander, to a random point
// reachable within 15 m, a new one on arrival, when no path was found, when stuck and after 15 s; one in
// twenty is a companion that follows the player once 25 m from its place (to the navmesh under its place,
// or while there is none there yet, the navmesh 15 m that way; renewed every 2 s). The player runs faster
// than agents walk: one 50 m from its place is put back near it, on a free spot of navmesh, as an open
// world's population is moved from behind the player to ahead of it. One human in five may not climb: it
// follows the human crowd's no-climbing filter (its paths, moves and wander goals keep off the huts'
// ladders), and no such agent is ever on a ladder (a check of the run).
//
// The frame's navigation work: the goals (random points and nearest points, Detour searches) are picked on
// the job threads, each agent from its own seed, and set in id order; then each crowd's Update (its path
// budget and corridor checks on this thread, the steering on the job threads). The same run gives the same
// agents for any number of threads.
//
// The checks of the run (not counted as navigation work): an agent inside a static body (each agent every
// half second, on the job threads), agents overlapping (every 10th frame), off the navmesh for more than
// 1 s, a corridor through a polygon that is gone (every second).
//
// Threads: the main thread only, between the physics step and the navmesh sync point (the tile schedulers'
// Update): the crowds read the navmesh and the published poses.

#include "DemoResult.h"
#include "TileStreamer.h"
#include "cairn/jobs/JobInterface.h"
#include "cairn/navmesh/Crowd.h"
#include "cairn/navmesh/NavMeshWorld.h"
#include "cairn/physics/PhysicsSystem.h"

#include <array>
#include <memory>
#include <vector>

namespace cairn::demo
{
using namespace cairn::physics;

/// The sphere whose overlap with a static body (not the terrain) counts an agent inside it: on the agent's
/// centre line at chest height, over its feet. Not its whole radius: Recast's contours cut round the corners
/// of obstacles by up to half a metre (cells and simplification), so agents brush corners, as in DetourCrowd.
constexpr float cChestProbeHeight = 1.0f;
constexpr float cChestProbeRadius = 0.05f;

/// The goal of an agent that follows the player: the navmesh point nearest the player, or, while the player's
/// tiles are not built yet, the one nearest the point inReach metres the player's way from the agent, on the
/// ground that inGroundHeight(x, z) gives (the agent's own invoker radius reaches past it). Points are
/// snapped within 4 m either way in x and z and 8 m up or down. Error when the player's point has no navmesh
/// and either the player is within inReach (the agent is as close as it gets that way) or the point ahead has
/// none either.
template <class GroundHeight>
Result<Vec3> FollowGoal(const navmesh::NavMeshWorld& inNavMesh, const Vec3& inAgent, const Vec3& inPlayer,
                        float inReach, GroundHeight&& inGroundHeight)
{
    const Vec3 searchExtent(4.0f, 8.0f, 4.0f);
    const Vec3 player(inPlayer.x(), inGroundHeight(inPlayer.x(), inPlayer.z()), inPlayer.z());
    Result<Vec3> goal = inNavMesh.FindNearestPoint(player, {}, searchExtent);
    const Vec3 towardsPlayer(inPlayer.x() - inAgent.x(), 0.0f, inPlayer.z() - inAgent.z());
    const float distance = towardsPlayer.norm();
    if (goal || !(distance > inReach)) return goal;
    const Vec3 ahead = inAgent + towardsPlayer * (inReach / distance);
    return inNavMesh.FindNearestPoint(Vec3(ahead.x(), inGroundHeight(ahead.x(), ahead.z()), ahead.z()), {},
                                      searchExtent);
}

class Agents
{
public:
    /// An agent profile's navmesh and the agents' radius on it.
    struct Profile
    {
        const navmesh::NavMeshWorld* mNavMesh = nullptr;
        float mRadius = 0.6f;
    };

    using Stats = AgentStats;

    Agents(PhysicsSystem& ioPhysics, const WorldGenerator& inGenerator, const TileStreamer& inStreamer,
           const Profile& inHuman, const Profile& inLarge, int inCount, uint64_t inSeed);
    ~Agents();

    /// Where inCount agents keep round the player: their places are within this of the player.
    static float HomeRadius(int inCount);
    /// The navmesh the agents need round the player: their places, and as far again as an agent walks from
    /// its place before it is put back.
    static float NavMeshRadius(int inCount);

    void Update(float inDeltaTime, const Vec3& inPlayer, jobs::JobInterface& ioJobs);
    /// The threads that do the navigation work (the caller of Update and the job workers, ThreadSwitches.h's
    /// ids): each frame counts the times another task took one of their cores during it. Between Updates.
    void WatchThreads(std::vector<int> inThreadIds) { mWatchedThreads = std::move(inThreadIds); }
    const Stats& GetStats() const { return mStats; }
    /// The crowds' path-queue wait histograms summed, for the percentiles.
    void FinishStats();

private:
    struct Agent;
    struct Action;

    /// What the agent should do now (a goal, a catch-up), on a job thread: reads the navmesh and the agent.
    void Decide(uint32_t inIndex, const Vec3& inPlayer, Action& outAction) const;
    /// The static bodies other than the terrain at an agent's centre line at inPosition; false when the query
    /// failed. Any thread.
    bool StaticBodiesAt(const Vec3& inPosition, std::vector<BodyID>& outBodies) const;
    /// Whether an agent at inPosition is inside a static body other than the terrain (a job thread).
    bool InsideStatic(const Vec3& inPosition) const;
    /// The static bodies InsideStatic finds at inPosition, for the error message.
    std::string DescribeStaticAt(const Vec3& inPosition) const;
    /// Agents overlapping another by more than a tenth of the smaller radius (all crowds).
    uint64_t CountOverlapping() const;
    /// Corridors holding a polygon their navmesh no longer has.
    uint64_t CountCorridorsThroughGone() const;
    void AddAgent(uint32_t inIndex, const Vec3& inPosition);
    /// Of a catch-up's spots, the first with no agent within cOccupiedCell (else the first spot).
    Vec3 FreeSpot(const Action& inAction);
    /// Two large agents' radii: a spot this far from every agent is free for any agent
    static constexpr float cOccupiedCell = 3.0f;

    PhysicsSystem& mPhysics;
    const WorldGenerator& mGenerator;
    const TileStreamer& mStreamer;
    Profile mProfiles[2];
    std::unique_ptr<navmesh::Crowd> mCrowds[2];
    std::vector<Agent> mAgents;
    std::vector<Action> mActions; ///< Scratch, by agent
    uint64_t mSeed;
    uint64_t mFrame = 0;
    std::vector<std::pair<uint64_t, Vec3>> mOccupied; ///< Agents' positions by cell, for FreeSpot
    bool mOccupiedValid = false;
    std::vector<uint32_t> mTrailAgents; ///< Indices of the agents whose trails are kept
    std::vector<int> mWatchedThreads;
    Stats mStats;
};

} // namespace cairn::demo
