// Crowd agents following path filters of their own: in one crowd, an agent that may swim crosses the river
// and one that may not takes the bridge; one that may not swim is never pushed into the water by another
// standing on it, whether its filter was set before the tiles were published or after; an agent whose
// filter changes mid-river leaves the water and takes the bridge; the world marks exactly the areas its
// crowds' filters exclude, however often their sets change; and bad filters and indices are refused.

#include "RiverSceneFixture.h"
#include "cairn/navmesh/Crowd.h"

#include <DetourNavMesh.h>
#include <bit>
#include <set>
#include <span>

namespace cairn::navmesh::test
{
using namespace cairn::physics;
namespace
{

constexpr float cStep = 1.0f / 60.0f;
constexpr int cMaySwim = 0;
constexpr int cMayNotSwim = 1;

class CrowdFilterTest : public RiverSceneFixture
{
protected:
    /// Whether inPosition is in the water (beyond its border by more than a centimetre), not on a bank or the
    /// bridge.
    static bool InWater(const Vec3& inPosition)
    {
        return std::abs(inPosition.z()) < 1.0f - 0.01f && inPosition.x() < 8.0f - 0.01f;
    }

    /// How many of inPolygons (Detour references into the published navmesh, each one there) are water.
    int CountWaterPolygons(std::span<const uint64_t> inPolygons) const
    {
        int water = 0;
        mWorld->Read(
            [&](const dtNavMesh& inNavMesh)
            {
                for (const uint64_t polygon : inPolygons)
                {
                    const dtMeshTile* tile = nullptr;
                    const dtPoly* poly = nullptr;
                    if (dtStatusFailed(inNavMesh.getTileAndPolyByRef(polygon, &tile, &poly)))
                    {
                        ADD_FAILURE() << "a corridor polygon the navmesh does not have";
                        continue;
                    }
                    water += poly->getArea() == cWater ? 1 : 0;
                }
            });
        return water;
    }

    /// Whether the first polygon of the agent's corridor, the one it stands in, is water.
    bool StandsInWaterPolygon(const Crowd& inCrowd, Crowd::AgentID inAgent) const
    {
        const std::vector<uint64_t> corridor = inCrowd.GetCorridor(inAgent).Value();
        return !corridor.empty() && CountWaterPolygons(std::span(corridor).first(1)) > 0;
    }

    /// Walks inAgent for inUpdates Updates or until it arrives; the Updates in which it was in the water.
    /// outFarthestX: the farthest east it went (over the bridge: beyond x = 8).
    int WalkCountingWater(Crowd& ioCrowd, Crowd::AgentID inAgent, float* outFarthestX = nullptr,
                          int inUpdates = 1200)
    {
        int inWater = 0;
        for (int update = 0; update < inUpdates; ++update)
        {
            EXPECT_TRUE(ioCrowd.Update(cStep).IsOk());
            const Vec3 position = ioCrowd.GetPosition(inAgent).Value();
            if (outFarthestX != nullptr) *outFarthestX = std::max(*outFarthestX, position.x());
            if (InWater(position) || StandsInWaterPolygon(ioCrowd, inAgent)) ++inWater;
            if (ioCrowd.GetState(inAgent).Value() == AgentState::Arrived) break;
        }
        return inWater;
    }

    static void ExpectArrivedAt(const Crowd& inCrowd, Crowd::AgentID inAgent, const Vec3& inGoal)
    {
        EXPECT_EQ(inCrowd.GetState(inAgent).Value(), AgentState::Arrived);
        EXPECT_EQ(inCrowd.GetPathStatus(inAgent).Value(), PathStatus::Complete);
        EXPECT_LT((inCrowd.GetPosition(inAgent).Value() - inGoal).norm(), AgentParams().mRadius);
    }

