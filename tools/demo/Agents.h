#pragma once

// Agents: the demo's AI. Each agent is a navmesh invoker (the tiles within its radius are built in the
// background) and walks paths on the navmesh as it appears and changes: it picks a goal on the navmesh (a
// random point reachable within 15 m, or the navmesh under the player when it falls behind, and while there
// is none there yet, the navmesh 15 m the player's way), asks the NavMeshWorld for a path, follows the
// straight path at walking speed, and asks again when it arrives at its goal or every two seconds (half a
// second after a path that ended short of its goal, a quarter when there was no navmesh to ask yet). The
// player runs faster than the agents walk: one left 60 m behind catches up (is put back beside the player).
// Every new path is checked against the physics world: a point of it inside a wall (a static body at chest
// height) counts as a path through a wall, which must never happen.
//
// Threads: the main thread only (path queries may come from any thread; the demo keeps them on one).

#include "TileStreamer.h"
#include "cairn/navmesh/NavMeshWorld.h"
#include "cairn/navmesh/TileScheduler.h"
#include "cairn/physics/PhysicsSystem.h"

#include <random>
#include <vector>

namespace cairn::demo
{
using namespace cairn::physics;

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
    struct Stats
    {
        uint64_t mPathQueries = 0;
        uint64_t mPathsFound = 0;   ///< Reaching the goal
        uint64_t mPathsPartial = 0; ///< Ending at the reachable point nearest the goal
        uint64_t mPathsFailed = 0;  ///< No path: mostly no navmesh under the agent or its goal yet
        double mPathMicros = 0.0;   ///< Summed
        double mDistance = 0.0;     ///< Metres walked by all agents
        /// Agents put back beside the player after falling 60 m behind (one that stands where there is no
        /// navmesh after a failed path is put there too, not counted: it is mostly there already)
        uint64_t mCatchUps = 0;
        uint32_t mPathsThroughWalls = 0;
        std::vector<std::string> mErrors;
    };

    Agents(PhysicsSystem& ioPhysics, const WorldGenerator& inGenerator, const TileStreamer& inStreamer,
           navmesh::NavMeshWorld& ioNavMesh, navmesh::TileScheduler& ioScheduler, int inCount,
           uint64_t inSeed);
    ~Agents();

    void Update(float inDeltaTime, const Vec3& inPlayer);
    const Stats& GetStats() const { return mStats; }

private:
    struct Agent
    {
        Vec3 mPosition;
        navmesh::TileScheduler::InvokerID mInvoker = 0;
        std::vector<Vec3> mPath;
        size_t mNext = 0;              ///< Next corner of mPath
        float mRepathIn = 0.0f;        ///< Seconds until it asks again
        bool mPathReachesGoal = false; ///< mPath ends at its goal (arriving asks for a new one at once)
    };

    void Repath(Agent& ioAgent, const Vec3& inPlayer);
    /// inPoint moved onto the terrain: where an agent put back beside the player stands.
    Vec3 OnGround(const Vec3& inPoint) const;
    /// Points of the path inside a static body other than the terrain, sampled every 0.25 m at chest height.
    bool GoesThroughWall(const std::vector<Vec3>& inPath) const;

    PhysicsSystem& mPhysics;
    const WorldGenerator& mGenerator;
    const TileStreamer& mStreamer;
    navmesh::NavMeshWorld& mNavMesh;
    navmesh::TileScheduler& mScheduler;
    std::vector<Agent> mAgents;
    std::mt19937_64 mRandom;
    Stats mStats;
};

} // namespace cairn::demo
