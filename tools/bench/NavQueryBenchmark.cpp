#include "bench/NavQueryBenchmark.h"

#include "cairn/navmesh/GeometryCollector.h"
#include "cairn/navmesh/NavMeshWorld.h"
#include "cairn/navmesh/TileBuilder.h"
#include "cairn/physics/PhysicsSystem.h"
#include "common/FrameTimes.h"
#include "common/PhysicsSystemOrExit.h"
#include "common/WorkloadBodies.h"

#include <DetourNavMesh.h>
#include <DetourNavMeshQuery.h>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace cairn::tools
{
using namespace cairn::navmesh;
using Clock = std::chrono::steady_clock;

namespace
{

/// The navmesh's 5 x 5 tiles over world tile 0 (x, z in [0, 64]), published.
std::unique_ptr<NavMeshWorld> PublishWorldTile0(const SharedBenchData& inData)
{
    PhysicsSettings settings;
    settings.mMaxBodies = 32768;
    const std::unique_ptr<PhysicsSystem> physics = CreatePhysicsSystemOrExit("cairn-bench-navmesh", settings);
    (void)AddWorkloadBoxes(physics->GetBodyInterface(), inData.mStatic, MotionType::Static);
    (void)physics->Update(1.0f / 60.0f); // The broad phase's first rebuild
    const AgentProfile profile;
    const TileGrid grid(0.0f, 0.0f, profile.mTileSize, -2.0f, 40.0f);
    const float border = float(profile.GetBorderCells()) * profile.mCellSize;
    const GeometryCollector collector(physics->GetBodyManager(), physics->GetBroadPhase());
    std::vector<BuiltTile> tiles;
    for (int z = 0; z < 5; ++z)
        for (int x = 0; x < 5; ++x)
        {
            const AABB box = grid.GetTileBoundsWithBorder({x, z}, border);
            std::vector<BodyID> found;
            TileGeometry geometry;
            CollectStats stats;
            collector.FindBodies(box, {}, found);
            collector.CollectTriangles(box, {}, found, geometry, stats);
            Result<BuiltTile> built = BuildTile(profile, grid, {x, z}, geometry);
            if (!built)
            {
                std::fprintf(stderr, "tile %d,%d: %s\n", x, z, built.GetError().mMessage.c_str());
                std::exit(1);
            }
            tiles.push_back(std::move(built.Value()));
        }
    std::unique_ptr<NavMeshWorld> world = std::move(NavMeshWorld::Create(grid, profile).Value());
    world->Publish(std::move(tiles));
    return world;
}

struct QueryKind
{
    QueryKind(const char* inName, std::function<bool(const Vec3&, const Vec3&)> inQuery)
        : mName(inName), mQuery(std::move(inQuery))
    {
    }

    const char* mName;
    std::function<bool(const Vec3&, const Vec3&)> mQuery; ///< True when it found something (a hit, a wall)
    std::vector<double> mMeans, mP50s, mP99s;
    int mFound = 0;
};

} // namespace

void RunNavQueries(const SharedBenchData& inData, int inRepetitions)
{
    const std::unique_ptr<NavMeshWorld> world = PublishWorldTile0(inData);
    // Seeded points on the navmesh, and for each a second one within 20 m (a raycast's reach)
    constexpr int cPairs = 2000;
    std::mt19937 random(7);
    std::uniform_real_distribution<float> across(1.0f, 63.0f), near(-20.0f, 20.0f);
    std::vector<std::pair<Vec3, Vec3>> pairs;
    for (int tries = 0; int(pairs.size()) < cPairs && tries < 100 * cPairs; ++tries)
    {
        Result<Vec3> from =
            world->FindNearestPoint(Vec3(across(random), 0.0f, across(random)), {}, Vec3(1.0f, 40.0f, 1.0f));
        if (!from) continue;
        const Vec3 to = from.Value() + Vec3(near(random), 0.0f, near(random));
        pairs.emplace_back(from.Value(), to);
    }
    if (int(pairs.size()) < cPairs)
    {
        std::fprintf(stderr, "nav_queries_world_tile0: only %zu points on the navmesh\n", pairs.size());
        std::exit(1);
    }
    const float maxRadius = NavMeshWorld::cMaxSearchExtentTiles * world->GetGrid().GetTileSize();
    const std::unique_ptr<dtNavMeshQuery, void (*)(dtNavMeshQuery*)> detourQuery(dtAllocNavMeshQuery(),
                                                                                 dtFreeNavMeshQuery);
    world->Read([&](const dtNavMesh& inNavMesh) { (void)detourQuery->init(&inNavMesh, 4096); });
    const dtQueryFilter detourFilter;
    QueryKind kinds[] = {
        {"path", [&](const Vec3& inA, const Vec3& inB) { return world->FindPath(inA, inB).IsOk(); }},
        {"raycast",
         [&](const Vec3& inA, const Vec3& inB)
         {
             Result<NavRaycastHit> hit = world->Raycast(inA, inB);
             return hit && hit.Value().mHit;
         }},
        {"wall_2m",
         [&](const Vec3& inA, const Vec3&)
         {
             Result<NavWall> wall = world->FindNearestWall(inA, 2.0f);
             return wall && wall.Value().mFound;
         }},
        {"wall_8m",
         [&](const Vec3& inA, const Vec3&)
         {
             Result<NavWall> wall = world->FindNearestWall(inA, 8.0f);
             return wall && wall.Value().mFound;
         }},
        {"wall_max",
         [&](const Vec3& inA, const Vec3&)
         {
             Result<NavWall> wall = world->FindNearestWall(inA, maxRadius);
             return wall && wall.Value().mFound;
         }},
        // Detour's own, for reference: it has no excluded areas to heed
        {"detour_wall_8m",
         [&](const Vec3& inA, const Vec3&)
         {
             float distance = 8.0f;
             world->Read(
                 [&](const dtNavMesh&)
                 {
                     dtPolyRef polygon = 0;
                     float onNavMesh[3], wall[3], normal[3];
                     const float extent[3] = {2.0f, 4.0f, 2.0f};
                     detourQuery->findNearestPoly(inA.data(), extent, &detourFilter, &polygon, onNavMesh);
                     if (polygon != 0)
                         detourQuery->findDistanceToWall(polygon, onNavMesh, 8.0f, &detourFilter, &distance,
                                                         wall, normal);
                 });
             return distance < 8.0f;
         }},
    };
    for (int rep = 0; rep < inRepetitions; ++rep)
        for (QueryKind& kind : kinds)
        {
            std::vector<double> micros;
            micros.reserve(pairs.size());
            kind.mFound = 0;
            for (const auto& [from, to] : pairs)
            {
                const Clock::time_point start = Clock::now();
                kind.mFound += kind.mQuery(from, to) ? 1 : 0;
                micros.push_back(1000.0 * MillisecondsSince(start));
            }
            const TimingSummary summary = Summarize(micros);
            kind.mMeans.push_back(summary.mMean);
            kind.mP50s.push_back(summary.mP50);
            kind.mP99s.push_back(summary.mP99);
        }
    std::printf("nav_queries_world_tile0 median of %d, %d queries each (one thread):", inRepetitions, cPairs);
    for (const QueryKind& kind : kinds)
        std::printf("  %s us mean %.2f p50 %.2f p99 %.2f", kind.mName, Median(kind.mMeans),
                    Median(kind.mP50s), Median(kind.mP99s));
    std::printf("  | checksum found");
    for (const QueryKind& kind : kinds)
        std::printf(" %s %d", kind.mName, kind.mFound);
    std::printf("\n");
}

} // namespace cairn::tools
