// The streaming open-world demo, run for 240 frames (4 s) in both broad-phase modes with a fast player
// (so tiles stream in and out several times): no body lost or duplicated by streaming, every navmesh tile the
// agents asked for built, no agent path through a wall, nothing reported wrong.

#include "DemoRunner.h"

#include <cstdio>
#include <gtest/gtest.h>
#include <string>

namespace cairn::demo
{
namespace
{

DemoSettings SmallDemo()
{
    DemoSettings settings;
    settings.mFrames = 240;
    settings.mAgents = 4;
    settings.mGameObjects = 64;
    settings.mGameObjectJobs = 4;
    // Paced at 60 Hz, as the demo runs: back to back frames under a loaded CI left the navmesh's background
    // thread no time to build tiles before the run ended
    settings.mRealTime = true;
    settings.mCollisionRadius = 2.0f; // 13 world tiles
    settings.mPropsPerTile = 200;
    settings.mDynamicPerTile = 30;
    settings.mPlayerSpeed = 40.0f; // 160 m in 240 frames: two and a half tiles
    return settings;
}

void ExpectInvariants(const DemoRunResult& inRun)
{
    EXPECT_EQ(inRun.mLostOrDuplicatedBodies, 0u) << inRun.mModeName;
    EXPECT_EQ(inRun.mTilesRequestedNeverBuilt, 0u) << inRun.mModeName;
    EXPECT_EQ(inRun.mPathsThroughWalls, 0u) << inRun.mModeName;
    for (const std::string& error : inRun.mErrors)
        ADD_FAILURE() << inRun.mModeName << ": " << error;
    // The run did what a demo does: streamed in and out, stepped, queried, built navmesh, walked
    EXPECT_GT(inRun.mTilesStreamedIn, 13u) << inRun.mModeName;
    EXPECT_GT(inRun.mTilesStreamedOut, 0u) << inRun.mModeName;
    EXPECT_EQ(inRun.mPhysicsMs.size(), 240u);
    EXPECT_GT(inRun.mQueries, 0u);
    EXPECT_GT(inRun.mNavTilesBuilt, 0u);
    const std::string paths =
        inRun.mModeName + ": path queries " + std::to_string(inRun.mPathQueries) + ", reached " +
        std::to_string(inRun.mPathsFound) + ", partial " + std::to_string(inRun.mPathsPartial) + ", failed " +
        std::to_string(inRun.mPathsFailed) + ", walked " + std::to_string(inRun.mAgentDistanceMetres) + " m";
    std::printf("%s\n", paths.c_str()); // The margins of the two checks below, in the log
    EXPECT_GT(inRun.mPathsFound, 0u) << paths;
    EXPECT_GT(inRun.mAgentDistanceMetres, 10.0) << paths;
    EXPECT_GT(inRun.mDynamicBodiesPeak, 0u);
}

TEST(DemoTest, LockFreeModeKeepsItsInvariants)
{
    ExpectInvariants(RunDemo(SmallDemo(), BroadPhaseType::QuadTree, nullptr));
}

TEST(DemoTest, GlobalMutexModeKeepsItsInvariants)
{
    ExpectInvariants(RunDemo(SmallDemo(), BroadPhaseType::QuadTreeGlobalMutex, nullptr));
}

} // namespace
} // namespace cairn::demo
