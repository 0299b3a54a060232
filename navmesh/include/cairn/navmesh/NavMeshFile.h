#pragma once

// NavMeshFile: a tiled navmesh on disk in the layout Recast's demo saves and loads (Sample_TileMesh's saveAll
// and loadAll), so that Detour-based runtimes load Cairn's bakes unchanged:
//   header: int32 magic 'MSET', int32 version 1, int32 tile count, dtNavMeshParams;
//   then per tile: dtTileRef (non-zero), int32 data size, the tile's Detour data.
// Raw structs in the machine's byte order, as the demo writes them (little-endian on x86-64 and ARM64).
// Tiles are written sorted by tile coordinate with the references a fresh dtNavMesh gives them in that order,
// so the same tiles always give the same bytes. Plain functions over plain data: any thread.

#include "cairn/navmesh/TileGrid.h"
#include "cairn/physics/math/Result.h"

#include <DetourNavMesh.h>
#include <memory>
#include <string>
#include <vector>

namespace cairn::navmesh
{

struct NavMeshFileTile
{
    TileCoord mTile;
    std::vector<unsigned char> mData; ///< Detour tile data as built (dtCreateNavMeshData)
};

struct NavMeshFileContents
{
    dtNavMeshParams mParams{};
    std::vector<NavMeshFileTile> mTiles; ///< Sorted by tile once saved or loaded
};

/// Detour's navmesh parameters for a tiled navmesh on inGrid: tile and polygon bits shared out of a 32-bit
/// polygon reference (10 bits of salt). Error when inMaxTiles leaves too few bits for polygons.
Result<dtNavMeshParams> MakeNavMeshParams(const TileGrid& inGrid, int inMaxTiles);

/// Writes inContents to inPath (through a temporary file renamed into place: no partial file on failure).
Status SaveNavMeshFile(const std::string& inPath, NavMeshFileContents inContents);
/// Reads a file written by SaveNavMeshFile or Recast's demo. Errors name the file and what is wrong.
Result<NavMeshFileContents> LoadNavMeshFile(const std::string& inPath);

struct DetourNavMeshDeleter
{
    void operator()(dtNavMesh* inNavMesh) const { dtFreeNavMesh(inNavMesh); }
};
using DetourNavMeshPtr = std::unique_ptr<dtNavMesh, DetourNavMeshDeleter>;
/// A dtNavMesh holding copies of the tiles, as a runtime would load it.
Result<DetourNavMeshPtr> CreateDetourNavMesh(const NavMeshFileContents& inContents);

} // namespace cairn::navmesh
