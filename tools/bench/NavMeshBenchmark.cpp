// cairn-bench-navmesh: the navmesh benchmarks of ../shared/bench/SPEC.md and issue 5's targets.
//  nav_tiles_world_tile0  every 12.8 m tile over world tile 0 (x, z in [0, 64]: 5 x 5 tiles) of the shared
//                         static world, built from the physics world: ms per tile for the query/collect part
//                         and for the Recast part, polygons per tile; checksum: polygons and triangles.
//  nav_step_pile2k_jobs   step_pile2k's physics step (1 thread, 300 real-time frames at 60 Hz) with 0 and
//                         with 2 background tile jobs running all the time (their tiles dirtied every
//                         frame): ms per step and the ratio, the tile jobs' longest lock wait.
//  nav_invoker_latency    at 60 Hz (real-time frames), an invoker appears at a new place every 20 frames:
//                         frames from request to publication of its tile, median and p99.
//  nav_queries_world_tile0 the published navmesh over world tile 0: FindPath, Raycast and FindNearestWall
//                         (radius 2 m, 8 m, the largest) between seeded points, µs per query.
// Own timers (Google Benchmark's loop does not fit multi-frame jobs); medians over --repetitions.

#include "bench/NavQueryBenchmark.h"
#include "cairn/jobs/BackgroundQueue.h"
#include "cairn/jobs/JobSystem.h"
#include "cairn/navmesh/GeometryCollector.h"
#include "cairn/navmesh/TileBuilder.h"
#include "cairn/navmesh/TileScheduler.h"
#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "common/BenchOptions.h"
#include "common/FrameTimes.h"
#include "common/PhysicsSystemOrExit.h"
#include "common/SharedBenchData.h"
#include "common/WorkloadBodies.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

using namespace cairn;
using namespace cairn::physics;
using namespace cairn::navmesh;
using Clock = std::chrono::steady_clock;
using tools::Median;
using tools::MillisecondsSince;

