#pragma once

// Baker: the offline tile baker. Loads level meshes into a physics world (each object a static mesh body, one
// per area when its materials map to several),
// then builds every tile that touches the geometry with the runtime's pipeline (GeometryCollector and
// TileBuilder), spread over a job system's threads, and returns the tiles in the navmesh file layout. Each
// tile is built alone from the same inputs, so the result is the same whatever the thread count; a shard
// (K of N) takes every N-th tile of the sorted list from the K-th on, and merged shards equal the full bake.
// Threads: Bake on one thread; it runs its own job system.

#include "BakeSummary.h"
#include "cairn/navmesh/AgentProfile.h"
#include "cairn/navmesh/NavMeshFile.h"
#include "cairn/navmesh/ObjMesh.h"

#include <functional>
#include <string>
#include <vector>

namespace cairn::bake
{

struct BakeSettings
{
    std::vector<std::string> mInputs; ///< OBJ and glTF (.gltf, .glb) files
    navmesh::AgentProfile mProfile;
    navmesh::AreaMapping mAreas; ///< Area ids of material names
    uint32_t mThreads = 0;       ///< 0: all cores
    uint32_t mShard = 0;         ///< This shard (0-based) ...
    uint32_t mShardCount = 1;    ///< ... of this many
    /// Called after each tile with (tiles done, tiles in all), one call at a time; may be empty
    std::function<void(uint32_t, uint32_t)> mProgress;
    /// Incremental: the previous bake's summary and navmesh (both or neither). A tile whose input hash is
    /// unchanged takes its previous output instead of being built again
    const BakeSummary* mPrevious = nullptr;
    const navmesh::NavMeshFileContents* mPreviousNavMesh = nullptr;
};

struct BakeResult
{
    navmesh::NavMeshFileContents mNavMesh; ///< Tiles with walkable polygons
    uint32_t mTilesBaked = 0;              ///< This shard's tiles, empty ones included
    uint32_t mTilesInWorld = 0;            ///< Of every shard
    uint64_t mPolygons = 0;
    uint32_t mBodies = 0; ///< Static bodies made from the inputs' objects
    double mBakeMs = 0.0; ///< Tiles only (loading excluded)
    double mLoadMs = 0.0;
    BakeSummary mSummary; ///< Per tile hashes, for the next incremental bake
};

/// Errors: unreadable or malformed inputs (naming the file and line), a world too large for the navmesh's
/// reference bits (before baking), a bad shard.
Result<BakeResult> Bake(const BakeSettings& inSettings);

/// Combines shard outputs into one navmesh: the same parameters, no tile twice.
Result<navmesh::NavMeshFileContents> MergeShards(const std::vector<navmesh::NavMeshFileContents>& inShards);

} // namespace cairn::bake
