// Baking part of a level: a box or a list of tiles gives exactly those tiles of the full bake, byte for byte,
// with the whole level's navmesh parameters; tiles that are not the level's and boxes that are not boxes are
// errors; a level too large for a navmesh's reference bits is refused before any tile is built.

#include "Baker.h"
#include "common/SharedBenchData.h"
#include "common/TempFiles.h"

#include <chrono>
#include <cstring>
#include <filesystem>
#include <gtest/gtest.h>
#include <limits>
#include <map>

namespace cairn::bake
{
using namespace cairn::physics;
namespace
{

std::map<navmesh::TileCoord, std::vector<unsigned char>> TilesOf(const BakeResult& inResult)
{
    std::map<navmesh::TileCoord, std::vector<unsigned char>> tiles;
    for (const navmesh::NavMeshFileTile& tile : inResult.mNavMesh.mTiles)
        tiles[tile.mTile] = tile.mData;
    return tiles;
}

TEST(BakeSelectionTest, ABoxOrAListGivesThoseTilesOfTheFullBake)
{
    const std::string path = GetSharedDataDir() + "/recast-meshes/nav_test.obj";
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "missing " << path;
    BakeSettings settings;
    settings.mInputs = {path};
    Result<BakeResult> full = Bake(settings);
    ASSERT_TRUE(full) << full.GetError().mMessage;
    const auto fullTiles = TilesOf(full.Value());

    BakeSettings boxed = settings;
    boxed.mRegion = AABB(Vec3(1, 0, 1), Vec3(20, 0, 20)); // y ignored
    Result<BakeResult> part = Bake(boxed);
    ASSERT_TRUE(part) << part.GetError().mMessage;
    EXPECT_EQ(part.Value().mTilesBaked, 4u); // Tiles 0 and 1 on both axes touch [1, 20] (12.8 m tiles)
    EXPECT_EQ(part.Value().mTilesInWorld, full.Value().mTilesInWorld);
    EXPECT_EQ(
        std::memcmp(&part.Value().mNavMesh.mParams, &full.Value().mNavMesh.mParams, sizeof(dtNavMeshParams)),
        0);
    for (const auto& [tile, data] : TilesOf(part.Value()))
    {
        EXPECT_GE(tile.mX, 0);
        EXPECT_LE(tile.mX, 1);
        ASSERT_TRUE(fullTiles.contains(tile));
        EXPECT_EQ(data, fullTiles.at(tile));
    }

    BakeSettings listed = settings;
    listed.mTiles = {{1, 0}, {0, 0}, {1, 0}}; // Any order, repeats ignored
    Result<BakeResult> two = Bake(listed);
    ASSERT_TRUE(two) << two.GetError().mMessage;
    EXPECT_EQ(two.Value().mTilesBaked, 2u);
    for (const auto& [tile, data] : TilesOf(two.Value()))
        EXPECT_EQ(data, fullTiles.at(tile));
    listed.mRegion = AABB(Vec3(1, 0, 1), Vec3(5, 0, 5)); // Both: the listed tiles in the box
    Result<BakeResult> inBox = Bake(listed);
    ASSERT_TRUE(inBox) << inBox.GetError().mMessage;
    EXPECT_EQ(inBox.Value().mTilesBaked, 1u);

    listed.mRegion.reset();
    listed.mTiles = {{0, 0}, {500, 3}};
    Result<BakeResult> outside = Bake(listed);
    ASSERT_FALSE(outside);
    EXPECT_NE(outside.GetError().mMessage.find("(500, 3)"), std::string::npos) << outside.GetError().mMessage;
    boxed.mRegion = AABB(Vec3(5, 0, 5), Vec3(1, 0, 1));
    EXPECT_EQ(Bake(boxed).GetError().mCode, ErrorCode::InvalidArgument);
    boxed.mRegion = AABB(Vec3(std::numeric_limits<float>::quiet_NaN(), 0, 0), Vec3(1, 0, 1));
    EXPECT_EQ(Bake(boxed).GetError().mCode, ErrorCode::InvalidArgument);
}

TEST(BakeSelectionTest, ALevelTooLargeForTheReferenceBitsIsRefusedBeforeBaking)
{
    // Two 10 m floors 1.65 km apart: 130 x 130 tiles of 12.8 m leave a 32-bit polygon reference too few bits
    // for a tile's polygons
    test::TempFiles files;
    BakeSettings settings;
    settings.mInputs = {files.Write(
        "far-apart.obj", "v 0 0 0\nv 0 0 10\nv 10 0 10\nv 10 0 0\nf 1 2 3 4\n"
                         "v 1650 0 1650\nv 1650 0 1660\nv 1660 0 1660\nv 1660 0 1650\nf 5 6 7 8\n")};
    uint32_t progressCalls = 0;
    settings.mProgress = [&](uint32_t, uint32_t) { ++progressCalls; };
    Result<BakeResult> refused = Bake(settings);
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.GetError().mCode, ErrorCode::OutOfCapacity);
    EXPECT_NE(refused.GetError().mMessage.find("too large for one navmesh"), std::string::npos)
        << refused.GetError().mMessage;
    EXPECT_EQ(progressCalls, 0u); // No tile was built
    // Larger tiles fit (7 x 7 of 256 m)
    settings.mProfile.mTileSize = 256.0f;
    Result<BakeResult> fits = Bake(settings);
    ASSERT_TRUE(fits) << fits.GetError().mMessage;
    EXPECT_GT(fits.Value().mPolygons, 0u);
}

} // namespace
} // namespace cairn::bake

namespace cairn::bake
{
using namespace cairn::physics;
namespace
{

TEST(FileLevelSourceTest, LargePartsAndDegeneratePartsAndTinyCells)
{
    test::TempFiles files;
    // A 2 km road (over far more cells than the index keeps per part), a small box, and a collapsed helper
    // object whose triangles have no area
    const std::string level =
        files.Write("level.obj", "o Road\nv 0 0 0\nv 0 0 4\nv 2000 0 4\nv 2000 0 0\nf 1 2 3 4\n"
                                 "o Box\nv 10 0 10\nv 10 0 12\nv 12 0 12\nf 5 6 7\n"
                                 "o Helper\nv 5 0 5\nv 6 0 5\nv 7 0 5\nf 8 9 10\n");
    Result<std::unique_ptr<FileLevelSource>> source = FileLevelSource::Load({level}, {}, 12.8f);
    ASSERT_TRUE(source) << source.GetError().mMessage;
    EXPECT_EQ(source.Value()->GetNumObjects(), 2u); // The helper is left out
    std::vector<SourceObject> near;
    source.Value()->FindObjects(AABB(Vec3(1500, -1, 0), Vec3(1510, 1, 10)), near);
    ASSERT_EQ(near.size(), 1u); // The road, far from its first cells
    near.clear();
    source.Value()->FindObjects(AABB(Vec3(9, -1, 0), Vec3(13, 1, 13)), near);
    EXPECT_EQ(near.size(), 2u); // The road and the box
    near.clear();
    source.Value()->FindObjects(AABB(Vec3(-1e6f, -1, -1e6f), Vec3(1e6f, 1, 1e6f)), near); // Every cell
    EXPECT_EQ(near.size(), 2u);

    // A tile size far too small is refused before the level is indexed by it
    BakeSettings settings;
    settings.mInputs = {level};
    settings.mProfile.mTileSize = 0.01f;
    EXPECT_EQ(Bake(settings).GetError().mCode, ErrorCode::InvalidArgument);
}

} // namespace
} // namespace cairn::bake
