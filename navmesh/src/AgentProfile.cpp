#include "cairn/navmesh/AgentProfile.h"

#include <Recast.h>
#include <cmath>
#include <cstring>
#include <string>

namespace cairn::navmesh
{
using namespace cairn::physics;

Status AgentProfile::Validate() const
{
    auto positive = [](float inValue) { return std::isfinite(inValue) && inValue > 0.0f; };
    if (!positive(mHeight) || !positive(mRadius) || !positive(mCellSize) || !positive(mCellHeight) ||
        !positive(mTileSize))
        return MakeError(ErrorCode::InvalidArgument,
                         "agent profile: height, radius, cell size, cell height and tile size must be > 0");
    if (!std::isfinite(mMaxClimb) || mMaxClimb < 0.0f)
        return MakeError(ErrorCode::InvalidArgument, "agent profile: max climb must be >= 0");
    if (!std::isfinite(mMaxSlopeDegrees) || mMaxSlopeDegrees < 0.0f || mMaxSlopeDegrees >= 90.0f)
        return MakeError(ErrorCode::InvalidArgument, "agent profile: max slope must be in [0, 90) degrees");
    const float cells = mTileSize / mCellSize;
    if (std::abs(cells - std::round(cells)) > 1.0e-3f || std::round(cells) < 8.0f ||
        std::round(cells) > 4096.0f)
        return MakeError(ErrorCode::InvalidArgument,
                         "agent profile: tile size must be a whole number (8 to 4096) "
                         "of cells, not " +
                             std::to_string(cells));
    if (mMaxVertsPerPoly < 3 || mMaxVertsPerPoly > 6)
        return MakeError(ErrorCode::InvalidArgument,
                         "agent profile: max vertices per polygon must be 3 to 6");
    // Upper bounds too: Recast takes these as ints of cells (a radius of 1e9 m, or an infinite region size,
    // overflowed them and silently built every tile empty)
    auto inRange = [](float inValue, float inMax)
    { return std::isfinite(inValue) && inValue >= 0.0f && inValue <= inMax; };
    if (!inRange(mHeight, 1e3f) || !inRange(mRadius, 1e3f) || !inRange(mMaxClimb, 1e3f))
        return MakeError(ErrorCode::InvalidArgument,
                         "agent profile: height, radius and max climb must be at most 1000 m");
    // A tile's build covers the tile and a border of the agent's radius around it: a radius beyond the tile
    // made each tile's voxels grow with the radius squared (1000 m took 2.3 GB for a 60 m level)
    if (mRadius > mTileSize)
        return MakeError(ErrorCode::InvalidArgument,
                         "agent profile: the agent radius (" + std::to_string(mRadius) +
                             " m) must be at most the tile size (" + std::to_string(mTileSize) + " m)");
    if (!inRange(mCellSize, 1e3f) || !inRange(mCellHeight, 1e3f) || mHeight / mCellHeight > 1e6f ||
        mRadius / mCellSize > 1e6f || mMaxClimb / mCellHeight > 1e6f)
        return MakeError(ErrorCode::InvalidArgument,
                         "agent profile: cells too small for the agent (over a million cells across it)");
    if (!inRange(mRegionMinSize, 1e4f) || !inRange(mRegionMergeSize, 1e4f) ||
        !inRange(mEdgeMaxLength, 1e6f) || !inRange(mEdgeMaxError, 1e6f) ||
        !inRange(mDetailSampleDistance, 1e6f) || !inRange(mDetailSampleMaxError, 1e6f))
        return MakeError(ErrorCode::InvalidArgument,
                         "agent profile: region, edge and detail settings must be finite, >= 0 and not huge "
                         "(region sizes up to 1e4 cells, the others up to 1e6)");
    return Status::Ok();
}

int AgentProfile::GetTileCells() const
{
    return int(std::lround(mTileSize / mCellSize));
}

int AgentProfile::GetBorderCells() const
{
    // Recast's rule (Sample_TileMesh): the agent radius eroded from the border, plus 3 cells of margin
    return int(std::ceil(mRadius / mCellSize)) + 3;
}

void AgentProfile::ToRecastConfig(const float inMin[3], const float inMax[3], rcConfig& outConfig) const
{
    // As Recast's Sample_TileMesh::buildTileMesh sets it up, so that tiles built here match its tiles
    rcConfig& c = outConfig;
    std::memset(&c, 0, sizeof(c));
    c.cs = mCellSize;
    c.ch = mCellHeight;
    c.walkableSlopeAngle = mMaxSlopeDegrees;
    c.walkableHeight = int(std::ceil(mHeight / c.ch));
    c.walkableClimb = int(std::floor(mMaxClimb / c.ch));
    c.walkableRadius = int(std::ceil(mRadius / c.cs));
    c.maxEdgeLen = int(mEdgeMaxLength / mCellSize);
    c.maxSimplificationError = mEdgeMaxError;
    c.minRegionArea = int(rcSqr(mRegionMinSize));
    c.mergeRegionArea = int(rcSqr(mRegionMergeSize));
    c.maxVertsPerPoly = mMaxVertsPerPoly;
    c.tileSize = GetTileCells();
    c.borderSize = c.walkableRadius + 3;
    c.width = c.tileSize + c.borderSize * 2;
    c.height = c.tileSize + c.borderSize * 2;
    c.detailSampleDist = mDetailSampleDistance < 0.9f ? 0.0f : mCellSize * mDetailSampleDistance;
    c.detailSampleMaxError = mCellHeight * mDetailSampleMaxError;
    rcVcopy(c.bmin, inMin);
    rcVcopy(c.bmax, inMax);
    c.bmin[0] -= float(c.borderSize) * c.cs;
    c.bmin[2] -= float(c.borderSize) * c.cs;
    c.bmax[0] += float(c.borderSize) * c.cs;
    c.bmax[2] += float(c.borderSize) * c.cs;
}

} // namespace cairn::navmesh
