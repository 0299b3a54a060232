#pragma once

// NavMeshFile: a tiled navmesh on disk in the layout Recast's demo saves and loads (Sample_TileMesh's saveAll
// and loadAll), so that Detour-based runtimes load Cairn's bakes unchanged:
//   header: int32 magic 'MSET', int32 version 1, int32 tile count, dtNavMeshParams;
//   then per tile: dtTileRef (non-zero), int32 data size, the tile's Detour data.
// Raw structs in the machine's byte order, as the demo writes them (little-endian on x86-64 and ARM64).
// Tiles are written sorted by tile coordinate with the references a fresh dtNavMesh gives them in that order,
// so the same tiles always give the same bytes. Plain functions over plain data: any thread.

#include "cairn/navmesh/PendingFile.h"
#include "cairn/navmesh/TileData.h"
#include "cairn/navmesh/TileGrid.h"
#include "cairn/physics/math/Result.h"

#include <DetourNavMesh.h>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace cairn::navmesh
{
using namespace cairn::physics;

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

struct DetourNavMeshDeleter
{
    void operator()(dtNavMesh* inNavMesh) const { dtFreeNavMesh(inNavMesh); }
};
using DetourNavMeshPtr = std::unique_ptr<dtNavMesh, DetourNavMeshDeleter>;

/// Writes a navmesh file tile by tile, holding none of them (a bake larger than memory streams its tiles
/// through it); the same bytes as SaveNavMeshFile when given the same tiles. Tiles must come in sorted order.
/// To a temporary file that Finish renames into place; destroyed unfinished, it leaves nothing behind. One
/// thread.
class NavMeshFileWriter
{
public:
    /// Errors: invalid parameters, the temporary file cannot be created.
    static Result<std::unique_ptr<NavMeshFileWriter>> Create(const std::string& inPath,
                                                             const dtNavMeshParams& inParams);
    ~NavMeshFileWriter();

    /// Errors: a tile out of order, more than the parameters' maxTiles, data that is not a Detour tile at
    /// inTile.
    Status Add(const TileCoord& inTile, std::span<const unsigned char> inData);
    /// Writes the tile count and closes the temporary file, complete but not yet in place.
    Status Complete();
    /// Completes (if not yet) and renames the file into place.
    Status Commit();
    /// Complete and Commit.
    Status Finish() { return Commit(); }
    /// Where the file is until Commit: to read it back first.
    const std::string& GetTemporaryPath() const { return mFile.GetTemporaryPath(); }

private:
    NavMeshFileWriter(std::string inPath, const dtNavMeshParams& inParams);

    std::string mPath;
    dtNavMeshParams mParams;
    DetourNavMeshPtr mLayout; ///< Only encodes the tiles' references
    PendingFile mFile;
    int32_t mNumTiles = 0;
    TileCoord mLastTile;
    bool mCompleted = false;
};

/// Writes inContents to inPath (through a temporary file renamed into place: no partial file on failure).
Status SaveNavMeshFile(const std::string& inPath, NavMeshFileContents inContents);
/// Reads a file written by SaveNavMeshFile or Recast's demo. Errors name the file and what is wrong: bad
/// parameters (CheckNavMeshParams), counts and sizes beyond the file's bytes (checked before anything is
/// allocated for them), a tile CheckTileData refuses, two tiles at one place, bytes after the last tile.
Result<NavMeshFileContents> LoadNavMeshFile(const std::string& inPath);

/// A dtNavMesh holding copies of the tiles, as a runtime would load it.
Result<DetourNavMeshPtr> CreateDetourNavMesh(const NavMeshFileContents& inContents);

} // namespace cairn::navmesh
