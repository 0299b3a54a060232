#pragma once

// BakeSummary: what a bake produced, tile by tile, as JSON (nlohmann-json, Debian's nlohmann-json3-dev): the
// hash of each tile's input geometry (the triangles its build read, and the settings) and of its output data.
// The next bake compares input hashes to rebuild only the tiles whose geometry changed (incremental bakes).
// Hashes are FNV-1a 64 over the exact bytes, the same on every machine of the same byte order.
// Plain data and functions: any thread.

#include "cairn/navmesh/NavMeshFile.h"
#include "cairn/navmesh/TileGrid.h"
#include "cairn/physics/math/Result.h"

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace cairn::bake
{
using namespace cairn::physics;

/// FNV-1a, 64 bits, continuing from inHash.
uint64_t Hash64(std::span<const unsigned char> inBytes, uint64_t inHash = 14695981039346656037ull);
template <class T> uint64_t Hash64Of(std::span<const T> inValues, uint64_t inHash)
{
    return Hash64({reinterpret_cast<const unsigned char*>(inValues.data()), inValues.size_bytes()}, inHash);
}

struct TileRecord
{
    navmesh::TileCoord mTile;
    uint64_t mInputHash = 0;  ///< Triangles read, their areas, the tile and the settings
    uint64_t mOutputHash = 0; ///< Detour data (0 for a tile without polygons)
    int mPolygons = 0;
    uint32_t mBytes = 0;
};

struct BakeSummary
{
    std::vector<std::string> mInputs;
    uint32_t mShard = 0;
    uint32_t mShardCount = 1;
    uint32_t mTilesInWorld = 0;
    uint32_t mTilesRebuilt = 0; ///< Built this time (the others were taken over from the previous bake)
    uint64_t mPolygons = 0;
    double mBakeMs = 0.0;
    std::vector<TileRecord> mTiles; ///< This shard's tiles, sorted

    /// The previous record of inTile, or nullptr.
    const TileRecord* Find(const navmesh::TileCoord& inTile) const;
};

/// The summary as the JSON SaveBakeSummary writes.
std::string BakeSummaryToJson(const BakeSummary& inSummary);
/// Writes the summary as JSON (temporary file, then renamed).
Status SaveBakeSummary(const std::string& inPath, const BakeSummary& inSummary);
/// Reads a summary; errors name the file and the element that is wrong.
Result<BakeSummary> LoadBakeSummary(const std::string& inPath);

/// "K/N" (digits only, K < N) to (K, N); false when malformed.
bool ParseShard(const std::string& inText, uint32_t& outShard, uint32_t& outCount);

/// Ok when inSummaries are the summaries of shards 0 to N-1 of one bake, each once (N their shard count, all
/// the same and equal to the number of shards), and inShards[i] is the navmesh inSummaries[i] describes.
/// Errors: InvalidArgument naming the missing, repeated or mismatched shard.
Status CheckShardsComplete(const std::vector<BakeSummary>& inSummaries,
                           const std::vector<navmesh::NavMeshFileContents>& inShards);

/// Ok when inNavMesh holds exactly the tiles inSummary recorded with data, each with the output hash and
/// size recorded: an incremental bake must not take one level's summary with another level's navmesh.
/// Errors: InvalidArgument naming the first tile that differs.
Status CheckPreviousBake(const BakeSummary& inSummary, const navmesh::NavMeshFileContents& inNavMesh);

} // namespace cairn::bake
