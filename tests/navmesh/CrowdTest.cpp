// A crowd on the navmesh: agents reach their goals keeping apart and on the navmesh; the same positions for
// any number of job threads; tiles rebuilt and removed under walking agents leave no corridor through a
// polygon that is gone; physics bodies and the agents of other crowds avoided; agents on the surface they
// walk over; clear errors.

#include "cairn/navmesh/Crowd.h"

#include "NavMeshSceneFixture.h"
#include "TileChanges.h"
#include "cairn/jobs/JobSystem.h"

#include <DetourNavMesh.h>
#include <random>

namespace cairn::navmesh::test
{
using namespace cairn::physics;
namespace
{

class CrowdTest : public NavMeshSceneFixture
{
protected:
    /// Ground over 2 x 2 tiles each side of the origin with walls to walk around.
    void BuildWalledGround()
    {
        AddStaticBox(Vec3(0, -0.5f, 0), Vec3(25, 0.5f, 25));
        for (int i = -1; i <= 1; ++i)
            AddStaticBox(Vec3(float(i) * 12.0f, 1.0f, float(i == 0 ? 5 : -5)), Vec3(0.5f, 1.5f, 15.0f));
        MakeNavMesh(2);
        ASSERT_TRUE(RunUntilIdle());
    }

    /// inCount agents at random places with random goals (a fixed seed), the goals at least inGoalSpacing
    /// apart; the ids.
    std::vector<Crowd::AgentID> AddAgentsWithGoals(Crowd& ioCrowd, int inCount, float inGoalSpacing = 3.0f)
    {
        std::mt19937 random(5);
        std::uniform_real_distribution<float> coordinate(-22.0f, 22.0f);
        std::vector<Crowd::AgentID> agents;
        while (int(agents.size()) < inCount)
        {
            const Vec3 start(coordinate(random), 0, coordinate(random));
            const Vec3 goal(coordinate(random), 0, coordinate(random));
            // Goals apart: an agent standing on its goal is not a way through for another (an occupied goal
            // is no goal to reach)
            bool taken = false;
            for (const Vec3& other : mGoals)
                taken |= (Vec3(goal.x(), 0, goal.z()) - Vec3(other.x(), 0, other.z())).norm() < inGoalSpacing;
            if (taken) continue;
            // Not on a wall, and a goal FindPath reaches
            const Result<PathResult> path = mWorld->FindPath(start, goal);
            if (!path || !path.Value().mReachedEnd ||
                std::abs(path.Value().mStraightPath.front().y()) > 0.3f ||
                std::abs(path.Value().mStraightPath.back().y()) > 0.3f)
                continue;
            Result<Crowd::AgentID> agent = ioCrowd.AddAgent(start);
            if (!agent) continue;
            EXPECT_TRUE(ioCrowd.SetTarget(agent.Value(), goal).IsOk());
            agents.push_back(agent.Value());
            mGoals.push_back(path.Value().mStraightPath.back());
        }
        return agents;
    }

    /// Agent-frames in which two agents overlap by more than 10 % of the smaller radius.
    static int CountOverlaps(const Crowd& inCrowd, const std::vector<Crowd::AgentID>& inAgents)
    {
        int overlapping = 0;
        for (size_t i = 0; i < inAgents.size(); ++i)
            for (size_t j = i + 1; j < inAgents.size(); ++j)
            {
                Vec3 d = inCrowd.GetPosition(inAgents[i]).Value() - inCrowd.GetPosition(inAgents[j]).Value();
                d.y() = 0.0f;
                const float ri = inCrowd.GetRadius(inAgents[i]).Value(),
                            rj = inCrowd.GetRadius(inAgents[j]).Value();
                if (ri + rj - d.norm() > 0.1f * std::min(ri, rj))
                {
                    overlapping += 2;
                }
            }
        return overlapping;
    }

    /// True if every agent's corridor holds only polygons the navmesh has now.
    bool CorridorsAreValid(const Crowd& inCrowd) const
    {
        bool valid = true;
        mWorld->Read(
            [&](const dtNavMesh& inNavMesh)
            {
                for (Crowd::AgentID agent : inCrowd.GetAgents())
                {
                    const std::vector<uint64_t> corridor = inCrowd.GetCorridor(agent).Value();
                    for (uint64_t polygon : corridor)
                        valid = valid && inNavMesh.isValidPolyRef(dtPolyRef(polygon));
                }
            });
        return valid;
    }

