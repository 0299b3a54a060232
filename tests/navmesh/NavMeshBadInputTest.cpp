// Bad input to the navmesh pipeline gets a clear error, never a crash: agent profiles out of range, tile
// geometry with NaN or bad indices, malformed OBJ files.

#include "cairn/navmesh/NavMeshWorld.h"
#include "cairn/navmesh/ObjMesh.h"
#include "cairn/navmesh/TileBuilder.h"
#include "common/TempFiles.h"

#include <gtest/gtest.h>
#include <limits>

namespace cairn::navmesh::test
{
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
    AgentProfile bad;
    bad.mCellSize = -0.2f;
    EXPECT_FALSE(NavMeshWorld::Create(TileGrid(0, 0, 12.8f, 0, 10), bad));
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

} // namespace
} // namespace cairn::navmesh::test
