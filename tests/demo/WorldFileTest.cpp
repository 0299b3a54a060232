// The demo's world file: the one data/ ships is the demo's documented world (DemoSettings' defaults, which
// the report and the benchmarks describe), fits its physics world, and a key it names changes that setting.

#include "WorldFile.h"

#include "common/TempFiles.h"

#include <gtest/gtest.h>

namespace cairn::demo
{
using namespace cairn::physics;
namespace
{

TEST(WorldFileTest, TheShippedWorldIsTheDefaultWorld)
{
    DemoSettings loaded;
    loaded.mSeed = 99; // Every key of the file must overwrite what was there
    loaded.mPropsPerTile = 1;
    loaded.mThrowBalls = false;
    loaded.mBuildingsPerTile = 7;
    const Status status = LoadDemoWorld(std::string(CAIRN_DATA_DIR) + "/demo/world.json", loaded);
    ASSERT_TRUE(status.IsOk()) << status.GetError().mMessage;
    const DemoSettings defaults;
    EXPECT_EQ(loaded.mSeed, defaults.mSeed);
    EXPECT_EQ(loaded.mPropsPerTile, defaults.mPropsPerTile);
    EXPECT_EQ(loaded.mDynamicPerTile, defaults.mDynamicPerTile);
    EXPECT_EQ(loaded.mBuildingsPerTile, defaults.mBuildingsPerTile);
    EXPECT_EQ(loaded.mCollisionRadius, defaults.mCollisionRadius);
    EXPECT_EQ(loaded.mPlayerSpeed, defaults.mPlayerSpeed);
    EXPECT_EQ(loaded.mThrowBalls, defaults.mThrowBalls);
    EXPECT_EQ(loaded.mAgents, defaults.mAgents);
    EXPECT_EQ(loaded.mGameObjects, defaults.mGameObjects);
    EXPECT_EQ(loaded.mGameObjectJobs, defaults.mGameObjectJobs);
    EXPECT_EQ(loaded.mCollisionSteps, defaults.mCollisionSteps);
    EXPECT_EQ(loaded.mCandidateMargin, defaults.mCandidateMargin);
    EXPECT_LE(EstimateMaxBodies(loaded), cDemoMaxBodies - cDemoSpareBodies);
}

TEST(WorldFileTest, KeysNotNamedKeepTheirValuesAndAnErrorChangesNothing)
{
    test::TempFiles files;
    DemoSettings settings;
    settings.mAgents = 3;
    ASSERT_TRUE(
        LoadDemoWorld(files.Write("small.json", R"({"props_per_tile": 50, "seed": 18446744073709551615})"),
                      settings)
            .IsOk());
    EXPECT_EQ(settings.mPropsPerTile, 50);
    EXPECT_EQ(settings.mSeed, UINT64_MAX);
    EXPECT_EQ(settings.mAgents, 3);

    const DemoSettings before = settings;
    const Status bad =
        LoadDemoWorld(files.Write("bad.json", R"({"agents": 20, "player_speed": -1})"), settings);
    ASSERT_FALSE(bad.IsOk());
    EXPECT_NE(bad.GetError().mMessage.find("\"player_speed\": expected a number from"), std::string::npos)
        << bad.GetError().mMessage;
    EXPECT_EQ(settings.mAgents, before.mAgents) << "a refused file leaves the settings as they were";
    const Status huts = LoadDemoWorld(files.Write("huts.json", R"({"buildings_per_tile": 17})"), settings);
    ASSERT_FALSE(huts.IsOk());
    EXPECT_NE(huts.GetError().mMessage.find("\"buildings_per_tile\": expected a whole number from 0 to 16"),
              std::string::npos)
        << huts.GetError().mMessage;
}

} // namespace
} // namespace cairn::demo
