#pragma once

// Crowd: agents that follow path corridors on a NavMeshWorld, keep apart from each other and stay on the
// navmesh surface while its tiles change under them.
//
// Each agent follows a polygon corridor (DetourCrowd's dtPathCorridor: the corridor's corners to steer for,
// the move along the navmesh surface, the check that its polygons still exist). Paths come from the crowd's
// own PathRequestQueue, so the frame's path finding stays within its budget whatever the number of agents.
// Every Update, before anyone moves, each corridor is checked whole against the navmesh as published: an
// agent whose corridor crosses a polygon that went away (a tile rebuilt, removed or streamed out) keeps the
// valid part, walks it and asks for a new path; an agent whose own polygon went away waits where it is until
// navmesh is published under it again. So no agent keeps a path through a polygon that no longer exists, and
// none walks off the navmesh.
//
// A path may go over an off-mesh link (a jump, a drop, a ladder). An agent that comes within a few radii of
// the link's start, with the link its next corner, takes it: its corridor moves over the link to the
// polygon at the far end, and the agent walks to the start and then along the link by itself, or waits at
// the start for the game to play its jump (OffMeshLinkMode). Others avoid it where it is meanwhile; it
// steers round no one.
//
// Why not dtCrowd itself: its update is one serial pass over every agent (and its own path queue): it cannot
// spread over job threads. Here the steering and moving run as a ParallelFor over the agents, each agent
// reading the others' positions and velocities as they were at the start of the Update (a snapshot) and
// writing only itself, so the result is the same for any number of threads. The path queue's budget is
// searched beside them, as a task: the calling thread only checks corridors, makes the snapshot and hands
// the paths found to their agents, so its cost is bounded by the agents' count, never by path finding.
//
// Each agent follows one of the crowd's path filters (SetFilter): it never enters an area its filter
// excludes, not on its path, nor pushed by others, nor by a shortcut, since the world marks those areas in
// Detour's polygon flags for the filter, and every Detour call the agent makes honours them. A filter changed
// under an agent is met as it stands: one in an area the filter now excludes leaves it for the nearest point
// it may stand on, one on its way to a link the filter now excludes stays on its side, and one already on a
// link (past its start) lands first. The crowd holds its world's marks: the world outlives the crowd.
//
// Threads. Update: one thread at a time, not inside another navmesh call; its loop and the path search run
// on the job interface's threads while the calling thread holds the navmesh shared (a Publish waits for the
// Update).
// AddAgent, RemoveAgent, SetTarget, CompleteOffMeshLink and the setters: the thread that calls Update,
// between Updates (SetFilter and the destructor never inside a navmesh call: they may mark the navmesh).
// The getters: that thread, or several threads at once between Updates (they only read).

#include "cairn/jobs/JobInterface.h"
#include "cairn/navmesh/NavMeshWorld.h"
#include "cairn/navmesh/PathRequestQueue.h"
#include "cairn/physics/body/BodyID.h"
#include "cairn/physics/body/Layers.h"

#include <array>
#include <cstdint>
#include <memory>
#include <set>
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

/// How an agent takes an off-mesh link (a jump, a drop, a ladder; TileScheduler::AddOffMeshLink) that its
/// path goes over. Either way the crowd first walks it to the link's start, and it is committed to the link
/// from there: its corridor goes on from the link's end.
enum class OffMeshLinkMode : uint8_t
{
    Automatic, ///< Then along the link to its end, in a straight line at its top speed (DetourCrowd's way)
    ByGame, ///< Then held at the start until the game calls CompleteOffMeshLink, after its own jump or climb
};

struct AgentParams
{
    float mRadius = 0.6f;          ///< m; at most the crowd's mMaxAgentRadius
    float mMaxSpeed = 3.5f;        ///< m/s
    float mMaxAcceleration = 8.0f; ///< m/s^2
    OffMeshLinkMode mLinkMode = OffMeshLinkMode::Automatic;
    uint8_t mFilter = 0; ///< Which of the crowd's path filters it follows (Crowd::SetFilter)
};

