// cairn-bench-bake: issue 7's baker figures on Recast's demo meshes (../shared/data/recast-meshes).
//  bake_vs_direct  per mesh: a direct Recast build of every tile (each tile given the raw triangles that
//                  touch its bordered box, as Recast's demo does with its chunky mesh; only the builds are
//                  timed), against cairn-bake's tile work (query, triangle copies and builds) on 1 and 2
//                  threads.
// Prints ms (medians of --repetitions), the ratio bake/direct (target <= 1.2 on 1 thread) and the 2-thread
// speed-up (target >= 1.7), and the polygon total as a checksum (equal for all three).
//  bake_large_world  a generated level (GeneratedLevel, made on demand) of 1x, 10x and 100x the area, baked
//                  on all cores with tiles streamed to a file, each in a child process of its own so that its
//                  peak resident memory (wait4's ru_maxrss) is its alone: time should grow with the area,
//                  peak memory should not (target: about the same at 100x).
//  bake_overlapping  2,000, 10,000 and 50,000 small objects over one floor, all overlapping one another's
//                  tiles, baked on 1 thread: ms per object should stay flat (each unloaded prop once woke
//                  every prop around it, n^2).
//  load_materials  an OBJ of 4 triangles whose materials come from 5,000 and 20,000 `mtllib`/`usemtl` line
//                  pairs: load ms should grow with the lines (each library line once answered every name).
// --only direct|large|overlapping|materials runs one of them.

#include "Baker.h"
#include "GeneratedLevel.h"
#include "cairn/navmesh/LevelMesh.h"
#include "cairn/navmesh/TileBuilder.h"
#include "common/BenchOptions.h"
#include "common/FrameTimes.h"
#include "common/SharedBenchData.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

using namespace cairn;
using namespace cairn::physics;
using tools::Median;

