#include "cairn/navmesh/TileBuilder.h"

#include "DetailHeights.h"

#include <DetourAlloc.h>
#include <DetourNavMesh.h>
#include <DetourNavMeshBuilder.h>
#include <Recast.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

namespace cairn::navmesh
{
using namespace cairn::physics;

void DetourFree::operator()(unsigned char* inData) const
{
    dtFree(inData);
}

namespace
{
// Recast's intermediate results, freed whatever step fails
struct RecastScratch
{
    rcHeightfield* mSolid = nullptr;
    rcCompactHeightfield* mCompact = nullptr;
    rcContourSet* mContours = nullptr;
    rcPolyMesh* mPolyMesh = nullptr;
    rcPolyMeshDetail* mDetail = nullptr;
    rcPolyMesh* mRoughPolygons = nullptr;
    rcPolyMeshDetail* mFineDetail = nullptr;
    ~RecastScratch()
    {
        rcFreeHeightField(mSolid);
        rcFreeCompactHeightfield(mCompact);
        rcFreeContourSet(mContours);
        rcFreePolyMesh(mPolyMesh);
        rcFreePolyMeshDetail(mDetail);
        rcFreePolyMesh(mRoughPolygons);
        rcFreePolyMeshDetail(mFineDetail);
    }
};

Error RecastFailed(const TileCoord& inTile, const char* inStep)
{
    return MakeError(ErrorCode::OutOfCapacity, std::string("tile (") + std::to_string(inTile.mX) + ", " +
                                                   std::to_string(inTile.mZ) + "): Recast failed to " +
                                                   inStep);
}

/// Cairn area id to Recast's: the default ground is Recast's walkable area, the others keep their id.
unsigned char ToRecastArea(uint8_t inArea)
{
    return inArea == cDefaultArea ? RC_WALKABLE_AREA : inArea;
}
} // namespace

Status ValidateProfileAndGrid(const AgentProfile& inProfile, const TileGrid& inGrid)
{
    if (Status valid = inProfile.Validate(); !valid) return valid;
    // The grid's tiles are the profile's: a different size would misplace every tile built with the profile
    if (!(inGrid.GetTileSize() == inProfile.mTileSize))
        return MakeError(ErrorCode::InvalidArgument, "navmesh: the tile grid's tile size (" +
                                                         std::to_string(inGrid.GetTileSize()) +
                                                         " m) is not the agent profile's (" +
                                                         std::to_string(inProfile.mTileSize) + " m)");
    // A NaN origin puts every tile nowhere, and an empty height range rasterises nothing
    if (!std::isfinite(inGrid.GetOriginX()) || !std::isfinite(inGrid.GetOriginZ()) ||
        !std::isfinite(inGrid.GetMinY()) || !std::isfinite(inGrid.GetMaxY()) ||
        !(inGrid.GetMinY() < inGrid.GetMaxY()))
        return MakeError(
            ErrorCode::InvalidArgument,
            "navmesh: the tile grid's origin and height range must be finite, min y below max y");
    // Recast keeps a span's top in RC_SPAN_HEIGHT_BITS bits of cells: a taller range clamps every floor above
    // it to that height, a navmesh that builds without a word and stands where nothing is
    const float maxRange = float(RC_SPAN_MAX_HEIGHT) * inProfile.mCellHeight;
    if (!(inGrid.GetMaxY() - inGrid.GetMinY() <= maxRange))
        return MakeError(ErrorCode::InvalidArgument, "navmesh: the tile grid's height range (" +
                                                         std::to_string(inGrid.GetMaxY() - inGrid.GetMinY()) +
                                                         " m) is over the " + std::to_string(maxRange) +
                                                         " m that Recast's spans hold at a cell height of " +
                                                         std::to_string(inProfile.mCellHeight) + " m");
    return Status::Ok();
}

Result<BuiltTile> BuildTile(const AgentProfile& inProfile, const TileGrid& inGrid, const TileCoord& inTile,
                            const TileGeometry& inGeometry, std::span<const OffMeshLink> inLinks)
{
    if (Status valid = ValidateProfileAndGrid(inProfile, inGrid); !valid) return valid.GetError();
    const int numVertices = inGeometry.GetNumVertices(), numTriangles = inGeometry.GetNumTriangles();
    if (inGeometry.mTriangles.size() % 3 != 0 || inGeometry.mAreas.size() != size_t(numTriangles))
        return MakeError(ErrorCode::InvalidArgument, "tile geometry: one area per triangle of 3 indices");
    for (float v : inGeometry.mVertices)
        if (!std::isfinite(v) || std::abs(v) > cMaxWorldCoordinate)
            return MakeError(ErrorCode::InvalidArgument,
                             "tile geometry: a vertex is not finite or out of range");
    for (int index : inGeometry.mTriangles)
        if (index < 0 || index >= numVertices)
            return MakeError(ErrorCode::InvalidArgument, "tile geometry: a triangle index is out of range");
    for (uint8_t area : inGeometry.mAreas)
        if (area > cMaxAreaId)
            return MakeError(ErrorCode::InvalidArgument, "tile geometry: an area id is above cMaxAreaId");
    // The links that start in this tile, in Detour's layout
    std::vector<float> linkVerts, linkRadii;
    std::vector<unsigned char> linkDirections, linkAreas;
    std::vector<unsigned short> linkFlags;
    std::vector<unsigned int> linkIDs;
    for (const OffMeshLink& link : inLinks)
    {
        if (!IsValidWorldPosition(link.mStart) || !IsValidWorldPosition(link.mEnd) ||
            !std::isfinite(link.mRadius) || link.mRadius <= 0.0f || link.mArea > cMaxAreaId)
            return MakeError(ErrorCode::InvalidArgument, "off-mesh link: bad end points, radius or area");
        if (inGrid.TileAt(link.mStart.x(), link.mStart.z()) != inTile) continue;
        linkVerts.insert(linkVerts.end(), {link.mStart.x(), link.mStart.y(), link.mStart.z(), link.mEnd.x(),
                                           link.mEnd.y(), link.mEnd.z()});
        linkRadii.push_back(link.mRadius);
        linkDirections.push_back(link.mBidirectional ? DT_OFFMESH_CON_BIDIR : 0);
        linkAreas.push_back(ToRecastArea(link.mArea));
        linkFlags.push_back(cPolyFlagWalk);
        linkIDs.push_back(link.mUserID);
    }

    const auto start = std::chrono::steady_clock::now();
    BuiltTile result;
    result.mTile = inTile;
    const AABB bounds = inGrid.GetTileBounds(inTile);
    const float tileMin[3] = {bounds.mMin.x(), bounds.mMin.y(), bounds.mMin.z()};
    const float tileMax[3] = {bounds.mMax.x(), bounds.mMax.y(), bounds.mMax.z()};
    rcConfig config;
    inProfile.ToRecastConfig(tileMin, tileMax, config);

    rcContext context(false); // No logging or timers: they are not thread-safe to share, and cost time
    RecastScratch scratch;

    // Rasterise: triangles steep than the slope stay unwalkable; walkable ones take their body's area
    scratch.mSolid = rcAllocHeightfield();
    if (scratch.mSolid == nullptr ||
        !rcCreateHeightfield(&context, *scratch.mSolid, config.width, config.height, config.bmin, config.bmax,
                             config.cs, config.ch))
        return RecastFailed(inTile, "allocate the heightfield");
    std::vector<unsigned char> areas(size_t(numTriangles), 0);
    rcMarkWalkableTriangles(&context, config.walkableSlopeAngle, inGeometry.mVertices.data(), numVertices,
                            inGeometry.mTriangles.data(), numTriangles, areas.data());
    for (int i = 0; i < numTriangles; ++i)
        if (areas[size_t(i)] != RC_NULL_AREA) areas[size_t(i)] = ToRecastArea(inGeometry.mAreas[size_t(i)]);
    if (!rcRasterizeTriangles(&context, inGeometry.mVertices.data(), numVertices,
                              inGeometry.mTriangles.data(), areas.data(), numTriangles, *scratch.mSolid,
                              config.walkableClimb))
        return RecastFailed(inTile, "rasterise the triangles");

    // Filter: what a walking agent could not stand on
    rcFilterLowHangingWalkableObstacles(&context, config.walkableClimb, *scratch.mSolid);
    rcFilterLedgeSpans(&context, config.walkableHeight, config.walkableClimb, *scratch.mSolid);
    rcFilterWalkableLowHeightSpans(&context, config.walkableHeight, *scratch.mSolid);

    // Compact and erode by the agent radius
    scratch.mCompact = rcAllocCompactHeightfield();
    if (scratch.mCompact == nullptr ||
        !rcBuildCompactHeightfield(&context, config.walkableHeight, config.walkableClimb, *scratch.mSolid,
                                   *scratch.mCompact))
        return RecastFailed(inTile, "build the compact heightfield");
    rcFreeHeightField(scratch.mSolid);
    scratch.mSolid = nullptr;
    if (!rcErodeWalkableArea(&context, config.walkableRadius, *scratch.mCompact))
        return RecastFailed(inTile, "erode the walkable area");

    // Regions
    switch (inProfile.mPartition)
    {
    case RegionPartition::Watershed:
        if (!rcBuildDistanceField(&context, *scratch.mCompact) ||
            !rcBuildRegions(&context, *scratch.mCompact, config.borderSize, config.minRegionArea,
                            config.mergeRegionArea))
            return RecastFailed(inTile, "build watershed regions");
        break;
    case RegionPartition::Monotone:
        if (!rcBuildRegionsMonotone(&context, *scratch.mCompact, config.borderSize, config.minRegionArea,
                                    config.mergeRegionArea))
            return RecastFailed(inTile, "build monotone regions");
        break;
    case RegionPartition::Layers:
        if (!rcBuildLayerRegions(&context, *scratch.mCompact, config.borderSize, config.minRegionArea))
            return RecastFailed(inTile, "build layer regions");
        break;
    }

    // Contours, polygons, detail
    scratch.mContours = rcAllocContourSet();
    if (scratch.mContours == nullptr ||
        !rcBuildContours(&context, *scratch.mCompact, config.maxSimplificationError, config.maxEdgeLen,
                         *scratch.mContours))
        return RecastFailed(inTile, "build contours");
    if (scratch.mContours->nconts == 0)
    {
        result.mBuildMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        return result; // Nothing walkable: an empty tile
    }
    scratch.mPolyMesh = rcAllocPolyMesh();
    if (scratch.mPolyMesh == nullptr ||
        !rcBuildPolyMesh(&context, *scratch.mContours, config.maxVertsPerPoly, *scratch.mPolyMesh))
        return RecastFailed(inTile, "build the polygon mesh");
    scratch.mDetail = rcAllocPolyMeshDetail();
    if (scratch.mDetail == nullptr ||
        !rcBuildPolyMeshDetail(&context, *scratch.mPolyMesh, *scratch.mCompact, config.detailSampleDist,
                               config.detailSampleMaxError, *scratch.mDetail))
        return RecastFailed(inTile, "build the detail mesh");

    rcPolyMesh& mesh = *scratch.mPolyMesh;
    // Polygons whose detail surface strays more than a step from the voxels are sampled again, finer
    DetailMeshArrays merged;
    std::vector<float> errors = MeasureDetailErrors(mesh, *scratch.mDetail, *scratch.mCompact);
    const auto overClimb = [&](float inError) { return inError > inProfile.mMaxClimb; };
    std::vector<int> rough;
    for (int p = 0; p < int(errors.size()); ++p)
        if (overClimb(errors[size_t(p)])) rough.push_back(p);
    if (config.detailSampleDist > 0.0f && !rough.empty())
    {
        const float fineDistance = std::max(config.cs, config.detailSampleDist / 3.0f);
        scratch.mRoughPolygons = CopyPolygons(mesh, rough);
        scratch.mFineDetail = rcAllocPolyMeshDetail();
        if (scratch.mRoughPolygons == nullptr || scratch.mFineDetail == nullptr ||
            !rcBuildPolyMeshDetail(&context, *scratch.mRoughPolygons, *scratch.mCompact, fineDistance,
                                   config.detailSampleMaxError, *scratch.mFineDetail))
            return RecastFailed(inTile, "build the fine detail mesh");
        const std::vector<float> fineErrors =
            MeasureDetailErrors(*scratch.mRoughPolygons, *scratch.mFineDetail, *scratch.mCompact);
        merged = MergeDetailMeshes(*scratch.mDetail, errors, *scratch.mFineDetail, fineErrors, rough,
                                   result.mResampledPolygons);
    }
    result.mRoughPolygons = int(std::count_if(errors.begin(), errors.end(), overClimb));
    result.mMaxDetailError = errors.empty() ? 0.0f : *std::max_element(errors.begin(), errors.end());
    result.mNumPolygons = mesh.npolys;
    result.mNumVertices = mesh.nverts;
    if (mesh.npolys == 0 || mesh.nverts == 0)
    {
        result.mBuildMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        return result;
    }
    if (config.maxVertsPerPoly > DT_VERTS_PER_POLYGON || mesh.nverts >= 0xffff)
        return MakeError(ErrorCode::OutOfCapacity, "tile has too many vertices for Detour (65535 at most)");
    for (int i = 0; i < mesh.npolys; ++i)
        mesh.flags[i] = mesh.areas[i] != RC_NULL_AREA ? cPolyFlagWalk : 0;

    dtNavMeshCreateParams params{};
    params.verts = mesh.verts;
    params.vertCount = mesh.nverts;
    params.polys = mesh.polys;
    params.polyAreas = mesh.areas;
    params.polyFlags = mesh.flags;
    params.polyCount = mesh.npolys;
    params.nvp = mesh.nvp;
    if (merged.mMeshes.empty())
    {
        params.detailMeshes = scratch.mDetail->meshes;
        params.detailVerts = scratch.mDetail->verts;
        params.detailVertsCount = scratch.mDetail->nverts;
        params.detailTris = scratch.mDetail->tris;
        params.detailTriCount = scratch.mDetail->ntris;
    }
    else
    {
        params.detailMeshes = merged.mMeshes.data();
        params.detailVerts = merged.mVerts.data();
        params.detailVertsCount = int(merged.mVerts.size() / 3);
        params.detailTris = merged.mTris.data();
        params.detailTriCount = int(merged.mTris.size() / 4);
    }
    params.offMeshConVerts = linkVerts.data();
    params.offMeshConRad = linkRadii.data();
    params.offMeshConDir = linkDirections.data();
    params.offMeshConAreas = linkAreas.data();
    params.offMeshConFlags = linkFlags.data();
    params.offMeshConUserID = linkIDs.data();
    params.offMeshConCount = int(linkRadii.size());
    params.walkableHeight = inProfile.mHeight;
    params.walkableRadius = inProfile.mRadius;
    params.walkableClimb = inProfile.mMaxClimb;
    params.tileX = inTile.mX;
    params.tileY = inTile.mZ;
    params.tileLayer = 0;
    rcVcopy(params.bmin, mesh.bmin);
    rcVcopy(params.bmax, mesh.bmax);
    params.cs = config.cs;
    params.ch = config.ch;
    params.buildBvTree = true;
    unsigned char* data = nullptr;
    int size = 0;
    if (!dtCreateNavMeshData(&params, &data, &size))
        return RecastFailed(inTile, "create the Detour tile data");
    result.mData.reset(data);
    result.mDataSize = size;
    result.mBuildMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return result;
}

} // namespace cairn::navmesh