/// Where an agent's path goes (Crowd::GetPathStatus), as Unity's NavMeshPathStatus tells it.
enum class PathStatus : uint8_t
{
    None,     ///< No path found since its target was set (or no target)
    Complete, ///< To the target
    /// To the reachable point nearest the target, which cannot be reached from where the agent asked (a
    /// closed door, a gap with no link, a target off the navmesh's connected part): the agent stops there,
    /// Arrived, and the game may choose another target
    Partial,
};

/// The off-mesh link an agent is on (Crowd::GetOffMeshLink).
struct OffMeshLinkCrossing
{
    Vec3 mStart = Vec3::Zero(); ///< The end it takes the link from (either end of a bidirectional link)
    Vec3 mEnd = Vec3::Zero();   ///< Where it comes off the link, on the navmesh
    uint32_t mUserID = 0;       ///< The link's OffMeshLink::mUserID: which jump or ladder, for the game
    uint8_t mArea = 0;          ///< The link's area
    bool mAtStart = false;      ///< It has reached the start (it is on the link itself from now on)
};

enum class AgentState : uint8_t
{
    Idle,           ///< No target
    WaitingForPath, ///< A path request is queued or searched (it may move along a valid part meanwhile)
    Moving,         ///< Following its corridor
    Arrived, ///< Within its radius of the target's reachable point (GetPathStatus: the target's, or short)
    NoPath,  ///< The last request found no path (target off the navmesh or unreachable)
    /// Its polygon went away with a tile, or its filter excludes it with no other within reach: waits in
    /// place for navmesh under it, or a filter that lets it stand there
    OffNavMesh,
    OnOffMeshLink, ///< Taking an off-mesh link (walking to its start, on it, or held there: GetOffMeshLink)
};

class Crowd
{
public:
    struct Settings
    {
        int mMaxAgents = 16384;
        float mMaxAgentRadius = 2.0f; ///< m: the neighbour grid's cell is twice this
        /// Per agent, in [3, 1024]: a longer path is walked a corridor at a time, the rest asked for as the
        /// agent nears the corridor's end (10 polygons before it; a third of a shorter corridor, 2 at least)
        int mMaxCorridorPolygons = 256;
        /// Updates an agent on a collision course keeps the velocity it sampled (DetourCrowd samples every
        /// Update: 1). 2 halves the sampling, the crowd's largest cost in a dense crowd: avoidance is planned
        /// at 30 Hz while agents move and part at 60.
        int mAvoidancePeriod = 1;
        /// The crowd's own path queue. Its budget is searched on a job thread beside the steering, not on
        /// the calling thread: four times the queue's own default, enough for 10,000 agents' requests
        PathRequestQueue::Settings mPaths{.mIterationsPerUpdate = 8192};
    };
    /// An agent's id: its slot in the low cAgentSlotBits bits, and above them the slot's generation, which
    /// RemoveAgent moves on. An id kept past RemoveAgent names no later agent of the slot (until the slot's
    /// 4,096th reuse), so every call with it is refused (InvalidArgument) instead of acting on a stranger.
    using AgentID = uint32_t;
    static constexpr uint32_t cAgentSlotBits = 20; ///< Settings::mMaxAgents is at most 2^20

    static Result<std::unique_ptr<Crowd>> Create(const NavMeshWorld& inWorld, const Settings& inSettings);
    static Result<std::unique_ptr<Crowd>> Create(const NavMeshWorld& inWorld)
    {
        return Create(inWorld, Settings{});
    }
    ~Crowd();
    Crowd(const Crowd&) = delete;
    Crowd& operator=(const Crowd&) = delete;