    std::vector<Vec3> mGoals;
};

// 60 agents cross the ground to their goals: at least 95 % arrive within 45 s (the longest walks take 20 s
// alone; jams at the ends of walls cost some agents seconds), pairs overlap by more than a
// tenth of a radius in under 1 % of agent-frames, and every agent stands on the navmesh in every frame
TEST_F(CrowdTest, AgentsReachTheirGoalsApartAndOnTheNavMesh)
{
    BuildWalledGround();
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
    const std::vector<Crowd::AgentID> agents = AddAgentsWithGoals(*crowd, 60);
    int overlaps = 0, agentFrames = 0, offNavMesh = 0;
    for (int frame = 0; frame < 2700; ++frame)
    {
        ASSERT_TRUE(crowd->Update(1.0f / 60.0f).IsOk());
        overlaps += CountOverlaps(*crowd, agents);
        agentFrames += int(agents.size());
        if (frame % 30 == 0)
            for (Crowd::AgentID agent : agents)
            {
                const Vec3 position = crowd->GetPosition(agent).Value();
                const Result<Vec3> nearest = mWorld->FindNearestPoint(position, {}, Vec3(0.1f, 0.5f, 0.1f));
                offNavMesh += nearest && (nearest.Value() - position).norm() < 0.05f ? 0 : 1;
            }
    }
    int arrived = 0;
    for (size_t i = 0; i < agents.size(); ++i)
    {
        Vec3 toGoal = crowd->GetPosition(agents[i]).Value() - mGoals[i];
        toGoal.y() = 0.0f;
        arrived += toGoal.norm() < 1.5f ? 1 : 0;
    }
    EXPECT_GE(arrived, 57) << "of 60";
    EXPECT_LT(overlaps, agentFrames / 100) << overlaps << " overlapping agent-frames of " << agentFrames;
    EXPECT_EQ(offNavMesh, 0);
    EXPECT_GE(crowd->GetStatistics().mPathsApplied, 60u);
}

/// The crowd above on inThreads job threads (0: none) for 300 frames; every agent's final position.
std::vector<Vec3> RunCrowd(CrowdTest& ioTest, Crowd& ioCrowd, const std::vector<Crowd::AgentID>& inAgents,
                           int inThreads)
{
    (void)ioTest;
    std::unique_ptr<jobs::JobSystem> jobSystem;
    if (inThreads > 0)
        jobSystem = std::make_unique<jobs::JobSystem>(jobs::JobSystem::Settings{uint32_t(inThreads)});
    for (int frame = 0; frame < 300; ++frame)
        EXPECT_TRUE(ioCrowd.Update(1.0f / 60.0f, jobSystem.get()).IsOk());
    std::vector<Vec3> positions;
    for (Crowd::AgentID agent : inAgents)
        positions.push_back(ioCrowd.GetPosition(agent).Value());
    return positions;
}

// 300 agents (five ParallelFor chunks) end in the same places, bit for bit, for no job system and 1, 2 and 4
// threads
TEST_F(CrowdTest, TheSamePositionsForAnyThreadCount)
{
    BuildWalledGround();
    std::vector<std::vector<Vec3>> results;
    for (int threads : {0, 1, 2, 4})
    {
        std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
        mGoals.clear();
        const std::vector<Crowd::AgentID> agents = AddAgentsWithGoals(*crowd, 300, 0.0f);
        results.push_back(RunCrowd(*this, *crowd, agents, threads));
    }
    for (size_t run = 1; run < results.size(); ++run)
        EXPECT_EQ(results[run], results[0]) << "run " << run;
}

// Tiles rebuilt and removed under 100 walking agents for 1,200 frames: after every Update each corridor holds
// only polygons that exist; agents on a removed tile wait on it, and walk on once it is built again
TEST_F(CrowdTest, TilesChangingUnderTheCrowdLeaveNoCorridorThroughAGonePolygon)
{
    BuildWalledGround();
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
    const std::vector<Crowd::AgentID> agents = AddAgentsWithGoals(*crowd, 100);
    std::mt19937 random(3);
    std::uniform_int_distribution<int> tile(-2, 1);
    for (int frame = 0; frame < 1200; ++frame)
    {
        if (frame % 100 == 0)
        {
            // Every tile asked for again (the scheduler rebuilds what is missing or dirty)...
            mScheduler->MarkDirty(AABB(Vec3(-25, -1, -25), Vec3(25, 3, 25)));
        }
        Frame(); // Physics and the tile scheduler: rebuilt tiles are published here
        if (frame % 100 == 50)
        {
            // ...and a tile removed outright (a tile streamed out), after the frame's sync point: the crowd
            // sees it gone even when a rebuild of it was under way (a loaded machine's slow jobs published
            // one in the same frame, and no agent ever stood on a removed tile)
            mWorld->Publish(Changes(NavMeshWorld::Removal(TileCoord{tile(random), tile(random)})));
        }
        ASSERT_TRUE(crowd->Update(1.0f / 60.0f).IsOk());
        ASSERT_TRUE(CorridorsAreValid(*crowd)) << "frame " << frame;
    }
    EXPECT_GT(crowd->GetStatistics().mReplans, 0u);
    EXPECT_GT(crowd->GetStatistics().mOffNavMeshFrames, 0u) << "some agents stood on a removed tile";
}

// Agents placed and given goals before their tiles are built wait where they are, then walk to their goals
// once the navmesh is published under them, one of them along a tile edge
TEST_F(CrowdTest, AgentsWaitForTheirNavMeshThenWalk)
{
    AddStaticBox(Vec3(0, -0.5f, 0), Vec3(25, 0.5f, 25));
    MakeNavMesh(2); // Nothing built yet
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
    std::vector<Crowd::AgentID> agents;
    for (int i = 0; i < 10; ++i)
    {
        // Agent 5 walks exactly along a tile edge (x = 0) through the corner where four tiles meet: it
        // turned back and forth there (its corridor turned back through the polygon it left)
        const float x = -20.0f + 4.0f * float(i);
        agents.push_back(crowd->AddAgent(Vec3(x, 0, -20)).Value());
        ASSERT_TRUE(crowd->SetTarget(agents.back(), Vec3(x, 0, 20)).IsOk());
        EXPECT_EQ(crowd->GetState(agents.back()).Value(), AgentState::OffNavMesh);
    }
    for (int frame = 0; frame < 30; ++frame)
        ASSERT_TRUE(crowd->Update(1.0f / 60.0f).IsOk());
    for (Crowd::AgentID agent : agents)
        EXPECT_EQ(crowd->GetPosition(agent).Value().z(), -20.0f) << "waited in place";
    ASSERT_TRUE(RunUntilIdle());
    for (int frame = 0; frame < 900; ++frame)
        ASSERT_TRUE(crowd->Update(1.0f / 60.0f).IsOk());
    for (Crowd::AgentID agent : agents)
    {
        EXPECT_EQ(crowd->GetState(agent).Value(), AgentState::Arrived);
        EXPECT_NEAR(crowd->GetPosition(agent).Value().z(), 20.0f, 1.0f) << "agent " << agent;
    }
}

// A dynamic crate standing in an agent's way, on navmesh built before it came (so the navmesh does not go
// round it): with the physics world's moving layer as obstacles, the agent walks round it, its centre never
// nearer the crate's than the two radii less a tenth of a metre; without, it walks through
TEST_F(CrowdTest, AgentsWalkRoundDynamicBodies)
{
    AddStaticBox(Vec3(0, -0.5f, 0), Vec3(25, 0.5f, 25));
    MakeNavMesh(2);
    ASSERT_TRUE(RunUntilIdle());
    const BodyID crate = AddDynamicBox(Vec3(0, 0.5f, 0), Vec3(0.5f, 0.5f, 0.5f));
    for (int frame = 0; frame < 30; ++frame)
        ASSERT_TRUE(mPhysics->Update(1.0f / 60.0f).IsOk()); // Settled; the tiles are not rebuilt round it
    const Vec3 crateAt = mPhysics->GetBodyInterface().GetPosition(crate).Value();
    auto closestApproach = [&](bool inAvoid)
    {
        std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
        if (inAvoid) crowd->SetPhysicsObstacles(mPhysics.get(), ObjectLayerMask(1) << Layers::cMoving);
        const Crowd::AgentID agent = crowd->AddAgent(Vec3(-8, 0, 0.05f)).Value();
        EXPECT_TRUE(crowd->SetTarget(agent, Vec3(8, 0, 0.05f)).IsOk());
        float closest = 1.0e9f;
        uint32_t mostObstacles = 0;
        for (int frame = 0; frame < 600; ++frame)
        {
            EXPECT_TRUE(crowd->Update(1.0f / 60.0f).IsOk());
            mostObstacles = std::max(mostObstacles, crowd->GetStatistics().mLastObstacles);
            Vec3 offset = crowd->GetPosition(agent).Value() - crateAt;
            offset.y() = 0.0f;
            closest = std::min(closest, offset.norm());
        }
        EXPECT_EQ(crowd->GetState(agent).Value(), AgentState::Arrived);
        EXPECT_EQ(mostObstacles, inAvoid ? 1u : 0u);
        return closest;
    };
    EXPECT_GE(closestApproach(true), 0.5f + 0.6f - 0.1f);
    EXPECT_LT(closestApproach(false), 0.5f)
        << "the crate is not in the navmesh: without obstacles it is walked through";
}

// A sleeping crate is in the navmesh once its tile is rebuilt (the scheduler's default): a crowd told to
// avoid only moving bodies leaves it to the navmesh, one told to avoid every dynamic body avoids it
TEST_F(CrowdTest, OnlyAwakeBodiesAreObstaclesWhenAsked)
{
    AddStaticBox(Vec3(0, -0.5f, 0), Vec3(25, 0.5f, 25));
    MakeNavMesh(2);
    ASSERT_TRUE(RunUntilIdle());
    const BodyID crate = AddDynamicBox(Vec3(0, 0.5f, 0), Vec3(0.5f, 0.5f, 0.5f));
    ASSERT_TRUE(mPhysics->Update(1.0f / 60.0f).IsOk()); // Publishes it awake (it sleeps after half a second)
    auto obstaclesSeen = [&](Crowd::Obstacles inWhich)
    {
        std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
        crowd->SetPhysicsObstacles(mPhysics.get(), ObjectLayerMask(1) << Layers::cMoving, inWhich);
        (void)crowd->AddAgent(Vec3(-3, 0, 0)).Value();
        EXPECT_TRUE(crowd->Update(1.0f / 60.0f).IsOk());
        return crowd->GetStatistics().mLastObstacles;
    };
    EXPECT_EQ(obstaclesSeen(Crowd::Obstacles::AwakeOnly), 1u) << "the crate is awake";
    ASSERT_TRUE(mPhysics->GetBodyInterface().DeactivateBody(crate).IsOk());
    ASSERT_TRUE(mPhysics->Update(1.0f / 60.0f).IsOk()); // Publishes it asleep
    EXPECT_EQ(obstaclesSeen(Crowd::Obstacles::AwakeOnly), 0u);
    EXPECT_EQ(obstaclesSeen(Crowd::Obstacles::AllDynamic), 1u);
}

/// Agents of two crowds walking at each other along one line, each crowd told of the other or not: the
/// closest any two of different crowds came, less the sum of their radii (negative: they overlapped).
float ClosestGapBetweenCrowds(const NavMeshWorld& inWorld, bool inTellEachOther)
{
    std::unique_ptr<Crowd> humans = Crowd::Create(inWorld).Value();
    std::unique_ptr<Crowd> large = Crowd::Create(inWorld).Value();
    if (inTellEachOther)
    {
        humans->SetOtherCrowds({large.get()});
        large->SetOtherCrowds({humans.get()});
    }
    AgentParams bigParams;
    bigParams.mRadius = 1.5f;
    std::vector<Crowd::AgentID> walkersEast, walkersWest;
    for (int i = 0; i < 3; ++i)
    {
        walkersEast.push_back(humans->AddAgent(Vec3(-15.0f - 2.0f * float(i), 0, 0.1f * float(i))).Value());
        EXPECT_TRUE(humans->SetTarget(walkersEast.back(), Vec3(15, 0, 0)).IsOk());
        walkersWest.push_back(
            large->AddAgent(Vec3(15.0f + 4.0f * float(i), 0, -0.1f * float(i)), bigParams).Value());
        EXPECT_TRUE(large->SetTarget(walkersWest.back(), Vec3(-15, 0, 0)).IsOk());
    }
    float closest = 1.0e9f;
    for (int frame = 0; frame < 900; ++frame)
    {
        // One after the other on this thread, as SetOtherCrowds asks
        EXPECT_TRUE(humans->Update(1.0f / 60.0f).IsOk());
        EXPECT_TRUE(large->Update(1.0f / 60.0f).IsOk());
        for (Crowd::AgentID a : walkersEast)
            for (Crowd::AgentID b : walkersWest)
            {
                Vec3 d = humans->GetPosition(a).Value() - large->GetPosition(b).Value();
                d.y() = 0.0f;
                closest = std::min(closest, d.norm() - 0.6f - 1.5f);
            }
    }
    return closest;
}

// Crowds of two profiles on the same ground (each crowd avoids the other's agents when told of them): humans
// and large agents walking at each other along one line pass without overlapping by more than a tenth of a
// radius; untold, they walk through each other, so the check can fail
TEST_F(CrowdTest, CrowdsToldOfEachOtherKeepApart)
{
    AddStaticBox(Vec3(0, -0.5f, 0), Vec3(25, 0.5f, 25));
    MakeNavMesh(2);
    ASSERT_TRUE(RunUntilIdle());
    EXPECT_GT(ClosestGapBetweenCrowds(*mWorld, true), -0.06f);
    EXPECT_LT(ClosestGapBetweenCrowds(*mWorld, false), -1.0f);
}

// Agents walking over low crates they can step onto stand on them: their height is the surface's wherever
// they are (Detour's corridor kept the ground's height when its getPolyHeight failed at a triangle's edge,
// and agents stood inside the crate)
TEST_F(CrowdTest, AgentsStandOnTheSurfaceTheyWalkOver)
{
    AddStaticBox(Vec3(0, -0.5f, 0), Vec3(25, 0.5f, 25));
    std::vector<AABB> crates;
    for (int i = -2; i <= 2; ++i)
    {
        const Vec3 centre(float(i) * 4.0f, 0.25f, 0.3f * float(i));
        const Vec3 half(1.2f, 0.25f, 1.5f + 0.2f * float(i + 2));
        AddStaticBox(centre, half);
        crates.push_back(AABB(centre - half, centre + half));
    }
    MakeNavMesh(2);
    ASSERT_TRUE(RunUntilIdle());
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
    std::vector<Crowd::AgentID> agents;
    for (int row = 0; row < 8; ++row)
    {
        agents.push_back(crowd->AddAgent(Vec3(-14, 0, -3.5f + float(row))).Value());
        EXPECT_TRUE(crowd->SetTarget(agents.back(), Vec3(14, 0, 3.5f - float(row))).IsOk());
    }
    int onCrates = 0, belowTheirTop = 0;
    for (int frame = 0; frame < 900; ++frame)
    {
        ASSERT_TRUE(crowd->Update(1.0f / 60.0f).IsOk());
        for (Crowd::AgentID agent : agents)
        {
            const Vec3 position = crowd->GetPosition(agent).Value();
            for (const AABB& crate : crates)
            {
                // Well inside the crate's footprint: on top of it, or inside it
                if (position.x() < crate.mMin.x() + 0.25f || position.x() > crate.mMax.x() - 0.25f ||
                    position.z() < crate.mMin.z() + 0.25f || position.z() > crate.mMax.z() - 0.25f)
                    continue;
                ++onCrates;
                if (position.y() < crate.mMax.y() - 0.15f)
                {
                    ++belowTheirTop;
                    ADD_FAILURE() << "frame " << frame << ": agent " << agent << " at "
                                  << position.transpose() << " below the crate's top " << crate.mMax.y();
                }
            }
        }
        if (belowTheirTop > 5) break;
    }
    EXPECT_GT(onCrates, 100) << "agent-frames on the crates: the scene must make them step up";
    EXPECT_EQ(belowTheirTop, 0);
}

// A path of more polygons than the agent's corridor holds is walked a corridor at a time, to its goal (the
// agent stopped at its corridor's end as if it had arrived; and a path as long as the corridor failed
// Detour's assertion)
TEST_F(CrowdTest, APathLongerThanTheCorridorIsWalkedWhole)
{
    BuildWalledGround();
    const Vec3 start(-22, 0, -22), goal(22, 0, 22);
    const Result<PathResult> path = mWorld->FindPath(start, goal);
    ASSERT_TRUE(path && path.Value().mReachedEnd);
    for (const int corridor : {3, path.Value().mNumPolygons})
    {
        Crowd::Settings settings;
        settings.mMaxCorridorPolygons = corridor;
        std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld, settings).Value();
        const Crowd::AgentID agent = crowd->AddAgent(start).Value();
        ASSERT_TRUE(crowd->SetTarget(agent, goal).IsOk());
        for (int frame = 0; frame < 1800; ++frame)
            ASSERT_TRUE(crowd->Update(1.0f / 60.0f).IsOk());
        EXPECT_EQ(crowd->GetState(agent).Value(), AgentState::Arrived) << corridor << " polygons";
        EXPECT_LT((crowd->GetPosition(agent).Value() - path.Value().mStraightPath.back()).norm(), 0.6f)
            << corridor << " polygons, of a path of " << path.Value().mNumPolygons;
    }
}

// A fast agent (30 m/s, half-second Updates) with a short corridor: each move crosses several polygons, which
// Detour merges into the corridor's start. Its corridor stays valid and it goes a good way (15 m steps
// overshoot corners: Detour's corridor is not made for them, and it need not arrive). Not a test of the
// merges' room (the crowd gives them 32 polygons at least): these moves visit too few polygons, and the
// sanitizers do not see inside Detour's library, so a corridor of 4 passed too
TEST_F(CrowdTest, AFastAgentWithAShortCorridorStaysInItsCorridorsRoom)
{
    BuildWalledGround();
    Crowd::Settings settings;
    settings.mMaxCorridorPolygons = 3;
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld, settings).Value();
    AgentParams fast;
    fast.mMaxSpeed = 30.0f;
    fast.mMaxAcceleration = 1000.0f;
    const Vec3 goal(22, 0, 22);
    const Crowd::AgentID agent = crowd->AddAgent(Vec3(-22, 0, -22), fast).Value();
    ASSERT_TRUE(crowd->SetTarget(agent, goal).IsOk());
    for (int update = 0; update < 120; ++update)
    {
        ASSERT_TRUE(crowd->Update(0.5f).IsOk());
        ASSERT_TRUE(CorridorsAreValid(*crowd)) << "update " << update;
    }
    EXPECT_LT((crowd->GetPosition(agent).Value() - goal).norm(), 55.0f) << "of 62 m";
}

