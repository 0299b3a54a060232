#pragma once

// TileBuilder: stage 3 of a tile job. Runs Recast over one tile's triangles (rasterise; filter low-hanging
// obstacles, ledges and low spans; compact; erode by the agent radius; regions; contours; polygon mesh;
// detail mesh) and makes Detour tile data. A pure function of its inputs: no locks, no shared state, so any
// number of tiles may be built at once on any threads.

#include "cairn/navmesh/AgentProfile.h"
#include "cairn/navmesh/TileGeometry.h"
#include "cairn/navmesh/TileGrid.h"

#include <memory>
#include <span>

namespace cairn::navmesh
{
using namespace cairn::physics;

/// Detour tile data (dtAlloc'ed), freed with dtFree by whoever holds it last (NavMeshWorld keeps the data of
/// the tiles it hands to Detour, and frees it after Detour lets go).
struct DetourFree
{
    void operator()(unsigned char* inData) const;
};
using TileDataPtr = std::unique_ptr<unsigned char, DetourFree>;

/// Polygon flags set on every navmesh polygon; path filters include or exclude them.
inline constexpr uint16_t cPolyFlagWalk = 1;

/// A link the navmesh cannot see in the geometry: a jump, a ladder, a drop. It belongs to the tile that holds
/// its start; Detour connects its end when the tile there is loaded.
struct OffMeshLink
{
    Vec3 mStart = Vec3::Zero();
    Vec3 mEnd = Vec3::Zero();
    float mRadius = 0.5f;       ///< m: how near the navmesh an end must be to connect
    bool mBidirectional = true; ///< False: from start to end only (a drop)
    uint8_t mArea = cDefaultArea;
    uint32_t mUserID = 0; ///< The game's id, kept with the link
};

struct BuiltTile
{
    TileCoord mTile;
    TileDataPtr mData; ///< Null when the tile has no walkable polygon (an empty tile)
    int mDataSize = 0;
    int mNumPolygons = 0;
    int mNumVertices = 0;
    double mBuildMs = 0.0; ///< Time spent in Recast and Detour
    /// m: the largest height difference between a polygon's detail surface (the height agents stand at) and
    /// the voxels of its walkable surface, over the cells it covers
    float mMaxDetailError = 0.0f;
    /// Polygons whose detail surface strayed more than the agent's climb from the voxels (Recast smooths
    /// steps inside a polygon into ramps, and two steps into a ramp deeper than a step) and were sampled
    /// again at a third of the detail sample distance (one cell at least), keeping the finer surface
    int mResampledPolygons = 0;
    int mRoughPolygons = 0; ///< Polygons whose surface still strays more than the climb after that
};

/// Error unless inProfile is valid (AgentProfile::Validate) and inGrid is a grid of its tiles: the profile's
/// tile size, a finite origin and height range, min y below max y. BuildTile and NavMeshWorld::Create both
/// check with it, so no tile is built on a grid the navmesh world would refuse.
Status ValidateProfileAndGrid(const AgentProfile& inProfile, const TileGrid& inGrid);

/// Builds tile inTile of inGrid from inGeometry (world space, covering at least the tile's bordered area) and
/// the off-mesh links whose start lies in the tile (others are ignored). Errors: invalid profile or grid
/// (ValidateProfileAndGrid), non-finite vertices or links, bad indices, or Recast running out of memory.
Result<BuiltTile> BuildTile(const AgentProfile& inProfile, const TileGrid& inGrid, const TileCoord& inTile,
                            const TileGeometry& inGeometry, std::span<const OffMeshLink> inLinks = {});

} // namespace cairn::navmesh