    /// An agent at inPosition, snapped to the navmesh within 2 m across and 4 m up and down, outside the
    /// areas its filter excludes; where there is none yet (its tiles not built), it waits there, OffNavMesh,
    /// until there is. Errors: bad parameters or
    /// numbers, the crowd full (OutOfCapacity).
    Result<AgentID> AddAgent(const Vec3& inPosition, const AgentParams& inParams = {});
    Status RemoveAgent(AgentID inAgent);
    /// Asks for a path to inTarget through the crowd's queue; the agent moves once it arrives.
    Status SetTarget(AgentID inAgent, const Vec3& inTarget);

    /// The path filters agents follow, picked by AgentParams::mFilter (DetourCrowd's query filter types,
    /// Unity's per-agent area mask and costs, an Unreal agent's query filter). Each says which areas its
    /// agents never enter and what each area costs their paths. Every one starts as PathFilter{}: no area
    /// excluded, each costing 1.
    static constexpr int cMaxFilters = 16;
    /// Filter inIndex is inFilter from now on. Its agents with a target ask for their paths again, walking on
    /// meanwhile along what their corridors keep outside the areas it excludes; one standing in such an area
    /// is moved to the nearest point it may stand on within 2 m across and 1 m up or down (DetourCrowd's
    /// way), or waits OffNavMesh. Errors: an index out of range, a cost FindPath refuses, or OutOfCapacity
    /// when the world's crowds hold 15 other sets of excluded areas (of all their filters together). Between
    /// Updates: a new set of excluded areas is marked on the world's navmesh at once, waiting for the queries
    /// in progress as a Publish does.
    Status SetFilter(int inIndex, const PathFilter& inFilter);
    Result<PathFilter> GetFilter(int inIndex) const;
    /// The agent follows filter inIndex from now on, as if its filter had changed (SetFilter).
    Status SetAgentFilter(AgentID inAgent, int inIndex);

    /// Which dynamic bodies the agents avoid as obstacles.
    enum class Obstacles : uint8_t
    {
        AllDynamic, ///< Every dynamic body: for a navmesh that has none of them
        AwakeOnly,  ///< Moving ones: the tile scheduler's default bakes the sleeping ones into the navmesh
    };
    /// Dynamic bodies of inPhysics in inLayers near the agents are avoided like agents that do not give way
    /// (circles in the ground plane, read from their published poses each Update, no lock; bodies wider than
    /// half the neighbour grid's cell are left out). Null: none. Between Updates; the world must outlive its
    /// use.
    void SetPhysicsObstacles(const PhysicsSystem* inPhysics, ObjectLayerMask inLayers,
                             Obstacles inWhich = Obstacles::AllDynamic);

    /// The agents of inOthers (crowds of other profiles on the same ground) are avoided as agents that give
    /// way half each, read as they stand when this crowd updates. The crowds must be updated one after
    /// another on one thread, never at once, and outlive their use here. Between Updates.
    void SetOtherCrowds(std::vector<const Crowd*> inOthers) { mOtherCrowds = std::move(inOthers); }

    /// One frame of inDeltaTime seconds: corridor checks and replans, then the path queue's budget (a task on
    /// ioJobs' threads when given) beside the steering and moves (a ParallelFor on them), then the paths
    /// found are handed to their agents. Error for a time step out of (0, 1] s.
    Status Update(float inDeltaTime, jobs::JobInterface* ioJobs = nullptr);