namespace
{

void AddBatch(PhysicsSystem& ioPhysics, const std::vector<BenchBox>& inBoxes, MotionType inMotion)
{
    (void)AddWorkloadBoxes(ioPhysics.GetBodyInterface(), inBoxes, inMotion);
}

PhysicsSettings PileSettings()
{
    PhysicsSettings settings;
    settings.mMaxBodies = 32768;
    return settings;
}

TileGrid WorldGrid(const AgentProfile& inProfile)
{
    return TileGrid(0.0f, 0.0f, inProfile.mTileSize, -2.0f, 40.0f);
}

void RunTiles(const SharedBenchData& inData, int inRepetitions)
{
    const std::unique_ptr<PhysicsSystem> physics =
        tools::CreatePhysicsSystemOrExit("cairn-bench-navmesh", PileSettings());
    AddBatch(*physics, inData.mStatic, MotionType::Static);
    (void)physics->Update(1.0f / 60.0f); // The broad phase's first rebuild
    const AgentProfile profile;
    const TileGrid grid = WorldGrid(profile);
    const float border = float(profile.GetBorderCells()) * profile.mCellSize;
    const GeometryCollector collector(physics->GetBodyManager(), physics->GetBroadPhase());

    std::vector<double> collectMedians, recastMedians, collectMaxes, recastMaxes;
    uint64_t polygons = 0, triangles = 0;
    int minPolygons = 1 << 30, maxPolygons = 0, tiles = 0;
    for (int rep = 0; rep < inRepetitions; ++rep)
    {
        std::vector<double> collectMs, recastMs;
        polygons = triangles = 0;
        tiles = 0;
        for (int z = 0; z < 5; ++z)
            for (int x = 0; x < 5; ++x)
            {
                const TileCoord tile{x, z};
                const AABB box = grid.GetTileBoundsWithBorder(tile, border);
                const Clock::time_point start = Clock::now();
                std::vector<BodyID> found;
                TileGeometry geometry;
                CollectStats stats;
                collector.FindBodies(box, {}, found);
                collector.CollectTriangles(box, {}, found, geometry, stats);
                collectMs.push_back(MillisecondsSince(start));
                Result<BuiltTile> built = BuildTile(profile, grid, tile, geometry);
                if (!built)
                {
                    std::fprintf(stderr, "tile %d,%d: %s\n", x, z, built.GetError().mMessage.c_str());
                    std::exit(1);
                }
                recastMs.push_back(built.Value().mBuildMs);
                polygons += uint64_t(built.Value().mNumPolygons);
                triangles += uint64_t(geometry.GetNumTriangles());
                minPolygons = std::min(minPolygons, built.Value().mNumPolygons);
                maxPolygons = std::max(maxPolygons, built.Value().mNumPolygons);
                ++tiles;
            }
        const tools::TimingSummary collect = tools::Summarize(collectMs), recast = tools::Summarize(recastMs);
        std::printf("nav_tiles_world_tile0 rep %d: %d tiles  collect ms/tile median %.3f max %.3f  recast "
                    "ms/tile median %.3f max %.3f\n",
                    rep, tiles, collect.mP50, collect.mMax, recast.mP50, recast.mMax);
        collectMedians.push_back(collect.mP50);
        recastMedians.push_back(recast.mP50);
        collectMaxes.push_back(collect.mMax);
        recastMaxes.push_back(recast.mMax);
    }
    std::printf(
        "nav_tiles_world_tile0 median of %d: collect %.3f ms/tile (max %.3f)  recast %.3f ms/tile (max "
        "%.3f)  collect/recast %.1f%%  polygons/tile mean %.1f min %d max %d  | checksum polygons %llu "
        "triangles %llu\n",
        inRepetitions, Median(collectMedians), Median(collectMaxes), Median(recastMedians),
        Median(recastMaxes), 100.0 * Median(collectMedians) / Median(recastMedians),
        double(polygons) / double(tiles), minPolygons, maxPolygons, (unsigned long long)polygons,
        (unsigned long long)triangles);
}

struct PileRun
{
    tools::TimingSummary mStep;
    uint64_t mTilesBuilt = 0;
};

/// step_pile2k on one physics thread, with inBackgroundJobs tile jobs kept running (0: none).
PileRun RunPile(const SharedBenchData& inData, uint32_t inBackgroundJobs)
{
    const std::unique_ptr<PhysicsSystem> physics =
        tools::CreatePhysicsSystemOrExit("cairn-bench-navmesh", PileSettings());
    AddBatch(*physics, inData.mStatic, MotionType::Static);
    AddBatch(*physics, inData.mDynamic, MotionType::Dynamic);
    jobs::JobSystem::Settings jobSettings;
    jobSettings.mNumThreads = 1;
    jobs::JobSystem frameJobs(jobSettings);

    const AgentProfile profile;
    std::unique_ptr<NavMeshWorld> world =
        std::move(NavMeshWorld::Create(WorldGrid(profile), profile).Value());
    jobs::BackgroundQueue::Settings queueSettings;
    queueSettings.mNumThreads = std::max(1u, inBackgroundJobs);
    queueSettings.mFrameJobs = &frameJobs;
    jobs::BackgroundQueue queue(queueSettings);
    std::unique_ptr<TileScheduler> scheduler;
    // The pile lands on world tile 0 and around: the area the jobs rebuild over and over
    const AABB area(Vec3(0, -2, 0), Vec3(64, 40, 64));
    if (inBackgroundJobs > 0)
    {
        TileScheduler::Settings settings;
        settings.mMaxConcurrentJobs = inBackgroundJobs;
        scheduler = std::make_unique<TileScheduler>(*physics, *world, queue, settings);
        (void)scheduler->AddArea(area).Value(); // The shared world's tile: always inside the world
    }
    // Real-time frames at 60 Hz, as in a game: the step, the sync point, then the rest of the frame, in which
    // the background jobs get the CPU the frame leaves
    std::vector<double> stepMs;
    const Clock::time_point begin = Clock::now();
    for (int step = 0; step < 300; ++step)
    {
        const Clock::time_point start = Clock::now();
        (void)physics->Update(1.0f / 60.0f, 1, frameJobs);
        stepMs.push_back(MillisecondsSince(start));
        if (scheduler != nullptr)
        {
            scheduler->MarkDirty(area); // Keep the jobs busy: every tile is always wanted again
            scheduler->Update();
        }
        std::this_thread::sleep_until(begin + std::chrono::microseconds(16667 * (step + 1)));
    }
    PileRun run;
    run.mStep = tools::Summarize(stepMs);
    if (scheduler != nullptr)
    {
        const TileScheduler::Stats stats = scheduler->GetStats();
        run.mTilesBuilt = stats.mTilesPublished;
    }
    return run;
}

void RunPileWithJobs(const SharedBenchData& inData, int inRepetitions)
{
    std::vector<double> without, with;
    for (int rep = 0; rep < inRepetitions; ++rep)
    {
        const PileRun none = RunPile(inData, 0);
        const PileRun two = RunPile(inData, 2);
        std::printf(
            "nav_step_pile2k_jobs rep %d: 0 jobs mean %.3f ms p99 %.3f  | 2 jobs mean %.3f ms p99 %.3f  "
            "tiles built %llu\n",
            rep, none.mStep.mMean, none.mStep.mP99, two.mStep.mMean, two.mStep.mP99,
            (unsigned long long)two.mTilesBuilt);
        without.push_back(none.mStep.mMean);
        with.push_back(two.mStep.mMean);
    }
    std::printf("nav_step_pile2k_jobs median of %d: step %.3f ms with 0 jobs, %.3f ms with 2 jobs (%.2fx)\n",
                inRepetitions, Median(without), Median(with), Median(with) / Median(without));
}

void RunInvokerLatency(const SharedBenchData& inData)
{
    const std::unique_ptr<PhysicsSystem> physics =
        tools::CreatePhysicsSystemOrExit("cairn-bench-navmesh", PileSettings());
    AddBatch(*physics, inData.mStatic, MotionType::Static);
    AddBatch(*physics, inData.mDynamic, MotionType::Dynamic);
    const AgentProfile profile;
    std::unique_ptr<NavMeshWorld> world =
        std::move(NavMeshWorld::Create(WorldGrid(profile), profile).Value());
    jobs::BackgroundQueue::Settings queueSettings;
    queueSettings.mNumThreads = 2;
    jobs::BackgroundQueue queue(queueSettings);
    TileScheduler::Settings settings;
    settings.mMaxConcurrentJobs = 2;
    settings.mDropDelayFrames = 10;
    TileScheduler scheduler(*physics, *world, queue, settings);
    // Invokers one after another across the world, each asking for its own tile only, every 20 frames: the
    // budget is free each time
    TileScheduler::InvokerID invoker = 0;
    const Clock::time_point begin = Clock::now();
    for (int frame = 0; frame < 600; ++frame)
    {
        if (frame % 20 == 0)
        {
            if (invoker != 0) (void)scheduler.RemoveInvoker(invoker); // The one added 20 frames before
            const int index = frame / 20;
            invoker = scheduler
                          .AddInvoker(Vec3(6.4f + 12.8f * float(index % 30), 0.0f,
                                           6.4f + 12.8f * float((index * 7) % 19)),
                                      1.0f)
                          .Value(); // Tile centres of the shared world: always inside it
        }
        (void)physics->Update(1.0f / 60.0f);
        scheduler.Update();
        // Real-time frames: wait for the next 1/60 s tick
        std::this_thread::sleep_until(begin + std::chrono::microseconds(16667 * (frame + 1)));
    }
    std::vector<double> frames;
    for (uint32_t f : scheduler.GetStats().mFirstPublishFrames)
        frames.push_back(double(f));
    const tools::TimingSummary summary = tools::Summarize(frames);
    std::printf(
        "nav_invoker_latency: %zu tiles requested, frames to publication median %.0f p99 %.0f max %.0f\n",
        frames.size(), summary.mP50, summary.mP99, summary.mMax);
}

} // namespace

