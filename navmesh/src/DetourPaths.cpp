#include "DetourPaths.h"

#include <cmath>
#include <string>

namespace cairn::navmesh
{

Result<dtQueryFilter> MakeDetourFilter(const PathFilter& inFilter, const char* inWhat,
                                       uint16_t inExcludeFlags)
{
    dtQueryFilter filter;
    filter.setIncludeFlags(cPolyFlagWalk);
    filter.setExcludeFlags(inExcludeFlags);
    for (int area = 0; area <= cMaxAreaId; ++area)
    {
        const bool excluded = (inFilter.mExcludedAreas >> area) & 1u;
        const float cost = inFilter.mAreaCost[size_t(area)];
        if (!std::isfinite(cost) || cost < 0.0f)
            return MakeError(ErrorCode::InvalidArgument,
                             std::string(inWhat) + ": area costs must be finite and >= 0");
        filter.setAreaCost(ToDetourArea(area), excluded ? 1.0e30f : cost);
    }
    return filter;
}

bool IsOffMeshLink(const dtNavMesh& inNavMesh, dtPolyRef inPolygon)
{
    const dtMeshTile* tile = nullptr;
    const dtPoly* poly = nullptr;
    inNavMesh.getTileAndPolyByRefUnsafe(inPolygon, &tile, &poly);
    return poly->getType() == DT_POLYTYPE_OFFMESH_CONNECTION;
}

bool IsExcluded(const dtNavMesh& inNavMesh, dtPolyRef inPolygon, const PathFilter& inFilter)
{
    const dtMeshTile* tile = nullptr;
    const dtPoly* poly = nullptr;
    inNavMesh.getTileAndPolyByRefUnsafe(inPolygon, &tile, &poly);
    const int area = FromDetourArea(poly->getArea());
    return area <= cMaxAreaId && ((inFilter.mExcludedAreas >> area) & 1u) != 0;
}

Status CheckSearchExtent(const Vec3& inSearchExtent, float inTileSize, const char* inWhat)
{
    if (!IsFinite(inSearchExtent) || (inSearchExtent.array() <= 0.0f).any())
        return MakeError(ErrorCode::InvalidArgument,
                         std::string(inWhat) + ": the search extent must be finite and positive");
    // Detour visits every tile cell under the extent while the navmesh is locked: a huge one would stall
    // Publish (and the frame) for minutes
    const float maxExtent = NavMeshWorld::cMaxSearchExtentTiles * inTileSize;
    if (inSearchExtent.x() > maxExtent || inSearchExtent.z() > maxExtent)
        return MakeError(ErrorCode::InvalidArgument,
                         std::string(inWhat) + ": the search extent may span at most " +
                             std::to_string(int(NavMeshWorld::cMaxSearchExtentTiles)) +
                             " tiles across (x and z)");
    return {};
}

Result<PathResult> FinishPath(const dtNavMeshQuery& inQuery, const dtNavMesh& inNavMesh,
                              const dtPolyRef* inCorridor, int inNumPolygons, dtPolyRef inEndRef,
                              const float* inStartPoint, const float* inEndPoint, const PathFilter& inFilter,
                              dtStatus inSearchStatus)
{
    // Cut the corridor before the first polygon of an excluded area
    for (int i = 0; i < inNumPolygons; ++i)
    {
        if (IsExcluded(inNavMesh, inCorridor[i], inFilter))
        {
            if (i == 0)
                return MakeError(ErrorCode::InvalidArgument, "path: the start is in an excluded area");
            inNumPolygons = i;
            break;
        }
    }
    // A partial corridor never ends on an off-mesh link: Detour's search steps onto a link whose far end
    // joins nothing (its tile not loaded) and, its node at the link's start, may find that nearest the end.
    // The path would end in the air between the link's ends, and a crowd agent would wait at the link for
    // ever
    if (inCorridor[inNumPolygons - 1] != inEndRef)
        while (inNumPolygons > 1 && IsOffMeshLink(inNavMesh, inCorridor[inNumPolygons - 1]))
            --inNumPolygons;
    PathResult result;
    result.mNumPolygons = inNumPolygons;
    result.mReachedEnd = inCorridor[inNumPolygons - 1] == inEndRef;
    result.mSearchLimited = !result.mReachedEnd && (dtStatusDetail(inSearchStatus, DT_OUT_OF_NODES) ||
                                                    dtStatusDetail(inSearchStatus, DT_BUFFER_TOO_SMALL));
    // A partial path ends at the point of its last polygon nearest the end
    float target[3] = {inEndPoint[0], inEndPoint[1], inEndPoint[2]};
    if (!result.mReachedEnd)
        inQuery.closestPointOnPoly(inCorridor[inNumPolygons - 1], inEndPoint, target, nullptr);
    float points[cMaxStraightPoints * 3];
    int numPoints = 0;
    inQuery.findStraightPath(inStartPoint, target, inCorridor, inNumPolygons, points, nullptr, nullptr,
                             &numPoints, cMaxStraightPoints);
    result.mPolygons.assign(inCorridor, inCorridor + inNumPolygons);
    for (int i = 0; i < numPoints; ++i)
        result.mStraightPath.emplace_back(points[3 * i], points[3 * i + 1], points[3 * i + 2]);
    return result;
}

} // namespace cairn::navmesh
