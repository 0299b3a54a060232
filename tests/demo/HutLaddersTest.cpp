// The huts' ladders (HutLadders.h) over world tile (1, 0) of the demo's default world, built into the human
// navmesh as the demo streams the tile in (terrain, props, the huts' walls; no door panels, so every doorway
// is open): each ladder's feet stand on the navmesh either side of its hut's back wall, a path from one foot
// to the other goes over the ladder (a few metres), and one that may not climb goes round through the
// doorway (much farther).

#include "HutLadders.h"

#include "WorldGenerator.h"
#include "WorldNavTile.h"
#include "cairn/navmesh/NavMeshWorld.h"
#include "common/MakePhysicsSystem.h"

#include <gtest/gtest.h>

namespace cairn::demo
{
namespace
{
using namespace cairn::physics;

/// The length of a path's straight line from corner to corner.
float PathLength(const navmesh::PathResult& inPath)
{
    float length = 0.0f;
    for (size_t i = 1; i < inPath.mStraightPath.size(); ++i)
        length += (inPath.mStraightPath[i] - inPath.mStraightPath[i - 1]).norm();
    return length;
}

TEST(HutLaddersTest, EachLadderJoinsItsHutsInsideToTheOutsideBehindIt)
{
    PhysicsSettings settings;
    settings.mMaxBodies = 4096;
    const std::unique_ptr<PhysicsSystem> physics = cairn::test::MakePhysicsSystem(settings);
    BodyInterface& bodies = physics->GetBodyInterface();
    const WorldGenerator generator(WorldSettings{});
    const WorldTile worldTile{1, 0};
    const TileContent content = generator.GenerateTile(worldTile, false);
    ASSERT_FALSE(content.mDoors.empty()) << "the tile has huts";
    ASSERT_TRUE(bodies.CreateAndAddBody(content.mTerrain, Activation::DontActivate));
    for (const BodyCreationSettings& prop : content.mProps)
        ASSERT_TRUE(bodies.CreateAndAddBody(prop, Activation::DontActivate));
    std::vector<navmesh::OffMeshLink> ladders;
    for (const DoorSpec& door : content.mDoors)
        ladders.push_back(MakeHutLadder(door.mOutside, door.mInside, generator));

    // The human navmesh of the world tile's 25 navmesh tiles, each with the ladders whose foot outside it
    // holds, published as the scheduler would
    const navmesh::AgentProfile profile;
    const navmesh::TileGrid grid(0.0f, 0.0f, profile.mTileSize, -50.0f, 100.0f);
    std::unique_ptr<navmesh::NavMeshWorld> world = navmesh::NavMeshWorld::Create(grid, profile).Value();
    const navmesh::GeometryCollector collector(physics->GetBodyManager(), physics->GetBroadPhase());
    const int across = int(std::lround(generator.GetSettings().mTileSize / profile.mTileSize));
    std::vector<navmesh::BuiltTile> tiles;
    for (int z = 0; z < across; ++z)
        for (int x = 0; x < across; ++x)
        {
            const navmesh::TileCoord tile{worldTile.mX * across + x, worldTile.mZ * across + z};
            std::vector<navmesh::OffMeshLink> links;
            for (const navmesh::OffMeshLink& ladder : ladders)
                if (grid.TileAt(ladder.mStart.x(), ladder.mStart.z()) == tile) links.push_back(ladder);
            Result<navmesh::BuiltTile> built = BuildWorldNavTile(collector, profile, grid, tile, links);
            ASSERT_TRUE(built) << built.GetError().mMessage;
            tiles.push_back(std::move(built.Value()));
        }
    world->Publish(std::move(tiles));
    ASSERT_EQ(world->GetRefusedTiles(), 0u);

    const Vec3 snap(0.6f, 1.0f, 0.6f); // The ladder's radius across
    for (size_t h = 0; h < ladders.size(); ++h)
    {
        SCOPED_TRACE("hut " + std::to_string(h));
        const navmesh::OffMeshLink& ladder = ladders[h];
        for (const Vec3& foot : {ladder.mStart, ladder.mEnd})
        {
            const Result<Vec3> onNavMesh = world->FindNearestPoint(foot, {}, snap);
            ASSERT_TRUE(onNavMesh) << "a foot off the navmesh";
            EXPECT_LT((onNavMesh.Value() - foot).norm(), 0.6f);
        }
        const Result<navmesh::PathResult> over = world->FindPath(ladder.mStart, ladder.mEnd, {}, snap);
        ASSERT_TRUE(over && over.Value().mReachedEnd);
        EXPECT_LT(PathLength(over.Value()), 3.5f) << "over the ladder";
        const Result<navmesh::PathResult> round =
            world->FindPath(ladder.mStart, ladder.mEnd, NoClimbing(), snap);
        ASSERT_TRUE(round && round.Value().mReachedEnd) << "round through the open doorway";
        EXPECT_GT(PathLength(round.Value()), 8.0f) << "round the hut";
    }
}

} // namespace
} // namespace cairn::demo