int main(int argc, char** argv)
{
    tools::BenchOptions options;
    if (auto stop =
            tools::ParseBenchOptions(argc, argv, "cairn-bench-navmesh: navmesh tile and tile-job figures",
                                     {"nav_tiles_world_tile0", "nav_step_pile2k_jobs", "nav_invoker_latency",
                                      "nav_queries_world_tile0"},
                                     options))
        return *stop;
    const int repetitions = options.mRepetitions;
    const std::string& only = options.mOnly;
#ifdef NDEBUG
    const char* buildType = "Release";
#else
    const char* buildType = "Debug";
#endif
    Result<SharedBenchData> data = LoadSharedBenchData();
    if (!data)
    {
        std::fprintf(stderr, "cairn-bench-navmesh: %s\n", data.GetError().mMessage.c_str());
        return 1;
    }
    std::printf("cairn-bench-navmesh: build %s, %d repetitions, %u hardware threads\n", buildType,
                repetitions, std::thread::hardware_concurrency());
    if (only.empty() || only == "nav_tiles_world_tile0") RunTiles(data.Value(), repetitions);
    if (only.empty() || only == "nav_step_pile2k_jobs") RunPileWithJobs(data.Value(), repetitions);
    if (only.empty() || only == "nav_invoker_latency") RunInvokerLatency(data.Value());
    if (only.empty() || only == "nav_queries_world_tile0") tools::RunNavQueries(data.Value(), repetitions);
    return 0;
}
