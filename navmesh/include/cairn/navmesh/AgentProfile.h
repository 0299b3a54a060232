#pragma once

// AgentProfile: who walks the navmesh and how finely it is sampled, in metres and degrees, plus the Recast
// settings derived from it. Defaults: a human-sized agent (2 m tall, 0.6 m wide radius, steps of 0.9 m,
// slopes up to 45 degrees) on 0.2 m cells, so a 12.8 m tile is 64 cells across. Plain value type.

#include "cairn/physics/math/Result.h"

#include <cstdint>

struct rcConfig;

namespace cairn::navmesh
{
using namespace cairn::physics;

/// How Recast splits the walkable area into regions (see Recast's Sample_TileMesh for the trade-offs).
enum class RegionPartition : uint8_t
{
    Watershed, ///< Best polygons; the slowest
    Monotone,  ///< Fastest; long thin polygons
    Layers,    ///< Good for tiles with overlapping floors; no holes artefacts
};

struct AgentProfile
{
    float mHeight = 2.0f;           ///< m: headroom the agent needs
    float mRadius = 0.6f;           ///< m: walkable area keeps this far from walls
    float mMaxClimb = 0.9f;         ///< m: highest step the agent climbs
    float mMaxSlopeDegrees = 45.0f; ///< Steepest walkable slope
    float mCellSize = 0.2f;         ///< m: horizontal voxel size
    float mCellHeight = 0.2f;       ///< m: vertical voxel size
    float mTileSize = 12.8f;        ///< m: a tile's side (a whole number of cells)
    RegionPartition mPartition = RegionPartition::Watershed;
    float mRegionMinSize = 8.0f;        ///< Cells (side of a square): smaller isolated regions are dropped
    float mRegionMergeSize = 20.0f;     ///< Cells (side of a square): smaller regions merge into neighbours
    float mEdgeMaxLength = 12.0f;       ///< m: longest polygon edge along a wall
    float mEdgeMaxError = 1.3f;         ///< Cells: how far a contour may stray from the wall it follows
    int mMaxVertsPerPoly = 6;           ///< 3 to 6 (Detour's limit)
    float mDetailSampleDistance = 6.0f; ///< Cells: detail mesh sampling (0: no detail heights)
    float mDetailSampleMaxError = 1.0f; ///< Cells: largest height error of the detail mesh

    /// Checks ranges (positive sizes, slope below 90 degrees, tile a whole number of cells...).
    Status Validate() const;
    /// Cells across one tile.
    int GetTileCells() const;
    /// Cells of border around a tile's own area, so that its edges match its neighbours'.
    int GetBorderCells() const;
    /// Recast's configuration for a tile whose own area (border excluded) spans inMin to inMax.
    void ToRecastConfig(const float inMin[3], const float inMax[3], rcConfig& outConfig) const;
};

} // namespace cairn::navmesh