TEST_F(CrowdTest, BadInputGetsClearErrors)
{
    BuildWalledGround();
    Crowd::Settings settings;
    settings.mMaxAgents = 2;
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld, settings).Value();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    // No navmesh there: the agent waits (takes one of the two places)
    const Crowd::AgentID waiting = crowd->AddAgent(Vec3(500, 0, 500)).Value();
    EXPECT_EQ(crowd->GetState(waiting).Value(), AgentState::OffNavMesh);
    EXPECT_TRUE(crowd->GetCorridor(waiting).Value().empty());
    EXPECT_TRUE(crowd->RemoveAgent(waiting).IsOk());
    EXPECT_EQ(crowd->AddAgent(Vec3(nan, 0, 0)).GetError().mCode, ErrorCode::InvalidArgument);
    AgentParams huge;
    huge.mRadius = 50.0f;
    EXPECT_EQ(crowd->AddAgent(Vec3(-20, 0, -20), huge).GetError().mCode, ErrorCode::InvalidArgument);
    const Crowd::AgentID a = crowd->AddAgent(Vec3(-20, 0, -20)).Value();
    crowd->AddAgent(Vec3(-18, 0, -20)).Value();
    EXPECT_EQ(crowd->AddAgent(Vec3(-16, 0, -20)).GetError().mCode, ErrorCode::OutOfCapacity);
    EXPECT_EQ(crowd->SetTarget(a, Vec3(nan, 0, 0)).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_EQ(crowd->SetTarget(99, Vec3::Zero()).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_FALSE(crowd->GetPosition(99));
    EXPECT_EQ(crowd->Update(0.0f).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_TRUE(crowd->RemoveAgent(a).IsOk());
    EXPECT_FALSE(crowd->RemoveAgent(a).IsOk()) << "removed twice";
    // The freed slot is reused at once (the lowest free): a's id, kept by mistake, must not name the newcomer
    const Crowd::AgentID newcomer = crowd->AddAgent(Vec3(20, 0, 20)).Value();
    EXPECT_NE(newcomer, a);
    EXPECT_EQ(crowd->SetTarget(a, Vec3(2, 0, 2)).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_FALSE(crowd->GetPosition(a));
    EXPECT_EQ(crowd->RemoveAgent(a).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_TRUE(crowd->GetPosition(newcomer)) << "the stale id's calls left the newcomer in place";
    EXPECT_TRUE(crowd->RemoveAgent(newcomer).IsOk());
    // A target off the navmesh: the agent's request fails and it says so
    const Crowd::AgentID b = crowd->AddAgent(Vec3(-20, 0, -20)).Value();
    ASSERT_TRUE(crowd->SetTarget(b, Vec3(500, 0, 500)).IsOk());
    for (int frame = 0; frame < 10; ++frame)
        ASSERT_TRUE(crowd->Update(1.0f / 60.0f).IsOk());
    EXPECT_EQ(crowd->GetState(b).Value(), AgentState::NoPath);
    EXPECT_EQ(crowd->GetPathStatus(b).Value(), PathStatus::None);
}

} // namespace
} // namespace cairn::navmesh::test
