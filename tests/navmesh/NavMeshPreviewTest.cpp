// Navmesh previews: the OBJ holds exactly the detail triangles, inside the tiles; the SVG map draws each
// polygon once, coloured by area with a legend, and the off-mesh links as arrows.

#include "cairn/navmesh/NavMeshPreview.h"

#include "cairn/navmesh/NavMeshFile.h"
#include "cairn/navmesh/TileBuilder.h"

#include <gtest/gtest.h>
#include <sstream>

namespace cairn::navmesh::test
{
using namespace cairn::physics;
namespace
{

size_t CountOf(const std::string& inText, const std::string& inWhat)
{
    size_t count = 0;
    for (size_t at = inText.find(inWhat); at != std::string::npos; at = inText.find(inWhat, at + 1))
        ++count;
    return count;
}

/// Two tiles of floor at y = 0: x < 12.8 (tile 0) with area 3, the next tile with the default area, and a
/// one-way drop link in tile 0.
NavMeshFileContents TwoTileFloor()
{
    const AgentProfile profile;
    const TileGrid grid(0, 0, profile.mTileSize, -2, 4);
    TileGeometry geometry;
    const float size = profile.mTileSize;
    geometry.AddTriangle(Vec3(-2, 0, -2), Vec3(-2, 0, size + 2), Vec3(size, 0, size + 2), 3);
    geometry.AddTriangle(Vec3(-2, 0, -2), Vec3(size, 0, size + 2), Vec3(size, 0, -2), 3);
    geometry.AddTriangle(Vec3(size, 0, -2), Vec3(size, 0, size + 2), Vec3(2 * size + 2, 0, size + 2), 0);
    geometry.AddTriangle(Vec3(size, 0, -2), Vec3(2 * size + 2, 0, size + 2), Vec3(2 * size + 2, 0, -2), 0);
    OffMeshLink drop;
    drop.mStart = Vec3(3, 0, 3);
    drop.mEnd = Vec3(8, 0, 8);
    drop.mBidirectional = false;
    NavMeshFileContents contents;
    contents.mParams = MakeNavMeshParams(grid, 4).Value();
    for (int x = 0; x < 2; ++x)
    {
        Result<BuiltTile> tile = BuildTile(profile, grid, {x, 0}, geometry, std::span(&drop, 1));
        EXPECT_TRUE(tile && tile.Value().mData != nullptr);
        if (!tile || tile.Value().mData == nullptr) continue;
        const unsigned char* data = tile.Value().mData.get();
        contents.mTiles.push_back({{x, 0}, std::vector<unsigned char>(data, data + tile.Value().mDataSize)});
    }
    return contents;
}

TEST(NavMeshPreviewTest, ObjHoldsTheDetailTrianglesInsideTheTiles)
{
    const DetourNavMeshPtr navMesh = CreateDetourNavMesh(TwoTileFloor()).Value();
    int detailTriangles = 0;
    for (int i = 0; i < navMesh->getMaxTiles(); ++i)
    {
        const dtMeshTile* tile = static_cast<const dtNavMesh&>(*navMesh).getTile(i);
        if (tile == nullptr || tile->header == nullptr) continue;
        for (int p = 0; p < tile->header->polyCount; ++p)
            if (tile->polys[p].getType() != DT_POLYTYPE_OFFMESH_CONNECTION)
                detailTriangles += tile->detailMeshes[p].triCount;
    }
    const std::string obj = NavMeshToObj(*navMesh);
    EXPECT_GT(detailTriangles, 0);
    EXPECT_EQ(int(CountOf(obj, "\nf ")), detailTriangles);
    EXPECT_EQ(int(CountOf(obj, "\nv ")), 3 * detailTriangles);
    EXPECT_EQ(CountOf(obj, "\no tile_"), 2u);
    std::istringstream lines(obj);
    std::string line;
    while (std::getline(lines, line))
    {
        if (line.rfind("v ", 0) != 0) continue;
        float x = 0, y = 0, z = 0;
        ASSERT_EQ(std::sscanf(line.c_str(), "v %f %f %f", &x, &y, &z), 3);
        EXPECT_GE(x, -0.01f);
        EXPECT_LE(x, 2 * 12.8f + 0.01f);
        EXPECT_NEAR(y, 0.0f, 0.5f);
    }
}

TEST(NavMeshPreviewTest, SvgDrawsEachPolygonByAreaAndTheLinks)
{
    const DetourNavMeshPtr navMesh = CreateDetourNavMesh(TwoTileFloor()).Value();
    int polygons = 0, links = 0;
    for (int i = 0; i < navMesh->getMaxTiles(); ++i)
    {
        const dtMeshTile* tile = static_cast<const dtNavMesh&>(*navMesh).getTile(i);
        if (tile == nullptr || tile->header == nullptr) continue;
        for (int p = 0; p < tile->header->polyCount; ++p)
            (tile->polys[p].getType() == DT_POLYTYPE_OFFMESH_CONNECTION ? links : polygons) += 1;
    }
    const std::string svg = NavMeshToSvg(*navMesh);
    EXPECT_EQ(svg.rfind("<svg", 0), 0u);
    EXPECT_NE(svg.find("</svg>"), std::string::npos);
    EXPECT_EQ(int(CountOf(svg, "<polygon ")), polygons);
    EXPECT_EQ(links, 1);
    EXPECT_EQ(CountOf(svg, "marker-end=\"url(#arrow)\""), 1u);
    // A legend entry per area: 3, and the default ground
    EXPECT_NE(svg.find("area 3: "), std::string::npos);
    EXPECT_NE(svg.find("ground: "), std::string::npos);
    EXPECT_EQ(CountOf(svg, "polygons</text>"), 2u);
    // Two tile borders
    EXPECT_EQ(CountOf(svg, "stroke=\"#cccccc\""), 2u);
}

TEST(NavMeshPreviewTest, AnEmptyNavMeshGivesAnEmptyPicture)
{
    NavMeshFileContents empty;
    const AgentProfile profile;
    empty.mParams = MakeNavMeshParams(TileGrid(0, 0, profile.mTileSize, -2, 4), 4).Value();
    const DetourNavMeshPtr navMesh = CreateDetourNavMesh(empty).Value();
    EXPECT_NE(NavMeshToSvg(*navMesh).find("empty navmesh"), std::string::npos);
    EXPECT_EQ(CountOf(NavMeshToObj(*navMesh), "\nf "), 0u);
}

} // namespace
} // namespace cairn::navmesh::test
