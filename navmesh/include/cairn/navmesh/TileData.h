#pragma once

// TileData: what Detour needs checked before it reads a tile, and the navmesh parameters for a tile grid. The
// runtime checks every tile it publishes (NavMeshWorld) and the navmesh file reader every tile it loads
// (NavMeshFile), with the same checks. Plain functions over plain data: any thread.

#include "cairn/navmesh/TileGrid.h"
#include "cairn/physics/math/Result.h"

#include <DetourNavMesh.h>
#include <span>
#include <string>

namespace cairn::navmesh
{
using namespace cairn::physics;

/// Empty when inData is a Detour tile whose sections fit its size, whose indices stay inside their arrays and
/// whose coordinates are finite and within the world's range, else what is wrong. Detour's addTile trusts
/// the header's counts and the polygons' indices: a flipped bit in a file, or a corrupt tile handed to
/// NavMeshWorld, made it write and read outside the tile's buffer; and its path search never ends on the NaN
/// costs that non-finite coordinates give.
std::string CheckTileData(std::span<const unsigned char> inData);

/// The most tiles a navmesh may be made for: Detour allocates a tile record for each when it is created, so a
/// file's header must not choose more (2^20 records are about 120 MB).
inline constexpr int cMaxNavMeshTiles = 1 << 20;

/// Empty when Detour can hold a navmesh of inParams: an origin and tile size finite and within the world's
/// range, 1 to cMaxNavMeshTiles tiles, and tile and polygon bits that leave Detour its 10 bits of salt in a
/// 32-bit reference (Detour's own test wraps around for large counts and passes). Else what is wrong.
std::string CheckNavMeshParams(const dtNavMeshParams& inParams);

/// Empty when the tile inData (which passed CheckTileData) has no more polygons than inParams' polygon bits
/// hold: past them, a polygon index spills into the tile bits and names another tile's polygon.
std::string CheckTileFitsParams(std::span<const unsigned char> inData, const dtNavMeshParams& inParams);

/// Detour's navmesh parameters for a tiled navmesh on inGrid: tile and polygon bits shared out of a 32-bit
/// polygon reference (10 bits of salt). Error when inMaxTiles leaves too few bits for polygons.
Result<dtNavMeshParams> MakeNavMeshParams(const TileGrid& inGrid, int inMaxTiles);

} // namespace cairn::navmesh
