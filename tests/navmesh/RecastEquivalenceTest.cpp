// Same tiles as Recast: each of Recast's demo meshes, loaded as one static triangle-mesh body, gives navmesh
// tiles whose polygon and vertex counts (and Detour data) equal those built straight from the OBJ's triangles
// with the same parameters, for every tile. The physics path adds the broad-phase query, the static-body
// locks, the shape's triangles-in-box and the world transform; none of it may change a tile.

#include "cairn/navmesh/GeometryCollector.h"
#include "cairn/navmesh/LevelMesh.h"
#include "cairn/navmesh/TileBuilder.h"
#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/shapes/TriangleMeshShape.h"
#include "common/MakePhysicsSystem.h"
#include "common/SharedBenchData.h"

#include <cstring>
#include <filesystem>
#include <gtest/gtest.h>

namespace cairn::navmesh::test
{
using namespace cairn::physics;
namespace
{

class RecastEquivalenceTest : public ::testing::TestWithParam<const char*>
{
};

TEST_P(RecastEquivalenceTest, PhysicsWorldTilesEqualRawMeshTiles)
{
    const std::string path = cairn::GetSharedDataDir() + "/recast-meshes/" + GetParam();
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "missing " << path << " (../shared/data not present)";
    Result<IndexedMesh> loaded = LoadObjMesh(path);
    ASSERT_TRUE(loaded) << loaded.GetError().mMessage;
    const IndexedMesh& mesh = loaded.Value();
    const TileGeometry raw = mesh.ToTileGeometry();

    const std::unique_ptr<PhysicsSystem> physics = cairn::test::MakePhysicsSystem();
    BodyCreationSettings settings;
    auto shape = TriangleMeshShape::Create(mesh.mVertices, mesh.mTriangles);
    ASSERT_TRUE(shape) << shape.GetError().mMessage;
    settings.mShape = shape.Value();
    settings.mMotionType = MotionType::Static;
    settings.mObjectLayer = Layers::cStatic;
    ASSERT_TRUE(physics->GetBodyInterface().CreateAndAddBody(settings, Activation::DontActivate));

    AgentProfile profile;
    const AABB bounds = mesh.GetBounds();
    const TileGrid grid(bounds.mMin.x(), bounds.mMin.z(), profile.mTileSize, bounds.mMin.y() - 1.0f,
                        bounds.mMax.y() + 1.0f);
    std::vector<TileCoord> tiles;
    ASSERT_TRUE(grid.TilesOverlapping(bounds, 0.0f, tiles));
    const float border = float(profile.GetBorderCells()) * profile.mCellSize;
    const GeometryCollector collector(physics->GetBodyManager(), physics->GetBroadPhase());

    int tilesWithPolygons = 0;
    for (const TileCoord& tile : tiles)
    {
        Result<BuiltTile> direct = BuildTile(profile, grid, tile, raw);
        ASSERT_TRUE(direct) << direct.GetError().mMessage;

        const AABB box = grid.GetTileBoundsWithBorder(tile, border);
        std::vector<BodyID> bodies;
        collector.FindBodies(box, {}, bodies);
        TileGeometry collected;
        CollectStats stats;
        collector.CollectTriangles(box, {}, bodies, collected, stats);
        Result<BuiltTile> viaPhysics = BuildTile(profile, grid, tile, collected);
        ASSERT_TRUE(viaPhysics) << viaPhysics.GetError().mMessage;

        const BuiltTile& a = direct.Value();
        const BuiltTile& b = viaPhysics.Value();
        EXPECT_EQ(a.mNumPolygons, b.mNumPolygons) << "tile " << tile.mX << "," << tile.mZ;
        EXPECT_EQ(a.mNumVertices, b.mNumVertices) << "tile " << tile.mX << "," << tile.mZ;
        ASSERT_EQ(a.mDataSize, b.mDataSize) << "tile " << tile.mX << "," << tile.mZ;
        if (a.mData != nullptr)
        {
            EXPECT_EQ(std::memcmp(a.mData.get(), b.mData.get(), size_t(a.mDataSize)), 0)
                << "tile " << tile.mX << "," << tile.mZ;
        }
        // Only the tile's triangles are copied, not the whole level
        EXPECT_LT(collected.GetNumTriangles(), raw.GetNumTriangles() + 1);
        tilesWithPolygons += a.mNumPolygons > 0 ? 1 : 0;
    }
    // The comparison compared something: the level is walkable in several tiles
    EXPECT_GE(tilesWithPolygons, 2);
}

INSTANTIATE_TEST_SUITE_P(RecastDemoMeshes, RecastEquivalenceTest,
                         ::testing::Values("dungeon.obj", "nav_test.obj", "undulating.obj"),
                         [](const ::testing::TestParamInfo<const char*>& inInfo)
                         {
                             std::string name = inInfo.param;
                             return name.substr(0, name.find('.'));
                         });

} // namespace
} // namespace cairn::navmesh::test