namespace
{

/// Every tile of the mesh built straight from its raw triangles: ms and polygons.
std::pair<double, uint64_t> DirectBuild(const navmesh::IndexedMesh& inMesh,
                                        const navmesh::AgentProfile& inProfile)
{
    const AABB bounds = inMesh.GetBounds();
    const navmesh::TileGrid grid(0.0f, 0.0f, inProfile.mTileSize, bounds.mMin.y() - 1.0f,
                                 bounds.mMax.y() + 1.0f);
    std::vector<navmesh::TileCoord> tiles;
    grid.TilesOverlapping(bounds, 0.0f, tiles);
    const float border = float(inProfile.GetBorderCells()) * inProfile.mCellSize;
    double ms = 0.0;
    uint64_t polygons = 0;
    for (const navmesh::TileCoord& tile : tiles)
    {
        const AABB box = grid.GetTileBoundsWithBorder(tile, border);
        navmesh::TileGeometry geometry;
        for (const std::array<uint32_t, 3>& t : inMesh.mTriangles)
        {
            AABB triangle;
            for (uint32_t v : t)
                triangle.Encapsulate(inMesh.mVertices[v]);
            if (triangle.Overlaps(box))
                geometry.AddTriangle(inMesh.mVertices[t[0]], inMesh.mVertices[t[1]], inMesh.mVertices[t[2]],
                                     0);
        }
        const auto start = std::chrono::steady_clock::now();
        Result<navmesh::BuiltTile> built = navmesh::BuildTile(inProfile, grid, tile, geometry);
        ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        if (built) polygons += uint64_t(built.Value().mNumPolygons);
    }
    return {ms, polygons};
}

/// What a child process reports of its bake.
struct LargeWorldRun
{
    double mBakeMs = 0.0;
    uint32_t mTiles = 0;
    uint32_t mPeakBodies = 0;
    uint64_t mBodiesMade = 0;
    uint64_t mPolygons = 0;
    uint64_t mObjects = 0;
    bool mOk = false;
};

/// Bakes a generated level of inCells x inCells cells in a child process; returns its figures and its peak
/// resident memory in KiB.
std::pair<LargeWorldRun, long> BakeLargeWorldInChild(uint32_t inCells)
{
    int channel[2];
    if (pipe(channel) != 0) return {};
    const pid_t child = fork();
    if (child == 0)
    {
        close(channel[0]);
        LargeWorldRun run;
        bake::GeneratedLevelSettings level;
        level.mCellsX = level.mCellsZ = inCells;
        Result<std::unique_ptr<bake::GeneratedLevel>> source = bake::GeneratedLevel::Create(level);
        if (source)
        {
            bake::BakeSettings settings;
            settings.mOutputPath = (std::filesystem::temp_directory_path() /
                                    ("cairn-bench-large-world-" + std::to_string(getpid()) + ".navmesh"))
                                       .string();
            Result<bake::BakeResult> result = bake::BakeSource(*source.Value(), settings);
            std::filesystem::remove(settings.mOutputPath);
            if (result)
            {
                run = {result.Value().mBakeMs,
                       result.Value().mTilesBaked,
                       result.Value().mPeakBodies,
                       result.Value().mBodies,
                       result.Value().mPolygons,
                       uint64_t(inCells) * inCells * (1 + level.mPropsPerCell),
                       true};
            }
            else
                std::fprintf(stderr, "bake_large_world: %s\n", result.GetError().mMessage.c_str());
        }
        const ssize_t written = write(channel[1], &run, sizeof(run));
        _exit(written == ssize_t(sizeof(run)) ? 0 : 1);
    }
    close(channel[1]);
    LargeWorldRun run;
    if (child < 0 || read(channel[0], &run, sizeof(run)) != ssize_t(sizeof(run))) run.mOk = false;
    close(channel[0]);
    int status = 0;
    rusage usage{};
    if (child > 0) wait4(child, &status, 0, &usage);
    return {run, usage.ru_maxrss};
}

void BenchLargeWorld()
{
    double firstMs = 0.0;
    long firstKiB = 0;
    for (uint32_t cells : {2u, 6u, 20u}) // 1x, 9x, 100x the area
    {
        const auto [run, peakKiB] = BakeLargeWorldInChild(cells);
        if (!run.mOk)
        {
            std::printf("bake_large_world %ux%u cells: failed\n", cells, cells);
            continue;
        }
        if (firstMs == 0.0)
        {
            firstMs = run.mBakeMs;
            firstKiB = peakKiB;
        }
        std::printf("bake_large_world %2ux%-2u cells (%5.0f m square, %6llu objects): %5u tiles in %8.1f ms "
                    "(%.1fx the first), peak memory %6.1f MiB (%.2fx), at most %u bodies at once (%llu made) "
                    "| checksum polygons %llu\n",
                    cells, cells, cells * 32.0, (unsigned long long)run.mObjects, run.mTiles, run.mBakeMs,
                    run.mBakeMs / firstMs, peakKiB / 1024.0, double(peakKiB) / double(firstKiB),
                    run.mPeakBodies, (unsigned long long)run.mBodiesMade, (unsigned long long)run.mPolygons);
    }
}

/// A temporary OBJ path of this process for a generated level called inName.
std::string TemporaryLevelPath(const std::string& inName)
{
    return (std::filesystem::temp_directory_path() /
            ("cairn-bench-" + inName + "-" + std::to_string(getpid()) + ".obj"))
        .string();
}

/// A floor and inObjects one-triangle objects on a 10 x 10 pattern over the same 5 m, as an OBJ file.
std::string WriteOverlappingLevel(int inObjects)
{
    const std::string path = TemporaryLevelPath("overlapping");
    std::FILE* file = std::fopen(path.c_str(), "w");
    std::fprintf(file, "v -20 0 -20\nv 20 0 -20\nv 20 0 20\nv -20 0 20\no floor\nf 1 3 2\nf 1 4 3\n");
    for (int i = 0; i < inObjects; ++i)
    {
        const float x = float(i % 10) * 0.5f, z = float(i / 10 % 10) * 0.5f;
        const int base = 4 + i * 3;
        std::fprintf(file, "o obj%d\nv %g 0.5 %g\nv %g 0.5 %g\nv %g 0.5 %g\nf %d %d %d\n", i, x, z, x + 1, z,
                     x, z + 1, base + 1, base + 3, base + 2);
    }
    std::fclose(file);
    return path;
}

void BenchOverlapping(int inRepetitions)
{
    for (const int objects : {2000, 10000, 50000})
    {
        const std::string path = WriteOverlappingLevel(objects);
        bake::BakeSettings settings;
        settings.mInputs = {path};
        settings.mThreads = 1;
        std::vector<double> ms;
        uint64_t polygons = 0;
        for (int rep = 0; rep < inRepetitions; ++rep)
        {
            const bake::BakeResult result = bake::Bake(settings).Value();
            ms.push_back(result.mBakeMs);
            polygons = result.mPolygons;
        }
        std::filesystem::remove(path);
        std::printf("bake_overlapping %6d objects  %.1f ms  %.2f us per object  | checksum polygons %llu\n",
                    objects, Median(ms), Median(ms) * 1000.0 / objects, (unsigned long long)polygons);
    }
}

void BenchManyMaterials(int inRepetitions)
{
    for (const int materials : {5000, 20000})
    {
        const std::string path = TemporaryLevelPath("materials");
        std::FILE* file = std::fopen(path.c_str(), "w");
        std::fprintf(file, "v 0 0 0\nv 10 0 0\nv 10 0 10\nv 0 0 10\n");
        for (int i = 0; i < materials; ++i)
            std::fprintf(file, "mtllib m%d.mtl\nusemtl m%d\n", i, i);
        std::fprintf(file, "f 1 3 2\nf 1 4 3\n");
        std::fclose(file);
        std::vector<double> ms;
        size_t loaded = 0;
        for (int rep = 0; rep < inRepetitions; ++rep)
        {
            const auto start = std::chrono::steady_clock::now();
            loaded = navmesh::LoadObjMesh(path).Value().mMaterials.size();
            ms.push_back(
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
        }
        std::filesystem::remove(path);
        std::printf("load_materials %6d library lines  %.1f ms  | checksum materials %zu\n", materials,
                    Median(ms), loaded);
    }
}

} // namespace

int main(int argc, char** argv)
{
    tools::BenchOptions options;
    if (auto stop = tools::ParseBenchOptions(argc, argv, "cairn-bench-bake: the offline baker's figures",
                                             {"direct", "large", "overlapping", "materials"}, options))
        return *stop;
    const int repetitions = options.mRepetitions;
    const std::string& only = options.mOnly;
    std::printf("cairn-bench-bake: %d repetitions\n", repetitions);
    if (only.empty() || only == "overlapping") BenchOverlapping(repetitions);
    if (only.empty() || only == "materials") BenchManyMaterials(repetitions);
    if (only.empty() || only == "large") BenchLargeWorld();
    if (!only.empty() && only != "direct") return 0;
    for (const char* name : {"dungeon.obj", "nav_test.obj", "undulating.obj"})
    {
        const std::string path = GetSharedDataDir() + "/recast-meshes/" + name;
        if (!std::filesystem::exists(path))
        {
            std::printf("%s skipped: missing %s\n", name, path.c_str());
            continue;
        }
        const navmesh::IndexedMesh mesh = navmesh::LoadObjMesh(path).Value();
        bake::BakeSettings settings;
        settings.mInputs = {path};
        std::vector<double> direct, one, two;
        uint64_t directPolygons = 0, onePolygons = 0, twoPolygons = 0;
        for (int rep = 0; rep < repetitions; ++rep)
        {
            const auto [ms, polygons] = DirectBuild(mesh, settings.mProfile);
            direct.push_back(ms);
            directPolygons = polygons;
            settings.mThreads = 1;
            const bake::BakeResult r1 = bake::Bake(settings).Value();
            one.push_back(r1.mBakeMs);
            onePolygons = r1.mPolygons;
            settings.mThreads = 2;
            const bake::BakeResult r2 = bake::Bake(settings).Value();
            two.push_back(r2.mBakeMs);
            twoPolygons = r2.mPolygons;
        }
        std::printf(
            "bake_vs_direct %-15s direct %.1f ms  bake 1 thread %.1f ms (%.2fx direct)  2 threads %.1f ms "
            "(speed-up %.2fx)  | checksum polygons %llu %llu %llu\n",
            name, Median(direct), Median(one), Median(one) / Median(direct), Median(two),
            Median(one) / Median(two), (unsigned long long)directPolygons, (unsigned long long)onePolygons,
            (unsigned long long)twoPolygons);
    }
    return 0;
}
