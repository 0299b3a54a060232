#pragma once

// Crowd: agents that follow path corridors on a NavMeshWorld, keep apart from each other and stay on the
// navmesh surface while its tiles change under them.
//
// Each agent follows a polygon corridor (DetourCrowd's dtPathCorridor: the corridor's corners to steer for,
// the move along the navmesh surface, the check that its polygons still exist). Paths come from the crowd's
// own PathRequestQueue, so the frame's path finding stays within its budget whatever the number of agents.
// Every Update, before anyone moves, each corridor is checked whole against the navmesh as published: an
// agent whose corridor crosses a polygon that went away (a tile rebuilt, removed or streamed out) keeps the
// valid part and asks for a new path; an agent whose own polygon went away waits where it is until navmesh
// is published under it again. So no agent keeps a path through a polygon that no longer exists, and none
// walks off the navmesh.
//
// Why not dtCrowd itself: its update is one serial pass over every agent (and its own path queue): it cannot
// spread over job threads. Here the steering and moving run as a ParallelFor over the agents, each agent
// reading the others' positions and velocities as they were at the start of the Update (a snapshot) and
// writing only itself, so the result is the same for any number of threads.
//
// Threads. Update: one thread at a time, not inside another navmesh call; its loop runs on the job
// interface's threads while the calling thread holds the navmesh shared (a Publish waits for the Update).
// AddAgent, RemoveAgent, SetTarget and the getters: the thread that calls Update, between Updates.

#include "cairn/jobs/JobInterface.h"
#include "cairn/navmesh/NavMeshWorld.h"
#include "cairn/navmesh/PathRequestQueue.h"
#include "cairn/physics/body/BodyID.h"
#include "cairn/physics/body/Layers.h"

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

class dtNavMeshQuery;
class dtObstacleAvoidanceQuery;
class dtQueryFilter;

namespace cairn::physics
{
class PhysicsSystem;
}

namespace cairn::navmesh
{

struct AgentParams
{
    float mRadius = 0.6f;          ///< m; at most the crowd's mMaxAgentRadius
    float mMaxSpeed = 3.5f;        ///< m/s
    float mMaxAcceleration = 8.0f; ///< m/s^2
};

enum class AgentState : uint8_t
{
    Idle,           ///< No target
    WaitingForPath, ///< A path request is queued or searched (it may move along a valid part meanwhile)
    Moving,         ///< Following its corridor
    Arrived,        ///< Within its radius of the target's reachable point
    NoPath,         ///< The last request found no path (target off the navmesh or unreachable)
    OffNavMesh,     ///< Its polygon went away with a tile: waits in place for navmesh under it
};

class Crowd
{
public:
    struct Settings
    {
        int mMaxAgents = 16384;
        float mMaxAgentRadius = 2.0f;      ///< m: the neighbour grid's cell is twice this
        int mMaxCorridorPolygons = 256;    ///< Per agent
        PathRequestQueue::Settings mPaths; ///< The crowd's own path queue
    };
    using AgentID = uint32_t;

    static Result<std::unique_ptr<Crowd>> Create(const NavMeshWorld& inWorld, const Settings& inSettings);
    static Result<std::unique_ptr<Crowd>> Create(const NavMeshWorld& inWorld)
    {
        return Create(inWorld, Settings{});
    }
    ~Crowd();
    Crowd(const Crowd&) = delete;
    Crowd& operator=(const Crowd&) = delete;

    /// An agent at inPosition, snapped to the navmesh within 2 m across and 4 m up and down; where there is
    /// none yet (its tiles not built), it waits there, OffNavMesh, until there is. Errors: bad parameters or
    /// numbers, the crowd full (OutOfCapacity).
    Result<AgentID> AddAgent(const Vec3& inPosition, const AgentParams& inParams = {});
    Status RemoveAgent(AgentID inAgent);
    /// Asks for a path to inTarget through the crowd's queue; the agent moves once it arrives.
    Status SetTarget(AgentID inAgent, const Vec3& inTarget);

    /// Dynamic bodies of inPhysics in inLayers near the agents are avoided like agents that do not give way
    /// (circles in the ground plane, read from their published poses each Update, no lock; bodies wider than
    /// half the neighbour grid's cell are left out). Null: none. Between Updates; the world must outlive its
    /// use.
    void SetPhysicsObstacles(const PhysicsSystem* inPhysics, ObjectLayerMask inLayers);

