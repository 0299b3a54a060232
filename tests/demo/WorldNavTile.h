#pragma once

// A navmesh tile of the demo world built from the bodies of a physics world around it, as the tile
// scheduler's jobs build it: the broad-phase query of its bordered box, those bodies' triangles, Recast.

#include "cairn/navmesh/GeometryCollector.h"
#include "cairn/navmesh/TileBuilder.h"

#include <span>
#include <vector>

namespace cairn::demo
{

inline physics::Result<navmesh::BuiltTile>
BuildWorldNavTile(const navmesh::GeometryCollector& inCollector, const navmesh::AgentProfile& inProfile,
                  const navmesh::TileGrid& inGrid, const navmesh::TileCoord& inTile,
                  std::span<const navmesh::OffMeshLink> inLinks = {})
{
    const physics::AABB box =
        inGrid.GetTileBoundsWithBorder(inTile, float(inProfile.GetBorderCells()) * inProfile.mCellSize);
    std::vector<physics::BodyID> found;
    navmesh::TileGeometry geometry;
    navmesh::CollectStats stats;
    inCollector.FindBodies(box, {}, found);
    inCollector.CollectTriangles(box, {}, found, geometry, stats);
    return navmesh::BuildTile(inProfile, inGrid, inTile, geometry, inLinks);
}

} // namespace cairn::demo