    /// An agent that may not swim at the water's edge, and one that may standing half its width into it
    /// from the land side: they part, and the one that may not swim must not be pushed in. The Updates it
    /// was in the water.
    int PushTowardsTheWater(Crowd& ioCrowd)
    {
        AgentParams walker;
        walker.mFilter = cMayNotSwim;
        const Crowd::AgentID edge = ioCrowd.AddAgent(Vec3(-5, 0, -1.15f), walker).Value();
        const Crowd::AgentID pusher = ioCrowd.AddAgent(Vec3(-5, 0, -1.75f)).Value();
        EXPECT_FALSE(InWater(ioCrowd.GetPosition(edge).Value()));
        int inWater = 0;
        for (int update = 0; update < 30; ++update)
        {
            EXPECT_TRUE(ioCrowd.Update(cStep).IsOk());
            if (InWater(ioCrowd.GetPosition(edge).Value()) || StandsInWaterPolygon(ioCrowd, edge)) ++inWater;
        }
        // They did part: the pusher went away from the water, the other stopped at its border
        const Vec3 apart = ioCrowd.GetPosition(edge).Value() - ioCrowd.GetPosition(pusher).Value();
        EXPECT_GT(Vec3(apart.x(), 0, apart.z()).norm(), 2.0f * walker.mRadius - 0.05f);
        return inWater;
    }

    /// How many of the sets inAreaSets holds (each once, however often it is listed) hold the area.
    static int SetsHolding(const std::vector<uint64_t>& inAreaSets, int inArea)
    {
        const std::set<uint64_t> sets(inAreaSets.begin(), inAreaSets.end());
        int count = 0;
        for (const uint64_t areas : sets)
            count += (areas >> inArea) & 1u ? 1 : 0;
        return count;
    }

