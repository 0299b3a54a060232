#include "Agents.h"

#include "HutLadders.h"
#include "common/Mix64.h"
#include "common/ThreadSwitches.h"

#include <DetourNavMesh.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <unordered_map>

namespace cairn::demo
{
using namespace cairn::physics;
using tools::Mix64;

namespace
{
using Clock = std::chrono::steady_clock;

constexpr float cWanderRadius = 15.0f;   ///< Goals within this of the agent, reachable from where it stands
constexpr float cFollowDistance = 25.0f; ///< Further from its place by the player, the agent follows
/// How far the player's way a follower heads while the player's tiles are not built (inside the navmesh)
constexpr float cFollowStep = 15.0f;
constexpr float cCatchUpDistance = 50.0f; ///< An agent this far from its place is put back there
constexpr uint32_t cCompanionEvery = 20;  ///< One agent in this many follows the player; the others wander
/// One human in this many may not climb (a pack animal, a child): it follows the human crowd's no-climbing
/// filter, so its paths, goals and moves keep off the huts' ladders
constexpr uint32_t cNonClimberEvery = 5;
constexpr int cNoClimbingFilter = 1;         ///< The human crowd's filter index of those that may not climb
constexpr int cPlacementTries = 4;           ///< Spots tried for an agent put back, the first free one taken
constexpr float cPlacementSpread = 6.0f;     ///< m round its place
constexpr float cGoalSeconds = 15.0f;        ///< A goal not reached in this long is given up for another
constexpr float cFollowRepathSeconds = 2.0f; ///< The player moves on: a follower's goal is renewed this often
constexpr float cRetrySeconds = 0.25f;       ///< Wait after finding no goal
constexpr float cStuckSeconds = 5.0f;        ///< Moving under cStuckMetres in this long is being stuck
constexpr float cStuckMetres = 1.0f;
constexpr uint32_t cCheckPeriodFrames = 30; ///< Each agent is checked against static bodies this often
constexpr uint32_t cOverlapPeriodFrames = 10;
constexpr uint32_t cCorridorPeriodFrames = 60;
constexpr uint32_t cTrailPeriodFrames = 15;
constexpr size_t cMaxTrails = 48;
constexpr uint32_t cAgentsPerChunk = 64;

double MillisecondsSince(Clock::time_point inStart)
{
    return std::chrono::duration<double, std::milli>(Clock::now() - inStart).count();
}

float FlatDistance(const Vec3& inA, const Vec3& inB)
{
    return std::hypot(inA.x() - inB.x(), inA.z() - inB.z());
}

/// A cell of a grid in the ground plane, as one key.
uint64_t CellKey(int32_t inX, int32_t inZ)
{
    return uint64_t(uint32_t(inX)) << 32 | uint32_t(inZ);
}

/// The cell of inCellSize metres that holds inPosition.
uint64_t CellKeyAt(const Vec3& inPosition, float inCellSize)
{
    return CellKey(int32_t(std::floor(inPosition.x() / inCellSize)),
                   int32_t(std::floor(inPosition.z() / inCellSize)));
}
} // namespace

struct Agents::Agent
{
    uint8_t mProfile = 0;
    bool mCompanion = false; ///< Follows the player (else it wanders where it is)
    bool mMayClimb = true;   ///< Else it follows cNoClimbingFilter: no ladder
    navmesh::Crowd::AgentID mID = 0;
    Vec3 mHome = Vec3::Zero(); ///< Its place relative to the player (x, z)
    bool mHasGoal = false;
    bool mFollowing = false;
    float mGoalSeconds = 0.0f;  ///< Since its goal was set
    float mRetrySeconds = 0.0f; ///< Until it looks for a goal again, after finding none
    Vec3 mProgressFrom = Vec3::Zero();
    float mProgressSeconds = 0.0f;
    Vec3 mLastPosition = Vec3::Zero();
    uint32_t mOffNavMeshFrames = 0;
};

struct Agents::Action
{
    enum class Kind : uint8_t
    {
        None,
        Goal,    ///< Head for mPoint
        NoGoal,  ///< Wanted a goal and found none
        CatchUp, ///< Put back at mPoint, then a goal from there
    };
    Kind mKind = Kind::None;
    Vec3 mPoint = Vec3::Zero();
    /// CatchUp: spots to put it (random navmesh points round its place), mPoint where none was found
    std::array<Vec3, cPlacementTries> mSpots;
    int mNumSpots = 0;
    bool mFollowing = false;
    bool mStuck = false;
    // The checks of the run
    bool mChecked = false;
    bool mInsideStatic = false;
    bool mOnForbiddenLadder = false; ///< On a ladder it may not climb
    float mWalked = 0.0f;
    bool mOffNavMesh = false;
};

Agents::Agents(PhysicsSystem& ioPhysics, const WorldGenerator& inGenerator, const TileStreamer& inStreamer,
               const Profile& inHuman, const Profile& inLarge, int inCount, uint64_t inSeed)
    : mPhysics(ioPhysics), mGenerator(inGenerator), mStreamer(inStreamer), mProfiles{inHuman, inLarge},
      mSeed(inSeed)
{
    for (int profile = 0; profile < 2; ++profile)
    {
        navmesh::Crowd::Settings settings;
        settings.mMaxAgents = std::max(1, inCount);
        settings.mAvoidancePeriod = 2; // Avoidance planned at 30 Hz, agents moved at 60
        Result<std::unique_ptr<navmesh::Crowd>> crowd =
            navmesh::Crowd::Create(*mProfiles[profile].mNavMesh, settings);
        if (!crowd)
        {
            mStats.mErrors.push_back("crowd: " + crowd.GetError().mMessage);
            return;
        }
        mCrowds[profile] = std::move(crowd).Value();
        // Crates and balls knocked about are avoided as they move (the navmesh learns of them only when
        // they come to rest and a tile is rebuilt: the sleeping ones are in it)
        mCrowds[profile]->SetPhysicsObstacles(&mPhysics, ObjectLayerMask(1) << Layers::cMoving,
                                              navmesh::Crowd::Obstacles::AwakeOnly);
        if (Status noClimbing = mCrowds[profile]->SetFilter(cNoClimbingFilter, NoClimbing()); !noClimbing)
            mStats.mErrors.push_back("crowd: " + noClimbing.GetError().mMessage);
    }
    // Humans and large agents walk the same ground: each crowd avoids the other's agents
    if (mCrowds[0] != nullptr && mCrowds[1] != nullptr)
    {
        mCrowds[0]->SetOtherCrowds({mCrowds[1].get()});
        mCrowds[1]->SetOtherCrowds({mCrowds[0].get()});
    }
    const float homeRadius = HomeRadius(inCount);
    const Vec3 start = mGenerator.GetPlayerPosition(0.0f);
    mAgents.resize(size_t(std::max(0, inCount)));
    mActions.resize(mAgents.size());
    for (uint32_t i = 0; i < mAgents.size(); ++i)
    {
        Agent& agent = mAgents[i];
        agent.mProfile = i % 10 == 9 ? 1 : 0; // One in ten large
        agent.mCompanion = i % cCompanionEvery == 0;
        agent.mMayClimb = !(agent.mProfile == 0 && i % cNonClimberEvery == 3);
        mStats.mNonClimbers += agent.mMayClimb ? 0 : 1;
        const uint64_t random = Mix64(mSeed ^ Mix64(i));
        const float angle = float(random & 0xffffff) / float(1 << 24) * 2.0f * std::numbers::pi_v<float>;
        const float distance = homeRadius * std::sqrt(float((random >> 24) & 0xffffff) / float(1 << 24));
        agent.mHome = Vec3(distance * std::cos(angle), 0.0f, distance * std::sin(angle));
        // On the navmesh near its place (the loading screen built it); where there is none, at the start
        const Vec3 place = start + agent.mHome;
        const Vec3 ground(place.x(), mGenerator.GetTerrainHeight(place.x(), place.z()), place.z());
        Result<Vec3> onNavMesh =
            mProfiles[agent.mProfile].mNavMesh->FindNearestPoint(ground, {}, Vec3(4.0f, 8.0f, 4.0f));
        AddAgent(i, onNavMesh ? onNavMesh.Value() : start);
        if (mTrailAgents.size() < cMaxTrails &&
            i % std::max<uint32_t>(1, uint32_t(inCount) / cMaxTrails) == 0)
            mTrailAgents.push_back(i);
    }
    mStats.mTrails.resize(mTrailAgents.size());
    for (uint32_t index : mTrailAgents)
        mStats.mTrailRadii.push_back(mProfiles[mAgents[index].mProfile].mRadius);
}

Agents::~Agents() = default;

float Agents::HomeRadius(int inCount)
{
    // Their places by the player: spread over a disc of 10 m^2 an agent (a busy street), at most 100 m across
    // the radius (3 m^2 an agent for 10,000), well inside the loaded world
    return std::clamp(std::sqrt(float(std::max(0, inCount)) * 10.0f / std::numbers::pi_v<float>), 8.0f,
                      100.0f);
}

float Agents::NavMeshRadius(int inCount)
{
    return HomeRadius(inCount) + cCatchUpDistance + 4.0f;
}

void Agents::AddAgent(uint32_t inIndex, const Vec3& inPosition)
{
    Agent& agent = mAgents[inIndex];
    navmesh::Crowd* crowd = mCrowds[agent.mProfile].get();
    if (crowd == nullptr) return;
    navmesh::AgentParams params;
    params.mRadius = mProfiles[agent.mProfile].mRadius;
    params.mFilter = agent.mMayClimb ? 0 : cNoClimbingFilter;
    Result<navmesh::Crowd::AgentID> id = crowd->AddAgent(inPosition, params);
    if (!id)
    {
        if (mStats.mErrors.size() < 20) mStats.mErrors.push_back("add agent: " + id.GetError().mMessage);
        return;
    }
    agent.mID = id.Value();
    agent.mHasGoal = false;
    agent.mProgressFrom = agent.mLastPosition = crowd->GetPosition(agent.mID).Value();
    agent.mProgressSeconds = 0.0f;
}

bool Agents::StaticBodiesAt(const Vec3& inPosition, std::vector<BodyID>& outBodies) const
{
    QueryFilter filter;
    filter.mObjectLayers = ObjectLayerMask(1) << Layers::cStatic;
    if (!mPhysics.GetWorldQuery().CollideSphere(inPosition + Vec3(0.0f, cChestProbeHeight, 0.0f),
                                                cChestProbeRadius, outBodies, filter))
        return false;
    std::erase_if(outBodies, [&](const BodyID& inBody) { return mStreamer.IsTerrain(inBody); });
    return true;
}

bool Agents::InsideStatic(const Vec3& inPosition) const
{
    std::vector<BodyID> bodies;
    // A spot that cannot be checked is not known to be clear: it counts against the invariant
    return !StaticBodiesAt(inPosition, bodies) || !bodies.empty();
}

std::string Agents::DescribeStaticAt(const Vec3& inPosition) const
{
    std::vector<BodyID> bodies;
    if (!StaticBodiesAt(inPosition, bodies)) return " (the query failed)";
    std::string text;
    for (const BodyID& body : bodies)
        if (const Result<AABB> bounds = mPhysics.GetBodyInterface().GetWorldBounds(body))
            text += " (a body from " + std::to_string(bounds.Value().mMin.x()) + ", " +
                    std::to_string(bounds.Value().mMin.y()) + ", " + std::to_string(bounds.Value().mMin.z()) +
                    " to " + std::to_string(bounds.Value().mMax.x()) + ", " +
                    std::to_string(bounds.Value().mMax.y()) + ", " + std::to_string(bounds.Value().mMax.z()) +
                    ")";
    return text;
}

void Agents::Decide(uint32_t inIndex, const Vec3& inPlayer, Action& outAction) const
{
    const Agent& agent = mAgents[inIndex];
    const navmesh::Crowd& crowd = *mCrowds[agent.mProfile];
    const navmesh::NavMeshWorld& navMesh = *mProfiles[agent.mProfile].mNavMesh;
    const Vec3 position = crowd.GetPosition(agent.mID).Value();
    const navmesh::AgentState state = crowd.GetState(agent.mID).Value();
    const Vec3 home = inPlayer + agent.mHome;
    const float toHome = FlatDistance(position, home);
    const uint64_t seed = Mix64(Mix64(mSeed ^ mFrame) + inIndex);
    auto ground = [&](float inX, float inZ) { return mGenerator.GetTerrainHeight(inX, inZ); };
    outAction = Action{};
    if (toHome > cCatchUpDistance)
    {
        // Left behind: put back on the navmesh near its place by the player, as a game's population is
        // moved from behind the player to ahead of it; spots to try, the first free one is taken (serially)
        Result<Vec3> near = FollowGoal(navMesh, home, home, 0.0f, ground);
        if (!near) return; // Not built there yet: it keeps walking and is asked again next frame
        outAction.mKind = Action::Kind::CatchUp;
        outAction.mPoint = near.Value();
        for (int k = 0; k < cPlacementTries; ++k)
            if (Result<Vec3> spot =
                    navMesh.FindRandomPointAround(near.Value(), cPlacementSpread, seed + uint64_t(k)))
                outAction.mSpots[size_t(outAction.mNumSpots++)] = spot.Value();
        return;
    }
    if (state == navmesh::AgentState::OffNavMesh || agent.mRetrySeconds > 0.0f) return;
    const bool moving = state == navmesh::AgentState::Moving ||
                        state == navmesh::AgentState::WaitingForPath ||
                        state == navmesh::AgentState::OnOffMeshLink;
    outAction.mStuck = moving && agent.mProgressSeconds >= cStuckSeconds &&
                       FlatDistance(position, agent.mProgressFrom) < cStuckMetres;
    const bool following = agent.mCompanion && toHome > cFollowDistance;
    const bool wantsGoal =
        !agent.mHasGoal || !moving || outAction.mStuck || agent.mGoalSeconds > cGoalSeconds ||
        (following && agent.mGoalSeconds > cFollowRepathSeconds) || (agent.mFollowing && !following);
    if (!wantsGoal) return;
    const Result<Vec3> goal =
        following ? FollowGoal(navMesh, position, home, cFollowStep, ground)
                  : navMesh.FindRandomPointAround(position, cWanderRadius, seed,
                                                  agent.mMayClimb ? navmesh::PathFilter{} : NoClimbing());
    outAction.mKind = goal ? Action::Kind::Goal : Action::Kind::NoGoal;
    if (goal) outAction.mPoint = goal.Value();
    outAction.mFollowing = following;
}

void Agents::Update(float inDeltaTime, const Vec3& inPlayer, jobs::JobInterface& ioJobs)
{
    if (mCrowds[0] == nullptr || mCrowds[1] == nullptr) return;
    const uint32_t count = uint32_t(mAgents.size());
    double mainMs = 0.0, jobMs = 0.0;
    // Read before the first clock read and after the last, so the reads stay out of the timed work
    const int64_t switchesBefore = mWatchedThreads.empty() ? -1 : tools::InvoluntarySwitches(mWatchedThreads);

    // What each agent does, on the job threads
    Clock::time_point start = Clock::now();
    ioJobs.ParallelFor(count, cAgentsPerChunk,
                       [&](uint32_t inBegin, uint32_t inEnd)
                       {
                           for (uint32_t i = inBegin; i < inEnd; ++i)
                               Decide(i, inPlayer, mActions[i]);
                       });
    jobMs += MillisecondsSince(start);
    mStats.mGoalPickingMs.push_back(jobMs);

    // Applied in agent order, so the crowds' queues get the same requests in the same order every run
    start = Clock::now();
    mOccupiedValid = false; // Made when the first agent of this frame is put back
    for (uint32_t i = 0; i < count; ++i)
    {
        Agent& agent = mAgents[i];
        const Action& action = mActions[i];
        navmesh::Crowd& crowd = *mCrowds[agent.mProfile];
        agent.mGoalSeconds += inDeltaTime;
        agent.mRetrySeconds = std::max(0.0f, agent.mRetrySeconds - inDeltaTime);
        agent.mProgressSeconds += inDeltaTime;
        if (action.mStuck)
            ++mStats.mStuck;
        else if (action.mKind == Action::Kind::Goal && agent.mHasGoal && !agent.mFollowing &&
                 agent.mGoalSeconds > cGoalSeconds)
            ++mStats.mGoalTimeouts;
        switch (action.mKind)
        {
        case Action::Kind::None:
            break;
        case Action::Kind::NoGoal:
            ++mStats.mGoalsNotFound;
            agent.mRetrySeconds = cRetrySeconds;
            break;
        case Action::Kind::CatchUp:
            (void)crowd.RemoveAgent(agent.mID); // Its own, known to the crowd
            AddAgent(i, FreeSpot(action));
            ++mStats.mCatchUps;
            // Its trail breaks here: it was put back, it did not walk
            for (size_t t = 0; t < mTrailAgents.size(); ++t)
                if (mTrailAgents[t] == i) mStats.mTrails[t].push_back(Vec3::Constant(std::nanf("")));
            break;
        case Action::Kind::Goal:
            if (Status set = crowd.SetTarget(agent.mID, action.mPoint); !set)
            {
                if (mStats.mErrors.size() < 20) mStats.mErrors.push_back("goal: " + set.GetError().mMessage);
                break;
            }
            ++mStats.mGoalsSet;
            agent.mHasGoal = true;
            agent.mFollowing = action.mFollowing;
            agent.mGoalSeconds = 0.0f;
            break;
        }
        if (agent.mProgressSeconds >= cStuckSeconds)
        {
            agent.mProgressFrom = crowd.GetPosition(agent.mID).Value();
            agent.mProgressSeconds = 0.0f;
        }
    }
    mainMs += MillisecondsSince(start);

    // The crowds: each its path budget, results and corridor checks here, the steering on the job threads
    for (const std::unique_ptr<navmesh::Crowd>& crowd : mCrowds)
    {
        const navmesh::Crowd::Statistics before = crowd->GetStatistics();
        if (Status updated = crowd->Update(inDeltaTime, &ioJobs); !updated && mStats.mErrors.size() < 20)
            mStats.mErrors.push_back("crowd: " + updated.GetError().mMessage);
        mainMs += crowd->GetStatistics().mLastSerialMs;
        jobMs += crowd->GetStatistics().mLastMoveMs;
        mStats.mReplans += crowd->GetStatistics().mReplans - before.mReplans;
        mStats.mLinksTaken += crowd->GetStatistics().mLinksTaken - before.mLinksTaken;
    }
    const int64_t switchesAfter = mWatchedThreads.empty() ? -1 : tools::InvoluntarySwitches(mWatchedThreads);
    mStats.mMainThreadMs.push_back(mainMs);
    mStats.mJobThreadsMs.push_back(jobMs);
    mStats.mOtherTaskSwitches.push_back(
        switchesBefore < 0 || switchesAfter < 0 ? -1 : switchesAfter - switchesBefore);

    // The checks of the run, not navigation work: each agent's own, on the job threads
    ioJobs.ParallelFor(count, cAgentsPerChunk,
                       [&](uint32_t inBegin, uint32_t inEnd)
                       {
                           for (uint32_t i = inBegin; i < inEnd; ++i)
                           {
                               const Agent& agent = mAgents[i];
                               const navmesh::Crowd& crowd = *mCrowds[agent.mProfile];
                               Action& action = mActions[i];
                               const Vec3 position = crowd.GetPosition(agent.mID).Value();
                               action.mWalked = FlatDistance(position, agent.mLastPosition);
                               const navmesh::AgentState state = crowd.GetState(agent.mID).Value();
                               action.mOffNavMesh = state == navmesh::AgentState::OffNavMesh;
                               // On a ladder it climbs over the hut's wall: not a place it walks to
                               action.mChecked = (i + mFrame) % cCheckPeriodFrames == 0 &&
                                                 state != navmesh::AgentState::OnOffMeshLink;
                               action.mInsideStatic = action.mChecked && InsideStatic(position);
                               action.mOnForbiddenLadder =
                                   !agent.mMayClimb && state == navmesh::AgentState::OnOffMeshLink &&
                                   crowd.GetOffMeshLink(agent.mID).Value().mArea == cLadderArea;
                           }
                       });
    for (uint32_t i = 0; i < count; ++i)
    {
        Agent& agent = mAgents[i];
        const Action& action = mActions[i];
        const navmesh::AgentState state = mCrowds[agent.mProfile]->GetState(agent.mID).Value();
        if (state == navmesh::AgentState::Arrived && agent.mHasGoal)
        {
            ++mStats.mArrivals;
            agent.mHasGoal = false; // Counted once; a new goal next frame
        }
        mStats.mDistance += action.mWalked;
        agent.mLastPosition = mCrowds[agent.mProfile]->GetPosition(agent.mID).Value();
        ++mStats.mAgentFrames;
        if (action.mOffNavMesh)
        {
            ++mStats.mOffNavMeshFrames;
            if (++agent.mOffNavMeshFrames == 61) ++mStats.mOffNavMeshOverOneSecond;
            mStats.mLongestOffNavMeshFrames =
                std::max(mStats.mLongestOffNavMeshFrames, agent.mOffNavMeshFrames);
        }
        else
            agent.mOffNavMeshFrames = 0;
        mStats.mInsideStaticChecks += action.mChecked ? 1 : 0;
        mStats.mInsideStatic += action.mInsideStatic ? 1 : 0;
        mStats.mNonClimberLadderFrames += action.mOnForbiddenLadder ? 1 : 0;
        if (action.mInsideStatic && mStats.mErrors.size() < 20)
        {
            const Vec3 p = agent.mLastPosition;
            mStats.mErrors.push_back("frame " + std::to_string(mFrame) + ": agent " + std::to_string(i) +
                                     " (profile " + std::to_string(agent.mProfile) + ", state " +
                                     std::to_string(int(state)) + ") inside a static body at " +
                                     std::to_string(p.x()) + ", " + std::to_string(p.y()) + ", " +
                                     std::to_string(p.z()) + DescribeStaticAt(p));
        }
    }
    if (mFrame % cOverlapPeriodFrames == 0)
    {
        mStats.mOverlapChecks += count;
        mStats.mOverlapping += CountOverlapping();
    }
    if (mFrame % cCorridorPeriodFrames == 0) mStats.mCorridorsThroughGone += CountCorridorsThroughGone();
    if (mFrame % cTrailPeriodFrames == 0)
        for (size_t t = 0; t < mTrailAgents.size(); ++t)
            mStats.mTrails[t].push_back(mAgents[mTrailAgents[t]].mLastPosition);
    ++mFrame;
}

Vec3 Agents::FreeSpot(const Action& inAction)
{
    if (!mOccupiedValid)
    {
        // Where the agents stand now, by cell of cOccupiedCell metres
        mOccupied.clear();
        for (const Agent& agent : mAgents)
            if (const Result<Vec3> position = mCrowds[agent.mProfile]->GetPosition(agent.mID))
                mOccupied.push_back({CellKeyAt(position.Value(), cOccupiedCell), position.Value()});
        std::sort(mOccupied.begin(), mOccupied.end(),
                  [](const auto& inA, const auto& inB) { return inA.first < inB.first; });
        mOccupiedValid = true;
    }
    for (int k = 0; k < inAction.mNumSpots; ++k)
    {
        const Vec3& spot = inAction.mSpots[size_t(k)];
        bool free = true;
        const int32_t cx = int32_t(std::floor(spot.x() / cOccupiedCell)),
                      cz = int32_t(std::floor(spot.z() / cOccupiedCell));
        for (int32_t dx = -1; dx <= 1 && free; ++dx)
            for (int32_t dz = -1; dz <= 1 && free; ++dz)
            {
                const uint64_t key = CellKey(cx + dx, cz + dz);
                auto it = std::lower_bound(mOccupied.begin(), mOccupied.end(), key,
                                           [](const auto& inEntry, uint64_t inKey)
                                           { return inEntry.first < inKey; });
                for (; it != mOccupied.end() && it->first == key && free; ++it)
                    free = FlatDistance(it->second, spot) >= cOccupiedCell;
            }
        if (free)
        {
            // Taken now: the next agent put back this frame does not land on it
            const uint64_t key = CellKeyAt(spot, cOccupiedCell);
            mOccupied.insert(std::upper_bound(mOccupied.begin(), mOccupied.end(), key,
                                              [](uint64_t inKey, const auto& inEntry)
                                              { return inKey < inEntry.first; }),
                             {key, spot});
            return spot;
        }
    }
    return inAction.mNumSpots > 0 ? inAction.mSpots[0] : inAction.mPoint;
}

uint64_t Agents::CountOverlapping() const
{
    // A grid of 4 m cells (twice the largest radius) over every agent of both crowds
    struct Entry
    {
        Vec3 mPosition;
        float mRadius;
    };
    std::vector<Entry> entries;
    entries.reserve(mAgents.size());
    std::unordered_map<uint64_t, std::vector<uint32_t>> cells;
    constexpr float cell = 4.0f;
    for (const Agent& agent : mAgents)
    {
        const Vec3 position = mCrowds[agent.mProfile]->GetPosition(agent.mID).Value();
        cells[CellKeyAt(position, cell)].push_back(uint32_t(entries.size()));
        entries.push_back({position, mProfiles[agent.mProfile].mRadius});
    }
    uint64_t overlapping = 0;
    for (uint32_t i = 0; i < entries.size(); ++i)
    {
        const Entry& a = entries[i];
        const int32_t cx = int32_t(std::floor(a.mPosition.x() / cell)),
                      cz = int32_t(std::floor(a.mPosition.z() / cell));
        bool found = false;
        for (int32_t dx = -1; dx <= 1 && !found; ++dx)
            for (int32_t dz = -1; dz <= 1 && !found; ++dz)
            {
                const auto it = cells.find(CellKey(cx + dx, cz + dz));
                if (it == cells.end()) continue;
                for (uint32_t j : it->second)
                {
                    if (j == i) continue;
                    const Entry& b = entries[j];
                    // Agents of the two profiles walk separate navmeshes but the same ground: they count too
                    if (std::abs(a.mPosition.y() - b.mPosition.y()) > 1.5f) continue; // Another floor
                    const float depth = a.mRadius + b.mRadius - FlatDistance(a.mPosition, b.mPosition);
                    if (depth > 0.1f * std::min(a.mRadius, b.mRadius))
                    {
                        found = true;
                        break;
                    }
                }
            }
        overlapping += found ? 1 : 0;
    }
    return overlapping;
}

uint64_t Agents::CountCorridorsThroughGone() const
{
    uint64_t gone = 0;
    for (int profile = 0; profile < 2; ++profile)
        mProfiles[profile].mNavMesh->Read(
            [&](const dtNavMesh& inNavMesh)
            {
                for (const Agent& agent : mAgents)
                {
                    if (agent.mProfile != profile) continue;
                    const Result<std::vector<uint64_t>> corridor = mCrowds[profile]->GetCorridor(agent.mID);
                    if (!corridor) continue;
                    for (uint64_t polygon : corridor.Value())
                        if (!inNavMesh.isValidPolyRef(dtPolyRef(polygon)))
                        {
                            ++gone;
                            break;
                        }
                }
            });
    return gone;
}

void Agents::FinishStats()
{
    std::array<uint64_t, 65> waits{};
    for (const std::unique_ptr<navmesh::Crowd>& crowd : mCrowds)
    {
        if (crowd == nullptr) continue;
        const navmesh::PathRequestQueue::Statistics& paths = crowd->GetPathQueue().GetStatistics();
        mStats.mPathsRequested += paths.mRequested;
        mStats.mPathsServed += paths.mServed;
        mStats.mPathsFailed += paths.mFailed;
        mStats.mPathWaitMaxFrames = std::max(mStats.mPathWaitMaxFrames, paths.mWaitUpdatesMax);
        for (size_t w = 0; w < waits.size(); ++w)
            waits[w] += paths.mWaitHistogram[w];
    }
    uint64_t total = 0;
    for (uint64_t n : waits)
        total += n;
    uint64_t seen = 0;
    for (size_t w = 0; w < waits.size() && total > 0; ++w)
    {
        seen += waits[w];
        if (seen * 100 >= total * 99)
        {
            mStats.mPathWaitP99Frames = w;
            break;
        }
    }
}

} // namespace cairn::demo
