// Crowd agents over off-mesh links: an agent whose path jumps a gap walks to the link, along it and on to its
// goal, either way over a two-way link and down a one-way drop; an agent the game crosses is held at the
// link's start until the game says it is over; an agent on a link lands on the navmesh as it is when the far
// side was rebuilt meanwhile; a removed link is no longer walked to.

#include "NavMeshSceneFixture.h"
#include "cairn/navmesh/Crowd.h"

#include <DetourNavMesh.h>
#include <optional>

namespace cairn::navmesh::test
{
using namespace cairn::physics;
namespace
{

constexpr float cFrame = 1.0f / 60.0f;
constexpr uint32_t cJumpID = 77;

class CrowdOffMeshLinkTest : public NavMeshSceneFixture
{
protected:
    /// Two platforms 3 m apart across x = 0 (a gap no agent walks), in different tiles; the near one inHigh
    /// metres higher. A link from x = -2.5 to x = 2.5 along z = 0, in area inArea.
    TileScheduler::LinkID BuildGapWithLink(bool inBidirectional, float inHigh = 0.0f,
                                           uint8_t inArea = cDefaultArea)
    {
        AddStaticBox(Vec3(-6, inHigh - 0.5f, 0), Vec3(4.5f, 0.5f, 4)); // x in [-10.5, -1.5]
        AddStaticBox(Vec3(6, -0.5f, 0), Vec3(4.5f, 0.5f, 4));          // x in [1.5, 10.5]
        MakeNavMesh();
        OffMeshLink jump;
        jump.mStart = Vec3(-2.5f, inHigh, 0);
        jump.mEnd = Vec3(2.5f, 0, 0);
        jump.mRadius = 0.6f;
        jump.mBidirectional = inBidirectional;
        jump.mUserID = cJumpID;
        jump.mArea = inArea;
        const TileScheduler::LinkID link = mScheduler->AddOffMeshLink(jump).Value();
        EXPECT_TRUE(RunUntilIdle());
        return link;
    }

    /// Whether inPosition stands on the navmesh (within a few centimetres of its surface).
    bool OnNavMesh(const Vec3& inPosition) const
    {
        const Result<Vec3> nearest = mWorld->FindNearestPoint(inPosition, {}, Vec3(0.1f, 0.5f, 0.1f));
        return nearest && (nearest.Value() - inPosition).norm() < 0.05f;
    }

    /// An agent at (-8, 0, 0) whose links the game crosses, on its way to (8, 0, 0).
    static Crowd::AgentID AddAgentTheGameCrosses(Crowd& ioCrowd)
    {
        AgentParams params;
        params.mLinkMode = OffMeshLinkMode::ByGame;
        const Crowd::AgentID agent = ioCrowd.AddAgent(Vec3(-8, 0, 0), params).Value();
        EXPECT_TRUE(ioCrowd.SetTarget(agent, Vec3(8, 0, 0)).IsOk());
        return agent;
    }

    /// What an agent walking from inFrom to inTo over the link did, Update by Update.
    struct Walk
    {
        int mUpdatesOnLink = 0;
        int mUpdatesAlongLink = 0; ///< Of those, on the link itself (past its start)
        OffMeshLinkCrossing mLink;
        float mWorstOffLinkLine = 0.0f;  ///< m: the farthest from the link's line while along it
        float mWorstSpeedOverMax = 0.0f; ///< m/s over the agent's top speed while on the link
        int mOffNavMeshElsewhere = 0;    ///< Updates off the navmesh while not on the link
        float mSlowest = 1e9f; ///< m/s: the slowest Update from full speed to 10 Updates after landing
        AgentState mFinalState = AgentState::Idle;
        PathStatus mFinalPathStatus = PathStatus::None;
        Vec3 mFinalPosition = Vec3::Zero();
    };

