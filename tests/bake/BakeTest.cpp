// The offline baker on Recast's demo meshes: the same polygons per tile as a direct Recast build; the file
// loads back into a dtNavMesh that answers path queries; 1 and 2 threads give the same bytes, and two merged
// shards equal the full bake; malformed inputs get clear errors and leave no output behind.

#include "Baker.h"
#include "cairn/navmesh/LevelMesh.h"
#include "cairn/navmesh/TileBuilder.h"
#include "common/SharedBenchData.h"
#include "common/TempFiles.h"

#include <DetourNavMeshQuery.h>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <iterator>
#include <map>
#include <random>

namespace cairn::bake
{
using namespace cairn::physics;
namespace
{

using cairn::test::ReadBytes;

std::string MeshPath(const char* inName)
{
    return GetSharedDataDir() + "/recast-meshes/" + inName;
}

std::string TempPath(const std::string& inName)
{
    static const cairn::test::TempFiles files; // A folder of this process's own, removed at exit
    return files.Path(inName);
}

class BakeMeshTest : public ::testing::TestWithParam<const char*>
{
};

TEST_P(BakeMeshTest, SamePolygonsAsDirectRecastAndLoadsBackForPaths)
{
    const std::string path = MeshPath(GetParam());
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "missing " << path << " (../shared/data not present)";
    BakeSettings settings;
    settings.mInputs = {path};
    settings.mThreads = 1;
    Result<BakeResult> baked = Bake(settings);
    ASSERT_TRUE(baked) << baked.GetError().mMessage;

    // The direct build: the OBJ's raw triangles into Recast, tile by tile, on the same grid
    const navmesh::IndexedMesh mesh = navmesh::LoadObjMesh(path).Value();
    const AABB bounds = mesh.GetBounds();
    const navmesh::TileGrid grid(0.0f, 0.0f, settings.mProfile.mTileSize, bounds.mMin.y() - 1.0f,
                                 bounds.mMax.y() + 1.0f);
    std::vector<navmesh::TileCoord> tiles;
    ASSERT_TRUE(grid.TilesOverlapping(bounds, 0.0f, tiles));
    const navmesh::TileGeometry raw = mesh.ToTileGeometry();
    std::map<navmesh::TileCoord, int> directPolygons;
    for (const navmesh::TileCoord& tile : tiles)
    {
        Result<navmesh::BuiltTile> direct = navmesh::BuildTile(settings.mProfile, grid, tile, raw);
        ASSERT_TRUE(direct) << direct.GetError().mMessage;
        if (direct.Value().mData != nullptr) directPolygons[tile] = direct.Value().mNumPolygons;
    }
    ASSERT_EQ(baked.Value().mNavMesh.mTiles.size(), directPolygons.size());
    for (const navmesh::NavMeshFileTile& tile : baked.Value().mNavMesh.mTiles)
    {
        dtMeshHeader header;
        std::memcpy(&header, tile.mData.data(), sizeof(header));
        ASSERT_TRUE(directPolygons.contains(tile.mTile));
        EXPECT_EQ(header.polyCount, directPolygons[tile.mTile])
            << "tile " << tile.mTile.mX << "," << tile.mTile.mZ;
    }

    // Saved, loaded back as a runtime would, and queried
    const std::string file = TempPath(std::string(GetParam()) + ".navmesh");
    ASSERT_TRUE(navmesh::SaveNavMeshFile(file, baked.Value().mNavMesh).IsOk());
    Result<navmesh::NavMeshFileContents> loaded = navmesh::LoadNavMeshFile(file);
    ASSERT_TRUE(loaded) << loaded.GetError().mMessage;
    Result<navmesh::DetourNavMeshPtr> navMesh = navmesh::CreateDetourNavMesh(loaded.Value());
    ASSERT_TRUE(navMesh) << navMesh.GetError().mMessage;
    dtNavMeshQuery query;
    ASSERT_TRUE(dtStatusSucceed(query.init(navMesh.Value().get(), 2048)));
    dtQueryFilter filter;
    auto frand = []() -> float
    {
        static std::mt19937 generator(9);
        return std::uniform_real_distribution<float>(0.0f, 1.0f)(generator);
    };
    int paths = 0;
    for (int i = 0; i < 20; ++i)
    {
        dtPolyRef start = 0, end = 0;
        float startPoint[3], endPoint[3];
        ASSERT_TRUE(dtStatusSucceed(query.findRandomPoint(&filter, frand, &start, startPoint)));
        // A point reachable from the start, by construction
        if (dtStatusFailed(query.findRandomPointAroundCircle(start, startPoint, 10.0f, &filter, frand, &end,
                                                             endPoint)) ||
            end == 0)
            continue;
        dtPolyRef corridor[256];
        int count = 0;
        ASSERT_TRUE(dtStatusSucceed(
            query.findPath(start, end, startPoint, endPoint, &filter, corridor, &count, 256)));
        ASSERT_GT(count, 0);
        EXPECT_EQ(corridor[count - 1], end);
        ++paths;
    }
    EXPECT_GT(paths, 10);
    std::filesystem::remove(file);
}

INSTANTIATE_TEST_SUITE_P(RecastDemoMeshes, BakeMeshTest,
                         ::testing::Values("dungeon.obj", "nav_test.obj", "undulating.obj"),
                         [](const ::testing::TestParamInfo<const char*>& inInfo)
                         {
                             std::string name = inInfo.param;
                             return name.substr(0, name.find('.'));
                         });

TEST(BakeTest, ThreadCountAndShardsDoNotChangeTheBytes)
{
    const std::string path = MeshPath("nav_test.obj");
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "missing " << path;
    BakeSettings settings;
    settings.mInputs = {path};
    auto bakeTo = [&](uint32_t inThreads, uint32_t inShard, uint32_t inShards, const std::string& inFile)
    {
        settings.mThreads = inThreads;
        settings.mShard = inShard;
        settings.mShardCount = inShards;
        Result<BakeResult> result = Bake(settings);
        EXPECT_TRUE(result);
        EXPECT_TRUE(navmesh::SaveNavMeshFile(inFile, result.Value().mNavMesh).IsOk());
        return result.Value().mNavMesh;
    };
    const std::string one = TempPath("one.navmesh"), two = TempPath("two.navmesh"),
                      four = TempPath("four.navmesh"), merged = TempPath("merged.navmesh");
    bakeTo(1, 0, 1, one);
    bakeTo(2, 0, 1, two);
    bakeTo(4, 0, 1, four);
    EXPECT_EQ(ReadBytes(one), ReadBytes(two));
    EXPECT_EQ(ReadBytes(one), ReadBytes(four));
    const navmesh::NavMeshFileContents shard0 = bakeTo(2, 0, 2, TempPath("s0.navmesh"));
    const navmesh::NavMeshFileContents shard1 = bakeTo(1, 1, 2, TempPath("s1.navmesh"));
    EXPECT_FALSE(shard0.mTiles.empty());
    EXPECT_FALSE(shard1.mTiles.empty());
    Result<navmesh::NavMeshFileContents> combined = MergeShards({shard0, shard1});
    ASSERT_TRUE(combined);
    ASSERT_TRUE(navmesh::SaveNavMeshFile(merged, combined.Value()).IsOk());
    EXPECT_EQ(ReadBytes(one), ReadBytes(merged));
    // A shard merged twice is refused
    EXPECT_FALSE(MergeShards({shard0, shard0}));
    for (const char* name :
         {"one.navmesh", "two.navmesh", "four.navmesh", "merged.navmesh", "s0.navmesh", "s1.navmesh"})
        std::filesystem::remove(TempPath(name));
}

TEST(BakeTest, BadInputGetsClearErrorsAndNoOutput)
{
    const std::string obj = TempPath("broken.obj");
    std::ofstream(obj) << "v 0 0 0\nv 1 0 0\nv oops 0 1\nf 1 2 3\n";
    BakeSettings settings;
    settings.mInputs = {obj};
    Result<BakeResult> broken = Bake(settings);
    ASSERT_FALSE(broken);
    EXPECT_NE(broken.GetError().mMessage.find(obj + ":3"), std::string::npos) << broken.GetError().mMessage;
    settings.mInputs = {TempPath("missing.obj")};
    EXPECT_EQ(Bake(settings).GetError().mCode, ErrorCode::IOError);
    settings.mInputs = {MeshPath("nav_test.obj")};
    settings.mShard = 2;
    settings.mShardCount = 2;
    EXPECT_EQ(Bake(settings).GetError().mCode, ErrorCode::InvalidArgument);

    // Navmesh files: wrong magic, truncated, missing
    const std::string bad = TempPath("bad.navmesh");
    std::ofstream(bad, std::ios::binary) << "not a navmesh at all, long enough for a header ................";
    EXPECT_EQ(navmesh::LoadNavMeshFile(bad).GetError().mCode, ErrorCode::ParseError);
    EXPECT_EQ(navmesh::LoadNavMeshFile(TempPath("missing.navmesh")).GetError().mCode, ErrorCode::IOError);
    // A save into a folder that does not exist fails and leaves nothing
    const std::string nowhere = TempPath("no-such-folder/out.navmesh");
    navmesh::NavMeshFileContents empty;
    empty.mParams = navmesh::MakeNavMeshParams(navmesh::TileGrid(0, 0, 12.8f, 0, 10), 16).Value();
    EXPECT_EQ(navmesh::SaveNavMeshFile(nowhere, empty).GetError().mCode, ErrorCode::IOError);
    std::filesystem::remove(obj);
    std::filesystem::remove(bad);
}

} // namespace
} // namespace cairn::bake