    Result<Vec3> GetPosition(AgentID inAgent) const;
    Result<Vec3> GetVelocity(AgentID inAgent) const;
    Result<AgentState> GetState(AgentID inAgent) const;
    /// Whether its last path found reaches its target; a new target's path (SetTarget) starts at None. A
    /// replan after a tile changed says it again.
    Result<PathStatus> GetPathStatus(AgentID inAgent) const;
    Result<float> GetRadius(AgentID inAgent) const;
    /// The link an agent in the OnOffMeshLink state is taking; error for an agent on none.
    Result<OffMeshLinkCrossing> GetOffMeshLink(AgentID inAgent) const;
    /// Ends an agent's link now: it stands at the link's end and goes on along its corridor (the game's
    /// call for OffMeshLinkMode::ByGame once its animation is done; it also cuts an automatic one short).
    /// Error for an agent on no link, or not yet at its start (OffMeshLinkCrossing::mAtStart).
    Status CompleteOffMeshLink(AgentID inAgent);
    /// The agent's corridor, Detour polygon references (to draw it, or to check it against the navmesh).
    Result<std::vector<uint64_t>> GetCorridor(AgentID inAgent) const;
    /// The ids of the agents in the crowd, in slot order (the order of their updates).
    std::vector<AgentID> GetAgents() const;

    struct Statistics
    {
        uint64_t mReplans = 0;          ///< Paths asked for again because a corridor polygon went away
        uint64_t mOffNavMeshFrames = 0; ///< Agent-frames spent waiting for navmesh under them
        uint64_t mPathsApplied = 0;
        uint64_t mPathsFailed = 0;
        /// The last Update's time on the calling thread alone (path requests, the snapshot, path results)
        /// and in its parallel parts (the corridor checks beside the gathering of physics obstacles, then the
        /// steering loop beside the path queue's budget, on the job threads, the caller taking part), wall
        /// ms; and the path search's own time, in the second parallel part
        double mLastSerialMs = 0.0;
        double mLastMoveMs = 0.0;
        double mLastPathSearchMs = 0.0;
        uint32_t mLastObstacles = 0; ///< Physics bodies avoided in the last Update
        /// Agents that sampled velocities in the last Update (on a collision course or near a wall): the
        /// steering's cost grows with them
        uint32_t mLastSampled = 0;
        /// Agents that gathered their walls again in the last Update (moved on, or a tile near them changed)
        uint32_t mLastWallUpdates = 0;
        uint64_t mLinksTaken = 0; ///< Off-mesh links agents have started to take
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
    /// The physics obstacles within inAround into mObstacles (a task beside the corridor checks).
    void GatherPhysicsObstacles(const AABB& inAround, float inDeltaTime);
    /// Appends an entry to the snapshot and its grid.
    void AddToSnapshot(const Vec3& inPosition, const Vec3& inVelocity, float inRadius);
    /// Before the moves, agents [inBegin, inEnd) of mOrder (a ParallelFor chunk): corridors checked against
    /// the navmesh, cut short where a polygon went away, agents re-snapped or set waiting.
    void CheckCorridors(uint32_t inBegin, uint32_t inEnd, dtNavMeshQuery& ioQuery);
    /// After the checks, agents in slot order: the requests for paths, and the checks' statistics.
    void RequestPaths();
    /// After the moves and the search, agents in slot order: the paths found handed to their agents.
    void ApplyPathResults();
    /// Appends the other crowds' agents to the snapshot and grid.
    void AddOtherCrowds();
    /// Steering and move of agents [inBegin, inEnd) of mOrder, from the snapshot.
    void MoveAgents(uint32_t inBegin, uint32_t inEnd, float inDeltaTime, dtNavMeshQuery& ioQuery,
                    dtObstacleAvoidanceQuery& ioAvoidance);

