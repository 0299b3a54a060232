// cairn-demo: the streaming open-world demo, Cairn's whole story in about a minute. A player crosses a
// generated open world; tiles of terrain and ~700 props stream in and out on a loading thread; physics steps
// at 60 Hz with about a thousand dynamic bodies; game objects query and move on the job threads; crowds of AI
// agents (two sizes, each on its own navmesh that background jobs build around them) steer, avoid each other
// and ask for paths on a budget. It runs once with the
// lock-free broad phase and once with one global read-write mutex (the "before"), prints both and writes a
// report. Flags are parsed with CLI11 (Debian's libcli11-dev): --help lists them.

#include "DemoReport.h"
#include "DemoRunner.h"
#include "WorldFile.h"
#include "common/MachineInfo.h"
#include "common/ParseWholeNumber.h"

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>
#include <utility>
#include <vector>

using namespace cairn;
using namespace cairn::physics;
using namespace cairn::demo;

int main(int argc, char** argv)
{
    DemoSettings settings;
    std::string world = CAIRN_DEFAULT_WORLD;
    std::string mode = "both";
    std::string output = "demo-output";
    bool fast = false;
    CLI::App app{"cairn-demo: the streaming open-world demo (lock-free broad phase against a global mutex)"};
    app.add_option("--world", world,
                   "The world's settings, a JSON file (see data/README.md); the flags below override it");
    app.add_option("--frames", settings.mFrames, "Frames per mode (60 per second)")
        ->check(CLI::Range(1, 1000000));
    // As text: CLI11 reads "-1" into an unsigned as 2^64 - 1
    std::string seedText = std::to_string(settings.mSeed);
    app.add_option("--seed", seedText, "World and agent seed (0 to 2^64 - 1)");
    app.add_option("--agents", settings.mAgents, "AI agents in two crowds (one in ten large)")
        ->check(CLI::Range(0, cDemoMaxAgents));
    app.add_option("--threads", settings.mThreads, "Job system threads (0: all cores)")
        ->check(CLI::Range(0, 64));
    app.add_option("--collision-steps", settings.mCollisionSteps, "Physics collision steps per frame")
        ->check(CLI::Range(1, cDemoMaxCollisionSteps));
    app.add_option("--candidate-margin", settings.mCandidateMargin,
                   "Broad-phase static candidate margin (m), 0 turns the cache off")
        ->check(CLI::Range(0.0f, cDemoMaxCandidateMargin));
    app.add_option("--game-objects", settings.mGameObjects, "Game objects updated by jobs each frame")
        ->check(CLI::Range(0u, cDemoMaxGameObjects));
    app.add_option("--mode", mode, "lock-free, global-mutex or both")
        ->check(CLI::IsMember({"lock-free", "global-mutex", "both"}));
    app.add_option("--output", output, "Folder for report.md, the SVG charts and navmesh.obj ('' for none)");
    app.add_flag("--fast", fast, "Do not wait for each 1/60 s tick (frames back to back)");
    try
    {
        app.parse(argc, argv);
    }
    catch (const CLI::ParseError& error)
    {
        // CLI11 prints the help or the message; a usage error exits with 1, as every other error (CLI11's
        // own codes are 104 to 109)
        return app.exit(error) == 0 ? 0 : 1;
    }
    auto usageError = [](const std::string& inMessage)
    {
        std::fprintf(stderr, "cairn-demo: %s\n", inMessage.c_str());
        return 1;
    };
    // The world file first, then the flags given: they override it
    {
        DemoSettings fromFile = settings;
        if (Status loaded = LoadDemoWorld(world, fromFile); !loaded)
            return usageError("--world: " + loaded.GetError().mMessage);
        auto unlessGiven = [&](const char* inFlag, auto& outField, const auto& inFileValue)
        {
            if (app.count(inFlag) == 0) outField = inFileValue;
        };
        unlessGiven("--agents", settings.mAgents, fromFile.mAgents);
        unlessGiven("--collision-steps", settings.mCollisionSteps, fromFile.mCollisionSteps);
        unlessGiven("--candidate-margin", settings.mCandidateMargin, fromFile.mCandidateMargin);
        unlessGiven("--game-objects", settings.mGameObjects, fromFile.mGameObjects);
        if (app.count("--seed") == 0) seedText = std::to_string(fromFile.mSeed);
        settings.mPropsPerTile = fromFile.mPropsPerTile;
        settings.mDynamicPerTile = fromFile.mDynamicPerTile;
        settings.mBuildingsPerTile = fromFile.mBuildingsPerTile;
        settings.mCollisionRadius = fromFile.mCollisionRadius;
        settings.mPlayerSpeed = fromFile.mPlayerSpeed;
        settings.mThrowBalls = fromFile.mThrowBalls;
        settings.mGameObjectJobs = fromFile.mGameObjectJobs;
    }
    if (!tools::ParseWholeNumber(seedText, settings.mSeed))
        return usageError("--seed " + seedText + ": expected a whole number from 0 to 2^64 - 1");
    // CLI11's range check compares, and NaN fails no comparison: every physics update then failed
    if (!std::isfinite(settings.mCandidateMargin))
        return usageError("--candidate-margin: expected a finite number from 0 to 100");
    // The report's folder is made and tried now: an unusable one was reported only after the whole run
    if (!output.empty())
    {
        std::error_code error;
        std::filesystem::create_directories(output, error);
        if (error || !std::filesystem::is_directory(output, error) || ::access(output.c_str(), W_OK) != 0)
            return usageError("--output " + output + ": not a folder that can be made and written");
    }
    settings.mRealTime = !fast;

    std::string commandLine = "cairn-demo";
    for (int i = 1; i < argc; ++i)
        commandLine += std::string(" ") + argv[i];
    std::printf("cairn-demo: %d frames per mode, world %s, seed %llu, %d agents; %s\n", settings.mFrames,
                world.c_str(), (unsigned long long)settings.mSeed, settings.mAgents,
                tools::DescribeMachine().c_str());

    std::vector<DemoRunResult> runs;
    std::vector<BroadPhaseType> modes;
    if (mode != "global-mutex") modes.push_back(BroadPhaseType::QuadTree);
    if (mode != "lock-free") modes.push_back(BroadPhaseType::QuadTreeGlobalMutex);
    for (BroadPhaseType runMode : modes)
    {
        Result<DemoRunResult> run = RunDemo(settings, runMode, stdout);
        // Settings that the physics world refuses: no frame ran, so there is nothing to report
        if (!run)
        {
            std::fprintf(stderr, "cairn-demo: %s\n", run.GetError().mMessage.c_str());
            return 1;
        }
        runs.push_back(std::move(run).Value());
    }
    for (const DemoRunResult& run : runs)
        PrintSummary(stdout, run);
    if (runs.size() == 2) PrintComparison(stdout, runs[0], runs[1]);

    int exitCode = 0;
    for (const DemoRunResult& run : runs)
        if (!run.mErrors.empty() || run.mLostOrDuplicatedBodies != 0 || run.mAgentStats.mInsideStatic != 0 ||
            run.mAgentStats.mOffNavMeshOverOneSecond != 0 || run.mAgentStats.mCorridorsThroughGone != 0 ||
            run.mTilesRequestedNeverBuilt != 0 || run.mAgentStats.mNonClimberLadderFrames != 0 ||
            run.mLaddersDead != 0)
            exitCode = 1;
    if (!output.empty())
    {
        std::string error;
        if (!WriteReport(output, runs, commandLine, error))
        {
            std::fprintf(stderr, "cairn-demo: %s\n", error.c_str());
            return 1;
        }
        // The first run's navmesh, to look at in any OBJ viewer
        const std::string objPath = output + "/navmesh.obj";
        std::ofstream obj(objPath);
        obj << runs.front().mNavMeshObj;
        if (!obj)
        {
            std::fprintf(stderr, "cairn-demo: %s: could not be written\n", objPath.c_str());
            return 1;
        }
        std::printf("report: %s/report.md (navmesh: %s)\n", output.c_str(), objPath.c_str());
    }
    return exitCode;
}