namespace cairn::bake
{
using namespace cairn::physics;
namespace
{

/// A 6 m square platform at (inX, inZ), 1 m thick, as an OBJ file.
void WritePlatform(const std::string& inPath, float inX, float inZ)
{
    std::ofstream out(inPath);
    const float h = 3.0f;
    for (float y : {0.0f, -1.0f})
        for (auto [dx, dz] : {std::pair{-h, -h}, std::pair{h, -h}, std::pair{h, h}, std::pair{-h, h}})
            out << "v " << inX + dx << " " << y << " " << inZ + dz << "\n";
    // Top (counter-clockwise from above), bottom and sides
    out << "f 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 "
           "5\nf 4 5 8\n";
}

TEST(BakeTest, AnIncrementalBakeRebuildsOnlyTheTilesAMovedObjectTouches)
{
    // A ground slab over 5 x 5 tiles and a platform on it
    const std::string ground = TempPath("ground.obj"), platform = TempPath("platform.obj");
    {
        std::ofstream out(ground);
        out << "v 0 -3 0\nv 64 -3 0\nv 64 -3 64\nv 0 -3 64\nf 1 4 3\nf 1 3 2\n";
    }
    WritePlatform(platform, 10.0f, 10.0f);
    BakeSettings settings;
    settings.mInputs = {ground, platform};
    Result<BakeResult> first = Bake(settings);
    ASSERT_TRUE(first) << first.GetError().mMessage;
    EXPECT_EQ(first.Value().mSummary.mTilesRebuilt, first.Value().mTilesBaked);
    const std::string summaryFile = TempPath("summary.json");
    ASSERT_TRUE(SaveBakeSummary(summaryFile, first.Value().mSummary).IsOk());
    Result<BakeSummary> summary = LoadBakeSummary(summaryFile);
    ASSERT_TRUE(summary) << summary.GetError().mMessage;

    // Unchanged: nothing rebuilt, the same tiles
    settings.mPrevious = &summary.Value();
    settings.mPreviousNavMesh = &first.Value().mNavMesh;
    Result<BakeResult> same = Bake(settings);
    ASSERT_TRUE(same);
    EXPECT_EQ(same.Value().mSummary.mTilesRebuilt, 0u);

    // The platform moved from one corner to the far one: only the tiles around its old and new place
    WritePlatform(platform, 50.0f, 50.0f);
    Result<BakeResult> incremental = Bake(settings);
    ASSERT_TRUE(incremental);
    const uint32_t rebuilt = incremental.Value().mSummary.mTilesRebuilt;
    EXPECT_GT(rebuilt, 0u);
    EXPECT_LE(rebuilt, 8u); // Each place touches at most 4 tiles (with the border)
    EXPECT_LT(rebuilt, incremental.Value().mTilesBaked);
    settings.mPrevious = nullptr;
    settings.mPreviousNavMesh = nullptr;
    Result<BakeResult> full = Bake(settings);
    ASSERT_TRUE(full);
    const std::string a = TempPath("incremental.navmesh"), b = TempPath("full.navmesh");
    ASSERT_TRUE(navmesh::SaveNavMeshFile(a, incremental.Value().mNavMesh).IsOk());
    ASSERT_TRUE(navmesh::SaveNavMeshFile(b, full.Value().mNavMesh).IsOk());
    EXPECT_EQ(ReadBytes(a), ReadBytes(b));

    // A malformed summary names what is wrong
    std::ofstream(summaryFile) << R"({"format": "cairn-bake-summary", "version": 1, "tiles": [{"x": 1}]})";
    Result<BakeSummary> broken = LoadBakeSummary(summaryFile);
    ASSERT_FALSE(broken);
    EXPECT_NE(broken.GetError().mMessage.find("tiles[0]"), std::string::npos);
    std::ofstream(summaryFile) << "{ not json";
    EXPECT_EQ(LoadBakeSummary(summaryFile).GetError().mCode, ErrorCode::ParseError);
    for (const std::string& file : {ground, platform, summaryFile, a, b})
        std::filesystem::remove(file);
}

} // namespace
} // namespace cairn::bake

