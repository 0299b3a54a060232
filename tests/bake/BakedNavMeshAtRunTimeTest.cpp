// A baked navmesh at run time: the tiles of a bake with an off-mesh link, saved and loaded back, published
// into a NavMeshWorld, where a path query and a crowd agent go over the link; a region's tiles alone, as a
// streaming game loads them, and their removal; a file baked on another grid or for another agent is refused.

#include "Baker.h"
#include "OffMeshLinksFile.h"
#include "cairn/navmesh/BakedTiles.h"
#include "cairn/navmesh/Crowd.h"
#include "cairn/navmesh/NavMeshWorld.h"
#include "common/TempFiles.h"

#include <gtest/gtest.h>
#include <limits>

namespace cairn::bake
{
using namespace cairn::physics;
namespace
{

/// Two floors a 3 m gap apart along x (x in [0, 10] and [13, 24], z in [0, 8]): tiles (0, 0) and (1, 0).
const char* cPlatforms = "v 0 0 0\nv 10 0 0\nv 10 0 8\nv 0 0 8\nv 13 0 0\nv 24 0 0\nv 24 0 8\nv 13 0 8\n"
                         "o West\nf 1 4 3\nf 1 3 2\no East\nf 5 8 7\nf 5 7 6\n";

class BakedNavMeshAtRunTimeTest : public ::testing::Test
{
protected:
    void SetUp() override
    {
        BakeSettings settings;
        settings.mInputs = {mFiles.Write("platforms.obj", cPlatforms)};
        settings.mThreads = 1;
        settings.mOutputPath = mFiles.Path("platforms.navmesh");
        settings.mLinks =
            LoadOffMeshLinks(
                mFiles.Write("links.json",
                             R"({"links": [{"start": [9, 0, 4], "end": [14, 0, 4], "user_id": 5}]})"))
                .Value();
        Result<BakeResult> baked = Bake(settings);
        ASSERT_TRUE(baked) << baked.GetError().mMessage;
        Result<navmesh::NavMeshFileContents> loaded = navmesh::LoadNavMeshFile(settings.mOutputPath);
        ASSERT_TRUE(loaded) << loaded.GetError().mMessage;
        mBaked = std::move(loaded.Value());
        ASSERT_EQ(mBaked.mTiles.size(), 2u);
        // The game's world on the bake's grid: the origin and tile size the baker used (its default profile)
        mWorld = navmesh::NavMeshWorld::Create(mGrid, navmesh::AgentProfile()).Value();
    }

