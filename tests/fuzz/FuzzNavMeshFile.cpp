// libFuzzer: the navmesh file reader, and Detour's queries on what it accepts. A file the reader passes must
// be safe for a runtime to load and query: no crash, no endless loop (libFuzzer's -timeout catches those).

#include "FuzzInputFile.h"
#include "cairn/navmesh/NavMeshFile.h"

#include <DetourNavMeshQuery.h>
#include <array>
#include <memory>

namespace
{
struct QueryDeleter
{
    void operator()(dtNavMeshQuery* inQuery) const { dtFreeNavMeshQuery(inQuery); }
};

/// What a runtime asks of a loaded navmesh: nearest polygons, a path and its corridor, a ray, a slide along
/// the surface, the wall distance, all between the centres of the first and the last tile.
void QueryNavMesh(const dtNavMesh& inNavMesh)
{
    std::unique_ptr<dtNavMeshQuery, QueryDeleter> query(dtAllocNavMeshQuery());
    if (query == nullptr || dtStatusFailed(query->init(&inNavMesh, 512))) return;
    const dtMeshTile* first = nullptr;
    const dtMeshTile* last = nullptr;
    for (int i = 0; i < inNavMesh.getMaxTiles(); ++i)
    {
        const dtMeshTile* tile = inNavMesh.getTile(i);
        if (tile == nullptr || tile->header == nullptr) continue;
        if (first == nullptr) first = tile;
        last = tile;
    }
    if (first == nullptr) return;
    auto centre = [](const dtMeshTile* inTile, std::array<float, 3>& outPoint)
    {
        for (int k = 0; k < 3; ++k)
            outPoint[size_t(k)] = 0.5f * (inTile->header->bmin[k] + inTile->header->bmax[k]);
    };
    std::array<float, 3> start, end, startNearest, endNearest, hitNormal, wallHit, wallNormal;
    centre(first, start);
    centre(last, end);
    const float halfExtents[3] = {4.0f, 8.0f, 4.0f};
    dtQueryFilter filter;
    dtPolyRef startRef = 0, endRef = 0;
    query->findNearestPoly(start.data(), halfExtents, &filter, &startRef, startNearest.data());
    query->findNearestPoly(end.data(), halfExtents, &filter, &endRef, endNearest.data());
    if (startRef == 0 || endRef == 0) return;
    std::array<dtPolyRef, 64> path;
    int pathLength = 0;
    query->findPath(startRef, endRef, startNearest.data(), endNearest.data(), &filter, path.data(),
                    &pathLength, int(path.size()));
    if (pathLength > 0)
    {
        std::array<float, 3 * 64> straight;
        std::array<unsigned char, 64> flags;
        std::array<dtPolyRef, 64> refs;
        int straightLength = 0;
        query->findStraightPath(startNearest.data(), endNearest.data(), path.data(), pathLength,
                                straight.data(), flags.data(), refs.data(), &straightLength,
                                int(refs.size()));
    }
    float hitT = 0.0f;
    query->raycast(startRef, startNearest.data(), endNearest.data(), &filter, &hitT, hitNormal.data(),
                   path.data(), &pathLength, int(path.size()));
    std::array<float, 3> moved;
    int visited = 0;
    query->moveAlongSurface(startRef, startNearest.data(), endNearest.data(), &filter, moved.data(),
                            path.data(), &visited, int(path.size()));
    float wallDistance = 0.0f;
    query->findDistanceToWall(startRef, startNearest.data(), 5.0f, &filter, &wallDistance, wallHit.data(),
                              wallNormal.data());
    float height = 0.0f;
    query->getPolyHeight(startRef, startNearest.data(), &height);
}
} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* inData, size_t inSize)
{
    const std::string path = cairn::fuzz::WriteInputFile(inData, inSize, ".bin");
    cairn::physics::Result<cairn::navmesh::NavMeshFileContents> contents = cairn::navmesh::LoadNavMeshFile(path);
    if (!contents) return 0;
    cairn::physics::Result<cairn::navmesh::DetourNavMeshPtr> navMesh =
        cairn::navmesh::CreateDetourNavMesh(contents.Value());
    if (navMesh) QueryNavMesh(*navMesh.Value());
    return 0;
}
