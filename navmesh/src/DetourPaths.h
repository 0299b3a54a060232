#pragma once

// DetourPaths: what every path search on the published navmesh shares, the synchronous queries of
// NavMeshWorld and the sliced ones of PathRequestQueue: Detour's filter for a PathFilter, the area check
// Detour cannot do, the search extent's limit and the last part of a search (the corridor cut before an
// excluded area, the straight path). The caller holds the navmesh (NavMeshWorld's mutex, shared).

#include "cairn/navmesh/NavMeshWorld.h"

#include <DetourNavMesh.h>
#include <DetourNavMeshQuery.h>

namespace cairn::navmesh
{

/// Detour's node pool for one query object.
inline constexpr int cMaxQueryNodes = 4096;
/// The longest corridor a search returns, in polygons.
inline constexpr int cMaxPathPolygons = 1024;
/// The most corner points of a straight path.
inline constexpr int cMaxStraightPoints = 256;

/// Detour's area id of a Cairn area id.
inline unsigned char ToDetourArea(int inArea)
{
    return inArea == cDefaultArea ? 63 : (unsigned char)inArea; // RC_WALKABLE_AREA is 63
}
/// The Cairn area id of a Detour area id.
inline int FromDetourArea(unsigned char inArea)
{
    return inArea == 63 ? cDefaultArea : int(inArea);
}

/// Detour's filter for a PathFilter. Detour excludes by polygon flags, not areas: an excluded area gets a
/// prohibitive cost, and callers check the areas of what they find (IsExcluded), unless the world marks the
/// filter's areas with a flag (NavMeshWorld::AcquireExclusionFlag), given as inExcludeFlags.
Result<dtQueryFilter> MakeDetourFilter(const PathFilter& inFilter, const char* inWhat,
                                       uint16_t inExcludeFlags = 0);
/// True if the polygon is an off-mesh link's (a jump, a drop, a ladder), not ground.
bool IsOffMeshLink(const dtNavMesh& inNavMesh, dtPolyRef inPolygon);
/// True if the polygon's Cairn area is one inFilter excludes.
bool IsExcluded(const dtNavMesh& inNavMesh, dtPolyRef inPolygon, const PathFilter& inFilter);
/// Checks a search extent against the grid's limit (NavMeshWorld::cMaxSearchExtentTiles tiles across).
Status CheckSearchExtent(const Vec3& inSearchExtent, float inTileSize, const char* inWhat);
/// A found corridor (inNumPolygons > 0) made a PathResult: cut before its first polygon of an excluded area,
/// ending at the end or, for a partial corridor, at the point of its last polygon nearest the end (never on
/// an off-mesh link). inSearchStatus: Detour's status of the search that found it (its budget details).
Result<PathResult> FinishPath(const dtNavMeshQuery& inQuery, const dtNavMesh& inNavMesh,
                              const dtPolyRef* inCorridor, int inNumPolygons, dtPolyRef inEndRef,
                              const float* inStartPoint, const float* inEndPoint, const PathFilter& inFilter,
                              dtStatus inSearchStatus);

} // namespace cairn::navmesh