#include "BakeConfig.h"

namespace cairn::bake
{
using namespace cairn::physics;
namespace
{

TEST(BakeConfigTest, AJsonFileSetsTheProfileAndNamesWhatIsWrong)
{
    const std::string path = TempPath("profile.json");
    std::ofstream(path)
        << R"({"agent_radius": 0.4, "cell_size": 0.25, "tile_size": 16, "region_partition": "monotone",
                               "max_verts_per_poly": 5})";
    navmesh::AgentProfile profile;
    ASSERT_TRUE(LoadBakeConfig(path, profile).IsOk());
    EXPECT_EQ(profile.mRadius, 0.4f);
    EXPECT_EQ(profile.mCellSize, 0.25f);
    EXPECT_EQ(profile.mTileSize, 16.0f);
    EXPECT_EQ(profile.mPartition, navmesh::RegionPartition::Monotone);
    EXPECT_EQ(profile.mMaxVertsPerPoly, 5);
    EXPECT_EQ(profile.mHeight, navmesh::AgentProfile{}.mHeight); // Not named: the default stays

    auto errorFor = [&](const char* inJson)
    {
        std::ofstream(path) << inJson;
        navmesh::AgentProfile any;
        const Status status = LoadBakeConfig(path, any);
        return status ? std::string() : status.GetError().mMessage;
    };
    EXPECT_NE(errorFor(R"({"agent_radus": 0.4})").find("unknown key 'agent_radus'"), std::string::npos);
    EXPECT_NE(errorFor(R"({"cell_size": "small"})").find("'cell_size' must be a number"), std::string::npos);
    EXPECT_NE(errorFor(R"({"region_partition": "voronoi"})").find("region_partition"), std::string::npos);
    EXPECT_NE(errorFor(R"({"tile_size": 12.7})").find("whole number"), std::string::npos); // Validate's
    EXPECT_NE(errorFor("[1, 2]").find("not a JSON object"), std::string::npos);
    navmesh::AgentProfile any;
    EXPECT_EQ(LoadBakeConfig(TempPath("missing.json"), any).GetError().mCode, ErrorCode::IOError);
    std::filesystem::remove(path);
}

} // namespace
} // namespace cairn::bake
