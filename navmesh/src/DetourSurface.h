#pragma once

// DetourSurface: the queries across the navmesh's surface near a point that NavMeshWorld answers (a straight
// walk, the nearest wall), on Detour's raycast and circle search, with what Detour's filter cannot say added:
// the border of an excluded area is a wall (Detour excludes by polygon flags, Cairn by area). The caller
// holds the navmesh (NavMeshWorld's mutex, shared) and has checked the numbers and the start's polygon.

#include "cairn/navmesh/NavMeshWorld.h"

#include <DetourNavMesh.h>
#include <DetourNavMeshQuery.h>

namespace cairn::navmesh
{

/// A straight walk from inStartPoint on inStart (not excluded) towards inEnd, stopped by the navmesh's edge
/// and by the border of an area inFilter excludes. Detour's raycast, taken up again past a tile's border or
/// corner where it stops with no wall there.
Result<NavRaycastHit> CastAcrossSurface(const dtNavMeshQuery& inQuery, const dtNavMesh& inNavMesh,
                                        dtPolyRef inStart, const Vec3& inStartPoint, const Vec3& inEnd,
                                        const dtQueryFilter& inDetourFilter, const PathFilter& inFilter);

/// The nearest wall within inMaxRadius of inPoint on inStart (not excluded), among the walls of the polygons
/// reached from inStart without crossing an excluded area or an off-mesh link.
Result<NavWall> FindWallAround(dtNavMeshQuery& inQuery, const dtNavMesh& inNavMesh, dtPolyRef inStart,
                               const Vec3& inPoint, float inMaxRadius, const dtQueryFilter& inDetourFilter,
                               const PathFilter& inFilter);

} // namespace cairn::navmesh
