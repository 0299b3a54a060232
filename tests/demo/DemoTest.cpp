// The streaming open-world demo, run for 240 frames (4 s) in both broad-phase modes with a fast player
// (so tiles stream in and out several times): no body lost or duplicated by streaming, every navmesh tile the
// agents asked for built, no agent inside a wall or off its navmesh for over a second, no corridor through a
// polygon that is gone, doors whose rest rebuilt their tiles with the doorway shut or open as the door stood,
// guards shot and gone limp, nothing reported wrong.

#include "DemoReport.h"
#include "DemoRunner.h"
#include "NavMapSvg.h"
#include "common/TempFiles.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <gtest/gtest.h>
#include <string>
#include <vector>

namespace cairn::demo
{
using namespace cairn::physics;
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

/// What inPrint writes to a file.
template <class Print> std::string Printed(const Print& inPrint)
{
    std::FILE* file = std::tmpfile();
    if (file == nullptr) return "";
    inPrint(file);
    std::rewind(file);
    std::string text;
    for (int c; (c = std::fgetc(file)) != EOF;)
        text += char(c);
    std::fclose(file);
    return text;
}

void ExpectInvariants(const DemoRunResult& inRun)
{
    EXPECT_EQ(inRun.mLostOrDuplicatedBodies, 0u) << inRun.mModeName;
    EXPECT_EQ(inRun.mTilesRequestedNeverBuilt, 0u) << inRun.mModeName;
    const AgentStats& agents = inRun.mAgentStats;
    EXPECT_EQ(agents.mInsideStatic, 0u) << inRun.mModeName;
    EXPECT_GT(agents.mInsideStaticChecks, 0u) << inRun.mModeName;
    EXPECT_EQ(agents.mOffNavMeshOverOneSecond, 0u) << inRun.mModeName;
    EXPECT_EQ(agents.mCorridorsThroughGone, 0u) << inRun.mModeName;
    EXPECT_EQ(agents.mNonClimberLadderFrames, 0u) << inRun.mModeName;
    EXPECT_GT(agents.mNonClimbers, 0u) << inRun.mModeName;
    EXPECT_EQ(inRun.mLaddersDead, 0u) << inRun.mModeName;
    EXPECT_GT(inRun.mLaddersJoined, 0u)
        << inRun.mModeName << ": the ladders by the player are in its navmesh";
    // The huts' doors moved on their timers and their tiles were built again as they came to rest; the
    // navmesh had each door where it stood: closed, no path through the doorway; open, one
    const DoorStats& doors = inRun.mDoorStats;
    std::printf("%s: doors %llu, commands %llu, rests %llu, tiles rebuilt %llu, doorway checks closed %llu "
                "open %llu\n",
                inRun.mModeName.c_str(), (unsigned long long)doors.mDoorsSeen,
                (unsigned long long)doors.mCommands, (unsigned long long)doors.mRests,
                (unsigned long long)doors.mRebuilds, (unsigned long long)doors.mClosedChecks,
                (unsigned long long)doors.mOpenChecks);
    EXPECT_GT(doors.mDoorsSeen, 0u) << inRun.mModeName;
    EXPECT_GT(doors.mCommands, 0u) << inRun.mModeName;
    EXPECT_EQ(doors.mLatencyFrames.size(), doors.mRebuilds) << inRun.mModeName;
    EXPECT_EQ(doors.mClosedBlocked, doors.mClosedChecks) << inRun.mModeName;
    EXPECT_EQ(doors.mOpenPassable, doors.mOpenChecks) << inRun.mModeName;
#ifndef CAIRN_TEST_UNDER_SANITIZER
    // How much happens in the 4 s: a sanitizer's build runs the frames, the navmesh's background builds and
    // the streaming several times slower, and under it few tiles are built again before the run ends
    EXPECT_GT(doors.mRebuilds, 0u) << inRun.mModeName;
    EXPECT_GT(doors.mClosedChecks + doors.mOpenChecks, 0u) << inRun.mModeName;
#endif
    // Guards were shot at, and those hit went limp as ragdolls
    const GuardStats& guards = inRun.mGuardStats;
    std::printf("%s: guards %llu, shots %llu, hits %llu, at rest %llu\n", inRun.mModeName.c_str(),
                (unsigned long long)guards.mPlaced, (unsigned long long)guards.mShots,
                (unsigned long long)guards.mHits, (unsigned long long)guards.mAtRest);
    EXPECT_GT(guards.mShots, 0u) << inRun.mModeName;
    EXPECT_GT(guards.mHits, 0u) << inRun.mModeName;
    EXPECT_EQ(guards.mMakeMs.size(), guards.mHits) << inRun.mModeName;
    for (const std::string& error : inRun.mErrors)
        ADD_FAILURE() << inRun.mModeName << ": " << error;
    // The run did what a demo does: streamed in and out, stepped, queried, built navmesh, walked
    EXPECT_GT(inRun.mTilesStreamedIn, 13u) << inRun.mModeName;
    EXPECT_GT(inRun.mTilesStreamedOut, 0u) << inRun.mModeName;
    EXPECT_EQ(inRun.mPhysicsMs.size(), 240u);
    EXPECT_EQ(inRun.mSteps.size(), 240u);
    EXPECT_EQ(inRun.mGameObjectLockWaitUs.size(), 240u);
    ASSERT_EQ(inRun.mPhysicsHostTakenMs.size(), 240u);
    ASSERT_EQ(inRun.mMainThreadStreamHostTakenMs.size(), 240u);
    for (size_t i = 0; i < 240; ++i) // Unknown, or a part of the frame's time
    {
        const double host = inRun.mPhysicsHostTakenMs[i];
        EXPECT_TRUE(std::isnan(host) || (host >= 0.0 && host <= inRun.mPhysicsMs[i]))
            << "frame " << i << ": " << host << " of " << inRun.mPhysicsMs[i] << " ms";
        const double streaming = inRun.mMainThreadStreamHostTakenMs[i];
        EXPECT_TRUE(std::isnan(streaming) || (streaming >= 0.0 && streaming <= inRun.mMainThreadStreamMs[i]))
            << "frame " << i << ": " << streaming << " of " << inRun.mMainThreadStreamMs[i] << " ms";
    }
    EXPECT_FALSE(LockWaitMicrosPerThreadFrame(inRun).empty());
    EXPECT_GT(inRun.mQueries, 0u);
    // The game objects walk as characters: one is put back at its spot (3 m behind it) far less often
    EXPECT_GT(inRun.mCharacterWalks, 0u);
    EXPECT_LT(inRun.mCharacterPutBack * 20, inRun.mCharacterWalks) << inRun.mModeName;
    EXPECT_GT(inRun.mNavTilesBuilt, 0u);
    const std::string paths =
        inRun.mModeName + ": paths requested " + std::to_string(agents.mPathsRequested) + ", served " +
        std::to_string(agents.mPathsServed) + ", failed " + std::to_string(agents.mPathsFailed) +
        ", arrivals " + std::to_string(agents.mArrivals) + ", walked " + std::to_string(agents.mDistance) +
        " m";
    std::printf("%s\n", paths.c_str()); // The margins of the checks below, in the log
    EXPECT_GT(agents.mPathsServed, 0u) << paths;
    EXPECT_GT(agents.mDistance, 10.0) << paths;
    EXPECT_EQ(agents.mMainThreadMs.size(), 240u);
    EXPECT_EQ(agents.mJobThreadsMs.size(), 240u);
    EXPECT_FALSE(agents.mTrails.empty());
    EXPECT_FALSE(inRun.mNavMap.empty());
    EXPECT_GT(inRun.mDynamicBodiesPeak, 0u);
}

TEST(DemoTest, LockFreeModeKeepsItsInvariantsAndLogsItsProgress)
{
    DemoRunResult run;
    // A file is not a terminal: the progress comes as plain lines every 300 frames, so of 240 frames the
    // first's and the last's
    const std::string progress = Printed(
        [&](std::FILE* inFile) { run = RunDemo(SmallDemo(), BroadPhaseType::QuadTree, inFile).Value(); });
    ExpectInvariants(run);
    // Its queries ran beside the step and read published poses: not one of them waited for a lock
    for (double waited : LockWaitMicrosPerThreadFrame(run))
        EXPECT_EQ(waited, 0.0);
    EXPECT_EQ(QueryLockWaitMicrosPerQuery(run), 0.0);
    EXPECT_EQ(progress.find('\r'), std::string::npos) << progress;
    EXPECT_EQ(std::count(progress.begin(), progress.end(), '\n'), 2) << progress;
    EXPECT_NE(progress.find("frame     1/240"), std::string::npos) << progress;
    EXPECT_NE(progress.find("frame   240/240"), std::string::npos) << progress;
    EXPECT_TRUE(!progress.empty() && progress.back() == '\n') << progress;
}

TEST(DemoTest, GlobalMutexModeKeepsItsInvariants)
{
    const Result<DemoRunResult> run = RunDemo(SmallDemo(), BroadPhaseType::QuadTreeGlobalMutex, nullptr);
    ASSERT_TRUE(run) << run.GetError().mMessage;
    ExpectInvariants(run.Value());
}

TEST(DemoReportTest, FramesCsvHasARowPerFrameOfEveryRun)
{
    DemoRunResult run;
    run.mModeName = "lock-free";
    run.mFrameMs = {2.5, 3.0};
    run.mPhysicsMs = {0.25, 0.5};
    run.mMainThreadStreamMs = {0.01, 0.02};
    run.mGameObjectLockWaitUs = {0.0, 12.5};
    run.mPhysicsHostTakenMs = {std::nan(""), 0.125}; // Unknown in the first frame
    run.mMainThreadStreamHostTakenMs = {0.0};        // A series one short: its second field is empty
    run.mAgentStats.mMainThreadMs = {0.125};         // Likewise the navigation's
    run.mAgentStats.mJobThreadsMs = {1.5};
    run.mAgentStats.mOtherTaskSwitches = {2, -1}; // Unreadable in the second frame: an empty field
    auto step = [](double inBroadPhase, double inNarrow, double inIslands, double inSolve, double inFinish,
                   uint32_t inActive, uint32_t inPairs, uint32_t inPoints, double inLockWait)
    {
        StepStatistics s;
        s.mBroadPhaseUpdateMs = inBroadPhase;
        s.mNarrowPhaseMs = inNarrow;
        s.mIslandsMs = inIslands;
        s.mSolveMs = inSolve;
        s.mFinishMs = inFinish;
        s.mNumActiveBodies = inActive;
        s.mNumBodyPairs = inPairs;
        s.mNumContactPoints = inPoints;
        s.mLockWaitMs = inLockWait;
        return s;
    };
    run.mSteps = {step(0.03, 0.1, 0.002, 0.05, 0.004, 26, 40, 66, 0.0),
                  step(0.3, 0.12, 0.003, 0.06, 0.005, 27, 41, 70, 0.25)};
    DemoRunResult odd = run;
    odd.mModeName = "a, \"b\"";
    odd.mSteps.pop_back(); // A series one frame short: its rows end there
    const std::string csv = FramesCsv({run, odd});
    std::vector<std::string> lines;
    for (size_t begin = 0, end; (end = csv.find('\n', begin)) != std::string::npos; begin = end + 1)
        lines.push_back(csv.substr(begin, end - begin));
    ASSERT_EQ(lines.size(), 4u) << csv;
    EXPECT_EQ(lines[0],
              "mode,frame,frame_ms,physics_ms,streaming_ms,broadphase_update_ms,narrow_phase_ms,"
              "islands_ms,solve_ms,finish_ms,active_bodies,body_pairs,contact_points,step_lock_wait_ms,"
              "game_object_lock_wait_us,physics_host_taken_ms,streaming_host_taken_ms,nav_main_thread_ms,"
              "nav_job_threads_ms,nav_other_task_switches");
    EXPECT_EQ(lines[1], "lock-free,0,2.5000,0.2500,0.0100,0.0300,0.1000,0.0020,0.0500,0.0040,26,40,66,0.0000,"
                        "0.00,,0.0000,0.1250,"
                        "1.5000,2");
    EXPECT_EQ(lines[2], "lock-free,1,3.0000,0.5000,0.0200,0.3000,0.1200,0.0030,0.0600,0.0050,27,41,70,0.2500,"
                        "12.50,0.1250,,,,");
    EXPECT_EQ(lines[3].rfind("\"a, \"\"b\"\"\",0,", 0), 0u) << lines[3];
}

TEST(DemoResultTest, SummarizePhasesGivesEachPhaseItsMeanPercentilesAndMax)
{
    // 99 ordinary steps, each phase its own time, and one whose solve and lock wait spiked
    std::vector<StepStatistics> steps(100);
    for (StepStatistics& step : steps)
    {
        step.mBroadPhaseUpdateMs = 0.125;
        step.mNarrowPhaseMs = 0.25;
        step.mIslandsMs = 0.0625;
        step.mSolveMs = 0.1;
        step.mFinishMs = 0.03125;
    }
    steps[42].mSolveMs = 2.08;
    steps[42].mLockWaitMs = 0.5;
    const PhaseSummaries phases = SummarizePhases(steps);
    EXPECT_NEAR(phases.mBroadPhaseUpdate.mMean, 0.125, 1e-12);
    EXPECT_NEAR(phases.mNarrowPhase.mMean, 0.25, 1e-12);
    EXPECT_NEAR(phases.mIslands.mMean, 0.0625, 1e-12);
    EXPECT_DOUBLE_EQ(phases.mFinish.mP99, 0.03125);
    EXPECT_NEAR(phases.mSolve.mMean, 0.1198, 1e-12);
    EXPECT_DOUBLE_EQ(phases.mSolve.mP50, 0.1);
    EXPECT_DOUBLE_EQ(phases.mSolve.mP99, 0.1);
    EXPECT_DOUBLE_EQ(phases.mSolve.mMax, 2.08);
    EXPECT_NEAR(phases.mLockWait.mMean, 0.005, 1e-12);
    EXPECT_DOUBLE_EQ(phases.mLockWait.mP50, 0.0);
    EXPECT_DOUBLE_EQ(phases.mLockWait.mMax, 0.5);
    EXPECT_EQ(phases.mIslands.mCount, 100u);
    EXPECT_EQ(SummarizePhases({}).mSolve.mCount, 0u);
}

TEST(DemoResultTest, AttributeSpikesCountsTheSpikesTheHostsTimeAccountsFor)
{
    DemoRunResult run;
    run.mPhysicsMs.assign(100, 1.0);
    run.mPhysicsHostTakenMs.assign(100, 0.0);
    run.mPhysicsMs.push_back(5.0); // Within 3x the average without the host's 2.5 ms
    run.mPhysicsHostTakenMs.push_back(2.5);
    run.mPhysicsMs.push_back(4.5); // Unknown share: not the host's
    run.mPhysicsHostTakenMs.push_back(std::nan(""));
    run.mPhysicsMs.push_back(4.0); // The host's 0.5 ms leaves it over 3x
    run.mPhysicsHostTakenMs.push_back(0.5);
    run.mPhysicsMs.push_back(std::nan("")); // A broken measurement: neither in the mean nor a spike
    run.mPhysicsHostTakenMs.push_back(0.0);
    const tools::SpikeAttribution spikes =
        AttributePhysicsSpikes(run, 3.0); // Bound 3 * 113.5 / 103 = 3.31 ms
    EXPECT_EQ(spikes.mSpikes, 3u);
    EXPECT_EQ(spikes.mSpikesByHost, 1u);
    EXPECT_EQ(spikes.mSpikesUnknown, 1u);
    EXPECT_DOUBLE_EQ(spikes.mHostTakenMinMs, 2.5);
    EXPECT_DOUBLE_EQ(spikes.mHostTakenMaxMs, 2.5);
    EXPECT_DOUBLE_EQ(spikes.mMaxLessHostMs, 4.5);

    run.mPhysicsHostTakenMs.clear(); // Not measured at all: nothing is the host's
    const tools::SpikeAttribution unmeasured = AttributePhysicsSpikes(run, 3.0);
    EXPECT_EQ(unmeasured.mSpikes, 3u);
    EXPECT_EQ(unmeasured.mSpikesByHost, 0u);
    EXPECT_EQ(unmeasured.mSpikesUnknown, 3u);
    EXPECT_DOUBLE_EQ(unmeasured.mMaxLessHostMs, 5.0);
    EXPECT_EQ(AttributePhysicsSpikes(DemoRunResult{}, 3.0).mSpikes, 0u);
}

TEST(DemoResultTest, MaxLessHostLeavesOutTheHostsKnownShareOfEachFrame)
{
    // 2.0 less 1.5 known; 1.5 less an unknown share; 1.0 less more than itself; a frame with no share at all
    EXPECT_DOUBLE_EQ(tools::MaxLessHost({2.0, 1.5, 1.0, 0.75}, {1.5, std::nan(""), 3.0}), 1.5);
    EXPECT_DOUBLE_EQ(tools::MaxLessHost({2.0, 1.25}, {1.5, 0.0}), 1.25);
    EXPECT_TRUE(std::isnan(tools::MaxLessHost({}, {})));
}

// The map: a polygon per navmesh polygon, coloured by its tile's latency (grey when not known), and a line
// per stretch of a trail: a put-back agent's trail breaks instead of drawing a line across the map
TEST(DemoReportTest, NavMapDrawsPolygonsByLatencyAndBreaksTrailsWhereAgentsWerePutBack)
{
    DemoRunResult run;
    run.mNavMap.push_back({{{0.0f, 0.0f}, {10.0f, 0.0f}, {10.0f, 10.0f}}, 0});
    run.mNavMap.push_back({{{10.0f, 0.0f}, {20.0f, 0.0f}, {20.0f, 10.0f}}, 100});
    run.mNavMap.push_back({{{0.0f, 10.0f}, {10.0f, 10.0f}, {0.0f, 20.0f}}, -1});
    const float nan = std::nanf("");
    run.mAgentStats.mTrails = {
        {Vec3(1, 0, 1), Vec3(2, 0, 2), Vec3(nan, nan, nan), Vec3(15, 0, 5), Vec3(16, 0, 6)}};
    run.mAgentStats.mTrailRadii = {0.6f};
    const std::string svg = SvgNavMap(run);
    auto count = [&](const std::string& inText)
    {
        size_t n = 0;
        for (size_t at = svg.find(inText); at != std::string::npos; at = svg.find(inText, at + 1))
            ++n;
        return n;
    };
    EXPECT_EQ(count("<polygon "), 3u) << svg;
    EXPECT_EQ(count("<polyline "), 2u) << svg;
    EXPECT_EQ(count("fill=\"#00c840\" stroke=\"#ffffff\""), 1u) << "built at once: green";
    EXPECT_EQ(count("fill=\"#ff0040\" stroke=\"#ffffff\""), 1u) << "the slowest (the p99): red";
    EXPECT_EQ(count("fill=\"#c8c8c8\" stroke=\"#ffffff\""), 1u) << "not known: grey";
    EXPECT_EQ(svg.find("nan"), std::string::npos);
    EXPECT_NE(SvgNavMap(DemoRunResult()).find("no data"), std::string::npos);
}

TEST(DemoReportTest, SummaryJudgesTheFrameTargets)
{
    DemoRunResult run;
    run.mModeName = "lock-free";
    run.mPhysicsMs.assign(200, 1.0);
    run.mPhysicsMs.back() = 2.0; // max 2x the average: the spike target holds
    run.mMainThreadStreamMs.assign(200, 0.1);
    std::string text = Printed([&](std::FILE* inFile) { PrintSummary(inFile, run); });
    EXPECT_NE(text.find("(target <= 3x: met)"), std::string::npos) << text;
    EXPECT_NE(text.find("(target <= 0.5 ms: met)"), std::string::npos) << text;
    EXPECT_NE(text.find("tile out ms p50 n/a"), std::string::npos) << text; // No tile streamed out

    run.mStreamOutMs = {1.25, 0.5, 3.0};
    text = Printed([&](std::FILE* inFile) { PrintSummary(inFile, run); });
    EXPECT_NE(text.find("tile out ms p50 1.250"), std::string::npos) << text;
    EXPECT_NE(text.find("tile out ms max 3.000"), std::string::npos) << text;

    run.mPhysicsMs[0] = 10.0; // A spike of about 9.9x the average
    run.mMainThreadStreamMs[7] = 0.75;
    run.mMainThreadStreamHostTakenMs.assign(200, 0.0);
    run.mMainThreadStreamHostTakenMs[7] = 0.5; // Of the 0.75 ms
    text = Printed([&](std::FILE* inFile) { PrintSummary(inFile, run); });
    EXPECT_NE(text.find("(target <= 3x: NOT met)"), std::string::npos) << text;
    EXPECT_NE(text.find("(target <= 0.5 ms: NOT met)  less the host's time 0.250"), std::string::npos)
        << text;
    EXPECT_NE(text.find("frames over 3x avg 1  of which the host's none  share unknown 1"), std::string::npos)
        << text;
    run.mPhysicsHostTakenMs.assign(200, 0.0);
    run.mPhysicsHostTakenMs[0] = 8.5; // The host took most of the spike
    text = Printed([&](std::FILE* inFile) { PrintSummary(inFile, run); });
    EXPECT_NE(text.find("of which the host's 1 (it took the updating thread's core for 8.500 ms)"),
              std::string::npos)
        << text;
    EXPECT_NE(text.find("max/avg less the host's time 1.90x"), std::string::npos) << text; // 2.0 / 1.055
    EXPECT_NE(text.find("(target <= 0.5 ms: NOT met)"), std::string::npos) << text;
    // p99 is at most 2.0 ms on an average of 1.055 ms, whichever sample the percentile picks
    EXPECT_NE(text.find("(target <= 2x: met)"), std::string::npos) << text;
}

TEST(DemoReportTest, SummaryCountsTheFramesAnotherTaskInterruptedAndTheRestsTail)
{
    DemoRunResult run;
    run.mModeName = "lock-free";
    run.mAgents = 1000;
    run.mAgentStats.mMainThreadMs.assign(100, 0.1);
    run.mAgentStats.mJobThreadsMs.assign(100, 1.0);
    run.mAgentStats.mOtherTaskSwitches.assign(100, 0);
    for (size_t i = 0; i < 4; ++i)
    {
        run.mAgentStats.mJobThreadsMs[i] = 3.0; // Each of these interrupted by another task...
        run.mAgentStats.mOtherTaskSwitches[i] = 1;
    }
    run.mAgentStats.mOtherTaskSwitches[4] = -1; // ... this one not known: counted in neither
    std::string text = Printed([&](std::FILE* inFile) { PrintSummary(inFile, run); });
    EXPECT_NE(text.find("p99 3.000 (target <= 2 ms: NOT met)"), std::string::npos) << text;
    EXPECT_NE(text.find("frames another task took a navigation thread's core 4 (4.04%)"), std::string::npos)
        << text;
    EXPECT_NE(text.find("job threads p99 in the other frames 1.000"), std::string::npos) << text;

    run.mAgentStats.mOtherTaskSwitches.clear(); // Not watched
    text = Printed([&](std::FILE* inFile) { PrintSummary(inFile, run); });
    EXPECT_NE(text.find("frames another task took a navigation thread's core n/a"), std::string::npos)
        << text;
}

TEST(DemoReportTest, ComparisonShowsTheLockWaitsOfBothModes)
{
    DemoRunResult lockFree, global;
    lockFree.mModeName = "lock-free";
    global.mModeName = "global mutex";
    // The broad phase's locks never made the lock-free mode wait, the body locks did: in all {1, 3} against
    // {20, 10}
    lockFree.mBroadPhaseLockWaitMicrosPerThreadFrame = {0.0, 0.0};
    global.mBroadPhaseLockWaitMicrosPerThreadFrame = {8.0, 10.0};
    lockFree.mBodyLockWaitMicrosPerThreadFrame = {1.0, 3.0};
    global.mBodyLockWaitMicrosPerThreadFrame = {12.0, 0.0};
    const std::string text = Printed([&](std::FILE* inFile) { PrintComparison(inFile, lockFree, global); });
    const size_t row = text.find("lock waits µs/frame per thread");
    ASSERT_NE(row, std::string::npos) << text;
    const std::string line = text.substr(row, text.find('\n', row) - row);
    EXPECT_NE(line.find(" 2.00 "), std::string::npos) << line;  // Lock-free mean
    EXPECT_NE(line.find(" 15.00 "), std::string::npos) << line; // Global mean
    EXPECT_NE(line.find(" 7.50x"), std::string::npos) << line;  // Their ratio

    auto lineOf = [&](const std::string& inName)
    {
        const size_t at = text.find(inName);
        return at == std::string::npos ? std::string() : text.substr(at, text.find('\n', at) - at);
    };
    const std::string broadPhase = lineOf("of which broad-phase locks");
    EXPECT_NE(broadPhase.find(" 9.00 "), std::string::npos) << text;
    EXPECT_NE(broadPhase.find("no waits lock-free"), std::string::npos) << text;
    const std::string bodies = lineOf("of which body locks");
    EXPECT_NE(bodies.find(" 6.00 "), std::string::npos) << text;
    EXPECT_NE(bodies.find(" 3.00x"), std::string::npos) << text;
}

TEST(DemoReportTest, ComparisonJudgesTheQueryTargetBothWays)
{
    DemoRunResult lockFree, global;
    lockFree.mModeName = "lock-free";
    global.mModeName = "global mutex";
    lockFree.mQueries = global.mQueries = 1000;
    auto lineOf = [](const std::string& inText, const std::string& inName)
    {
        const size_t at = inText.find(inName);
        return at == std::string::npos ? std::string() : inText.substr(at, inText.find('\n', at) - at);
    };
    auto compare = [&]
    { return Printed([&](std::FILE* inFile) { PrintComparison(inFile, lockFree, global); }); };
    const std::string queryRow = "query µs/query mean";
    const std::string waitRow = "lock waits µs/frame per thread";

    // The queries' own time barely differs, their lock waits 12x: one reading is met, the other not
    lockFree.mQueryMicrosMean = 2.0;
    global.mQueryMicrosMean = 2.2;
    lockFree.mBroadPhaseLockWaitMicrosPerThreadFrame = {0.5, 0.5};
    global.mBroadPhaseLockWaitMicrosPerThreadFrame = {6.0, 6.0};
    lockFree.mBodyLockWaitMicrosPerThreadFrame = {0.0, 0.0};
    global.mBodyLockWaitMicrosPerThreadFrame = {0.0, 0.0};
    std::string text = compare();
    EXPECT_NE(text.find("10x target, read as"), std::string::npos) << text;
    EXPECT_NE(lineOf(text, queryRow).find("1.10x  µs per query: NOT met"), std::string::npos) << text;
    EXPECT_NE(lineOf(text, waitRow).find("12.00x  lock cost per thread: met"), std::string::npos) << text;

    // Just under 10x on the waits, 10x on the queries: the verdicts turn over
    global.mQueryMicrosMean = 20.0;
    global.mBroadPhaseLockWaitMicrosPerThreadFrame = {4.9, 4.9};
    text = compare();
    EXPECT_NE(lineOf(text, queryRow).find("µs per query: met"), std::string::npos) << text;
    EXPECT_NE(lineOf(text, waitRow).find("lock cost per thread: NOT met"), std::string::npos) << text;

    // A lock-free mode that never waited against one that did meets it
    lockFree.mBroadPhaseLockWaitMicrosPerThreadFrame = {0.0, 0.0};
    text = compare();
    EXPECT_NE(lineOf(text, waitRow).find("no waits lock-free  lock cost per thread: met"), std::string::npos)
        << text;

    // Neither waited, or nothing was measured, or a mode made no queries: no verdict
    global.mBroadPhaseLockWaitMicrosPerThreadFrame = {0.0, 0.0};
    lockFree.mQueries = 0;
    text = compare();
    EXPECT_NE(lineOf(text, waitRow).find("lock cost per thread: unknown"), std::string::npos) << text;
    EXPECT_NE(lineOf(text, queryRow).find("µs per query: unknown"), std::string::npos) << text;
    lockFree.mQueries = 1000;
    global.mQueries = 0;
    lockFree.mBroadPhaseLockWaitMicrosPerThreadFrame.clear();
    lockFree.mBodyLockWaitMicrosPerThreadFrame.clear();
    global.mBroadPhaseLockWaitMicrosPerThreadFrame.clear();
    global.mBodyLockWaitMicrosPerThreadFrame.clear();
    text = compare();
    EXPECT_NE(lineOf(text, waitRow).find("lock cost per thread: unknown"), std::string::npos) << text;
    EXPECT_NE(lineOf(text, queryRow).find("µs per query: unknown"), std::string::npos) << text;
}

TEST(DemoReportTest, ReportMarkdownTablesHaveEveryColumnInEveryRow)
{
    DemoRunResult lockFree, global;
    lockFree.mModeName = "lock-free";
    global.mModeName = "global mutex";
    lockFree.mQueries = global.mQueries = 1000;
    lockFree.mQueryMicrosMean = 2.0;
    global.mQueryMicrosMean = 2.5;
    lockFree.mSteps.resize(3);
    lockFree.mSteps[0].mSolveMs = 0.25;
    lockFree.mSteps[1].mSolveMs = 0.5;
    lockFree.mSteps[2].mSolveMs = 0.75;
    const test::TempFiles files;
    std::string error;
    ASSERT_TRUE(WriteReport(files.Path("report"), {lockFree, global}, "cairn-demo", error)) << error;
    const std::vector<unsigned char> bytes = test::ReadBytes(files.Path("report/report.md"));
    const std::string report(bytes.begin(), bytes.end());
    const size_t comparison = report.find("## Comparison");
    ASSERT_NE(comparison, std::string::npos) << report;
    // The numbers right-aligned, the verdicts' text column left-aligned
    EXPECT_NE(report.find("|---|--:|--:|--:|---|", comparison), std::string::npos) << report;
    // A row without a verdict still has all five cells
    const size_t row = report.find("| game-object queries |", comparison);
    ASSERT_NE(row, std::string::npos) << report;
    const std::string line = report.substr(row, report.find('\n', row) - row);
    EXPECT_EQ(std::count(line.begin(), line.end(), '|'), 6) << line;
    EXPECT_NE(report.find("| 1.25x | µs per query: NOT met |", comparison), std::string::npos) << report;

    // Each run's step phases: a row a phase with its avg, p50, p99 and max, not four rows in the summary
    const size_t phases = report.find("| phase | avg | p50 | p99 | max |");
    ASSERT_NE(phases, std::string::npos) << report;
    EXPECT_LT(phases, comparison) << report;
    EXPECT_NE(report.find("| solve | 0.500 | 0.500 | 0.750 | 0.750 |", phases), std::string::npos) << report;
    EXPECT_EQ(report.find("| solve ms |"), std::string::npos) << report;
}

} // namespace
} // namespace cairn::demo
