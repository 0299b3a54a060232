#pragma once

// Previews of a Detour navmesh for people: the walkable surface as a Wavefront OBJ (the detail triangles of
// every polygon, to load next to the level in any 3D viewer), and a top-down SVG map (polygons coloured by
// area, tile borders, off-mesh links as arrows). Plain functions on a navmesh that no thread changes while
// they run (NavMeshWorld holds its lock around them).

#include <DetourNavMesh.h>
#include <string>

namespace cairn::navmesh
{

/// Every polygon's detail triangles, one OBJ object per tile ("o tile_x_z"), vertices in world space.
std::string NavMeshToObj(const dtNavMesh& inNavMesh);

struct SvgPreviewSettings
{
    float mMaxPixels = 1600.0f; ///< The longer side of the picture
    bool mTileBorders = true;
};

/// A top-down map: x to the right, z downwards (as a level editor's top view), one colour per area id with a
/// legend, polygon outlines, tile borders and off-mesh links. An empty navmesh gives a small empty picture.
std::string NavMeshToSvg(const dtNavMesh& inNavMesh, const SvgPreviewSettings& inSettings = {});

} // namespace cairn::navmesh