    /// Polygons whose flags do not carry one mark for each set of inAreaSets holding their area: the world's
    /// marks when its 15 flags are given to exactly those sets (a flag no one holds keeps its marks).
    int WronglyMarkedPolygons(const std::vector<uint64_t>& inAreaSets) const
    {
        int wrong = 0, polygons = 0;
        mWorld->Read(
            [&](const dtNavMesh& inNavMesh)
            {
                for (int i = 0; i < inNavMesh.getMaxTiles(); ++i)
                {
                    const dtMeshTile* tile = inNavMesh.getTile(i);
                    if (tile->header == nullptr) continue;
                    for (int p = 0; p < tile->header->polyCount; ++p)
                    {
                        const dtPoly& polygon = tile->polys[p];
                        const int area = polygon.getArea() == 63 ? cDefaultArea : polygon.getArea();
                        ++polygons;
                        wrong += std::popcount(unsigned(polygon.flags & ~cPolyFlagWalk)) !=
                                 SetsHolding(inAreaSets, area);
                    }
                }
            });
        EXPECT_GT(polygons, 0);
        return wrong;
    }
};

TEST_F(CrowdFilterTest, AgentsOfOneCrowdTakeTheWaysTheirFiltersAllow)
{
    BuildRiver();
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
    ASSERT_TRUE(crowd->SetFilter(cMayNotSwim, NoSwimming()).IsOk());
    AgentParams walker;
    walker.mFilter = cMayNotSwim;
    const Crowd::AgentID swimmer = crowd->AddAgent(mStart).Value();
    ASSERT_TRUE(crowd->SetTarget(swimmer, mEnd).IsOk());
    const Crowd::AgentID walking = crowd->AddAgent(mStart + Vec3(0, 0, -1.5f), walker).Value();
    const Vec3 walkerEnd = mEnd + Vec3(0, 0, 2);
    ASSERT_TRUE(crowd->SetTarget(walking, walkerEnd).IsOk());

    // The swimmer goes straight across, the other by the bridge: it is in the water never
    float farthestSwimmerX = -100.0f, farthestWalkerX = -100.0f;
    int walkerInWater = 0, swimmerInWater = 0;
    for (int update = 0; update < 1500; ++update)
    {
        ASSERT_TRUE(crowd->Update(cStep).IsOk());
        const Vec3 swimmerAt = crowd->GetPosition(swimmer).Value(),
                   walkerAt = crowd->GetPosition(walking).Value();
        farthestSwimmerX = std::max(farthestSwimmerX, swimmerAt.x());
        farthestWalkerX = std::max(farthestWalkerX, walkerAt.x());
        swimmerInWater += InWater(swimmerAt) ? 1 : 0;
        walkerInWater += InWater(walkerAt) || StandsInWaterPolygon(*crowd, walking) ? 1 : 0;
        if (crowd->GetState(swimmer).Value() == AgentState::Arrived &&
            crowd->GetState(walking).Value() == AgentState::Arrived)
            break;
    }
    ExpectArrivedAt(*crowd, swimmer, mEnd);
    ExpectArrivedAt(*crowd, walking, walkerEnd);
    EXPECT_GT(swimmerInWater, 0);
    EXPECT_LT(farthestSwimmerX, -6.0f) << "the swimmer went straight across";
    EXPECT_EQ(walkerInWater, 0);
    EXPECT_GT(farthestWalkerX, 8.0f) << "the other took the bridge";
    EXPECT_EQ(crowd->GetFilter(cMayNotSwim).Value().mExcludedAreas, NoSwimming().mExcludedAreas);
    EXPECT_EQ(crowd->GetFilter(cMaySwim).Value().mExcludedAreas, 0u);
}

TEST_F(CrowdFilterTest, AnAgentIsNeverPushedIntoAnAreaItsFilterExcludes)
{
    BuildRiver();
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
    ASSERT_TRUE(crowd->SetFilter(cMayNotSwim, NoSwimming()).IsOk());
    EXPECT_EQ(PushTowardsTheWater(*crowd), 0);
}

TEST_F(CrowdFilterTest, TilesPublishedAfterTheFilterWasSetKeepItsAgentsOutToo)
{
    AddStaticBox(Vec3(0, -0.5f, -5.5f), Vec3(10, 0.5f, 4.5f));
    AddStaticBox(Vec3(0, -0.5f, 5.5f), Vec3(10, 0.5f, 4.5f));
    AddStaticBox(Vec3(-1, -0.5f, 0), Vec3(9, 0.5f, 1), cWater);
    AddStaticBox(Vec3(9, -0.5f, 0), Vec3(1, 0.5f, 1));
    MakeNavMesh();
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
    ASSERT_TRUE(crowd->SetFilter(cMayNotSwim, NoSwimming()).IsOk());
    ASSERT_EQ(mWorld->GetNumTiles(), 0);
    ASSERT_TRUE(RunUntilIdle());
    EXPECT_EQ(PushTowardsTheWater(*crowd), 0);
}

TEST_F(CrowdFilterTest, AnAgentWhoseFilterChangesInTheWaterLeavesItAndTakesTheBridge)
{
    BuildRiver();
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
    ASSERT_TRUE(crowd->SetFilter(cMayNotSwim, NoSwimming()).IsOk());
    for (const bool byAgent : {true, false})
    {
        SCOPED_TRACE(byAgent ? "SetAgentFilter" : "SetFilter");
        // Filter 2 lets it swim, until SetFilter says otherwise
        const Crowd::AgentID agent = crowd->AddAgent(mStart, AgentParams{.mFilter = 2}).Value();
        ASSERT_TRUE(crowd->SetFilter(2, PathFilter{}).IsOk());
        ASSERT_TRUE(crowd->SetTarget(agent, mEnd).IsOk());
        int update = 0;
        while (!(std::abs(crowd->GetPosition(agent).Value().z()) < 0.3f) && update++ < 600)
            ASSERT_TRUE(crowd->Update(cStep).IsOk());
        ASSERT_TRUE(InWater(crowd->GetPosition(agent).Value())) << "it swam to the river's middle";
        if (byAgent)
            ASSERT_TRUE(crowd->SetAgentFilter(agent, cMayNotSwim).IsOk());
        else
            ASSERT_TRUE(crowd->SetFilter(2, NoSwimming()).IsOk());
        // Out of the water at once, onto the nearer bank, then by the bridge
        float farthestX = -100.0f;
        EXPECT_EQ(WalkCountingWater(*crowd, agent, &farthestX), 0);
        EXPECT_GT(farthestX, 8.0f) << "it took the bridge";
        ExpectArrivedAt(*crowd, agent, mEnd);
        ASSERT_TRUE(crowd->RemoveAgent(agent).IsOk());
    }
}

TEST_F(CrowdFilterTest, UntilItsNewPathComesAnAgentKeepsOnlyTheWayItsNewFilterAllows)
{
    BuildRiver();
    // A search of a few polygons an Update: the new path takes Updates to come
    Crowd::Settings settings;
    settings.mPaths.mIterationsPerUpdate = 2;
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld, settings).Value();
    const Crowd::AgentID agent = crowd->AddAgent(mStart).Value();
    ASSERT_TRUE(crowd->SetTarget(agent, mEnd).IsOk());
    for (int update = 0; update < 600 && crowd->GetState(agent).Value() != AgentState::Moving; ++update)
        ASSERT_TRUE(crowd->Update(cStep).IsOk());
    ASSERT_EQ(crowd->GetState(agent).Value(), AgentState::Moving);
    ASSERT_TRUE(crowd->SetFilter(cMaySwim, NoSwimming()).IsOk());
    // Its corridor, through the water, is cut at the bank as soon as the filter is checked
    int updatesWaiting = 0, waterPolygonsKept = 0;
    while (crowd->GetState(agent).Value() == AgentState::WaitingForPath && updatesWaiting < 600)
    {
        ASSERT_TRUE(crowd->Update(cStep).IsOk());
        ++updatesWaiting;
        waterPolygonsKept += CountWaterPolygons(crowd->GetCorridor(agent).Value());
    }
    EXPECT_GT(updatesWaiting, 1) << "the new path took Updates to come";
    EXPECT_EQ(waterPolygonsKept, 0);
    EXPECT_EQ(WalkCountingWater(*crowd, agent), 0);
    ExpectArrivedAt(*crowd, agent, mEnd);
}

TEST_F(CrowdFilterTest, AFilterThatMakesTheWaterCostlySendsItsAgentsOnTheirWayRoundByTheBridge)
{
    BuildRiver();
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
    const Crowd::AgentID agent = crowd->AddAgent(mStart).Value();
    ASSERT_TRUE(crowd->SetTarget(agent, mEnd).IsOk());
    for (int update = 0; update < 20; ++update)
        ASSERT_TRUE(crowd->Update(cStep).IsOk());
    ASSERT_EQ(crowd->GetState(agent).Value(), AgentState::Moving);
    ASSERT_FALSE(InWater(crowd->GetPosition(agent).Value())) << "still on the south bank";
    // No area excluded: the water may be crossed, but the bridge is far cheaper. Only turning round the
    // bridge's corners may it cut over the water's edge
    PathFilter costly;
    costly.mAreaCost[cWater] = 100.0f;
    ASSERT_TRUE(crowd->SetFilter(cMaySwim, costly).IsOk());
    float farthestX = -100.0f, deepestInWater = 0.0f;
    for (int update = 0; update < 1200 && crowd->GetState(agent).Value() != AgentState::Arrived; ++update)
    {
        ASSERT_TRUE(crowd->Update(cStep).IsOk());
        const Vec3 position = crowd->GetPosition(agent).Value();
        farthestX = std::max(farthestX, position.x());
        if (InWater(position))
            deepestInWater =
                std::max(deepestInWater, std::min(1.0f - std::abs(position.z()), 8.0f - position.x()));
    }
    EXPECT_GT(farthestX, 8.0f) << "it took the bridge";
    EXPECT_LT(deepestInWater, 0.25f);
    ExpectArrivedAt(*crowd, agent, mEnd);
}

TEST_F(CrowdFilterTest, ATargetSetWithTheFilterChangeIsSoughtFromWhereTheAgentMayStand)
{
    BuildRiver();
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
    ASSERT_TRUE(crowd->SetFilter(cMayNotSwim, NoSwimming()).IsOk());
    // Idle in the river's middle, then both at once: its path must not start in the water
    const Crowd::AgentID agent = crowd->AddAgent(Vec3(-5, 0, 0.2f)).Value();
    ASSERT_TRUE(crowd->SetAgentFilter(agent, cMayNotSwim).IsOk());
    ASSERT_TRUE(crowd->SetTarget(agent, mEnd).IsOk());
    EXPECT_EQ(WalkCountingWater(*crowd, agent), 0);
    ExpectArrivedAt(*crowd, agent, mEnd);
    EXPECT_EQ(crowd->GetStatistics().mPathsFailed, 0u);
}

TEST_F(CrowdFilterTest, TheWorldMarksExactlyTheAreasItsCrowdsExcludeAsTheirSetsChange)
{
    BuildRiver();
    constexpr uint64_t cGround = uint64_t(1) << cDefaultArea, cSwim = uint64_t(1) << cWater;
    {
        // Every one of the 15 marks held, the ground's among them; a 16th set has none left
        std::unique_ptr<Crowd> first = Crowd::Create(*mWorld).Value();
        std::vector<uint64_t> held;
        for (int index = 1; index < Crowd::cMaxFilters; ++index)
        {
            PathFilter filter;
            filter.mExcludedAreas = index == 1 ? cGround : uint64_t(1) << (index + 10);
            ASSERT_TRUE(first->SetFilter(index, filter).IsOk());
            held.push_back(filter.mExcludedAreas);
        }
        EXPECT_EQ(WronglyMarkedPolygons(held), 0);
        PathFilter sixteenth;
        sixteenth.mExcludedAreas = cSwim;
        const Status full = first->SetFilter(0, sixteenth);
        ASSERT_FALSE(full.IsOk());
        EXPECT_EQ(full.GetError().mCode, ErrorCode::OutOfCapacity);
        EXPECT_EQ(first->GetFilter(0).Value().mExcludedAreas, 0u) << "the refused filter is not taken";
        // Bits of no area (Cairn's areas end at 62) take no flag
        PathFilter noArea;
        noArea.mExcludedAreas = uint64_t(1) << 63;
        EXPECT_TRUE(first->SetFilter(0, noArea).IsOk());
        // A set held already shares its mark
        PathFilter again;
        again.mExcludedAreas = cGround;
        ASSERT_TRUE(first->SetFilter(0, again).IsOk());
        held.push_back(cGround);
        EXPECT_EQ(WronglyMarkedPolygons(held), 0);
        // Refused, it keeps its shared mark: the ground's has both holders still, so none is free after one
        // lets go
        PathFilter other;
        other.mExcludedAreas = uint64_t(1) << 40;
        EXPECT_FALSE(first->SetFilter(0, other).IsOk());
        ASSERT_TRUE(first->SetFilter(1, PathFilter{}).IsOk());
        EXPECT_FALSE(first->SetFilter(1, other).IsOk()) << "filter 0 still holds the ground's mark";
        ASSERT_TRUE(first->SetFilter(1, again).IsOk());
        EXPECT_EQ(WronglyMarkedPolygons(held), 0);
        // Replacing a filter lets its mark go: the ground keeps its mark while another holds it, and a
        // filter replaced with every mark held takes its own for its new areas
        ASSERT_TRUE(first->SetFilter(0, PathFilter{}).IsOk());
        held.pop_back();
        EXPECT_EQ(WronglyMarkedPolygons(held), 0);
        ASSERT_TRUE(first->SetFilter(2, sixteenth).IsOk());
        held[1] = cSwim;
        EXPECT_EQ(WronglyMarkedPolygons(held), 0);
        EXPECT_FALSE(first->SetFilter(0, other).IsOk()) << "the water took the one mark let go";
    }
    // The crowd gone, its marks are free: a second crowd's sets take them, the ground's mark cleared where
    // no set holds it, and an agent that may not swim walks the ground and stays out of the water
    std::unique_ptr<Crowd> second = Crowd::Create(*mWorld).Value();
    std::vector<uint64_t> held;
    for (int index = 1; index < Crowd::cMaxFilters; ++index)
    {
        PathFilter filter;
        filter.mExcludedAreas = index == cMayNotSwim ? cSwim : uint64_t(1) << (index + 30);
        ASSERT_TRUE(second->SetFilter(index, filter).IsOk());
        held.push_back(filter.mExcludedAreas);
    }
    EXPECT_EQ(WronglyMarkedPolygons(held), 0);
    EXPECT_EQ(PushTowardsTheWater(*second), 0);
    const Crowd::AgentID agent = second->AddAgent(mStart, AgentParams{.mFilter = cMayNotSwim}).Value();
    ASSERT_TRUE(second->SetTarget(agent, mEnd).IsOk());
    EXPECT_EQ(WalkCountingWater(*second, agent), 0);
    ExpectArrivedAt(*second, agent, mEnd);
}

TEST_F(CrowdFilterTest, RandomPointsOfAFilterACrowdHoldsAreDrawnFromTheGroundItMayReachAlone)
{
    // A dry island 3 m across in a lake: nearly all the circle round its centre is water
    AddStaticBox(Vec3(0, -0.5f, 0), Vec3(1.5f, 0.5f, 1.5f));
    AddStaticBox(Vec3(0, -0.5f, -6), Vec3(10, 0.5f, 4.5f), cWater);
    AddStaticBox(Vec3(0, -0.5f, 6), Vec3(10, 0.5f, 4.5f), cWater);
    AddStaticBox(Vec3(-6, -0.5f, 0), Vec3(4.5f, 0.5f, 1.5f), cWater);
    AddStaticBox(Vec3(6, -0.5f, 0), Vec3(4.5f, 0.5f, 1.5f), cWater);
    MakeNavMesh();
    ASSERT_TRUE(RunUntilIdle());
    const Vec3 island(0.2f, 0, 0.3f);
    auto draw = [&](int& outFailed)
    {
        outFailed = 0;
        for (uint64_t seed = 1; seed <= 40; ++seed)
        {
            const Result<Vec3> point = mWorld->FindRandomPointAround(island, 8.0f, seed, NoSwimming());
            if (!point)
            {
                ++outFailed;
                continue;
            }
            // The island's polygons follow its edge to within the voxels' resolution
            EXPECT_LT(std::max(std::abs(point.Value().x()), std::abs(point.Value().z())), 1.75f)
                << "on the island";
        }
    };
    // Unmarked, each point drawn is checked and most are in the water: many calls give up
    int failedUnmarked = 0;
    draw(failedUnmarked);
    EXPECT_GT(failedUnmarked, 0);
    // Marked for a crowd's filter, Detour's spread keeps to the island: every call finds a point there
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
    ASSERT_TRUE(crowd->SetFilter(cMayNotSwim, NoSwimming()).IsOk());
    int failedMarked = 0;
    draw(failedMarked);
    EXPECT_EQ(failedMarked, 0);
    // The marks stay while no one holds them, until another set takes the flag
    crowd.reset();
    draw(failedMarked);
    EXPECT_EQ(failedMarked, 0);
}

TEST_F(CrowdFilterTest, BadFiltersAndIndicesAreRefused)
{
    BuildRiver();
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
    for (const int index : {-1, Crowd::cMaxFilters, 1 << 20})
    {
        EXPECT_FALSE(crowd->SetFilter(index, PathFilter{}).IsOk());
        EXPECT_FALSE(crowd->GetFilter(index).IsOk());
    }
    for (const float cost : {std::nanf(""), -1.0f, std::numeric_limits<float>::infinity()})
    {
        PathFilter bad = NoSwimming();
        bad.mAreaCost[cWater] = cost;
        EXPECT_FALSE(crowd->SetFilter(3, bad).IsOk());
        EXPECT_EQ(crowd->GetFilter(3).Value().mExcludedAreas, 0u) << "a refused filter is not taken";
    }
    EXPECT_FALSE(crowd->AddAgent(mStart, AgentParams{.mFilter = Crowd::cMaxFilters}).IsOk());
    const Crowd::AgentID agent = crowd->AddAgent(mStart).Value();
    EXPECT_FALSE(crowd->SetAgentFilter(agent, Crowd::cMaxFilters).IsOk());
    EXPECT_FALSE(crowd->SetAgentFilter(agent, -1).IsOk());
    ASSERT_TRUE(crowd->RemoveAgent(agent).IsOk());
    EXPECT_FALSE(crowd->SetAgentFilter(agent, 1).IsOk()) << "a stale id";
}

} // namespace
} // namespace cairn::navmesh::test