    Walk WalkOver(const Vec3& inFrom, const Vec3& inTo, int inUpdates = 600)
    {
        std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
        const Crowd::AgentID agent = crowd->AddAgent(inFrom).Value();
        EXPECT_TRUE(crowd->SetTarget(agent, inTo).IsOk());
        const float maxSpeed = AgentParams().mMaxSpeed;
        Walk walk;
        Vec3 previous = crowd->GetPosition(agent).Value();
        bool atSpeed = false, wasOnLink = false;
        int landedAt = -1;
        for (int update = 0; update < inUpdates; ++update)
        {
            EXPECT_TRUE(crowd->Update(cFrame).IsOk());
            const Vec3 position = crowd->GetPosition(agent).Value();
            const bool onLink = crowd->GetState(agent).Value() == AgentState::OnOffMeshLink;
            // From full speed to the link's end, and for 10 Updates after the one it lands in (a part of a
            // step), it keeps its pace
            const float speed = (position - previous).norm() / cFrame;
            if (wasOnLink && !onLink) landedAt = update;
            wasOnLink = onLink;
            atSpeed |= speed >= 0.99f * maxSpeed;
            if (atSpeed && update != landedAt && (landedAt < 0 || update <= landedAt + 10))
                walk.mSlowest = std::min(walk.mSlowest, speed);
            if (onLink)
            {
                ++walk.mUpdatesOnLink;
                walk.mLink = crowd->GetOffMeshLink(agent).Value();
                walk.mWorstSpeedOverMax =
                    std::max(walk.mWorstSpeedOverMax, (position - previous).norm() / cFrame - maxSpeed);
                if (walk.mLink.mAtStart)
                {
                    ++walk.mUpdatesAlongLink;
                    const Vec3 along = walk.mLink.mEnd - walk.mLink.mStart;
                    const Vec3 offset = position - walk.mLink.mStart;
                    const float t = std::clamp(offset.dot(along) / along.squaredNorm(), 0.0f, 1.0f);
                    walk.mWorstOffLinkLine = std::max(walk.mWorstOffLinkLine, (offset - along * t).norm());
                }
            }
            else if (!OnNavMesh(position))
                ++walk.mOffNavMeshElsewhere;
            previous = position;
        }
        walk.mFinalState = crowd->GetState(agent).Value();
        walk.mFinalPathStatus = crowd->GetPathStatus(agent).Value();
        walk.mFinalPosition = crowd->GetPosition(agent).Value();
        EXPECT_EQ(crowd->GetStatistics().mLinksTaken, walk.mUpdatesOnLink > 0 ? 1u : 0u);
        return walk;
    }

