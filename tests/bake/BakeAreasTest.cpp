// Area types from material names: a floor of two materials bakes into polygons of the mapped areas, on the
// right side of the floor; the mapping file's errors name the file and the key.

#include "BakeConfig.h"
#include "Baker.h"
#include "cairn/navmesh/NavMeshFile.h"
#include "common/TempFiles.h"

#include <DetourNavMesh.h>
#include <Recast.h>
#include <gtest/gtest.h>
#include <map>

namespace cairn::bake
{
using namespace cairn::physics;
namespace
{

class BakeAreasTest : public ::testing::Test
{
protected:
    std::string Write(const std::string& inName, const std::string& inText)
    {
        return mFiles.Write(inName, inText);
    }
    cairn::test::TempFiles mFiles;
};

/// A 24 m x 24 m floor: x < 12 is "road", the rest "grass", as two objects of one file.
const char* cTwoMaterialFloor = "v 0 0 0\nv 12 0 0\nv 12 0 24\nv 0 0 24\nv 24 0 0\nv 24 0 24\n"
                                "o Road\nusemtl road\nf 1 4 3\nf 1 3 2\n"
                                "o Field\nusemtl grass\nf 2 3 6\nf 2 6 5\n";

/// Polygon area -> the smallest and largest x of its polygons' vertices.
std::map<int, std::pair<float, float>> AreasAndTheirExtent(const navmesh::NavMeshFileContents& inContents)
{
    std::map<int, std::pair<float, float>> areas;
    Result<navmesh::DetourNavMeshPtr> navMesh = navmesh::CreateDetourNavMesh(inContents);
    EXPECT_TRUE(navMesh);
    if (!navMesh) return areas;
    const dtNavMesh& mesh = *navMesh.Value();
    for (int i = 0; i < mesh.getMaxTiles(); ++i)
    {
        const dtMeshTile* tile = mesh.getTile(i);
        if (tile == nullptr || tile->header == nullptr) continue;
        for (int p = 0; p < tile->header->polyCount; ++p)
        {
            const dtPoly& poly = tile->polys[p];
            auto [it, inserted] = areas.try_emplace(poly.getArea(), 1e9f, -1e9f);
            for (int v = 0; v < poly.vertCount; ++v)
            {
                const float x = tile->verts[poly.verts[v] * 3];
                it->second.first = std::min(it->second.first, x);
                it->second.second = std::max(it->second.second, x);
            }
        }
    }
    return areas;
}

TEST_F(BakeAreasTest, MaterialsBecomeTheirAreas)
{
    BakeSettings settings;
    settings.mInputs = {Write("floor.obj", cTwoMaterialFloor)};
    settings.mThreads = 1;
    settings.mAreas.mMaterialAreas = {{"road", 5}};

    Result<BakeResult> baked = Bake(settings);
    ASSERT_TRUE(baked) << baked.GetError().mMessage;
    EXPECT_EQ(baked.Value().mBodies, 2u); // One per object
    const auto areas = AreasAndTheirExtent(baked.Value().mNavMesh);
    ASSERT_EQ(areas.size(), 2u);
    ASSERT_TRUE(areas.contains(5));
    ASSERT_TRUE(areas.contains(RC_WALKABLE_AREA)); // The default area, as Recast calls it
    // The road's polygons on the road, the grass's on the grass (Recast keeps a seam where areas meet)
    EXPECT_LE(areas.at(5).second, 12.0f + 0.5f);
    EXPECT_GE(areas.at(RC_WALKABLE_AREA).first, 12.0f - 0.5f);

    // Without the mapping, one area; an incremental bake sees the change of areas as changed input
    BakeSettings plain = settings;
    plain.mAreas = {};
    Result<BakeResult> unmapped = Bake(plain);
    ASSERT_TRUE(unmapped) << unmapped.GetError().mMessage;
    EXPECT_EQ(AreasAndTheirExtent(unmapped.Value().mNavMesh).size(), 1u);
    BakeSettings incremental = settings;
    incremental.mPrevious = &unmapped.Value().mSummary;
    incremental.mPreviousNavMesh = &unmapped.Value().mNavMesh;
    Result<BakeResult> again = Bake(incremental);
    ASSERT_TRUE(again) << again.GetError().mMessage;
    EXPECT_GT(again.Value().mSummary.mTilesRebuilt, 0u);
    EXPECT_EQ(again.Value().mNavMesh.mTiles.size(), baked.Value().mNavMesh.mTiles.size());
    for (size_t i = 0; i < baked.Value().mNavMesh.mTiles.size(); ++i)
        EXPECT_EQ(again.Value().mNavMesh.mTiles[i].mData, baked.Value().mNavMesh.mTiles[i].mData);
}

TEST_F(BakeAreasTest, MappingFilesAreReadAndCheckedByName)
{
    Result<navmesh::AreaMapping> good =
        LoadAreaMapping(Write("good.json", R"({"default": 2, "materials": {"road": 1, "water": 9}})"));
    ASSERT_TRUE(good) << good.GetError().mMessage;
    EXPECT_EQ(good.Value().mDefaultArea, 2);
    EXPECT_EQ(good.Value().GetArea("water"), 9);
    EXPECT_EQ(good.Value().GetArea("stone"), 2);

    struct BadCase
    {
        const char* mText;
        const char* mNamed; ///< What the message must name
    };
    const BadCase cases[] = {
        {R"({"materials": {"lava": 63}})", "'lava'"},
        {R"({"materials": {"lava": -1}})", "'lava'"},
        {R"({"materials": {"lava": "hot"}})", "'lava'"},
        {R"({"materials": ["road"]})", "'materials'"},
        {R"({"default": 1.5})", "'default'"},
        {R"({"defualt": 1})", "'defualt'"},
        {R"([1, 2])", "not a JSON object"},
        {R"({"materials": {)", "parse error at line 1, column 16"},
        {R"({"default": 1e400})", "number overflow"},
        {R"({"default": 4294967296})", "'default'"},
    };
    for (const BadCase& bad : cases)
    {
        const std::string path = Write("bad.json", bad.mText);
        Result<navmesh::AreaMapping> mapping = LoadAreaMapping(path);
        ASSERT_FALSE(mapping) << bad.mText;
        EXPECT_EQ(mapping.GetError().mCode, ErrorCode::ParseError);
        EXPECT_NE(mapping.GetError().mMessage.find(path), std::string::npos) << mapping.GetError().mMessage;
        EXPECT_NE(mapping.GetError().mMessage.find(bad.mNamed), std::string::npos)
            << mapping.GetError().mMessage;
    }
    EXPECT_EQ(LoadAreaMapping("/nonexistent/areas.json").GetError().mCode, ErrorCode::IOError);
}

} // namespace
} // namespace cairn::bake
