#include "cairn/navmesh/Crowd.h"

#include "DetourPaths.h"
#include "LinkMotion.h"
#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/body/PublishedPose.h"

#include <DetourCommon.h>
#include <DetourLocalBoundary.h>
#include <DetourObstacleAvoidance.h>
#include <DetourPathCorridor.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

namespace cairn::navmesh
{

namespace
{
/// Where AddAgent looks for navmesh under a position (half extents), as FindPath snaps its ends.
const Vec3 cSnapExtent(2.0f, 4.0f, 2.0f);
/// Where an agent standing in an area its filter excludes looks for a polygon it may stand on: as far across,
/// but no farther up or down than a step or two (not onto another floor)
const Vec3 cLeaveExcludedExtent(2.0f, 1.0f, 2.0f);
/// Agents in a ParallelFor chunk: steering one costs a few microseconds.
constexpr uint32_t cAgentsPerChunk = 64;
/// The neighbours and walls an agent avoids: within this many of its radii (DetourCrowd's choice)
constexpr float cCollisionRangeRadii = 8.0f;
/// The neighbours an agent avoids: within this many of its radii, the nearest cMaxNeighbours (at walking
/// speed and DetourCrowd's time horizon, those further off are not met before the next few Updates see them
/// again)
constexpr float cNeighbourRangeRadii = 6.0f;
/// Updates over which agents near a changed tile gather their walls again (by id)
constexpr uint64_t cWallRefreshSpread = 8;
/// How far ahead a corridor is shortened by a straight look (DetourCrowd's pathOptimizationRange)
constexpr float cPathOptimizationRangeRadii = 30.0f;
/// At most this many neighbours, the nearest
constexpr int cMaxNeighbours = 6;
/// The wall segments a dtLocalBoundary keeps (its MAX_LOCAL_SEGS, private there)
constexpr int cMaxWallSegments = 8;
/// An agent's corners are found again after this many Updates at the most, and once it is this many radii
/// off the straight line from where they were found to the first (see Crowd::Agent::Corners)
constexpr uint64_t cCornerReuseUpdates = 8;
constexpr float cCornerLineToleranceRadii = 0.1f;
/// An agent takes an off-mesh link that is its next corner within this many of its radii (DetourCrowd's
/// trigger): it walks the rest of the way to the start as part of the link, so no Update finds it short of
/// the start with the link behind it
constexpr float cLinkReachRadii = 2.25f;
/// An agent whose corridor was cut short of its path asks for the rest when this many polygons are left
/// (DetourCrowd's CHECK_LOOKAHEAD): enough to walk on while the queue searches
constexpr int cCutCorridorReplanPolygons = 10; ///< At most: a third of a short corridor, 2 at least
/// The polygons dtPathCorridor's merges may put at a corridor's start: a raycast's (optimizePathVisibility)
constexpr int cDetourMergeRoom = 32;

/// DetourCrowd's "medium" quality: adaptive sampling, 5 divisions, 2 rings, depth 2 (22 samples a threatened
/// agent, against 75 for its "good": the sampling was half of a 10,000-agent crowd's time at "good").
dtObstacleAvoidanceParams AvoidanceParams()
{
    dtObstacleAvoidanceParams params;
    params.velBias = 0.5f;
    params.weightDesVel = 2.0f;
    params.weightCurVel = 0.75f;
    params.weightSide = 0.75f;
    params.weightToi = 2.5f;
    params.horizTime = 2.5f;
    params.gridSize = 33;
    params.adaptiveDivs = 5;
    params.adaptiveRings = 2;
    params.adaptiveDepth = 2;
    return params;
}

uint64_t CellKey(int32_t inX, int32_t inZ)
{
    return uint64_t(uint32_t(inX)) << 32 | uint32_t(inZ);
}

/// A cell's bucket before the mask (splitmix64's finalizer: neighbouring cells land far apart).
uint64_t CellHash(uint64_t inKey)
{
    inKey = (inKey ^ (inKey >> 30)) * 0xbf58476d1ce4e5b9ull;
    inKey = (inKey ^ (inKey >> 27)) * 0x94d049bb133111ebull;
    return inKey ^ (inKey >> 31);
}

Vec3 Flat(const Vec3& inV)
{
    return Vec3(inV.x(), 0.0f, inV.z());
}

/// The first three corners of inCorridor's straight path (as dtPathCorridor::findCorners), looked for in its
/// first cCornerWindow polygons only: Detour's string pulling walks the portals until it has its corners,
/// which on open ground is the whole corridor, every Update. The window ends on its last polygon's edge, at
/// the point nearest the corridor's target: a point the agent heads for until the window moves on, not a
/// corner of the path (no slowing down there).
constexpr int cCornerWindow = 16;
int FindCorners(dtPathCorridor& ioCorridor, dtNavMeshQuery& ioQuery, const dtQueryFilter& inFilter,
                float* outCorners, unsigned char* outFlags, dtPolyRef* outPolygons)
{
    constexpr int cMaxCorners = 3;
    const int count = ioCorridor.getPathCount();
    const dtPolyRef* path = ioCorridor.getPath();
    if (count <= cCornerWindow)
        return ioCorridor.findCorners(outCorners, outFlags, outPolygons, cMaxCorners, &ioQuery, &inFilter);
    // The window ends on its last polygon's edge, at the point nearest the corridor's target
    float end[3];
    if (dtStatusFailed(
            ioQuery.closestPointOnPolyBoundary(path[cCornerWindow - 1], ioCorridor.getTarget(), end)))
        return ioCorridor.findCorners(outCorners, outFlags, outPolygons, cMaxCorners, &ioQuery, &inFilter);
    int numCorners = 0;
    ioQuery.findStraightPath(ioCorridor.getPos(), end, path, cCornerWindow, outCorners, outFlags, outPolygons,
                             &numCorners, cMaxCorners);
    // As Detour's findCorners: corners on the agent are passed already; an off-mesh link ends the list
    int first = 0;
    while (first < numCorners && dtVdist2DSqr(&outCorners[3 * first], ioCorridor.getPos()) < 0.01f * 0.01f &&
           (outFlags[first] & DT_STRAIGHTPATH_OFFMESH_CONNECTION) == 0)
        ++first;
    int kept = 0;
    for (int c = first; c < numCorners; ++c)
    {
        dtVcopy(&outCorners[3 * kept], &outCorners[3 * c]);
        outFlags[kept] = outFlags[c] & ~DT_STRAIGHTPATH_END; // The window's end is not the corridor's
        outPolygons[kept] = outPolygons[c];
        ++kept;
        if ((outFlags[c] & DT_STRAIGHTPATH_OFFMESH_CONNECTION) != 0) break;
    }
    return kept;
}

} // namespace

struct Crowd::Agent
{
    AgentParams mParams;
    dtPathCorridor mCorridor;
    dtLocalBoundary mBoundary; ///< The walls near it, for its avoidance
    Vec3 mVelocity = Vec3::Zero();
    Vec3 mTarget = Vec3::Zero();
    bool mHasTarget = false;
    PathTicket mTicket;
    AgentState mState = AgentState::Idle;
    float mStuckSeconds = 0.0f; ///< Moving but hardly: how long, for the way out of a jam
    bool mReplanned = false;    ///< This Update's corridor check cut its corridor short
    bool mResnapped = false;    ///< This Update's corridor check moved it onto another polygon
    /// Its filter changed since the last corridor check (SetFilter): the check covers its whole corridor
    bool mFilterChanged = false;
    /// Its path was longer than its corridor holds: the corridor ends short of the target, and the agent
    /// asks for the rest as it nears that end
    bool mCorridorCut = false;
    PathStatus mPathStatus = PathStatus::None;
    dtPolyRef mBoundaryPolygon = 0; ///< Where mBoundary was gathered (0: not yet)
    dtPolyRef mLastPolygon = 0;     ///< Its corridor's first polygon at its last move
    bool mWallsStale = false;       ///< A tile near its walls changed since they were gathered
    uint64_t mSampledAt = 0; ///< The Update of its last velocity sampling (0: not threatened last time)
    Vec3 mSampledVelocity = Vec3::Zero();
    /// The off-mesh link it is taking: its corridor already goes on from the link's end, where it lands
    std::optional<LinkMotion> mLink;
    dtPolyRef mLinkPolygon = 0; ///< mLink's polygon

