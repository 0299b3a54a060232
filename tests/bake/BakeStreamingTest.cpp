// The streaming bake: tiles written to the file as they are done give the same bytes as the in-memory bake;
// only the objects near the tiles in flight are in the world; a generated level (made on demand, never held)
// bakes to the same navmesh as the same level written out as OBJ, whatever the thread count or shard.

#include "Baker.h"
#include "GeneratedLevel.h"
#include "common/SharedBenchData.h"
#include "common/TempFiles.h"

#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <iterator>

namespace cairn::bake
{
using namespace cairn::physics;
namespace
{

using cairn::test::ReadBytes;

TEST(BakeStreamingTest, TilesStreamedToTheFileEqualTheInMemoryBake)
{
    const std::string path = GetSharedDataDir() + "/recast-meshes/nav_test.obj";
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "missing " << path;
    test::TempFiles files;
    BakeSettings settings;
    settings.mInputs = {path};
    settings.mThreads = 2;
    Result<BakeResult> inMemory = Bake(settings);
    ASSERT_TRUE(inMemory) << inMemory.GetError().mMessage;
    ASSERT_TRUE(navmesh::SaveNavMeshFile(files.Path("memory.navmesh"), inMemory.Value().mNavMesh).IsOk());

    settings.mOutputPath = files.Path("streamed.navmesh");
    Result<BakeResult> streamed = Bake(settings);
    ASSERT_TRUE(streamed) << streamed.GetError().mMessage;
    EXPECT_TRUE(streamed.Value().mNavMesh.mTiles.empty()); // Nothing held
    EXPECT_EQ(streamed.Value().mTilesWithPolygons, inMemory.Value().mNavMesh.mTiles.size());
    EXPECT_EQ(ReadBytes(files.Path("streamed.navmesh")), ReadBytes(files.Path("memory.navmesh")));
    for (const auto& entry : std::filesystem::directory_iterator(files.Path("")))
        EXPECT_EQ(entry.path().string().find(".tmp"), std::string::npos) << "left behind: " << entry.path();
    // The level's 30 objects were never all in the world at once
    EXPECT_EQ(streamed.Value().mBodies, 30u);
    EXPECT_LT(streamed.Value().mPeakBodies, 30u);
    EXPECT_GT(streamed.Value().mPeakBodies, 0u);

    // An output that cannot be written: an error naming it, nothing left
    settings.mOutputPath = files.Path("no-such-folder/out.navmesh");
    Result<BakeResult> failed = Bake(settings);
    ASSERT_FALSE(failed);
    EXPECT_NE(failed.GetError().mMessage.find("no-such-folder"), std::string::npos);
}

class GeneratedBakeTest : public ::testing::Test
{
protected:
    static std::unique_ptr<GeneratedLevel> MakeLevel(uint32_t inCells)
    {
        GeneratedLevelSettings settings;
        settings.mSeed = 7;
        settings.mCellsX = inCells;
        settings.mCellsZ = inCells;
        settings.mPropsPerCell = 12;
        Result<std::unique_ptr<GeneratedLevel>> level = GeneratedLevel::Create(settings);
        EXPECT_TRUE(level) << level.GetError().mMessage;
        return level ? std::move(level.Value()) : nullptr;
    }
    test::TempFiles mFiles;
};

TEST_F(GeneratedBakeTest, SameNavMeshAsTheLevelWrittenAsObj)
{
    const std::unique_ptr<GeneratedLevel> level = MakeLevel(2);
    ASSERT_NE(level, nullptr);
    BakeSettings settings;
    settings.mThreads = 1;
    Result<BakeResult> generated = BakeSource(*level, settings);
    ASSERT_TRUE(generated) << generated.GetError().mMessage;
    EXPECT_GT(generated.Value().mPolygons, 0u);

    // The same objects in the same order from a file: a body per object, keys in file order
    settings.mInputs = {mFiles.Write("generated.obj", level->ToObj())};
    Result<BakeResult> fromFile = Bake(settings);
    ASSERT_TRUE(fromFile) << fromFile.GetError().mMessage;
    ASSERT_EQ(generated.Value().mNavMesh.mTiles.size(), fromFile.Value().mNavMesh.mTiles.size());
    for (size_t i = 0; i < generated.Value().mNavMesh.mTiles.size(); ++i)
        EXPECT_EQ(generated.Value().mNavMesh.mTiles[i].mData, fromFile.Value().mNavMesh.mTiles[i].mData)
            << "tile " << i;
    ASSERT_EQ(generated.Value().mSummary.mTiles.size(), fromFile.Value().mSummary.mTiles.size());
    for (size_t i = 0; i < generated.Value().mSummary.mTiles.size(); ++i)
        EXPECT_EQ(generated.Value().mSummary.mTiles[i].mInputHash,
                  fromFile.Value().mSummary.mTiles[i].mInputHash);
}

TEST_F(GeneratedBakeTest, ThreadsAndShardsGiveTheSameBytesWithAFewObjectsInTheWorld)
{
    const std::unique_ptr<GeneratedLevel> level = MakeLevel(3);
    ASSERT_NE(level, nullptr);
    auto bakeTo = [&](uint32_t inThreads, uint32_t inShard, uint32_t inShards, const std::string& inName)
    {
        BakeSettings settings;
        settings.mThreads = inThreads;
        settings.mShard = inShard;
        settings.mShardCount = inShards;
        settings.mOutputPath = mFiles.Path(inName);
        Result<BakeResult> result = BakeSource(*level, settings);
        EXPECT_TRUE(result) << result.GetError().mMessage;
        return result ? std::move(result.Value()) : BakeResult{};
    };
    const BakeResult one = bakeTo(1, 0, 1, "one.navmesh");
    const BakeResult two = bakeTo(2, 0, 1, "two.navmesh");
    EXPECT_EQ(ReadBytes(mFiles.Path("one.navmesh")), ReadBytes(mFiles.Path("two.navmesh")));
    // More threads than cores, several times: a result that hung on which job ran when would show here
    for (int run = 0; run < 3; ++run)
    {
        bakeTo(4, 0, 1, "four.navmesh");
        EXPECT_EQ(ReadBytes(mFiles.Path("four.navmesh")), ReadBytes(mFiles.Path("one.navmesh")))
            << "run " << run;
    }
    // 9 cells of 13 objects; the world held only those near the tiles in flight
    const uint32_t objects = 9 * 13;
    EXPECT_LT(one.mPeakBodies, objects);
    EXPECT_LT(two.mPeakBodies, objects);

    // A world with room for a few tiles' objects only: tiles wait for the ones ahead to leave, same bytes
    {
        BakeSettings settings;
        settings.mThreads = 2;
        settings.mMaxBodiesInWorld = 40;
        ASSERT_GT(two.mPeakBodies, 40u); // Unlimited, the world held more
        settings.mOutputPath = mFiles.Path("small-world.navmesh");
        Result<BakeResult> small = BakeSource(*level, settings);
        ASSERT_TRUE(small) << small.GetError().mMessage;
        EXPECT_LE(small.Value().mPeakBodies, 40u);
        EXPECT_EQ(ReadBytes(mFiles.Path("small-world.navmesh")), ReadBytes(mFiles.Path("one.navmesh")));
        settings.mMaxBodiesInWorld = 3; // Fewer than one tile's objects: a clear error
        Result<BakeResult> tooSmall = BakeSource(*level, settings);
        ASSERT_FALSE(tooSmall);
        EXPECT_NE(tooSmall.GetError().mMessage.find("too many objects"), std::string::npos)
            << tooSmall.GetError().mMessage;
    }

    bakeTo(2, 0, 2, "shard0.navmesh");
    bakeTo(2, 1, 2, "shard1.navmesh");
    Result<navmesh::NavMeshFileContents> shard0 = navmesh::LoadNavMeshFile(mFiles.Path("shard0.navmesh"));
    Result<navmesh::NavMeshFileContents> shard1 = navmesh::LoadNavMeshFile(mFiles.Path("shard1.navmesh"));
    ASSERT_TRUE(shard0 && shard1);
    Result<navmesh::NavMeshFileContents> merged = MergeShards({shard0.Value(), shard1.Value()});
    ASSERT_TRUE(merged) << merged.GetError().mMessage;
    ASSERT_TRUE(navmesh::SaveNavMeshFile(mFiles.Path("merged.navmesh"), merged.Value()).IsOk());
    EXPECT_EQ(ReadBytes(mFiles.Path("merged.navmesh")), ReadBytes(mFiles.Path("one.navmesh")));
}

TEST_F(GeneratedBakeTest, BadSettingsAreRefused)
{
    GeneratedLevelSettings settings;
    settings.mCellsX = 0;
    EXPECT_FALSE(GeneratedLevel::Create(settings));
    settings = {};
    settings.mCellSize = std::numeric_limits<float>::quiet_NaN();
    EXPECT_FALSE(GeneratedLevel::Create(settings));
    settings = {};
    settings.mPropsPerCell = 1000000;
    EXPECT_FALSE(GeneratedLevel::Create(settings));
    const std::unique_ptr<GeneratedLevel> level = MakeLevel(1);
    ASSERT_NE(level, nullptr);
    Result<SourceBody> unknown = level->MakeBody(uint64_t(1) << 40);
    ASSERT_FALSE(unknown);
    EXPECT_EQ(unknown.GetError().mCode, ErrorCode::InvalidArgument);
}

} // namespace
} // namespace cairn::bake