    const NavMeshWorld& mWorld;
    const Settings mSettings;
    std::unique_ptr<PathRequestQueue> mPaths;
    /// By filter index: the PathFilter, its Detour filter (excluding the world's flag for its areas) and that
    /// flag, held from the world (0: no area excluded)
    std::array<PathFilter, cMaxFilters> mPathFilters;
    std::vector<dtQueryFilter> mDetourFilters;
    std::array<uint16_t, cMaxFilters> mExclusionFlags{};
    const dtQueryFilter& FilterOf(const Agent& inAgent) const;
    /// After its filter changed: it checks its corridor, its corners and walls again, and asks for its path
    /// again after the check, if it has a target.
    void NoteFilterChanged(Agent& ioAgent);
    std::vector<dtNavMeshQuery*> mQueries; ///< One per ParallelFor chunk, made as needed (scratch only)
    std::vector<std::unique_ptr<dtObstacleAvoidanceQuery>> mAvoidance; ///< Likewise, for the avoidance
    std::vector<std::unique_ptr<Agent>> mAgents;                       ///< By slot; null where removed
    std::vector<uint16_t> mGenerations; ///< By slot: the generation of its agent's id (12 bits), see AgentID
    std::set<uint32_t> mFreeSlots;      ///< The slots below mAgents.size() that are null, for the lowest free
    std::vector<uint32_t> mOrder;       ///< The agents' slots in order, for this Update
    std::vector<uint32_t> mChunkSampled; ///< Per ParallelFor chunk: its agents that sampled (a chunk's own)
    std::vector<uint32_t> mChunkWalls;   ///< Per ParallelFor chunk: its agents that gathered walls again
    std::vector<uint32_t> mChunkLinks;   ///< Per ParallelFor chunk: its agents that took a link
    // The snapshot every agent steers from: positions and velocities at the Update's start, by mOrder index
    std::vector<Vec3> mSnapshotPositions;
    std::vector<Vec3> mSnapshotVelocities;
    std::vector<float> mSnapshotRadii;
    /// Entries from here on (physics bodies) do not give way; those before (this crowd's agents, then the
    /// other crowds') give way half each
    uint32_t mSnapshotNoYield = 0;
    /// The neighbour grid over the snapshot: each entry's cell, by snapshot index
    std::vector<std::pair<uint64_t, uint32_t>> mCellAgents;
    /// The same entries by hashed cell (a counting sort, so each bucket keeps snapshot order): bucket b holds
    /// mBuckets[mBucketStart[b], mBucketStart[b + 1]); a bucket may hold other cells' entries too
    std::vector<uint32_t> mBucketStart;
    std::vector<std::pair<uint64_t, uint32_t>> mBuckets;
    uint64_t mBucketMask = 0;
    std::vector<uint32_t> mBucketFill; ///< Scratch of BuildBuckets
    /// Sorts mCellAgents into the buckets.
    void BuildBuckets();
    /// Which tile slots changed since the last Update (mTileChanged, mChangedAreas).
    void NoteTileChanges(const dtNavMesh& inNavMesh);
    /// Whether a tile that changed since the last Update is within inRange of inCentre (x-z).
    bool NearChangedTile(const Vec3& inCentre, float inRange) const;
    /// Each Detour tile slot as the last Update saw it
    struct TileSeen
    {
        unsigned int mSalt = 0;
        bool mPresent = false;
        std::array<float, 4> mArea{}; ///< min x, min z, max x, max z (while present, and after)
    };
    std::vector<TileSeen> mTileSeen;
    std::vector<uint8_t> mTileChanged; ///< By slot: changed since the last Update
    std::vector<std::array<float, 4>> mChangedAreas;
    bool mAnyTileChanged = true;
    float mCellSize = 1.0f; ///< The grid's, this Update
    uint64_t mUpdates = 0;  ///< Updates so far (the walls' refresh is spread over them)
    std::vector<const Crowd*> mOtherCrowds;
    const PhysicsSystem* mObstaclePhysics = nullptr;
    ObjectLayerMask mObstacleLayers = 0;
    Obstacles mObstacleKind = Obstacles::AllDynamic;
    std::vector<BodyID> mObstacleIDs; ///< Scratch
    struct Obstacle
    {
        Vec3 mCentre;
        Vec3 mVelocity;
        float mRadius;
    };
    std::vector<Obstacle> mObstacles; ///< This Update's, gathered beside the corridor checks
    /// By id: where each was, for its velocity
    std::vector<std::pair<BodyID, Vec3>> mPreviousObstacles;
    Statistics mStatistics;
};

} // namespace cairn::navmesh
