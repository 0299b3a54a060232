// Bad input to the navmesh pipeline gets a clear error, never a crash: agent profiles out of range, tile
// geometry with NaN or bad indices, malformed OBJ files.

#include "TileChanges.h"
#include "cairn/navmesh/LevelMesh.h"
#include "cairn/navmesh/NavMeshFile.h"
#include "cairn/navmesh/NavMeshWorld.h"
#include "cairn/navmesh/TileBuilder.h"
#include "common/TempFiles.h"

#include <DetourCommon.h>
#include <DetourNavMesh.h>
#include <cstring>
#include <gtest/gtest.h>
#include <limits>

namespace cairn::navmesh::test
{
using namespace cairn::physics;
namespace
{

TEST(NavMeshBadInputTest, AgentProfilesOutOfRangeAreRefused)
{
    EXPECT_TRUE(AgentProfile{}.Validate().IsOk());
    auto refused = [](auto inChange)
    {
        AgentProfile profile;
        inChange(profile);
        return !profile.Validate().IsOk();
    };
    EXPECT_TRUE(refused([](AgentProfile& p) { p.mRadius = -1.0f; }));
    EXPECT_TRUE(refused([](AgentProfile& p) { p.mHeight = std::numeric_limits<float>::quiet_NaN(); }));
    EXPECT_TRUE(refused([](AgentProfile& p) { p.mMaxSlopeDegrees = 90.0f; }));
    EXPECT_TRUE(refused([](AgentProfile& p) { p.mTileSize = 12.7f; })); // Not a whole number of 0.2 m cells
    EXPECT_TRUE(refused([](AgentProfile& p) { p.mMaxVertsPerPoly = 7; }));
    EXPECT_TRUE(refused([](AgentProfile& p) { p.mCellSize = 0.0f; }));
    // Values Recast turns into int cell counts: too large ones overflowed and built every tile empty
    EXPECT_TRUE(refused([](AgentProfile& p) { p.mRadius = 1e9f; }));
    EXPECT_TRUE(refused([](AgentProfile& p) { p.mRegionMinSize = std::numeric_limits<float>::infinity(); }));
    EXPECT_TRUE(refused([](AgentProfile& p) { p.mEdgeMaxLength = 1e30f; }));
    // A radius beyond the tile: each tile's build grew with its square (1000 m: 2.3 GB for a 60 m level)
    EXPECT_TRUE(refused([](AgentProfile& p) { p.mRadius = 1000.0f; }));
    EXPECT_TRUE(refused([](AgentProfile& p) { p.mRadius = p.mTileSize * 1.01f; }));
    EXPECT_FALSE(refused([](AgentProfile& p) { p.mRadius = p.mTileSize; }));
    AgentProfile bad;
    bad.mCellSize = -0.2f;
    EXPECT_FALSE(NavMeshWorld::Create(TileGrid(0, 0, 12.8f, 0, 10), bad));
}

TEST(NavMeshBadInputTest, AGridThatDoesNotMatchTheProfileIsRefused)
{
    const AgentProfile profile;
    EXPECT_TRUE(NavMeshWorld::Create(TileGrid(0, 0, profile.mTileSize, 0, 10), profile));
    EXPECT_FALSE(NavMeshWorld::Create(TileGrid(0, 0, 2 * profile.mTileSize, 0, 10), profile))
        << "tiles of another size than the profile's";
    EXPECT_FALSE(NavMeshWorld::Create(TileGrid(0, 0, 0.0f, 0, 10), profile));
    EXPECT_FALSE(NavMeshWorld::Create(
        TileGrid(std::numeric_limits<float>::quiet_NaN(), 0, profile.mTileSize, 0, 10), profile));
    EXPECT_FALSE(NavMeshWorld::Create(TileGrid(0, 0, profile.mTileSize, 10, 0), profile))
        << "min y above max y";
}

// Recast keeps a span's top in 13 bits of cells (1,638 m at 0.2 m cells): a grid taller than that built a
// floor at y = 2,000 at y = 1,638.2, without a word, and no query found it
TEST(NavMeshBadInputTest, AHeightRangeRecastsSpansCannotHoldIsRefused)
{
    const AgentProfile profile;
    EXPECT_TRUE(NavMeshWorld::Create(TileGrid(0, 0, profile.mTileSize, 0, 1600), profile));
    const TileGrid tall(0, 0, profile.mTileSize, 0, 2100);
    const auto world = NavMeshWorld::Create(tall, profile);
    ASSERT_FALSE(world);
    EXPECT_EQ(world.GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_NE(world.GetError().mMessage.find("height range"), std::string::npos) << world.GetError().mMessage;
    TileGeometry floor;
    floor.AddTriangle(Vec3(-20, 2000, -20), Vec3(-20, 2000, 40), Vec3(40, 2000, 40), cDefaultArea);
    EXPECT_EQ(BuildTile(profile, tall, {0, 0}, floor).GetError().mCode, ErrorCode::InvalidArgument);
}

// The profile accepts tiles of any positive size; a world of tiles under a quarter metre made a crowd agent's
// snap to the navmesh (2 m each way) visit millions of tile slots, seconds a frame. A navmesh file is held
// to the same least tile size
TEST(NavMeshBadInputTest, TilesTooSmallForDetoursQueriesAreRefused)
{
    AgentProfile tiny;
    tiny.mCellSize = 1e-5f;
    tiny.mTileSize = 8e-5f;
    tiny.mRadius = 5e-5f;
    ASSERT_TRUE(tiny.Validate()) << tiny.Validate().GetError().mMessage;
    const auto world = NavMeshWorld::Create(TileGrid(0, 0, tiny.mTileSize, -1, 10), tiny);
    ASSERT_FALSE(world);
    EXPECT_NE(world.GetError().mMessage.find("tile size"), std::string::npos) << world.GetError().mMessage;
}

// A tile built on another grid (another origin) but handed in under a coordinate of this world's: Detour
// places it by its header's box, so it answered a query at (6, 0, 6) with a point 700 m away. Refused
TEST(NavMeshBadInputTest, ATileBuiltOnAnotherGridIsRefused)
{
    const AgentProfile profile;
    const TileGrid grid(0, 0, profile.mTileSize, -5, 20);
    const std::unique_ptr<NavMeshWorld> world = NavMeshWorld::Create(grid, profile).Value();
    auto floorOver = [&](const TileGrid& inGrid)
    {
        const AABB bounds = inGrid.GetTileBoundsWithBorder({0, 0}, 2.0f);
        TileGeometry geometry;
        geometry.AddTriangle(Vec3(bounds.mMin.x(), 0, bounds.mMin.z()),
                             Vec3(bounds.mMin.x(), 0, bounds.mMax.z()),
                             Vec3(bounds.mMax.x(), 0, bounds.mMax.z()), cDefaultArea);
        geometry.AddTriangle(Vec3(bounds.mMin.x(), 0, bounds.mMin.z()),
                             Vec3(bounds.mMax.x(), 0, bounds.mMax.z()),
                             Vec3(bounds.mMax.x(), 0, bounds.mMin.z()), cDefaultArea);
        return BuildTile(profile, inGrid, {0, 0}, geometry).Value();
    };
    for (const float offset : {500.0f, profile.mTileSize, -0.5f * profile.mTileSize})
    {
        const TileGrid other(offset, offset, profile.mTileSize, -5, 20);
        EXPECT_EQ(world->Publish(Changes(floorOver(other))), 0) << "grid moved by " << offset << " m";
    }
    std::string reason;
    EXPECT_EQ(world->GetRefusedTiles(&reason), 3u);
    EXPECT_NE(reason.find("grid"), std::string::npos) << reason;
    EXPECT_EQ(world->Publish(Changes(floorOver(grid))), 1) << "its own grid's tile";
    EXPECT_TRUE(world->FindNearestPoint(Vec3(6, 0, 6)));
}

TEST(NavMeshBadInputTest, HugeBoxesGiveACutOffNotAnOverflow)
{
    const TileGrid grid(0, 0, 12.8f, 0, 10);
    std::vector<TileCoord> tiles;
    // 5e10 m across: the tile span overflowed int32 and passed the cut-off, then billions of tiles were
    // listed
    EXPECT_FALSE(grid.TilesOverlapping(AABB(Vec3(-2.5e10f, 0, 0), Vec3(2.5e10f, 1, 1)), 0.0f, tiles));
    EXPECT_TRUE(tiles.empty());
    const TileCoord far = grid.TileAt(1e30f, -1e30f);
    EXPECT_EQ(far.mX, 1 << 30);
    EXPECT_EQ(far.mZ, -(1 << 30));
    EXPECT_TRUE(grid.TilesOverlapping(AABB(Vec3(0, 0, 0), Vec3(30, 1, 1)), 0.0f, tiles));
    EXPECT_EQ(tiles.size(), 3u);
}

TEST(NavMeshBadInputTest, AHugePathSearchExtentIsRefused)
{
    const AgentProfile profile;
    auto world = NavMeshWorld::Create(TileGrid(0, 0, profile.mTileSize, 0, 10), profile);
    ASSERT_TRUE(world);
    // Detour would visit every tile cell under it while holding the navmesh: minutes for 1e6 m
    const Result<PathResult> path =
        world.Value()->FindPath(Vec3(0, 0, 0), Vec3(5, 0, 5), {}, Vec3(1e6f, 1, 1e6f));
    ASSERT_FALSE(path);
    EXPECT_NE(path.GetError().mMessage.find("search extent"), std::string::npos);
}

TEST(NavMeshBadInputTest, BrokenTileGeometryIsRefused)
{
    const AgentProfile profile;
    const TileGrid grid(0, 0, profile.mTileSize, -1, 10);
    TileGeometry geometry;
    geometry.AddTriangle(Vec3(0, 0, 0), Vec3(0, 0, 10), Vec3(10, 0, 0), cDefaultArea);
    EXPECT_TRUE(BuildTile(profile, grid, {0, 0}, geometry));

    TileGeometry nan = geometry;
    nan.mVertices[4] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(BuildTile(profile, grid, {0, 0}, nan).GetError().mCode, ErrorCode::InvalidArgument);
    TileGeometry badIndex = geometry;
    badIndex.mTriangles[2] = 3;
    EXPECT_EQ(BuildTile(profile, grid, {0, 0}, badIndex).GetError().mCode, ErrorCode::InvalidArgument);
    TileGeometry negativeIndex = geometry;
    negativeIndex.mTriangles[0] = -1;
    EXPECT_EQ(BuildTile(profile, grid, {0, 0}, negativeIndex).GetError().mCode, ErrorCode::InvalidArgument);
    TileGeometry missingArea = geometry;
    missingArea.mAreas.clear();
    EXPECT_EQ(BuildTile(profile, grid, {0, 0}, missingArea).GetError().mCode, ErrorCode::InvalidArgument);
    TileGeometry badArea = geometry;
    badArea.mAreas[0] = 200;
    EXPECT_EQ(BuildTile(profile, grid, {0, 0}, badArea).GetError().mCode, ErrorCode::InvalidArgument);
    // Nothing walkable is not an error: an empty tile
    Result<BuiltTile> empty = BuildTile(profile, grid, {5, 5}, geometry);
    ASSERT_TRUE(empty);
    EXPECT_EQ(empty.Value().mData, nullptr);
}

class ObjFileTest : public ::testing::Test
{
protected:
    std::string Write(const std::string& inText)
    {
        return mFiles.Write("level-" + std::to_string(mCount++) + ".obj", inText);
    }
    cairn::test::TempFiles mFiles;
    int mCount = 0;
};

TEST_F(ObjFileTest, AGoodFileLoads)
{
    Result<IndexedMesh> mesh = LoadObjMesh(Write("v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 2 3 4\n"));
    ASSERT_TRUE(mesh) << mesh.GetError().mMessage;
    EXPECT_EQ(mesh.Value().mVertices.size(), 4u);
    EXPECT_EQ(mesh.Value().mTriangles.size(), 2u); // The quad, split
}

TEST_F(ObjFileTest, MalformedFilesGetClearErrors)
{
    EXPECT_EQ(LoadObjMesh("/nonexistent/level.obj").GetError().mCode, ErrorCode::IOError);
    EXPECT_EQ(LoadObjMesh(Write("")).GetError().mCode, ErrorCode::ParseError); // No triangles
    EXPECT_EQ(LoadObjMesh(Write("v 0 0 0\nv 1 0 0\nf 1 2 9\n")).GetError().mCode, ErrorCode::ParseError);
    EXPECT_EQ(LoadObjMesh(Write("v 0 0 0\nv 1 0 0\nv 1e20 0 0\nf 1 2 3\n")).GetError().mCode,
              ErrorCode::ParseError); // Beyond the world's range
    EXPECT_EQ(LoadObjMesh(Write("v 0 0 0\nv 1 0 0\nv nan 0 0\nf 1 2 3\n")).GetError().mCode,
              ErrorCode::ParseError);
    Result<IndexedMesh> garbage = LoadObjMesh(Write("\x01\x02 this is not an obj file\n\xff\xfe"));
    EXPECT_FALSE(garbage);
}

TEST(NavMeshBadInputTest, CorruptTileDataIsRefusedBeforeDetourReadsIt)
{
    // One real tile: a flat 10 m square
    const AgentProfile profile;
    const TileGrid grid(0, 0, profile.mTileSize, -1, 10);
    TileGeometry geometry;
    geometry.AddTriangle(Vec3(0, 0, 0), Vec3(0, 0, 10), Vec3(10, 0, 0), cDefaultArea);
    geometry.AddTriangle(Vec3(10, 0, 0), Vec3(0, 0, 10), Vec3(10, 0, 10), cDefaultArea);
    Result<BuiltTile> built = BuildTile(profile, grid, {0, 0}, geometry);
    ASSERT_TRUE(built);
    ASSERT_NE(built.Value().mData, nullptr);
    NavMeshFileContents contents;
    contents.mParams = MakeNavMeshParams(grid, 16).Value();
    const unsigned char* bytes = built.Value().mData.get();
    contents.mTiles.push_back({{0, 0}, std::vector<unsigned char>(bytes, bytes + built.Value().mDataSize)});
    ASSERT_TRUE(CreateDetourNavMesh(contents)) << "the good tile loads";

    cairn::test::TempFiles files;
    auto loadError = [&](const NavMeshFileContents& inCorrupt)
    {
        const std::string path = files.Path("corrupt.navmesh");
        EXPECT_TRUE(SaveNavMeshFile(path, inCorrupt).IsOk());
        Result<NavMeshFileContents> loaded = LoadNavMeshFile(path);
        EXPECT_FALSE(loaded.IsOk());
        EXPECT_EQ(CreateDetourNavMesh(inCorrupt).GetError().mCode, ErrorCode::InvalidArgument);
        return loaded.IsOk() ? std::string() : loaded.GetError().mMessage;
    };
    // A header count larger than the data: Detour would read and link past the buffer
    NavMeshFileContents moreVertices = contents;
    dtMeshHeader header;
    std::memcpy(&header, moreVertices.mTiles[0].mData.data(), sizeof(header));
    header.vertCount += 1000;
    std::memcpy(moreVertices.mTiles[0].mData.data(), &header, sizeof(header));
    EXPECT_NE(loadError(moreVertices).find("bytes"), std::string::npos);
    // A polygon naming a vertex that is not there
    NavMeshFileContents badIndex = contents;
    dtMeshHeader original;
    std::memcpy(&original, contents.mTiles[0].mData.data(), sizeof(original));
    const size_t polysOffset = size_t(dtAlign4(sizeof(dtMeshHeader)) + dtAlign4(12 * original.vertCount));
    dtPoly poly;
    std::memcpy(&poly, badIndex.mTiles[0].mData.data() + polysOffset, sizeof(poly));
    poly.verts[0] = 60000;
    std::memcpy(badIndex.mTiles[0].mData.data() + polysOffset, &poly, sizeof(poly));
    EXPECT_NE(loadError(badIndex).find("missing vertex"), std::string::npos);
}

TEST(NavMeshBadInputTest, ATileDetourCannotTakeIsRefusedAndTheOldOneStays)
{
    const AgentProfile profile;
    const TileGrid grid(0, 0, profile.mTileSize, -1, 10);
    auto world = NavMeshWorld::Create(grid, profile);
    ASSERT_TRUE(world);
    TileGeometry geometry;
    geometry.AddTriangle(Vec3(0, 0, 0), Vec3(0, 0, 10), Vec3(10, 0, 0), cDefaultArea);
    auto build = [&] { return BuildTile(profile, grid, {0, 0}, geometry).Value(); };
    ASSERT_EQ(world.Value()->Publish(Changes(build())), 1);
    const int polygons = world.Value()->GetTilePolygonCount({0, 0});
    ASSERT_GT(polygons, 0);

    // As a tile of a dense scene would be: more polygons than the 32-bit references leave room for
    BuiltTile tooMany = build();
    tooMany.mNumPolygons = 1 << 20;
    EXPECT_EQ(world.Value()->Publish(Changes(std::move(tooMany))), 0);
    std::string reason;
    EXPECT_EQ(world.Value()->GetRefusedTiles(&reason), 1u);
    EXPECT_NE(reason.find("polygons"), std::string::npos);
    EXPECT_EQ(world.Value()->GetTilePolygonCount({0, 0}), polygons)
        << "before, the old tile was removed first";
}

} // namespace
} // namespace cairn::navmesh::test