    /// The first corners of its corridor's straight path, as FindCorners found them at mFrom. From any point
    /// on the straight line from mFrom to the first corner, the path through the same polygons has the same
    /// corners (a part of a shortest path is the shortest path between its ends), so they are kept while the
    /// agent walks that line with the corridor unchanged: string pulling was a third of the steering's cost.
    /// Found again when the corridor changes (mValid false, another first polygon or length), the agent is
    /// off the line (avoiding others, sliding along a wall) or near the first corner, and every
    /// cCornerReuseUpdates Updates.
    struct Corners
    {
        float mPoints[3 * 3];
        unsigned char mFlags[3];
        dtPolyRef mPolygons[3];
        int mCount = 0;
        Vec3 mFrom = Vec3::Zero();
        dtPolyRef mFirstPolygon = 0;
        int mPathCount = 0;
        uint64_t mFoundAt = 0;
        bool mValid = false;
    } mCorners;

    /// mCorners, found again unless they still hold for the agent at inPosition (at the Update inUpdate).
    void UpdateCorners(const Vec3& inPosition, uint64_t inUpdate, dtNavMeshQuery& ioQuery,
                       const dtQueryFilter& inFilter)
    {
        Corners& c = mCorners;
        if (c.mValid && c.mCount > 0 && c.mFirstPolygon == mCorridor.getFirstPoly() &&
            c.mPathCount == mCorridor.getPathCount() && inUpdate - c.mFoundAt < cCornerReuseUpdates)
        {
            const float tolerance = cCornerLineToleranceRadii * mParams.mRadius;
            float along = 0.0f;
            const Vec3 first(c.mPoints[0], c.mPoints[1], c.mPoints[2]);
            if (dtDistancePtSegSqr2D(inPosition.data(), c.mFrom.data(), first.data(), along) <
                    tolerance * tolerance &&
                Flat(first - inPosition).squaredNorm() > mParams.mRadius * mParams.mRadius)
                return;
        }
        c.mCount = FindCorners(mCorridor, ioQuery, inFilter, c.mPoints, c.mFlags, c.mPolygons);
        c.mFrom = inPosition;
        c.mFirstPolygon = mCorridor.getFirstPoly();
        c.mPathCount = mCorridor.getPathCount();
        c.mFoundAt = inUpdate;
        c.mValid = true;
    }

    /// Detour's corridor keeps its old height when getPolyHeight fails, which it does on the edges of a
    /// polygon's detail triangles: an agent stepping onto a crate kept the ground's height, a metre inside
    /// the crate. The height is taken from the polygon's surface after every move (SetHeightFromSurface).
    float mHeight = 0.0f;

    /// Where it stands on its corridor (on a link: the link's end)
    Vec3 CorridorPosition() const { return Vec3(mCorridor.getPos()[0], mHeight, mCorridor.getPos()[2]); }
    /// Where it is: on a link, the way along it
    Vec3 Position() const { return mLink ? mLink->GetPosition() : CorridorPosition(); }
    /// mHeight from the surface of the agent's polygon under its position (its corridor's height if none).
    void SetHeightFromSurface(const dtNavMeshQuery& inQuery)
    {
        mHeight = mCorridor.getPos()[1];
        float closest[3];
        if (mCorridor.getFirstPoly() != 0 &&
            dtStatusSucceed(
                inQuery.closestPointOnPoly(mCorridor.getFirstPoly(), mCorridor.getPos(), closest, nullptr)))
            mHeight = closest[1];
    }

    /// Takes the off-mesh link inLink, the first of its corners, from inPosition: its corridor moves over the
    /// link to the polygon at the far end. False (and nothing changed) where Detour finds no such link in the
    /// corridor.
    bool TakeLink(dtPolyRef inLink, const Vec3& inPosition, dtNavMeshQuery& ioQuery)
    {
        const dtNavMesh& navMesh = *ioQuery.getAttachedNavMesh();
        const dtOffMeshConnection* connection = navMesh.getOffMeshConnectionByRef(inLink);
        const dtMeshTile* tile = nullptr;
        const dtPoly* polygon = nullptr;
        // The link with a polygon after it in the corridor: Detour's move cuts the corridor up to there
        // before it asks for the link's ends, and a corridor cut short may end on the link (the agent then
        // waits at the start for the rest of its path)
        bool inCorridor = false;
        for (int p = 0; p + 1 < mCorridor.getPathCount() && !inCorridor; ++p)
            inCorridor = mCorridor.getPath()[p] == inLink;
        if (connection == nullptr || !inCorridor ||
            dtStatusFailed(navMesh.getTileAndPolyByRef(inLink, &tile, &polygon)))
            return false;
        const dtPolyRef before = mCorridor.getFirstPoly();
        const Vec3 beforePosition = CorridorPosition();
        dtPolyRef ends[2];
        Vec3 start, end;
        if (!mCorridor.moveOverOffmeshConnection(inLink, ends, start.data(), end.data(), &ioQuery))
        {
            // Not expected (the link is there): it stands where it was and asks for its path again
            mCorridor.reset(before, beforePosition.data());
            mCorners.mValid = false;
            if (mState == AgentState::Moving) mState = AgentState::WaitingForPath;
            return false;
        }
        SetHeightFromSurface(ioQuery); // At the link's end, for the corridor's place
        OffMeshLinkCrossing crossing;
        crossing.mStart = start;
        crossing.mEnd = end; // Detour moved it onto the polygon it lands on when it joined the link
        crossing.mUserID = connection->userId;
        crossing.mArea = uint8_t(FromDetourArea(polygon->getArea()));
        mLink.emplace(inPosition, crossing, mParams.mMaxSpeed, mParams.mLinkMode);
        mLinkPolygon = inLink;
        mCorners.mValid = false;
        return true;
    }