    /// One frame of inDeltaTime seconds: the path queue's budget, results and replans, then steering and
    /// moves (on ioJobs' threads when given). Error for a time step out of (0, 1] s.
    Status Update(float inDeltaTime, jobs::JobInterface* ioJobs = nullptr);

    Result<Vec3> GetPosition(AgentID inAgent) const;
    Result<Vec3> GetVelocity(AgentID inAgent) const;
    Result<AgentState> GetState(AgentID inAgent) const;
    Result<float> GetRadius(AgentID inAgent) const;
    /// The agent's corridor, Detour polygon references (to draw it, or to check it against the navmesh).
    Result<std::vector<uint64_t>> GetCorridor(AgentID inAgent) const;
    /// Agents in the crowd, and the ids in use in increasing order.
    std::vector<AgentID> GetAgents() const;

    struct Statistics
    {
        uint64_t mReplans = 0;          ///< Paths asked for again because a corridor polygon went away
        uint64_t mOffNavMeshFrames = 0; ///< Agent-frames spent waiting for navmesh under them
        uint64_t mPathsApplied = 0;
        uint64_t mPathsFailed = 0;
        /// The last Update's time on the calling thread (the path queue's budget, path results and corridor
        /// checks, the snapshot) and in the steering loop (on the job threads, the caller taking part), ms
        double mLastSerialMs = 0.0;
        double mLastMoveMs = 0.0;
        uint32_t mLastObstacles = 0; ///< Physics bodies avoided in the last Update
    };
    const Statistics& GetStatistics() const { return mStatistics; }
    const PathRequestQueue& GetPathQueue() const { return *mPaths; }

private:
    struct Agent;
    explicit Crowd(const NavMeshWorld& inWorld, const Settings& inSettings);
    Agent* Find(AgentID inAgent) const;
    /// Makes the per-chunk scratch (a navmesh query and an avoidance query each) for inChunks chunks; false
    /// when Detour cannot allocate it (nothing half-made is kept).
    bool MakeScratch(const dtNavMesh& inNavMesh, size_t inChunks);
    /// Asks the crowd's queue for a path from the agent to its target.
    Result<PathTicket> RequestPath(const Agent& inAgent);
    /// Appends the physics obstacles near the first inNumAgents snapshot entries to the snapshot and grid.
    void AddPhysicsObstacles(uint32_t inNumAgents, float inDeltaTime);
    /// The serial part of an Update (agents in id order): path results, corridor checks, replans.
    void UpdatePaths(dtNavMeshQuery& ioQuery);
    /// Steering and move of agents [inBegin, inEnd) of mOrder, from the snapshot.
    void MoveAgents(uint32_t inBegin, uint32_t inEnd, float inDeltaTime, dtNavMeshQuery& ioQuery,
                    dtObstacleAvoidanceQuery& ioAvoidance);

    const NavMeshWorld& mWorld;
    const Settings mSettings;
    std::unique_ptr<PathRequestQueue> mPaths;
    std::unique_ptr<dtQueryFilter> mFilter;
    std::vector<dtNavMeshQuery*> mQueries; ///< One per ParallelFor chunk, made as needed (scratch only)
    std::vector<std::unique_ptr<dtObstacleAvoidanceQuery>> mAvoidance; ///< Likewise, for the avoidance
    std::vector<std::unique_ptr<Agent>> mAgents;                       ///< By id; null where removed
    std::vector<AgentID> mOrder; ///< The agents in id order, for this Update
    // The snapshot every agent steers from: positions and velocities at the Update's start, by mOrder index
    std::vector<Vec3> mSnapshotPositions;
    std::vector<Vec3> mSnapshotVelocities;
    std::vector<float> mSnapshotRadii;
    /// The neighbour grid over the snapshot: cell -> first entry in mCellAgents, each cell's agents in order
    std::vector<std::pair<uint64_t, uint32_t>> mCellAgents;
    float mCellSize = 1.0f; ///< The grid's, this Update
    uint64_t mUpdates = 0;
    const PhysicsSystem* mObstaclePhysics = nullptr;
    ObjectLayerMask mObstacleLayers = 0;
    std::vector<BodyID> mObstacleIDs; ///< Scratch
    std::vector<std::pair<BodyID, Vec3>>
        mPreviousObstacles; ///< By id: where each was, for its velocity  ///< Updates so far (the walls'
                            ///< refresh is spread over them)
    Statistics mStatistics;
};

} // namespace cairn::navmesh
