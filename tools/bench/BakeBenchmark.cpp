// cairn-bench-bake: issue 7's baker figures on Recast's demo meshes (../shared/data/recast-meshes).
//  bake_vs_direct  per mesh: a direct Recast build of every tile (each tile given the raw triangles that
//  touch
//                  its bordered box, as Recast's demo does with its chunky mesh; only the builds are timed),
//                  against cairn-bake's tile work (query, triangle copies and builds) on 1 and 2 threads.
// Prints ms (medians of --repetitions), the ratio bake/direct (target <= 1.2 on 1 thread) and the 2-thread
// speed-up (target >= 1.7), and the polygon total as a checksum (equal for all three).

#include "Baker.h"
#include "cairn/navmesh/ObjMesh.h"
#include "cairn/navmesh/TileBuilder.h"
#include "common/SharedBenchData.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

using namespace cairn;

namespace
{
double Median(std::vector<double> inValues)
{
    std::sort(inValues.begin(), inValues.end());
    return inValues[inValues.size() / 2];
}

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
} // namespace

int main(int argc, char** argv)
{
    int repetitions = 3;
    for (int i = 1; i < argc; ++i)
        if (std::strcmp(argv[i], "--repetitions") == 0 && i + 1 < argc)
            repetitions = std::max(1, std::atoi(argv[++i]));
        else
        {
            std::fprintf(stderr, "usage: cairn-bench-bake [--repetitions N]\n");
            return 2;
        }
    std::printf("cairn-bench-bake: %d repetitions\n", repetitions);
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