    /// One Update along its link from inPosition; off it at the end (an automatic link), going on at the
    /// speed it had along the link, not the shorter last step's (it slowed to a crawl as it landed).
    void MoveAlongLink(const Vec3& inPosition, float inDeltaTime)
    {
        if (mLink->Advance(inDeltaTime))
        {
            mLink.reset(); // mVelocity stays the last Update's along the link
            return;
        }
        mVelocity = Flat(Position() - inPosition) / inDeltaTime;
    }
};

Crowd::Crowd(const NavMeshWorld& inWorld, const Settings& inSettings) : mWorld(inWorld), mSettings(inSettings)
{
}

Crowd::~Crowd()
{
    for (dtNavMeshQuery* query : mQueries)
        dtFreeNavMeshQuery(query);
    for (const uint16_t flag : mExclusionFlags)
        mWorld.ReleaseExclusionFlag(flag);
}

Result<std::unique_ptr<Crowd>> Crowd::Create(const NavMeshWorld& inWorld, const Settings& inSettings)
{
    if (!(inSettings.mMaxAgents >= 1 && inSettings.mMaxAgents <= 1 << 20))
        return MakeError(ErrorCode::InvalidArgument, "crowd: max agents must be in [1, 2^20]");
    if (!(inSettings.mMaxAgentRadius > 0.0f && inSettings.mMaxAgentRadius <= inWorld.GetGrid().GetTileSize()))
        return MakeError(ErrorCode::InvalidArgument, "crowd: the max agent radius must be in (0, a tile]");
    if (!(inSettings.mAvoidancePeriod >= 1 && inSettings.mAvoidancePeriod <= 60))
        return MakeError(ErrorCode::InvalidArgument,
                         "crowd: the avoidance period must be in [1, 60] Updates");
    // Three at least: an off-mesh link and a polygon on either side of it
    if (!(inSettings.mMaxCorridorPolygons >= 3 && inSettings.mMaxCorridorPolygons <= cMaxPathPolygons))
        return MakeError(ErrorCode::InvalidArgument, "crowd: corridor polygons must be in [3, 1024]");
    std::unique_ptr<Crowd> crowd(new Crowd(inWorld, inSettings));
    Result<std::unique_ptr<PathRequestQueue>> paths = PathRequestQueue::Create(inWorld, inSettings.mPaths);
    if (!paths) return paths.GetError();
    crowd->mPaths = std::move(paths).Value();
    crowd->mDetourFilters.assign(cMaxFilters, MakeDetourFilter(PathFilter{}, "crowd").Value());
    return crowd;
}

namespace
{
constexpr uint32_t cAgentGenerationMask = (1u << (32 - Crowd::cAgentSlotBits)) - 1;

uint32_t SlotOf(Crowd::AgentID inAgent)
{
    return inAgent & ((1u << Crowd::cAgentSlotBits) - 1);
}
uint32_t GenerationOf(Crowd::AgentID inAgent)
{
    return inAgent >> Crowd::cAgentSlotBits;
}
Crowd::AgentID MakeAgentID(uint32_t inSlot, uint16_t inGeneration)
{
    return inSlot | Crowd::AgentID(inGeneration) << Crowd::cAgentSlotBits;
}
} // namespace

Crowd::Agent* Crowd::Find(AgentID inAgent) const
{
    const uint32_t slot = SlotOf(inAgent);
    return slot < mAgents.size() && mGenerations[slot] == GenerationOf(inAgent) ? mAgents[slot].get()
                                                                                : nullptr;
}

namespace
{
/// Error unless inIndex names one of a crowd's filters; inWhat starts the message ("crowd", "agent").
Status CheckFilterIndex(int inIndex, const char* inWhat)
{
    if (inIndex >= 0 && inIndex < Crowd::cMaxFilters) return Status::Ok();
    return MakeError(ErrorCode::InvalidArgument, std::string(inWhat) + ": a filter index must be in [0, " +
                                                     std::to_string(Crowd::cMaxFilters) + ")");
}
} // namespace

const dtQueryFilter& Crowd::FilterOf(const Agent& inAgent) const
{
    return mDetourFilters[inAgent.mParams.mFilter];
}

Status Crowd::SetFilter(int inIndex, const PathFilter& inFilter)
{
    if (Status index = CheckFilterIndex(inIndex, "crowd"); !index) return index.GetError();
    if (Result<dtQueryFilter> checked = MakeDetourFilter(inFilter, "crowd filter"); !checked)
        return checked.GetError();
    // The old areas' flag goes in the same step: with every flag held, the new areas may take it
    Result<uint16_t> flag =
        mWorld.AcquireExclusionFlag(inFilter.mExcludedAreas, mExclusionFlags[size_t(inIndex)]);
    if (!flag) return flag.GetError();
    mExclusionFlags[size_t(inIndex)] = flag.Value();
    mPathFilters[size_t(inIndex)] = inFilter;
    mDetourFilters[size_t(inIndex)] = MakeDetourFilter(inFilter, "crowd filter", flag.Value()).Value();
    for (const std::unique_ptr<Agent>& agent : mAgents)
        if (agent != nullptr && agent->mParams.mFilter == inIndex) NoteFilterChanged(*agent);
    return Status::Ok();
}

Result<PathFilter> Crowd::GetFilter(int inIndex) const
{
    if (Status index = CheckFilterIndex(inIndex, "crowd"); !index) return index.GetError();
    return mPathFilters[size_t(inIndex)];
}

Status Crowd::SetAgentFilter(AgentID inAgent, int inIndex)
{
    Agent* agent = Find(inAgent);
    if (agent == nullptr) return MakeError(ErrorCode::InvalidArgument, "agent: no such agent");
    if (Status index = CheckFilterIndex(inIndex, "agent"); !index) return index.GetError();
    agent->mParams.mFilter = uint8_t(inIndex);
    NoteFilterChanged(*agent);
    return Status::Ok();
}

void Crowd::NoteFilterChanged(Agent& ioAgent)
{
    ioAgent.mFilterChanged = true;
    ioAgent.mCorners.mValid = false;
    ioAgent.mBoundaryPolygon = 0; // Its walls gathered again: borders of excluded areas are walls
    // Its path asked for again once the check has put it where it may stand (RequestPaths); meanwhile it
    // walks on along what the check keeps of its corridor
    if (!ioAgent.mHasTarget || ioAgent.mState == AgentState::OffNavMesh) return;
    if (ioAgent.mTicket.mValue != 0) mPaths->Cancel(ioAgent.mTicket);
    ioAgent.mTicket = {};
    ioAgent.mState = AgentState::WaitingForPath;
}

Result<Crowd::AgentID> Crowd::AddAgent(const Vec3& inPosition, const AgentParams& inParams)
{
    if (!IsValidWorldPosition(inPosition))
        return MakeError(ErrorCode::InvalidArgument, "agent: bad position");
    if (Status index = CheckFilterIndex(inParams.mFilter, "agent"); !index) return index.GetError();
    if (!(inParams.mRadius > 0.0f && inParams.mRadius <= mSettings.mMaxAgentRadius) ||
        !(inParams.mMaxSpeed > 0.0f && inParams.mMaxSpeed <= 100.0f) ||
        !(inParams.mMaxAcceleration > 0.0f && inParams.mMaxAcceleration <= 1000.0f))
        return MakeError(
            ErrorCode::InvalidArgument,
            "agent: radius in (0, the crowd's max], speed in (0, 100], acceleration in (0, 1000]");
    if (mAgents.size() - mFreeSlots.size() >= size_t(mSettings.mMaxAgents))
        return MakeError(ErrorCode::OutOfCapacity, "agent: the crowd is full");
    auto agent = std::make_unique<Agent>();
    agent->mParams = inParams;
    // One more than it holds: Detour's setCorridor asserts that a path is shorter than the corridor's size.
    // And room for what a move or a shortcut merges in at its start: this Detour's merges do not check
    // their room, and wrote past a corridor smaller than a raycast's 32 polygons
    if (!agent->mCorridor.init(std::max(mSettings.mMaxCorridorPolygons, cDetourMergeRoom) + 1))
        return MakeError(ErrorCode::OutOfCapacity, "agent: Detour could not allocate its corridor");
    bool queryReady = false, onNavMesh = false;
    mWorld.Read(
        [&](const dtNavMesh& inNavMesh)
        {
            queryReady = MakeScratch(inNavMesh, 1);
            if (!queryReady) return;
            dtPolyRef polygon = 0;
            float nearest[3];
            mQueries[0]->findNearestPoly(inPosition.data(), cSnapExtent.data(),
                                         &mDetourFilters[inParams.mFilter], &polygon, nearest);
            onNavMesh = polygon != 0;
            agent->mCorridor.reset(polygon, onNavMesh ? nearest : inPosition.data());
            agent->SetHeightFromSurface(*mQueries[0]);
        });
    if (!queryReady) return MakeError(ErrorCode::OutOfCapacity, "agent: Detour could not make its query");
    // No navmesh there yet (its tiles not built): it waits in place until there is
    if (!onNavMesh) agent->mState = AgentState::OffNavMesh;
    // The lowest free slot: slots are reused (under a new generation), and the order of updates is the
    // order of slots
    uint32_t slot = uint32_t(mAgents.size());
    if (!mFreeSlots.empty())
    {
        slot = *mFreeSlots.begin();
        mFreeSlots.erase(mFreeSlots.begin());
    }
    else
    {
        mAgents.emplace_back();
        mGenerations.push_back(0);
    }
    mAgents[slot] = std::move(agent);
    return MakeAgentID(slot, mGenerations[slot]);
}

Status Crowd::RemoveAgent(AgentID inAgent)
{
    Agent* agent = Find(inAgent);
    if (agent == nullptr) return MakeError(ErrorCode::InvalidArgument, "agent: no such agent");
    if (agent->mTicket.mValue != 0) mPaths->Cancel(agent->mTicket);
    const uint32_t slot = SlotOf(inAgent);
    mAgents[slot].reset();
    mGenerations[slot] = uint16_t((mGenerations[slot] + 1) & cAgentGenerationMask);
    mFreeSlots.insert(slot);
    return Status::Ok();
}

Status Crowd::SetTarget(AgentID inAgent, const Vec3& inTarget)
{
    Agent* agent = Find(inAgent);
    if (agent == nullptr) return MakeError(ErrorCode::InvalidArgument, "agent: no such agent");
    if (!IsValidWorldPosition(inTarget)) return MakeError(ErrorCode::InvalidArgument, "agent: bad target");
    if (agent->mTicket.mValue != 0) mPaths->Cancel(agent->mTicket);
    agent->mTicket = {};
    agent->mTarget = inTarget;
    agent->mHasTarget = true;
    agent->mPathStatus = PathStatus::None;
    // An agent with no navmesh under it asks once it has some (CheckCorridors)
    if (agent->mState == AgentState::OffNavMesh) return Status::Ok();
    Result<PathTicket> ticket = RequestPath(*agent);
    if (!ticket) return ticket.GetError();
    agent->mTicket = ticket.Value();
    agent->mState = AgentState::WaitingForPath;
    return Status::Ok();
}

Status Crowd::Update(float inDeltaTime, jobs::JobInterface* ioJobs)
{
    if (!(inDeltaTime > 0.0f && inDeltaTime <= 1.0f))
        return MakeError(ErrorCode::InvalidArgument, "crowd: the time step must be in (0, 1] s");
    using Clock = std::chrono::steady_clock;
    double parallelMs = 0.0, searchMs = 0.0;
    auto since = [](Clock::time_point inStart)
    { return std::chrono::duration<double, std::milli>(Clock::now() - inStart).count(); };
    const Clock::time_point start = Clock::now();
    ++mUpdates;
    mOrder.clear();
    for (uint32_t slot = 0; slot < mAgents.size(); ++slot)
        if (mAgents[slot] != nullptr) mOrder.push_back(slot);
    const uint32_t count = uint32_t(mOrder.size());
    const uint32_t chunks = (count + cAgentsPerChunk - 1) / cAgentsPerChunk;
    // Runs inTask beside inLoop(begin, end) over the agents, on the job threads when there are any
    auto besideLoop = [&](auto& inTask, const auto& inLoop)
    {
        const Clock::time_point parallelStart = Clock::now();
        if (ioJobs != nullptr)
        {
            const jobs::TaskHandle task = ioJobs->StartTask("crowd", inTask);
            if (chunks > 1)
                ioJobs->ParallelFor(count, cAgentsPerChunk, inLoop);
            else if (count > 0)
                inLoop(0, count);
            (void)ioJobs->TryRunTaskHere(task); // Not started yet: this thread does it
            ioJobs->FinishTask(task);
        }
        else
        {
            inTask();
            for (uint32_t begin = 0; begin < count; begin += cAgentsPerChunk)
                inLoop(begin, std::min(count, begin + cAgentsPerChunk));
        }
        parallelMs += since(parallelStart);
    };
    bool scratchReady = false;
    mWorld.Read(
        [&](const dtNavMesh& inNavMesh)
        {
            scratchReady = MakeScratch(inNavMesh, std::max<uint32_t>(chunks, 1));
            if (!scratchReady) return;
            NoteTileChanges(inNavMesh);
            // The grid's cell is the largest neighbour range of the agents now: a 3 x 3 block of cells holds
            // every neighbour in range, and few more. The physics bodies are looked for round the agents
            float largestRadius = 0.0f;
            AABB around;
            for (const uint32_t id : mOrder)
            {
                largestRadius = std::max(largestRadius, mAgents[id]->mParams.mRadius);
                const Vec3 position = mAgents[id]->Position();
                around.Encapsulate(AABB(position, position));
            }
            mCellSize = cNeighbourRangeRadii * std::max(largestRadius, 0.01f);
            around = AABB(around.mMin - Vec3(mCellSize, 1.0f, mCellSize),
                          around.mMax + Vec3(mCellSize, 2.5f, mCellSize));

            // Each agent's corridor checked against the navmesh (its own agent each), beside the gathering
            // of the physics bodies to avoid
            auto gather = [&] { GatherPhysicsObstacles(around, inDeltaTime); };
            auto check = [&](uint32_t inBegin, uint32_t inEnd)
            { CheckCorridors(inBegin, inEnd, *mQueries[inBegin / cAgentsPerChunk]); };
            besideLoop(gather, check);
            RequestPaths();

            // The snapshot every agent steers from, and its neighbour grid
            mSnapshotPositions.clear();
            mSnapshotVelocities.clear();
            mSnapshotRadii.clear();
            mCellAgents.clear();
            for (const uint32_t id : mOrder)
            {
                const Agent& agent = *mAgents[id];
                AddToSnapshot(agent.Position(), agent.mVelocity, agent.mParams.mRadius);
            }
            AddOtherCrowds();
            mSnapshotNoYield = uint32_t(mSnapshotPositions.size());
            for (const Obstacle& obstacle : mObstacles)
                AddToSnapshot(obstacle.mCentre, obstacle.mVelocity, obstacle.mRadius);
            mStatistics.mLastObstacles = uint32_t(mObstacles.size());
            BuildBuckets();

            // The path search reads only the navmesh and its queue, the moves only the snapshot and their own
            // agents: the two run side by side, the search as a task
            mChunkSampled.assign(std::max<uint32_t>(chunks, 1), 0);
            mChunkWalls.assign(std::max<uint32_t>(chunks, 1), 0);
            mChunkLinks.assign(std::max<uint32_t>(chunks, 1), 0);
            auto search = [&]
            {
                const Clock::time_point searchStart = Clock::now();
                (void)mPaths->UpdateWithin(inNavMesh); // The crowd's own queue, on its world: never refused
                searchMs = since(searchStart);
            };
            auto move = [&](uint32_t inBegin, uint32_t inEnd)
            {
                const uint32_t chunk = inBegin / cAgentsPerChunk;
                MoveAgents(inBegin, inEnd, inDeltaTime, *mQueries[chunk], *mAvoidance[chunk]);
            };
            besideLoop(search, move);
            mStatistics.mLastSampled = 0;
            for (uint32_t sampled : mChunkSampled)
                mStatistics.mLastSampled += sampled;
            mStatistics.mLastWallUpdates = 0;
            for (uint32_t walls : mChunkWalls)
                mStatistics.mLastWallUpdates += walls;
            for (uint32_t links : mChunkLinks)
                mStatistics.mLinksTaken += links;
            ApplyPathResults();
        });
    if (!scratchReady)
        return MakeError(ErrorCode::OutOfCapacity, "crowd: Detour could not allocate a query for the update");
    const double totalMs = since(start);
    mStatistics.mLastSerialMs = totalMs - parallelMs;
    mStatistics.mLastMoveMs = parallelMs;
    mStatistics.mLastPathSearchMs = searchMs;
    return Status::Ok();
}

void Crowd::AddOtherCrowds()
{
    for (const Crowd* other : mOtherCrowds)
    {
        if (other == nullptr || other == this) continue;
        for (const std::unique_ptr<Agent>& agent : other->mAgents)
            if (agent != nullptr && agent->mCorridor.getFirstPoly() != 0)
                AddToSnapshot(agent->Position(), agent->mVelocity, agent->mParams.mRadius);
    }
}

void Crowd::SetPhysicsObstacles(const PhysicsSystem* inPhysics, ObjectLayerMask inLayers, Obstacles inWhich)
{
    mObstaclePhysics = inPhysics;
    mObstacleLayers = inLayers;
    mObstacleKind = inWhich;
    mPreviousObstacles.clear();
}

void Crowd::GatherPhysicsObstacles(const AABB& inAround, float inDeltaTime)
{
    mObstacles.clear();
    if (mObstaclePhysics == nullptr) return;
    // The dynamic bodies near the agents, as last published (no lock: the step may be running), as circles
    // in the ground plane; their velocity from where they were at the last Update. The broad phase's bounds
    // are enough: each body's circle comes from its own bounds below, and an exact test of the agents' box
    // against hundreds of shapes (most of them asleep) cost as much as the corridor checks it runs beside
    mObstacleIDs.clear();
    mObstaclePhysics->GetBroadPhase().CollideAABox(inAround, {mObstacleLayers},
                                                   [this](BodyID inBody) { mObstacleIDs.push_back(inBody); });
    std::sort(mObstacleIDs.begin(), mObstacleIDs.end()); // The broad phase's order is not fixed
    const PoseReader poses(mObstaclePhysics->GetBodyManager());
    std::vector<std::pair<BodyID, Vec3>> current;
    for (const BodyID& id : mObstacleIDs)
    {
        PublishedPose pose;
        if (!poses.Read(id, pose) || pose.mMotionType != MotionType::Dynamic || pose.mShape == nullptr ||
            (mObstacleKind == Obstacles::AwakeOnly && !pose.mActive))
            continue;
        const AABB bounds = pose.mShape->GetWorldBounds(pose.mTransform);
        const Vec3 centre(0.5f * (bounds.mMin.x() + bounds.mMax.x()), bounds.mMin.y(),
                          0.5f * (bounds.mMin.z() + bounds.mMax.z()));
        const float radius =
            0.5f * std::max(bounds.mMax.x() - bounds.mMin.x(), bounds.mMax.z() - bounds.mMin.z());
        // A body wider than half a cell is not found from every cell it covers: left to the agents' contacts
        if (!(radius > 0.0f && radius <= 0.5f * mCellSize)) continue;
        Vec3 velocity = Vec3::Zero();
        const auto previous = std::lower_bound(
            mPreviousObstacles.begin(), mPreviousObstacles.end(), std::pair<BodyID, Vec3>(id, Vec3::Zero()),
            [](const auto& inA, const auto& inB) { return inA.first < inB.first; });
        if (previous != mPreviousObstacles.end() && previous->first == id)
            velocity = Vec3(centre.x() - previous->second.x(), 0.0f, centre.z() - previous->second.z()) /
                       inDeltaTime;
        current.push_back({id, centre});
        mObstacles.push_back({centre, velocity, radius});
    }
    mPreviousObstacles = std::move(current);
}

void Crowd::NoteTileChanges(const dtNavMesh& inNavMesh)
{
    // A tile slot whose salt or presence changed since the last Update was rebuilt, removed or added: the
    // polygon references into it may be stale, and the walls near it moved
    const int slots = inNavMesh.getMaxTiles();
    const bool first = mTileSeen.size() != size_t(slots);
    mTileSeen.resize(size_t(slots));
    mTileChanged.assign(size_t(slots), first ? 1 : 0);
    mChangedAreas.clear();
    mAnyTileChanged = first;
    for (int slot = 0; slot < slots; ++slot)
    {
        const dtMeshTile* tile = inNavMesh.getTile(slot);
        TileSeen now;
        now.mSalt = tile->salt;
        now.mPresent = tile->header != nullptr;
        if (now.mPresent)
        {
            now.mArea = {tile->header->bmin[0], tile->header->bmin[2], tile->header->bmax[0],
                         tile->header->bmax[2]};
        }
        TileSeen& seen = mTileSeen[size_t(slot)];
        if (!first && now.mSalt == seen.mSalt && now.mPresent == seen.mPresent) continue;
        mTileChanged[size_t(slot)] = 1;
        mAnyTileChanged = true;
        // The area it covered, and the area it covers now
        if (seen.mPresent) mChangedAreas.push_back(seen.mArea);
        if (now.mPresent) mChangedAreas.push_back(now.mArea);
        if (!now.mPresent) now.mArea = seen.mArea;
        seen = now;
    }
}

bool Crowd::NearChangedTile(const Vec3& inCentre, float inRange) const
{
    for (const std::array<float, 4>& area : mChangedAreas)
    {
        const float dx = std::max({area[0] - inCentre.x(), 0.0f, inCentre.x() - area[2]});
        const float dz = std::max({area[1] - inCentre.z(), 0.0f, inCentre.z() - area[3]});
        if (dx * dx + dz * dz <= inRange * inRange) return true;
    }
    return false;
}

void Crowd::BuildBuckets()
{
    // A power of two of at least twice the entries: few cells share a bucket
    size_t buckets = 64;
    while (buckets < 2 * mCellAgents.size())
        buckets *= 2;
    mBucketMask = buckets - 1;
    mBucketStart.assign(buckets + 1, 0);
    for (const auto& [key, index] : mCellAgents)
        ++mBucketStart[(CellHash(key) & mBucketMask) + 1];
    for (size_t b = 0; b < buckets; ++b)
        mBucketStart[b + 1] += mBucketStart[b];
    mBuckets.resize(mCellAgents.size());
    std::vector<uint32_t>& next = mBucketFill;
    next.assign(mBucketStart.begin(), mBucketStart.end() - 1);
    for (const auto& entry : mCellAgents) // In snapshot order: each bucket keeps it
        mBuckets[next[CellHash(entry.first) & mBucketMask]++] = entry;
}

void Crowd::AddToSnapshot(const Vec3& inPosition, const Vec3& inVelocity, float inRadius)
{
    const uint32_t index = uint32_t(mSnapshotPositions.size());
    mSnapshotPositions.push_back(inPosition);
    mSnapshotVelocities.push_back(inVelocity);
    mSnapshotRadii.push_back(inRadius);
    mCellAgents.push_back({CellKey(int32_t(std::floor(inPosition.x() / mCellSize)),
                                   int32_t(std::floor(inPosition.z() / mCellSize))),
                           index});
}

bool Crowd::MakeScratch(const dtNavMesh& inNavMesh, size_t inChunks)
{
    // The query keeps a pointer to Detour's navmesh, which lives as long as the world
    while (mQueries.size() < inChunks)
    {
        dtNavMeshQuery* query = dtAllocNavMeshQuery();
        if (query == nullptr || dtStatusFailed(query->init(&inNavMesh, cMaxQueryNodes)))
        {
            dtFreeNavMeshQuery(query);
            return false;
        }
        mQueries.push_back(query);
    }
    while (mAvoidance.size() < inChunks)
    {
        auto avoidance = std::make_unique<dtObstacleAvoidanceQuery>();
        if (!avoidance->init(cMaxNeighbours, cMaxWallSegments)) return false;
        mAvoidance.push_back(std::move(avoidance));
    }
    return true;
}

Result<PathTicket> Crowd::RequestPath(const Agent& inAgent)
{
    // From the agent's own polygon: snapping its position may pick the neighbour on a shared edge. From its
    // corridor's place, which on a link is the link's end: where the path will start
    return mPaths->Request(inAgent.CorridorPosition(), inAgent.mTarget, mPathFilters[inAgent.mParams.mFilter],
                           cSnapExtent, inAgent.mCorridor.getFirstPoly());
}

void Crowd::CheckCorridors(uint32_t inBegin, uint32_t inEnd, dtNavMeshQuery& ioQuery)
{
    const dtNavMesh& navMesh = *ioQuery.getAttachedNavMesh();
    for (uint32_t i = inBegin; i < inEnd; ++i)
    {
        Agent& agent = *mAgents[mOrder[i]];
        dtPathCorridor& corridor = agent.mCorridor;
        const dtQueryFilter& filter = FilterOf(agent);
        agent.mReplanned = false;
        agent.mResnapped = false;
        // A changed filter that excludes the link an agent is walking to, or the polygon it lands on: the
        // agent does not take it, and stands where it is. One on the link itself (it reached the start) is
        // committed: it lands, and then leaves an excluded landing as anyone standing in an excluded area
        // does
        if (agent.mFilterChanged && agent.mLink && !agent.mLink->GetCrossing().mAtStart &&
            (!ioQuery.isValidPolyRef(agent.mLinkPolygon, &filter) ||
             !ioQuery.isValidPolyRef(corridor.getFirstPoly(), &filter)))
        {
            const Vec3 standing = agent.Position();
            agent.mLink.reset();
            corridor.reset(0, standing.data()); // Snapped again below, from where it stands
        }
        if (!ioQuery.isValidPolyRef(corridor.getFirstPoly(), &filter))
        {
            // Its tile went away under it, it was added where no tile was built yet, or it stands in an area
            // its filter excludes now: it goes to the nearest polygon it may stand on within the snapping
            // extent, or waits in place until there is one
            const bool excluded = navMesh.isValidPolyRef(corridor.getFirstPoly());
            dtPolyRef polygon = 0;
            float nearest[3];
            ioQuery.findNearestPoly(corridor.getPos(), (excluded ? cLeaveExcludedExtent : cSnapExtent).data(),
                                    &filter, &polygon, nearest);
            // A request made from where it stood starts where it may no longer stand, or from a place it
            // left: asked again (a polygon rebuilt under it in place leaves the request as good as it was)
            agent.mResnapped = polygon != 0 && (excluded || dtVdistSqr(nearest, corridor.getPos()) > 1.0e-4f);
            if (polygon == 0)
            {
                corridor.reset(0, corridor.getPos()); // Holds no polygon until navmesh is back under it
                agent.mCorners.mValid = false;
                agent.mHeight = corridor.getPos()[1];
                agent.mState = AgentState::OffNavMesh;
                agent.mVelocity.setZero();
                continue;
            }
            corridor.reset(polygon, nearest);
            agent.mCorners.mValid = false;
            agent.SetHeightFromSurface(ioQuery);
            if (agent.mState == AgentState::OffNavMesh || agent.mState == AgentState::Moving)
            {
                agent.mState = agent.mHasTarget ? AgentState::WaitingForPath : AgentState::Idle;
            }
        }
        // Only a corridor crossing a tile that changed since the last Update can hold a polygon that is gone:
        // the others are as valid as they were
        bool crossesChange = false;
        if (mAnyTileChanged)
            for (int p = 0; p < corridor.getPathCount() && !crossesChange; ++p)
                crossesChange = mTileChanged[navMesh.decodePolyIdTile(corridor.getPath()[p])] != 0;
        // Or its filter changed
        crossesChange |= agent.mFilterChanged;
        agent.mFilterChanged = false;
        if (crossesChange) agent.mCorners.mValid = false; // Its polygons may have moved
        if (crossesChange && corridor.getPathCount() > 1 &&
            !corridor.isValid(corridor.getPathCount(), &ioQuery, &filter))
        {
            // A polygon of its corridor went away (a tile rebuilt or removed) or is in an area its filter
            // excludes now: it keeps the part up to there and walks it meanwhile, and, if it was on its way,
            // asks again from here (DetourCrowd does so)
            corridor.trimInvalidPath(corridor.getFirstPoly(), corridor.getPos(), &ioQuery, &filter);
            if (agent.mState == AgentState::Moving)
            {
                agent.mState = AgentState::WaitingForPath;
                agent.mReplanned = true;
            }
        }
    }
}

void Crowd::RequestPaths()
{
    // In slot order, so the queue gets the same requests in the same order for any number of threads
    for (const uint32_t id : mOrder)
    {
        Agent& agent = *mAgents[id];
        mStatistics.mReplans += agent.mReplanned ? 1 : 0;
        if (agent.mState == AgentState::OffNavMesh)
        {
            ++mStatistics.mOffNavMeshFrames;
            // A path asked for before its tile went: it asks again from where it stands once navmesh is
            // back under it (the result would only fail, and say NoPath instead of OffNavMesh)
            if (agent.mTicket.mValue != 0) mPaths->Cancel(agent.mTicket);
            agent.mTicket = {};
            continue;
        }
        // Near the end of a corridor cut short, the rest of the way, walking on meanwhile (DetourCrowd asks
        // again likewise); it would stop there as if it had arrived
        if (agent.mState == AgentState::Moving && agent.mCorridorCut &&
            agent.mCorridor.getPathCount() <=
                std::min(cCutCorridorReplanPolygons, std::max(2, mSettings.mMaxCorridorPolygons / 3)))
            agent.mState = AgentState::WaitingForPath;
        // A request made before the check moved it to another polygon starts where it may no longer stand
        // (an area its filter excludes now: a target set with a filter change, a tile rebuilt with other
        // areas): asked again from here, before the search (it would fail there)
        if (agent.mResnapped && agent.mState == AgentState::WaitingForPath && agent.mTicket.mValue != 0)
        {
            mPaths->Cancel(agent.mTicket);
            agent.mTicket = {};
        }
        // An agent that needs a path and has no request (a replan, back on navmesh, a corridor cut short, a
        // changed filter, or a full queue last time) asks now; a full queue is asked again next Update
        if (agent.mState == AgentState::WaitingForPath && agent.mTicket.mValue == 0)
        {
            Result<PathTicket> ticket = RequestPath(agent);
            if (ticket) agent.mTicket = ticket.Value();
        }
    }
}

void Crowd::ApplyPathResults()
{
    for (const uint32_t id : mOrder)
    {
        Agent& agent = *mAgents[id];
        if (agent.mTicket.mValue == 0) continue;
        std::optional<Result<PathResult>> result = mPaths->TakeResult(agent.mTicket);
        if (!result) continue;
        agent.mTicket = {};
        dtPathCorridor& corridor = agent.mCorridor;
        if (!*result || result->Value().mStraightPath.empty())
        {
            ++mStatistics.mPathsFailed;
            agent.mState = AgentState::NoPath;
            agent.mPathStatus = PathStatus::None;
            continue;
        }
        // The path starts where the agent was when it asked; it may have walked on since, along what was
        // left of its corridor: the path from the polygon it stands in, if the path crosses it
        const std::vector<uint64_t>& polygons = result->Value().mPolygons;
        size_t from = 0;
        while (from < polygons.size() && polygons[from] != corridor.getFirstPoly())
            ++from;
        if (from == polygons.size())
        {
            // It left the path's polygons meanwhile: it asks again from where it is (searched in the same
            // navmesh, so this ends once it stands still at the end of what it had)
            Result<PathTicket> ticket = RequestPath(agent);
            if (ticket) agent.mTicket = ticket.Value();
            agent.mState = AgentState::WaitingForPath;
            continue;
        }
        std::vector<dtPolyRef> path(polygons.begin() + long(from), polygons.end());
        // A search that ran out of its budget went that way but not all of it: asked again on the way, as a
        // corridor cut short is, and not short of the target for want of a way
        const bool searchCut = result->Value().mSearchLimited;
        agent.mPathStatus =
            result->Value().mReachedEnd || searchCut ? PathStatus::Complete : PathStatus::Partial;
        agent.mCorridorCut = path.size() > size_t(mSettings.mMaxCorridorPolygons) || searchCut;
        if (path.size() > size_t(mSettings.mMaxCorridorPolygons))
            path.resize(size_t(mSettings.mMaxCorridorPolygons));
        corridor.setCorridor(result->Value().mStraightPath.back().data(), path.data(), int(path.size()));
        agent.mCorners.mValid = false;
        agent.mState = AgentState::Moving;
        ++mStatistics.mPathsApplied;
    }
}

void Crowd::MoveAgents(uint32_t inBegin, uint32_t inEnd, float inDeltaTime, dtNavMeshQuery& ioQuery,
                       dtObstacleAvoidanceQuery& ioAvoidance)
{
    const float cell = mCellSize;
    static const dtObstacleAvoidanceParams params = AvoidanceParams();
    for (uint32_t i = inBegin; i < inEnd; ++i)
    {
        Agent& agent = *mAgents[mOrder[i]];
        const Vec3 position = mSnapshotPositions[i];
        // On a link it steers round no one (DetourCrowd's agents do not either): the others avoid it. Its
        // corridor, from the link's end, may meanwhile be checked, cut or replaced: it lands on what is there
        if (agent.mLink)
        {
            agent.MoveAlongLink(position, inDeltaTime);
            continue;
        }
        if (agent.mState == AgentState::OffNavMesh) continue;
        const float radius = agent.mParams.mRadius, maxSpeed = agent.mParams.mMaxSpeed;
        const dtQueryFilter& filter = FilterOf(agent);
        const float range = cCollisionRangeRadii * radius;
        const float neighbourRange = cNeighbourRangeRadii * radius;
        // The walls near it, again once it has moved a quarter of the range from where they were gathered,
        // and within cWallRefreshSpread Updates of a tile within the range changing (a tile published next
        // to it turns a wall at the tile's edge into a way through; a tile rebuilt moves walls). Spread by
        // id: a world tile's crates waking rebuild a dozen tiles at once, and the hundreds of agents near
        // them gathered walls in the same Update. Walls only steer the sampling: the corridor keeps the
        // agent on the navmesh as it is now meanwhile
        const Vec3 boundaryCentre(agent.mBoundary.getCenter()[0], agent.mBoundary.getCenter()[1],
                                  agent.mBoundary.getCenter()[2]);
        if (NearChangedTile(boundaryCentre, range)) agent.mWallsStale = true;
        if (Flat(position - boundaryCentre).norm() > 0.25f * range || agent.mBoundaryPolygon == 0 ||
            (agent.mWallsStale && (mUpdates + mOrder[i]) % cWallRefreshSpread == 0))
        {
            agent.mBoundary.update(agent.mCorridor.getFirstPoly(), position.data(), range, &ioQuery, &filter);
            agent.mBoundaryPolygon = agent.mCorridor.getFirstPoly();
            agent.mWallsStale = false;
            ++mChunkWalls[inBegin / cAgentsPerChunk];
        }

        Vec3 desired = Vec3::Zero();
        bool wallsThreaten = true; ///< See the walls' threat below
        // An agent waiting for a new path walks on along what is left of its old corridor
        const bool waitingOnItsWay =
            agent.mState == AgentState::WaitingForPath && agent.mCorridor.getPathCount() > 1;
        if (agent.mState == AgentState::Moving || waitingOnItsWay)
        {
            agent.UpdateCorners(position, mUpdates, ioQuery, filter);
            const float* corners = agent.mCorners.mPoints;
            const unsigned char* flags = agent.mCorners.mFlags;
            int numCorners = agent.mCorners.mCount;
            // Into a new polygon whose corridor turns back through the one it left: an agent walking along a
            // tile's edge crosses the corner where four tiles meet into a polygon the path does not take,
            // and its first corner falls behind it (it turned back and forth there). A straight look towards
            // the next corners and a short local search cut the detour off (DetourCrowd runs them every
            // Update and every half second; here only on such a turn back)
            const dtPolyRef first = agent.mCorridor.getFirstPoly();
            if (first != agent.mLastPolygon && numCorners > 0)
            {
                bool turnsBack = false;
                for (int p = 1; p < std::min(4, agent.mCorridor.getPathCount()) && !turnsBack; ++p)
                    turnsBack = agent.mCorridor.getPath()[p] == agent.mLastPolygon;
                if (turnsBack)
                {
                    agent.mCorridor.optimizePathVisibility(&corners[3 * std::min(1, numCorners - 1)],
                                                           cPathOptimizationRangeRadii * radius, &ioQuery,
                                                           &filter);
                    agent.mCorridor.optimizePathTopology(&ioQuery, &filter);
                    agent.mCorners.mValid = false;
                    agent.UpdateCorners(position, mUpdates, ioQuery, filter);
                    numCorners = agent.mCorners.mCount;
                }
            }
            agent.mLastPolygon = first;
            if (numCorners > 0 && (flags[0] & DT_STRAIGHTPATH_OFFMESH_CONNECTION) != 0 &&
                Flat(Vec3(corners[0], corners[1], corners[2]) - position).norm() < cLinkReachRadii * radius &&
                agent.TakeLink(agent.mCorners.mPolygons[0], position, ioQuery))
            {
                ++mChunkLinks[inBegin / cAgentsPerChunk];
                agent.MoveAlongLink(position, inDeltaTime);
                continue;
            }
            const Vec3 end(agent.mCorridor.getTarget()[0], agent.mCorridor.getTarget()[1],
                           agent.mCorridor.getTarget()[2]);
            if (numCorners == 0 || Flat(end - position).norm() < radius)
            {
                // The end of a trimmed corridor is not the target: it waits there for its path
                if (!waitingOnItsWay) agent.mState = AgentState::Arrived;
            }
            else
            {
                const Vec3 toCorner = Flat(Vec3(corners[0], corners[1], corners[2]) - position);
                const float distance = toCorner.norm();
                // Slow down within two radii of the last corner, so the agent stops on its target
                const bool last = (flags[0] & DT_STRAIGHTPATH_END) != 0;
                const float speed = last ? maxSpeed * std::min(1.0f, distance / (2.0f * radius)) : maxSpeed;
                if (distance > 1.0e-4f) desired = toCorner * (speed / distance);
                // Heading for a link's start, no wall threatens it: the straight line there is clear (the
                // start is its next corner), and the edge the link goes over, just beyond, slowed it before
                // every jump
                wallsThreaten = (flags[0] & DT_STRAIGHTPATH_OFFMESH_CONNECTION) == 0;
                // A jam (agents wanting through each other, each waiting for the other) dissolves when the
                // stuck ones step aside for a moment: to the left or the right by the parity of their ids
                agent.mStuckSeconds = Flat(mSnapshotVelocities[i]).norm() < 0.1f * maxSpeed
                                          ? agent.mStuckSeconds + inDeltaTime
                                          : 0.0f;
                if (agent.mStuckSeconds > 1.0f)
                {
                    const float side = (mOrder[i] & 1u) != 0 ? 1.0f : -1.0f;
                    desired = 0.5f * desired + side * Vec3(-desired.z(), 0.0f, desired.x());
                    if (agent.mStuckSeconds > 2.0f) agent.mStuckSeconds = 0.0f;
                }
            }
        }

        // The nearest neighbours in range, as the snapshot has them, by gap (ties by order: deterministic)
        std::pair<float, uint32_t> neighbours[cMaxNeighbours];
        int numNeighbours = 0;
        const int32_t cx = int32_t(std::floor(position.x() / cell)),
                      cz = int32_t(std::floor(position.z() / cell));
        for (int32_t dx = -1; dx <= 1; ++dx)
            for (int32_t dz = -1; dz <= 1; ++dz)
            {
                const uint64_t key = CellKey(cx + dx, cz + dz);
                const uint64_t bucket = CellHash(key) & mBucketMask;
                for (uint32_t e = mBucketStart[bucket]; e < mBucketStart[bucket + 1]; ++e)
                {
                    if (mBuckets[e].first != key) continue; // Another cell in the same bucket
                    const uint32_t j = mBuckets[e].second;
                    if (j == i) continue;
                    const float ox = position.x() - mSnapshotPositions[j].x(),
                                oz = position.z() - mSnapshotPositions[j].z();
                    const float distanceSq = ox * ox + oz * oz;
                    if (distanceSq >= neighbourRange * neighbourRange) continue;
                    const float distance = std::sqrt(distanceSq);
                    // Kept sorted by insertion: at most cMaxNeighbours, the nearest
                    // Nearest by the gap between them, not their centres: a large agent next to a crowd of
                    // small ones is among the neighbours it touches
                    const std::pair<float, uint32_t> entry(distance - radius - mSnapshotRadii[j], j);
                    if (numNeighbours == cMaxNeighbours && !(entry < neighbours[cMaxNeighbours - 1]))
                        continue;
                    int at = numNeighbours < cMaxNeighbours ? numNeighbours++ : cMaxNeighbours - 1;
                    while (at > 0 && entry < neighbours[at - 1])
                    {
                        neighbours[at] = neighbours[at - 1];
                        --at;
                    }
                    neighbours[at] = entry;
                }
            }

        // Velocity obstacles (DetourCrowd's sampling): the velocity nearest the desired one that meets no
        // neighbour and no wall within the time horizon
        Vec3 velocity = desired;
        // Sampling costs microseconds an agent: only an agent that would meet a neighbour within the horizon
        // (both going on as they go) or is heading into a wall samples; the others take their desired
        // velocity
        bool threatened = false;
        for (int n = 0; n < numNeighbours && !threatened; ++n)
        {
            const uint32_t j = neighbours[n].second;
            const Vec3 offset = Flat(mSnapshotPositions[j] - position);
            const Vec3 closing = Flat(desired - mSnapshotVelocities[j]);
            const float closingSq = closing.squaredNorm();
            const float t = closingSq > 1.0e-8f
                                ? std::clamp(offset.dot(closing) / closingSq, 0.0f, params.horizTime)
                                : 0.0f;
            const float reach = radius + mSnapshotRadii[j] + 0.1f * radius;
            threatened = (offset - closing * t).squaredNorm() < reach * reach;
        }
        // A wall threatens only an agent heading into it: where its desired velocity takes it in half a
        // second is within half a radius of the wall, in front of it. The corridor keeps every agent on the
        // navmesh whatever it samples, so walls beside an agent's way (nearly every agent among props) are
        // left to the move along the surface
        const Vec3 ahead = position + desired * 0.5f;
        for (int w = 0; w < agent.mBoundary.getSegmentCount() && wallsThreaten && !threatened; ++w)
        {
            const float* segment = agent.mBoundary.getSegment(w);
            if (dtTriArea2D(position.data(), segment, segment + 3) < 0.0f) continue; // Behind it
            float along = 0.0f;
            threatened =
                dtDistancePtSegSqr2D(ahead.data(), segment, segment + 3, along) < 0.25f * radius * radius;
        }
        // A threatened agent keeps the velocity it sampled for mAvoidancePeriod Updates from then on: the
        // acceleration limit and the contacts below still act every Update
        const bool keepsSample = threatened && agent.mSampledAt != 0 &&
                                 mUpdates - agent.mSampledAt < uint64_t(mSettings.mAvoidancePeriod);
        if (keepsSample)
            velocity = agent.mSampledVelocity;
        else if (threatened)
        {
            ++mChunkSampled[inBegin / cAgentsPerChunk];
            ioAvoidance.reset();
            for (int n = 0; n < numNeighbours; ++n)
            {
                const uint32_t j = neighbours[n].second;
                ioAvoidance.addCircle(mSnapshotPositions[j].data(), mSnapshotRadii[j],
                                      mSnapshotVelocities[j].data(), mSnapshotVelocities[j].data());
            }
            for (int w = 0; w < agent.mBoundary.getSegmentCount(); ++w)
            {
                const float* segment = agent.mBoundary.getSegment(w);
                // Walls the agent is behind do not matter (DetourCrowd skips them too)
                if (dtTriArea2D(position.data(), segment, segment + 3) < 0.0f) continue;
                ioAvoidance.addSegment(segment, segment + 3);
            }
            Vec3 chosen = Vec3::Zero();
            ioAvoidance.sampleVelocityAdaptive(position.data(), radius, maxSpeed,
                                               mSnapshotVelocities[i].data(), desired.data(), chosen.data(),
                                               &params);
            velocity = Flat(chosen);
            agent.mSampledVelocity = velocity;
            agent.mSampledAt = mUpdates;
        }
        if (!threatened) agent.mSampledAt = 0;
        // The acceleration limit
        Vec3 change = velocity - mSnapshotVelocities[i];
        const float maxChange = agent.mParams.mMaxAcceleration * inDeltaTime;
        if (change.norm() > maxChange) change *= maxChange / change.norm();
        velocity = mSnapshotVelocities[i] + change;
        // Agents already overlapping part, and neither moves into the other meanwhile (DetourCrowd moves
        // them apart after integrating, in passes that need every agent; here each from the snapshot)
        for (int n = 0; n < numNeighbours; ++n)
        {
            const uint32_t j = neighbours[n].second;
            const float gap = neighbours[n].first;
            if (gap >= 0.0f) break; // Sorted by gap
            const float distance = gap + radius + mSnapshotRadii[j];
            const Vec3 away = Flat(position - mSnapshotPositions[j]);
            const Vec3 direction =
                distance > 1.0e-4f ? Vec3(away / distance) : Vec3(j < i ? 1.0f : -1.0f, 0.0f, 0.0f);
            const float into = velocity.dot(direction);
            if (into < 0.0f) velocity -= into * direction;
            // Half the overlap each (the other agent does the same), within this step; all of it from a body
            const float share = j >= mSnapshotNoYield ? 1.0f : 0.5f;
            velocity += direction * (share * -gap / inDeltaTime);
        }
        if (velocity.norm() > 2.0f * maxSpeed) velocity *= 2.0f * maxSpeed / velocity.norm();
        const Vec3 wanted = position + velocity * inDeltaTime;
        // Along the navmesh surface, inside the corridor: never off it
        agent.mCorridor.movePosition(wanted.data(), &ioQuery, &filter);
        agent.SetHeightFromSurface(ioQuery);
        agent.mVelocity = Flat(agent.Position() - position) / inDeltaTime;
    }
}

std::vector<Crowd::AgentID> Crowd::GetAgents() const
{
    std::vector<AgentID> ids;
    for (uint32_t slot = 0; slot < mAgents.size(); ++slot)
        if (mAgents[slot] != nullptr) ids.push_back(MakeAgentID(slot, mGenerations[slot]));
    return ids;
}

Result<Vec3> Crowd::GetPosition(AgentID inAgent) const
{
    const Agent* agent = Find(inAgent);
    if (agent == nullptr) return MakeError(ErrorCode::InvalidArgument, "agent: no such agent");
    return agent->Position();
}

Result<Vec3> Crowd::GetVelocity(AgentID inAgent) const
{
    const Agent* agent = Find(inAgent);
    if (agent == nullptr) return MakeError(ErrorCode::InvalidArgument, "agent: no such agent");
    return agent->mVelocity;
}

Result<AgentState> Crowd::GetState(AgentID inAgent) const
{
    const Agent* agent = Find(inAgent);
    if (agent == nullptr) return MakeError(ErrorCode::InvalidArgument, "agent: no such agent");
    return agent->mLink ? AgentState::OnOffMeshLink : agent->mState;
}

Result<PathStatus> Crowd::GetPathStatus(AgentID inAgent) const
{
    const Agent* agent = Find(inAgent);
    if (agent == nullptr) return MakeError(ErrorCode::InvalidArgument, "agent: no such agent");
    return agent->mPathStatus;
}

Result<OffMeshLinkCrossing> Crowd::GetOffMeshLink(AgentID inAgent) const
{
    const Agent* agent = Find(inAgent);
    if (agent == nullptr) return MakeError(ErrorCode::InvalidArgument, "agent: no such agent");
    if (!agent->mLink) return MakeError(ErrorCode::InvalidArgument, "agent: not on an off-mesh link");
    return agent->mLink->GetCrossing();
}

Status Crowd::CompleteOffMeshLink(AgentID inAgent)
{
    Agent* agent = Find(inAgent);
    if (agent == nullptr) return MakeError(ErrorCode::InvalidArgument, "agent: no such agent");
    if (!agent->mLink) return MakeError(ErrorCode::InvalidArgument, "agent: not on an off-mesh link");
    if (!agent->mLink->GetCrossing().mAtStart)
        return MakeError(ErrorCode::InvalidArgument, "agent: not at its off-mesh link's start yet");
    agent->mLink.reset(); // At its corridor's place now: the link's end
    agent->mVelocity.setZero();
    return Status::Ok();
}

Result<float> Crowd::GetRadius(AgentID inAgent) const
{
    const Agent* agent = Find(inAgent);
    if (agent == nullptr) return MakeError(ErrorCode::InvalidArgument, "agent: no such agent");
    return agent->mParams.mRadius;
}

Result<std::vector<uint64_t>> Crowd::GetCorridor(AgentID inAgent) const
{
    const Agent* agent = Find(inAgent);
    if (agent == nullptr) return MakeError(ErrorCode::InvalidArgument, "agent: no such agent");
    const dtPathCorridor& corridor = agent->mCorridor;
    if (corridor.getFirstPoly() == 0) return std::vector<uint64_t>(); // Off the navmesh
    return std::vector<uint64_t>(corridor.getPath(), corridor.getPath() + corridor.getPathCount());
}

} // namespace cairn::navmesh
