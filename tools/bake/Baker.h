#pragma once

// Baker: the offline tile baker. Builds every tile that touches a level's geometry with the runtime's
// pipeline (a broad-phase query, GeometryCollector and TileBuilder) on a job system's threads, in the order
// of the sorted tile list with a few tiles per thread in flight. The level's objects (each a static mesh
// body, one per area when its materials map to several) are in the physics world only while a tile in flight
// is near them (LiveObjects), and a tile's triangles come in the order of their objects' keys, so each tile
// is built from the same inputs whatever the thread count or the shard: 1 and N threads give the same bytes,
// a shard (K of N) takes every N-th tile of the sorted list from the K-th on, and merged shards equal the
// full bake. Threads: Bake and BakeSource on one thread; each runs its own job system.

#include "BakeSummary.h"
#include "LevelSource.h"
#include "LinkCheck.h"
#include "cairn/navmesh/AgentProfile.h"
#include "cairn/navmesh/LevelMesh.h"
#include "cairn/navmesh/NavMeshFile.h"
#include "cairn/navmesh/TileBuilder.h"

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace cairn::bake
{
using namespace cairn::physics;

struct BakeSettings
{
    std::vector<std::string> mInputs; ///< OBJ and glTF (.gltf, .glb) files (Bake; BakeSource has its source)
    /// When set, tiles are written to this navmesh file as they are done (BakeResult::mNavMesh stays empty):
    /// the bake then holds only the tiles in flight
    std::string mOutputPath;
    /// With mOutputPath: false leaves the file complete under a temporary name in BakeResult::mOutput, for
    /// the caller to commit with its other outputs (all in place, or none)
    bool mCommitOutput = true;
    /// Bodies the bake's world holds at most (0: twice the objects one tile can have near it). Tiles wait to
    /// enter while their objects would not fit; a single tile with more objects near it is an error
    uint32_t mMaxBodiesInWorld = 0;
    navmesh::AgentProfile mProfile;
    navmesh::AreaMapping mAreas; ///< Area ids of material names
    /// Off-mesh links (LoadOffMeshLinks), each built into the tile its start lies in; a link with an end in
    /// no tile of the level is an error (it could never join the navmesh there)
    std::vector<navmesh::OffMeshLink> mLinks;
    navmesh::LevelLoadLimits mLoadLimits; ///< What the level files may make the loaders do (Bake)
    uint32_t mThreads = 0;                ///< 0: all cores
    uint32_t mShard = 0;                  ///< This shard (0-based) ...
    uint32_t mShardCount = 1;             ///< ... of this many
    /// Called after each tile with (tiles done, tiles in all), one call at a time; may be empty
    std::function<void(uint32_t, uint32_t)> mProgress;
    /// Incremental: the previous bake's summary and navmesh (both or neither). A tile whose input hash is
    /// unchanged takes its previous output instead of being built again
    const BakeSummary* mPrevious = nullptr;
    const navmesh::NavMeshFileContents* mPreviousNavMesh = nullptr;
    /// Only the level's tiles that overlap this box (x and z; y is ignored), when set
    std::optional<AABB> mRegion;
    /// Only these of the level's tiles, when not empty (with mRegion: those of them in the box). The navmesh
    /// parameters stay the whole level's, so partial bakes merge with others
    std::vector<navmesh::TileCoord> mTiles;
};

struct BakeResult
{
    navmesh::NavMeshFileContents mNavMesh; ///< Tiles with walkable polygons (none kept with mOutputPath)
    uint32_t mTilesWithPolygons = 0;
    uint32_t mTilesBaked = 0;   ///< This shard's tiles, empty ones included
    uint32_t mTilesInWorld = 0; ///< Of every shard
    uint64_t mPolygons = 0;
    uint64_t mBodies = 0; ///< Static bodies made (an object near tiles far apart in the list, several times)
    uint32_t mPeakBodies = 0; ///< Most bodies in the world at once (the objects near the tiles in flight)
    double mBakeMs = 0.0;     ///< Tiles only (loading excluded)
    double mLoadMs = 0.0;
    BakeSummary mSummary; ///< Per tile hashes, for the next incremental bake
    /// With mOutputPath and not mCommitOutput: the navmesh file, complete, to Commit into place
    std::unique_ptr<navmesh::NavMeshFileWriter> mOutput;
    /// The off-mesh links no agent can take (FindUnjoinedLinks): looked for when the bake holds every tile
    /// of the level (no shard, region or tile list; mLinksChecked), since a link's end may lie in the tile
    /// next to its start's. After a sharded bake, the merge looks
    std::vector<UnjoinedLink> mUnjoinedLinks;
    bool mLinksChecked = false;
};

/// Bakes the files of inSettings.mInputs. Errors: unreadable or malformed inputs (naming the file and line),
/// a world too large for the navmesh's reference bits (before baking), a bad shard.
Result<BakeResult> Bake(const BakeSettings& inSettings);

/// Bakes the level inSource gives (inSettings.mInputs is not used). Tiles go through in sorted order with a
/// few per thread in flight; the physics world holds only the objects near those, and with mOutputPath no
/// finished tile is held either: peak memory follows the tiles in flight, not the size of the level.
Result<BakeResult> BakeSource(const LevelSource& inSource, const BakeSettings& inSettings);

/// Combines shard outputs into one navmesh: the same parameters, no tile twice.
Result<navmesh::NavMeshFileContents> MergeShards(const std::vector<navmesh::NavMeshFileContents>& inShards);

} // namespace cairn::bake