    cairn::test::TempFiles mFiles;
    navmesh::NavMeshFileContents mBaked;
    const navmesh::TileGrid mGrid{0.0f, 0.0f, navmesh::AgentProfile().mTileSize, -50.0f, 100.0f};
    std::unique_ptr<navmesh::NavMeshWorld> mWorld;
};

TEST_F(BakedNavMeshAtRunTimeTest, ACrowdAgentGoesOverTheBakedLink)
{
    Result<std::vector<navmesh::BuiltTile>> tiles = navmesh::MakeBakedTileChanges(mBaked, *mWorld);
    ASSERT_TRUE(tiles) << tiles.GetError().mMessage;
    EXPECT_EQ(mWorld->Publish(std::move(tiles.Value())), 2);
    EXPECT_EQ(mWorld->GetRefusedTiles(), 0u);
    const Vec3 west(3, 0, 4), east(20, 0, 4);
    Result<navmesh::PathResult> path = mWorld->FindPath(west, east);
    ASSERT_TRUE(path) << path.GetError().mMessage;
    EXPECT_TRUE(path.Value().mReachedEnd);

    std::unique_ptr<navmesh::Crowd> crowd = navmesh::Crowd::Create(*mWorld).Value();
    const navmesh::Crowd::AgentID agent = crowd->AddAgent(west).Value();
    ASSERT_TRUE(crowd->SetTarget(agent, east).IsOk());
    uint32_t linkSeen = 0;
    for (int update = 0; update < 600; ++update)
    {
        ASSERT_TRUE(crowd->Update(1.0f / 60.0f).IsOk());
        if (Result<navmesh::OffMeshLinkCrossing> link = crowd->GetOffMeshLink(agent))
            linkSeen = link.Value().mUserID;
    }
    EXPECT_EQ(linkSeen, 5u) << "it took the baked link";
    EXPECT_EQ(crowd->GetState(agent).Value(), navmesh::AgentState::Arrived);
    EXPECT_LT((crowd->GetPosition(agent).Value() - east).norm(), 0.6f);
}

// A streaming game publishes a region's tiles as it loads and removes them as it goes
TEST_F(BakedNavMeshAtRunTimeTest, ARegionsTilesAloneAreLoadedAndRemoved)
{
    const AABB westOnly(Vec3(1, -10, 1), Vec3(5, 10, 5));
    Result<std::vector<navmesh::BuiltTile>> tiles = navmesh::MakeBakedTileChanges(mBaked, *mWorld, westOnly);
    ASSERT_TRUE(tiles);
    ASSERT_EQ(tiles.Value().size(), 1u);
    EXPECT_EQ(tiles.Value()[0].mTile, (navmesh::TileCoord{0, 0}));
    EXPECT_EQ(mWorld->Publish(std::move(tiles.Value())), 1);
    EXPECT_TRUE(mWorld->FindNearestPoint(Vec3(3, 0, 4)));
    EXPECT_FALSE(mWorld->FindNearestPoint(Vec3(20, 0, 4))) << "the east tile is not loaded";

    std::vector<navmesh::BuiltTile> removal;
    removal.push_back(navmesh::NavMeshWorld::Removal({0, 0}));
    EXPECT_EQ(mWorld->Publish(std::move(removal)), 1);
    EXPECT_FALSE(mWorld->FindNearestPoint(Vec3(3, 0, 4)));
}

// A file baked on another grid, or for another agent, is refused, as is a region that is no box
TEST_F(BakedNavMeshAtRunTimeTest, AFileBakedForAnotherGridOrAgentIsRefused)
{
    const auto refusal = [&](const navmesh::NavMeshWorld& inWorld, const std::optional<AABB>& inRegion = {})
    {
        Result<std::vector<navmesh::BuiltTile>> tiles =
            navmesh::MakeBakedTileChanges(mBaked, inWorld, inRegion);
        return tiles ? std::string("accepted") : tiles.GetError().mMessage;
    };
    const navmesh::AgentProfile human;
    const navmesh::TileGrid shifted(1.0f, 0.0f, mGrid.GetTileSize(), -50.0f, 100.0f);
    EXPECT_NE(
        refusal(*navmesh::NavMeshWorld::Create(shifted, human).Value()).find("baked on a grid of origin"),
        std::string::npos);
    navmesh::AgentProfile wide = human;
    wide.mTileSize *= 2.0f;
    const navmesh::TileGrid wider(0.0f, 0.0f, wide.mTileSize, -50.0f, 100.0f);
    EXPECT_NE(refusal(*navmesh::NavMeshWorld::Create(wider, wide).Value()).find("baked on a grid"),
              std::string::npos);
    navmesh::AgentProfile large = human;
    large.mRadius = 1.5f;
    EXPECT_NE(
        refusal(*navmesh::NavMeshWorld::Create(mGrid, large).Value()).find("baked for an agent of height"),
        std::string::npos)
        << "a large agent's world";
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_NE(refusal(*mWorld, AABB(Vec3(nan, 0, 0), Vec3(1, 1, 1))).find("not a box"), std::string::npos);
    EXPECT_NE(refusal(*mWorld, AABB(Vec3(5, 0, 0), Vec3(1, 1, 1))).find("not a box"), std::string::npos);
    EXPECT_EQ(refusal(*mWorld), "accepted");
}

} // namespace
} // namespace cairn::bake