    static void ExpectCrossed(const Walk& inWalk, const Vec3& inStart, const Vec3& inEnd, const Vec3& inGoal)
    {
        EXPECT_GT(inWalk.mUpdatesAlongLink, 0) << "it took the link";
        EXPECT_LT((inWalk.mLink.mStart - inStart).norm(), 0.3f);
        EXPECT_LT((inWalk.mLink.mEnd - inEnd).norm(), 0.3f);
        EXPECT_EQ(inWalk.mLink.mUserID, cJumpID);
        EXPECT_EQ(inWalk.mLink.mArea, cDefaultArea) << "Cairn's area id, not Detour's";
        // Along the link at its top speed: 5 m or more at 3.5 m/s, from its start to its end
        const float length = (inEnd - inStart).norm();
        EXPECT_NEAR(float(inWalk.mUpdatesAlongLink) * cFrame, length / AgentParams().mMaxSpeed, 0.05f);
        EXPECT_LT(inWalk.mWorstOffLinkLine, 0.01f);
        EXPECT_LT(inWalk.mWorstSpeedOverMax, 0.01f);
        EXPECT_GT(inWalk.mSlowest, 0.95f * AgentParams().mMaxSpeed) << "it slowed at the link";
        EXPECT_EQ(inWalk.mOffNavMeshElsewhere, 0);
        EXPECT_EQ(inWalk.mFinalState, AgentState::Arrived);
        EXPECT_EQ(inWalk.mFinalPathStatus, PathStatus::Complete);
        EXPECT_LT((inWalk.mFinalPosition - inGoal).norm(), AgentParams().mRadius);
    }
};

// Across the gap over a two-way link, then back over it the other way
TEST_F(CrowdOffMeshLinkTest, AnAgentJumpsAGapOverALinkEitherWay)
{
    BuildGapWithLink(true);
    const Vec3 west(-8, 0, 1), east(8, 0, -1);
    ExpectCrossed(WalkOver(west, east), Vec3(-2.5f, 0, 0), Vec3(2.5f, 0, 0), east);
    ExpectCrossed(WalkOver(east, west), Vec3(2.5f, 0, 0), Vec3(-2.5f, 0, 0), west);
}

// Down a one-way drop from a platform 2 m higher: it comes down along the link and lands on the lower
// navmesh; it cannot go back up (it walks to the nearest point it can reach, on its own side)
TEST_F(CrowdOffMeshLinkTest, AnAgentWhoseFilterComesToExcludeTheLinkAheadStaysOnItsSide)
{
    constexpr uint8_t cJumpArea = 7;
    BuildGapWithLink(true, 0.0f, cJumpArea);
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
    const Crowd::AgentID agent = crowd->AddAgent(Vec3(-8, 0, 0)).Value();
    ASSERT_TRUE(crowd->SetTarget(agent, Vec3(8, 0, 0)).IsOk());
    for (int update = 0; update < 600 && crowd->GetState(agent).Value() != AgentState::OnOffMeshLink;
         ++update)
        ASSERT_TRUE(crowd->Update(cFrame).IsOk());
    ASSERT_EQ(crowd->GetState(agent).Value(), AgentState::OnOffMeshLink);
    ASSERT_FALSE(crowd->GetOffMeshLink(agent).Value().mAtStart) << "on its way to the start";
    // Its filter now excludes the jump: it stops where it is, and the far side is out of its reach
    const Vec3 before = crowd->GetPosition(agent).Value();
    PathFilter noJumping;
    noJumping.mExcludedAreas = uint64_t(1) << cJumpArea;
    ASSERT_TRUE(crowd->SetFilter(0, noJumping).IsOk());
    ASSERT_TRUE(crowd->Update(cFrame).IsOk());
    EXPECT_LT((crowd->GetPosition(agent).Value() - before).norm(), 0.1f) << "no jump to the far side";
    float farthestX = -100.0f;
    for (int update = 0; update < 300; ++update)
    {
        ASSERT_TRUE(crowd->Update(cFrame).IsOk());
        EXPECT_NE(crowd->GetState(agent).Value(), AgentState::OnOffMeshLink);
        farthestX = std::max(farthestX, crowd->GetPosition(agent).Value().x());
    }
    EXPECT_LT(farthestX, -1.5f) << "it never crossed the gap";
    EXPECT_EQ(crowd->GetState(agent).Value(), AgentState::Arrived);
    EXPECT_EQ(crowd->GetPathStatus(agent).Value(), PathStatus::Partial);
    EXPECT_EQ(crowd->GetStatistics().mLinksTaken, 1u) << "taken once, then let go";
}

TEST_F(CrowdOffMeshLinkTest, AnAgentTakesAOneWayDropDown)
{
    BuildGapWithLink(false, 2.0f);
    const Vec3 high(-8, 2, 0), low(8, 0, 0);
    ExpectCrossed(WalkOver(high, low), Vec3(-2.5f, 2, 0), Vec3(2.5f, 0, 0), low);
    const Walk up = WalkOver(low, high, 120);
    EXPECT_EQ(up.mUpdatesOnLink, 0);
    EXPECT_EQ(up.mOffNavMeshElsewhere, 0);
    EXPECT_GT(up.mFinalPosition.x(), 1.5f);
    EXPECT_EQ(up.mFinalState, AgentState::Arrived);
    EXPECT_EQ(up.mFinalPathStatus, PathStatus::Partial) << "short of its target";
}

// The game crosses the link: the agent waits at its start, as long as the game takes, and goes on from the
// link's end when the game says so
TEST_F(CrowdOffMeshLinkTest, AnAgentTheGameCrossesWaitsAtTheStartUntilTheGameIsDone)
{
    BuildGapWithLink(true);
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
    const Crowd::AgentID agent = AddAgentTheGameCrosses(*crowd);
    const Crowd::AgentID walker = crowd->AddAgent(Vec3(-8, 0, 3)).Value(); // On no link, ever
    EXPECT_FALSE(crowd->GetOffMeshLink(agent)) << "on no link yet";
    EXPECT_FALSE(crowd->CompleteOffMeshLink(agent)) << "on no link yet";
    int update = 0;
    for (; update < 600 && crowd->GetState(agent).Value() != AgentState::OnOffMeshLink; ++update)
        ASSERT_TRUE(crowd->Update(cFrame).IsOk());
    ASSERT_FALSE(crowd->GetOffMeshLink(agent).Value().mAtStart) << "it takes the link short of its start";
    EXPECT_FALSE(crowd->CompleteOffMeshLink(agent)) << "not at the start yet";
    for (; update < 600 && !(crowd->GetState(agent).Value() == AgentState::OnOffMeshLink &&
                             crowd->GetOffMeshLink(agent).Value().mAtStart);
         ++update)
        ASSERT_TRUE(crowd->Update(cFrame).IsOk());
    ASSERT_LT(update, 600) << "it reached the link's start";
    const OffMeshLinkCrossing link = crowd->GetOffMeshLink(agent).Value();
    EXPECT_EQ(link.mUserID, cJumpID);
    EXPECT_LT((crowd->GetPosition(agent).Value() - link.mStart).norm(), 1e-4f);

    // The game's animation takes its time: the agent stays at the start, still on the link
    for (int wait = 0; wait < 120; ++wait)
        ASSERT_TRUE(crowd->Update(cFrame).IsOk());
    EXPECT_EQ(crowd->GetState(agent).Value(), AgentState::OnOffMeshLink);
    EXPECT_LT((crowd->GetPosition(agent).Value() - link.mStart).norm(), 1e-4f);
    EXPECT_LT(crowd->GetVelocity(agent).Value().norm(), 1e-4f);

    EXPECT_FALSE(crowd->CompleteOffMeshLink(walker)) << "on no link";
    ASSERT_TRUE(crowd->CompleteOffMeshLink(agent).IsOk());
    EXPECT_LT((crowd->GetPosition(agent).Value() - link.mEnd).norm(), 1e-4f) << "at the link's end at once";
    EXPECT_FALSE(crowd->GetOffMeshLink(agent));
    EXPECT_FALSE(crowd->CompleteOffMeshLink(agent)) << "already done";
    for (int more = 0; more < 600; ++more)
        ASSERT_TRUE(crowd->Update(cFrame).IsOk());
    EXPECT_EQ(crowd->GetState(agent).Value(), AgentState::Arrived);
    EXPECT_LT((crowd->GetPosition(agent).Value() - Vec3(8, 0, 0)).norm(), AgentParams().mRadius);

    ASSERT_TRUE(crowd->RemoveAgent(agent).IsOk());
    EXPECT_FALSE(crowd->GetOffMeshLink(agent)) << "a stale id";
    EXPECT_FALSE(crowd->CompleteOffMeshLink(agent)) << "a stale id";
    EXPECT_FALSE(crowd->GetPathStatus(agent)) << "a stale id";
}

// An agent held on the link while the far side's tile is rebuilt (its corridor's polygons there are gone)
// and its goal changes: it lands on the navmesh as it is now and reaches its new goal; no corridor holds a
// polygon that is gone
TEST_F(CrowdOffMeshLinkTest, AnAgentOnALinkLandsOnTheFarSideAsRebuilt)
{
    BuildGapWithLink(true);
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
    const Crowd::AgentID agent = AddAgentTheGameCrosses(*crowd);
    for (int update = 0; update < 600 && crowd->GetState(agent).Value() != AgentState::OnOffMeshLink;
         ++update)
        ASSERT_TRUE(crowd->Update(cFrame).IsOk());
    ASSERT_EQ(crowd->GetState(agent).Value(), AgentState::OnOffMeshLink);
    const uint64_t landing = crowd->GetCorridor(agent).Value().front();

    mScheduler->MarkDirty(AABB(Vec3(3, -1, -3), Vec3(9, 1, 3)));
    ASSERT_TRUE(RunUntilIdle());
    mWorld->Read([&](const dtNavMesh& inNavMesh)
                 { ASSERT_FALSE(inNavMesh.isValidPolyRef(dtPolyRef(landing))) << "the far side rebuilt"; });
    ASSERT_TRUE(crowd->SetTarget(agent, Vec3(8, 0, 3)).IsOk());
    EXPECT_EQ(crowd->GetPathStatus(agent).Value(), PathStatus::None) << "a new target, no path yet";
    for (int update = 0; update < 30; ++update)
        ASSERT_TRUE(crowd->Update(cFrame).IsOk());
    EXPECT_EQ(crowd->GetState(agent).Value(), AgentState::OnOffMeshLink) << "the game has not finished";
    ASSERT_TRUE(crowd->CompleteOffMeshLink(agent).IsOk());
    for (int update = 0; update < 600; ++update)
    {
        ASSERT_TRUE(crowd->Update(cFrame).IsOk());
        const std::vector<uint64_t> corridor = crowd->GetCorridor(agent).Value();
        mWorld->Read(
            [&](const dtNavMesh& inNavMesh)
            {
                for (uint64_t polygon : corridor)
                    ASSERT_TRUE(inNavMesh.isValidPolyRef(dtPolyRef(polygon))) << "update " << update;
            });
    }
    EXPECT_EQ(crowd->GetState(agent).Value(), AgentState::Arrived);
    EXPECT_LT((crowd->GetPosition(agent).Value() - Vec3(8, 0, 3)).norm(), AgentParams().mRadius);
}

// The link removed while an agent walks to it: its corridor loses the link with the tile rebuilt without
// it, and the agent walks to the nearest point it can reach instead, on its own side: it never steps into the
// gap
TEST_F(CrowdOffMeshLinkTest, ALinkRemovedBeforeAnAgentReachesItIsNotTaken)
{
    const TileScheduler::LinkID link = BuildGapWithLink(true);
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
    const Crowd::AgentID agent = crowd->AddAgent(Vec3(-9, 0, 0)).Value();
    ASSERT_TRUE(crowd->SetTarget(agent, Vec3(8, 0, 0)).IsOk());
    for (int update = 0; update < 30; ++update)
        ASSERT_TRUE(crowd->Update(cFrame).IsOk());
    ASSERT_EQ(crowd->GetState(agent).Value(), AgentState::Moving);
    mScheduler->RemoveOffMeshLink(link);
    ASSERT_TRUE(RunUntilIdle());
    for (int update = 0; update < 300; ++update)
    {
        ASSERT_TRUE(crowd->Update(cFrame).IsOk());
        ASSERT_NE(crowd->GetState(agent).Value(), AgentState::OnOffMeshLink) << "update " << update;
        ASSERT_LT(crowd->GetPosition(agent).Value().x(), -1.5f) << "update " << update;
    }
    EXPECT_EQ(crowd->GetState(agent).Value(), AgentState::Arrived);
    EXPECT_EQ(crowd->GetPathStatus(agent).Value(), PathStatus::Partial) << "short of its target";
    EXPECT_GT(crowd->GetPosition(agent).Value().x(), -3.5f) << "at the gap's edge";
    EXPECT_EQ(crowd->GetStatistics().mLinksTaken, 0u);
}

// A corridor that holds only three polygons (a link and one on either side), on a path of more (the
// platforms cross a tile border at z = 0: a polygon each side of it): the corridor first ends on the link,
// and the agent takes the link once its corridor reaches past it
TEST_F(CrowdOffMeshLinkTest, AnAgentWithAShortCorridorTakesTheLinkOnceItReachesPastIt)
{
    BuildGapWithLink(true);
    const Vec3 start(-8, 0, -3), goal(8, 0, 3);
    ASSERT_GE(mWorld->FindPath(start, goal).Value().mNumPolygons, 4);
    Crowd::Settings settings;
    settings.mMaxCorridorPolygons = 3;
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld, settings).Value();
    const Crowd::AgentID agent = crowd->AddAgent(start).Value();
    ASSERT_TRUE(crowd->SetTarget(agent, goal).IsOk());
    for (int update = 0; update < 600; ++update)
    {
        ASSERT_TRUE(crowd->Update(cFrame).IsOk());
        ASSERT_FALSE(crowd->GetCorridor(agent).Value().empty()) << "update " << update;
    }
    EXPECT_EQ(crowd->GetStatistics().mLinksTaken, 1u);
    EXPECT_EQ(crowd->GetState(agent).Value(), AgentState::Arrived);
    EXPECT_LT((crowd->GetPosition(agent).Value() - goal).norm(), AgentParams().mRadius);
    settings.mMaxCorridorPolygons = 2;
    EXPECT_FALSE(Crowd::Create(*mWorld, settings)) << "no room for a link";
}

// Twenty agents walk back and forth across the gap for 1,800 frames while the link is removed and added
// again (each time its tile is rebuilt in the background) and the far side's tile is rebuilt every 37
// frames: after every Update each corridor holds only polygons the navmesh has, no agent is on a link longer
// than its walk there and across takes, every agent not on a link stands on the navmesh, and the agents keep
// crossing
TEST_F(CrowdOffMeshLinkTest, AgentsCrossWhileTheLinkComesAndGoesAndTilesRebuild)
{
    const TileScheduler::LinkID first = BuildGapWithLink(true);
    OffMeshLink jump;
    jump.mStart = Vec3(-2.5f, 0, 0);
    jump.mEnd = Vec3(2.5f, 0, 0);
    jump.mRadius = 0.6f;
    std::optional<TileScheduler::LinkID> link = first;
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
    std::vector<Crowd::AgentID> agents;
    std::vector<int> onLinkFor, arrivals;
    for (int i = 0; i < 20; ++i)
    {
        const float z = -3.0f + 0.3f * float(i);
        agents.push_back(crowd->AddAgent(Vec3(i % 2 == 0 ? -8.0f : 8.0f, 0, z)).Value());
        EXPECT_TRUE(crowd->SetTarget(agents.back(), Vec3(i % 2 == 0 ? 8.0f : -8.0f, 0, z)).IsOk());
    }
    onLinkFor.assign(agents.size(), 0);
    arrivals.assign(agents.size(), 0);
    // The longest time on a link: the walk to its start from 2.25 radii and the 5 m across, at 3.5 m/s
    const int longestOnLink = int((2.25f * 0.6f + 5.0f) / AgentParams().mMaxSpeed / cFrame) + 2;
    int offNavMesh = 0;
    for (int frame = 0; frame < 1800; ++frame)
    {
        if (frame % 300 == 150 && link)
        {
            mScheduler->RemoveOffMeshLink(*link);
            link.reset();
        }
        else if (frame % 300 == 0 && !link)
            link = mScheduler->AddOffMeshLink(jump).Value();
        if (frame % 37 == 0) mScheduler->MarkDirty(AABB(Vec3(3, -1, -3), Vec3(9, 1, 3)));
        Frame(); // Tiles built in the background are published here, whenever they are done
        ASSERT_TRUE(crowd->Update(cFrame).IsOk());
        std::vector<uint64_t> corridors;
        for (Crowd::AgentID agent : agents)
        {
            const std::vector<uint64_t> corridor = crowd->GetCorridor(agent).Value();
            corridors.insert(corridors.end(), corridor.begin(), corridor.end());
        }
        mWorld->Read(
            [&](const dtNavMesh& inNavMesh)
            {
                for (uint64_t polygon : corridors)
                    ASSERT_TRUE(inNavMesh.isValidPolyRef(dtPolyRef(polygon))) << "frame " << frame;
            });
        for (size_t i = 0; i < agents.size(); ++i)
        {
            const AgentState state = crowd->GetState(agents[i]).Value();
            const Vec3 at = crowd->GetPosition(agents[i]).Value();
            onLinkFor[i] = state == AgentState::OnOffMeshLink ? onLinkFor[i] + 1 : 0;
            ASSERT_LE(onLinkFor[i], longestOnLink) << "agent " << i << ", frame " << frame;
            if (frame % 10 == 0 && state != AgentState::OnOffMeshLink && state != AgentState::OffNavMesh &&
                !OnNavMesh(at))
                ++offNavMesh;
            if (state != AgentState::Arrived) continue;
            // At its goal: back the other way. Short of it (the link was away): again, now and then
            const bool atGoal = crowd->GetPathStatus(agents[i]).Value() == PathStatus::Complete;
            if (atGoal) ++arrivals[i];
            if (atGoal || frame % 60 == 0)
            {
                EXPECT_TRUE(crowd->SetTarget(agents[i], Vec3(at.x() < 0 ? 8.0f : -8.0f, 0, at.z())).IsOk());
            }
        }
    }
    EXPECT_EQ(offNavMesh, 0);
    int crossings = 0;
    for (int count : arrivals)
        crossings += count;
    // How often the link is there depends on how soon the background builds publish it (38 to 45 crossings
    // on an idle machine, 29 beside two busy cores): half an agent's worth, at least
    EXPECT_GE(crossings, 10) << "the agents kept crossing";
    EXPECT_GE(crowd->GetStatistics().mLinksTaken, uint64_t(crossings));
    EXPECT_GT(crowd->GetStatistics().mReplans, 0u) << "some corridors lost the link or the far tile";
}

// A link whose far end joins nothing (no navmesh there) to a platform no link reaches: Detour's search steps
// onto the link and may find its start nearest the goal. The path must not end on the link (in the air
// between its ends): it ends on the near side, and an agent arrives there, short (it waited at the link)
TEST_F(CrowdOffMeshLinkTest, APathShortOfItsGoalNeverEndsOnALinkToNowhere)
{
    AddStaticBox(Vec3(-6, -0.5f, 0), Vec3(4.5f, 0.5f, 4)); // x in [-10.5, -1.5]
    AddStaticBox(Vec3(6, -0.5f, 0), Vec3(4.5f, 0.5f, 4));  // x in [1.5, 10.5]
    MakeNavMesh();
    OffMeshLink nowhere;
    nowhere.mStart = Vec3(-2.5f, 0, 0);
    nowhere.mEnd = Vec3(0, 0, 0); // Over the gap: no polygon within its radius
    nowhere.mRadius = 0.6f;
    ASSERT_TRUE(mScheduler->AddOffMeshLink(nowhere));
    ASSERT_TRUE(RunUntilIdle());
    const Result<PathResult> path = mWorld->FindPath(Vec3(-8, 0, 0), Vec3(8, 0, 0));
    ASSERT_TRUE(path) << path.GetError().mMessage;
    EXPECT_FALSE(path.Value().mReachedEnd);
    mWorld->Read(
        [&](const dtNavMesh& inNavMesh)
        {
            const dtMeshTile* tile = nullptr;
            const dtPoly* poly = nullptr;
            inNavMesh.getTileAndPolyByRefUnsafe(dtPolyRef(path.Value().mPolygons.back()), &tile, &poly);
            EXPECT_NE(poly->getType(), DT_POLYTYPE_OFFMESH_CONNECTION) << "the path ends on the link";
        });
    EXPECT_TRUE(OnNavMesh(path.Value().mStraightPath.back())) << "it ends on the navmesh";

    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
    const Crowd::AgentID agent = crowd->AddAgent(Vec3(-8, 0, 0)).Value();
    ASSERT_TRUE(crowd->SetTarget(agent, Vec3(8, 0, 0)).IsOk());
    for (int update = 0; update < 300; ++update)
        ASSERT_TRUE(crowd->Update(cFrame).IsOk());
    EXPECT_EQ(crowd->GetState(agent).Value(), AgentState::Arrived);
    EXPECT_EQ(crowd->GetPathStatus(agent).Value(), PathStatus::Partial);
    EXPECT_LT(crowd->GetPosition(agent).Value().x(), -1.5f);
}

} // namespace
} // namespace cairn::navmesh::test
