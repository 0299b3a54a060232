// TileScheduler: which tiles exist (invokers, areas), in which order they are built, the job budget, and
// when tiles are dropped.

#include "NavMeshSceneFixture.h"

#include <algorithm>
#include <limits>

namespace cairn::navmesh::test
{
using namespace cairn::physics;
namespace
{

class TileSchedulerTest : public NavMeshSceneFixture
{
protected:
    /// A floor of 4 x 4 tiles (51.2 m) and no kept area: invokers decide.
    void MakeFloorWorld(TileScheduler::Settings inSettings)
    {
        AddStaticBox(Vec3(0, -0.5f, 0), Vec3(25.6f, 0.5f, 25.6f));
        MakeNavMesh(2, inSettings);
        ASSERT_TRUE(mScheduler->RemoveArea(mArea).IsOk());
    }
    TileCoord TileAt(float inX, float inZ) const { return mWorld->GetGrid().TileAt(inX, inZ); }
};

TEST_F(TileSchedulerTest, AnInvokerGetsTheTilesWithinItsRadiusNearestFirstWithinTheBudget)
{
    TileScheduler::Settings settings;
    settings.mMaxConcurrentJobs = 1;
    MakeFloorWorld(settings);
    // 2 m from the tile corner at the origin: a 5 m radius reaches the four tiles around the origin
    ASSERT_TRUE(mScheduler->AddInvoker(Vec3(2, 0, 2), 5.0f));
    std::vector<TileCoord> publishOrder;
    const auto deadline = std::chrono::steady_clock::now() + cIdleTimeout; // See there
    while (std::chrono::steady_clock::now() < deadline && !mScheduler->IsIdle())
    {
        Frame();
        EXPECT_LE(mScheduler->GetNumRunningJobs(), 1u);
        for (int x = 0; x < 4; ++x)
            for (int z = 0; z < 4; ++z)
                if (mWorld->HasTile({x, z}) && std::find(publishOrder.begin(), publishOrder.end(),
                                                         TileCoord{x, z}) == publishOrder.end())
                    publishOrder.push_back({x, z});
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    mScheduler->Update();
    ASSERT_EQ(publishOrder.size(), 4u);
    EXPECT_EQ(publishOrder.front(), TileAt(2, 2)); // The invoker's own tile first
    EXPECT_EQ(mWorld->GetNumTiles(), 4);
    EXPECT_TRUE(mWorld->HasTile(TileAt(-2, -2)));
    EXPECT_FALSE(mWorld->HasTile(TileAt(-20, -20))); // Beyond the radius
    EXPECT_EQ(mScheduler->GetStats().mFirstPublishFrames.size(), 4u);
    // Each latency with its tile, in the order the tiles were first published
    const std::vector<TileCoord> latencyTiles = mScheduler->GetStats().mFirstPublishTiles;
    ASSERT_EQ(latencyTiles.size(), 4u);
    std::vector<TileCoord> sortedLatencyTiles = latencyTiles, sortedPublished = publishOrder;
    auto byCoordinate = [](const TileCoord& inA, const TileCoord& inB)
    { return std::pair(inA.mX, inA.mZ) < std::pair(inB.mX, inB.mZ); };
    std::sort(sortedLatencyTiles.begin(), sortedLatencyTiles.end(), byCoordinate);
    std::sort(sortedPublished.begin(), sortedPublished.end(), byCoordinate);
    EXPECT_EQ(sortedLatencyTiles, sortedPublished);
    EXPECT_EQ(latencyTiles.front(), TileAt(2, 2));
}

TEST_F(TileSchedulerTest, TilesNoInvokerNeedsAreDroppedAfterTheDelay)
{
    TileScheduler::Settings settings;
    settings.mDropDelayFrames = 10;
    MakeFloorWorld(settings);
    const TileScheduler::InvokerID invoker = mScheduler->AddInvoker(Vec3(6.4f, 0, 6.4f), 1.0f).Value();
    ASSERT_TRUE(RunUntilIdle());
    const TileCoord before = TileAt(6.4f, 6.4f), after = TileAt(-19.2f, -19.2f);
    ASSERT_TRUE(mWorld->HasTile(before));
    ASSERT_TRUE(mScheduler->MoveInvoker(invoker, Vec3(-19.2f, 0, -19.2f)).IsOk()); // Another tile's centre
    for (int frame = 0; frame < 5; ++frame)
        Frame();
    EXPECT_TRUE(mWorld->HasTile(before)); // Kept for a while: the agent may come back
    ASSERT_TRUE(RunUntilIdle());
    for (int frame = 0; frame < 12; ++frame)
        Frame();
    EXPECT_FALSE(mWorld->HasTile(before));
    EXPECT_TRUE(mWorld->HasTile(after));
    EXPECT_GE(mScheduler->GetStats().mTilesDropped, 1u);
}

TEST_F(TileSchedulerTest, ARemovedAreasTilesGoAtOnce)
{
    AddStaticBox(Vec3(0, -0.5f, 0), Vec3(12.8f, 0.5f, 12.8f));
    MakeNavMesh(1);
    ASSERT_TRUE(RunUntilIdle());
    ASSERT_EQ(mWorld->GetNumTiles(), 4);
    ASSERT_TRUE(mScheduler->RemoveArea(mArea).IsOk()); // Streamed out
    Frame();
    EXPECT_EQ(mWorld->GetNumTiles(), 0);
}

TEST_F(TileSchedulerTest, ATileIsPublishedOnlyAtTheSyncPoint)
{
    AddStaticBox(Vec3(0, -0.5f, 0), Vec3(12.8f, 0.5f, 12.8f));
    MakeNavMesh(1);
    // Jobs run and finish between Updates, but the navmesh changes only inside Update
    Frame();
    const auto deadline = std::chrono::steady_clock::now() + cIdleTimeout; // See there
    while (std::chrono::steady_clock::now() < deadline && !mScheduler->HasFinishedJobs())
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    ASSERT_TRUE(mScheduler->HasFinishedJobs());
    EXPECT_EQ(mWorld->GetNumTiles(), 0);
    mScheduler->Update();
    EXPECT_GT(mWorld->GetNumTiles(), 0);
}

TEST_F(TileSchedulerTest, BadInvokersAreasAndLinksAreRefused)
{
    MakeFloorWorld({});
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_FALSE(mScheduler->AddInvoker(Vec3(nan, 0, 0), 5.0f));
    EXPECT_FALSE(mScheduler->AddInvoker(Vec3(0, 0, 0), -1.0f));
    EXPECT_FALSE(mScheduler->AddInvoker(Vec3(0, 0, 0), 1e9f));
    EXPECT_FALSE(mScheduler->AddArea(AABB(Vec3(1, 1, 1), Vec3(0, 0, 0))));
    EXPECT_FALSE(mScheduler->AddArea(AABB(Vec3(-2.5e10f, 0, 0), Vec3(2.5e10f, 1, 1))));
    OffMeshLink link;
    link.mStart = Vec3(1, 0, 1);
    link.mEnd = Vec3(3, 0, 1);
    link.mArea = 63; // Over cMaxAreaId: the tile build would refuse the whole start tile
    EXPECT_FALSE(mScheduler->AddOffMeshLink(link));
    link.mArea = cDefaultArea;
    link.mRadius = 0.0f;
    EXPECT_FALSE(mScheduler->AddOffMeshLink(link));
    link.mRadius = 0.5f;
    EXPECT_TRUE(mScheduler->AddOffMeshLink(link));
}

TEST_F(TileSchedulerTest, AJobBudgetOfZeroStillBuilds)
{
    TileScheduler::Settings settings;
    settings.mMaxConcurrentJobs = 0;
    MakeFloorWorld(settings);
    ASSERT_TRUE(mScheduler->AddInvoker(Vec3(2, 0, 2), 1.0f));
    EXPECT_TRUE(RunUntilIdle()) << "a budget of 0 never built anything, and IsIdle never came";
    EXPECT_GE(mWorld->GetNumTiles(), 1);
}

} // namespace
} // namespace cairn::navmesh::test
