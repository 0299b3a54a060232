#include "Baker.h"

#include "LiveObjects.h"
#include "cairn/jobs/JobSystem.h"
#include "cairn/navmesh/GeometryCollector.h"
#include "cairn/navmesh/TileBuilder.h"
#include "cairn/physics/PhysicsSystem.h"
#include "common/FrameTimes.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <deque>
#include <map>
#include <optional>

namespace cairn::bake
{
using namespace cairn::physics;

namespace
{
using Clock = std::chrono::steady_clock;
using tools::MillisecondsSince;

/// Everything besides the triangles that decides a tile's output: the settings and the grid's height range.
uint64_t SettingsHash(const navmesh::AgentProfile& inProfile, const navmesh::TileGrid& inGrid)
{
    const navmesh::AgentProfile& p = inProfile;
    const float values[] = {p.mHeight,
                            p.mRadius,
                            p.mMaxClimb,
                            p.mMaxSlopeDegrees,
                            p.mCellSize,
                            p.mCellHeight,
                            p.mTileSize,
                            p.mRegionMinSize,
                            p.mRegionMergeSize,
                            p.mEdgeMaxLength,
                            p.mEdgeMaxError,
                            float(p.mMaxVertsPerPoly),
                            p.mDetailSampleDistance,
                            p.mDetailSampleMaxError,
                            float(int(p.mPartition)),
                            inGrid.GetTileBounds({0, 0}).mMin.y(),
                            inGrid.GetTileBounds({0, 0}).mMax.y()};
    return Hash64Of(std::span<const float>(values), Hash64({}));
}

/// A tile in flight: entered (its objects' bodies held) by the main thread, built by a job, then written out
/// and left, in the order of the sorted tile list.
struct TileInFlight
{
    navmesh::TileCoord mTile;
    std::vector<TileObject> mObjects; ///< In key order: the order its triangles are read in
    jobs::JobHandle mJob;
    // Written by the job, read by the main thread after Wait
    TileRecord mRecord;
    std::optional<Result<navmesh::BuiltTile>> mBuilt; ///< Empty when taken over from the previous bake
    const navmesh::NavMeshFileTile* mReused = nullptr;
};

/// What the tile jobs share (read only while they run).
struct TileJobContext
{
    const BakeSettings* mSettings;
    const navmesh::TileGrid* mGrid;
    const navmesh::GeometryCollector* mCollector;
    float mBorder;
    uint64_t mSettingsHash;
    const std::map<navmesh::TileCoord, std::vector<navmesh::OffMeshLink>>* mLinks; ///< By their start's tile
};

/// inHash with the links added: what a link decides of its tile's output.
uint64_t HashLinks(std::span<const navmesh::OffMeshLink> inLinks, uint64_t inHash)
{
    for (const navmesh::OffMeshLink& link : inLinks)
    {
        const float numbers[] = {link.mStart.x(), link.mStart.y(), link.mStart.z(), link.mEnd.x(),
                                 link.mEnd.y(),   link.mEnd.z(),   link.mRadius};
        const uint32_t words[] = {uint32_t(link.mBidirectional), link.mArea, link.mUserID};
        inHash = Hash64Of(std::span<const float>(numbers), inHash);
        inHash = Hash64Of(std::span<const uint32_t>(words), inHash);
    }
    return inHash;
}

/// Links that never join the navmesh: an end in no tile of the level (inTiles, sorted), or an end more than
/// a tile from the start's tile (Detour joins a link's end in its start's tile and the eight around it only).
/// An error naming the first. Either end's tile is the one its x and z fall in.
Status CheckLinksInLevel(std::span<const navmesh::OffMeshLink> inLinks, const navmesh::TileGrid& inGrid,
                         const std::vector<navmesh::TileCoord>& inTiles)
{
    for (size_t i = 0; i < inLinks.size(); ++i)
    {
        if (!navmesh::TileGrid::AreNeighbours(inGrid.TileAt(inLinks[i].mStart.x(), inLinks[i].mStart.z()),
                                              inGrid.TileAt(inLinks[i].mEnd.x(), inLinks[i].mEnd.z())))
            return MakeError(ErrorCode::InvalidArgument, "off-mesh link " + std::to_string(i) +
                                                             ": its end is more than a tile from its start's "
                                                             "tile, where Detour never joins it");
        for (const bool start : {true, false})
        {
            const Vec3& end = start ? inLinks[i].mStart : inLinks[i].mEnd;
            if (!std::binary_search(inTiles.begin(), inTiles.end(), inGrid.TileAt(end.x(), end.z())))
                return MakeError(ErrorCode::InvalidArgument,
                                 "off-mesh link " + std::to_string(i) + ": its " + (start ? "start" : "end") +
                                     " (" + std::to_string(end.x()) + ", " + std::to_string(end.z()) +
                                     ") is in no tile of the level");
        }
    }
    return Status::Ok();
}

const navmesh::NavMeshFileTile* FindPreviousTile(const navmesh::NavMeshFileContents& inPrevious,
                                                 const navmesh::TileCoord& inTile)
{
    auto it = std::lower_bound(inPrevious.mTiles.begin(), inPrevious.mTiles.end(), inTile,
                               [](const navmesh::NavMeshFileTile& inT, const navmesh::TileCoord& inC)
                               { return inT.mTile < inC; });
    return it != inPrevious.mTiles.end() && it->mTile == inTile ? &*it : nullptr;
}

/// A tile job: the broad-phase query around the tile, its objects' triangles in key order, and Recast, or the
/// previous bake's output when the input hash is unchanged.
void BuildTileInFlight(const TileJobContext& inContext, TileInFlight& ioTile)
{
    const BakeSettings& settings = *inContext.mSettings;
    const AABB box = inContext.mGrid->GetTileBoundsWithBorder(ioTile.mTile, inContext.mBorder);
    std::vector<BodyID> found, ordered;
    inContext.mCollector->FindBodies(box, {}, found);
    // The bodies the query found, in the order of their objects' keys: body ids depend on which tiles were in
    // flight, keys do not, so the triangles (and the input hash) are the same however the bake ran. A body of
    // another tile's object that the query finds was not there when this tile entered, or is gone before it
    // leaves: it is not this tile's
    std::sort(found.begin(), found.end());
    for (const TileObject& object : ioTile.mObjects)
        if (std::binary_search(found.begin(), found.end(), object.mBody)) ordered.push_back(object.mBody);
    navmesh::TileGeometry geometry;
    navmesh::CollectStats stats;
    inContext.mCollector->CollectTriangles(box, {}, ordered, geometry, stats);
    uint64_t hash = Hash64Of(std::span<const int32_t>(&ioTile.mTile.mX, 1), inContext.mSettingsHash);
    hash = Hash64Of(std::span<const int32_t>(&ioTile.mTile.mZ, 1), hash);
    hash = Hash64Of(std::span<const float>(geometry.mVertices), hash);
    hash = Hash64Of(std::span<const int>(geometry.mTriangles), hash);
    hash = Hash64Of(std::span<const uint8_t>(geometry.mAreas), hash);
    std::span<const navmesh::OffMeshLink> links;
    if (auto found = inContext.mLinks->find(ioTile.mTile); found != inContext.mLinks->end())
        links = found->second;
    hash = HashLinks(links, hash); // No links: the hash of a bake without any
    ioTile.mRecord.mTile = ioTile.mTile;
    ioTile.mRecord.mInputHash = hash;
    // Unchanged input: the previous output, built or empty, is this tile's
    const TileRecord* before =
        settings.mPrevious != nullptr ? settings.mPrevious->Find(ioTile.mTile) : nullptr;
    const navmesh::NavMeshFileTile* beforeTile =
        before != nullptr ? FindPreviousTile(*settings.mPreviousNavMesh, ioTile.mTile) : nullptr;
    if (before != nullptr && before->mInputHash == hash && (beforeTile != nullptr) == (before->mBytes > 0))
    {
        ioTile.mReused = beforeTile;
        ioTile.mRecord = *before;
        return;
    }
    ioTile.mBuilt = navmesh::BuildTile(settings.mProfile, *inContext.mGrid, ioTile.mTile, geometry, links);
}

/// The tiles of the sorted list inTiles that inSettings' region and tile list choose, sorted. Errors: a
/// listed tile that is not the level's, a region that is not a box.
Result<std::vector<navmesh::TileCoord>> SelectTiles(const std::vector<navmesh::TileCoord>& inTiles,
                                                    const navmesh::TileGrid& inGrid,
                                                    const BakeSettings& inSettings)
{
    std::vector<navmesh::TileCoord> selected;
    if (inSettings.mTiles.empty())
        selected = inTiles;
    else
    {
        for (const navmesh::TileCoord& tile : inSettings.mTiles)
            if (!std::binary_search(inTiles.begin(), inTiles.end(), tile))
                return MakeError(ErrorCode::InvalidArgument, "tile (" + std::to_string(tile.mX) + ", " +
                                                                 std::to_string(tile.mZ) +
                                                                 ") is not one of the level's " +
                                                                 std::to_string(inTiles.size()) + " tiles");
        selected = inSettings.mTiles;
        std::sort(selected.begin(), selected.end());
        selected.erase(std::unique(selected.begin(), selected.end()), selected.end());
    }
    if (inSettings.mRegion.has_value())
    {
        const AABB& region = *inSettings.mRegion;
        if (!navmesh::TileGrid::IsRegion(region))
            return MakeError(ErrorCode::InvalidArgument, "the region to bake is not a box (min above max)");
        std::erase_if(selected, [&](const navmesh::TileCoord& inTile)
                      { return !inGrid.TileMeetsRegion(inTile, region); });
    }
    return selected;
}

} // namespace

Result<BakeResult> BakeSource(const LevelSource& inSource, const BakeSettings& inSettings)
{
    if (Status valid = inSettings.mProfile.Validate(); !valid) return valid.GetError();
    if (inSettings.mShardCount == 0 || inSettings.mShard >= inSettings.mShardCount)
        return MakeError(ErrorCode::InvalidArgument, "shard " + std::to_string(inSettings.mShard) + "/" +
                                                         std::to_string(inSettings.mShardCount) +
                                                         ": K must be below N");
    if ((inSettings.mPrevious == nullptr) != (inSettings.mPreviousNavMesh == nullptr))
        return MakeError(ErrorCode::InvalidArgument,
                         "an incremental bake needs the previous summary and navmesh");
    if (inSettings.mPrevious != nullptr)
        if (Status matching = CheckPreviousBake(*inSettings.mPrevious, *inSettings.mPreviousNavMesh);
            !matching)
            return matching.GetError();
    const AABB bounds = inSource.GetBounds();
    if (bounds.IsEmpty()) return MakeError(ErrorCode::InvalidArgument, "the level has no geometry");

    // Tiles on a grid anchored at the world origin, so that every shard and every bake agree on them
    BakeResult result;
    const navmesh::AgentProfile& profile = inSettings.mProfile;
    const navmesh::TileGrid grid(0.0f, 0.0f, profile.mTileSize, bounds.mMin.y() - 1.0f,
                                 bounds.mMax.y() + 1.0f);
    std::vector<navmesh::TileCoord> tiles;
    if (!grid.TilesOverlapping(bounds, 0.0f, tiles, size_t(1) << 20))
        return MakeError(ErrorCode::OutOfCapacity, "the level spans more than 2^20 tiles of " +
                                                       std::to_string(profile.mTileSize) + " m");
    Result<dtNavMeshParams> params = navmesh::MakeNavMeshParams(grid, int(tiles.size()));
    if (!params)
        return MakeError(params.GetError().mCode,
                         "the level is too large for one navmesh: " + params.GetError().mMessage);
    result.mNavMesh.mParams = params.Value();
    result.mTilesInWorld = uint32_t(tiles.size());
    std::sort(tiles.begin(), tiles.end()); // The sorted list the shards split and the file keeps
    if (Status inLevel = CheckLinksInLevel(inSettings.mLinks, grid, tiles); !inLevel)
        return inLevel.GetError();
    std::map<navmesh::TileCoord, std::vector<navmesh::OffMeshLink>> linksByTile;
    for (const navmesh::OffMeshLink& link : inSettings.mLinks)
        linksByTile[grid.TileAt(link.mStart.x(), link.mStart.z())].push_back(link);
    // The tiles with links and those next to them, kept for the link check when this bake holds every tile
    const bool wholeLevel = inSettings.mShardCount == 1 && !inSettings.mRegion && inSettings.mTiles.empty();
    navmesh::NavMeshFileContents linkTiles;
    linkTiles.mParams = params.Value();
    Result<std::vector<navmesh::TileCoord>> selected = SelectTiles(tiles, grid, inSettings);
    if (!selected) return selected.GetError();
    std::vector<navmesh::TileCoord> mine;
    for (size_t i = 0; i < selected.Value().size(); ++i)
        if (i % inSettings.mShardCount == inSettings.mShard) mine.push_back(selected.Value()[i]);
    tiles = {};
    selected = std::vector<navmesh::TileCoord>();
    std::unique_ptr<navmesh::NavMeshFileWriter> output;
    if (!inSettings.mOutputPath.empty())
    {
        Result<std::unique_ptr<navmesh::NavMeshFileWriter>> writer =
            navmesh::NavMeshFileWriter::Create(inSettings.mOutputPath, params.Value());
        if (!writer) return writer.GetError();
        output = std::move(writer.Value());
    }

    // A world for the objects near the tiles in flight only
    jobs::JobSystem::Settings jobSettings;
    jobSettings.mNumThreads = inSettings.mThreads;
    jobs::JobSystem jobSystem(jobSettings);
    // Enough tiles in flight to keep every thread busy while the front one is written out
    const size_t maxInFlight = std::max<size_t>(8, size_t(jobSystem.GetNumThreads()) * 8);
    // Room for the objects near a few tiles: a tile that would not fit waits until tiles ahead of it leave
    // (tiles far apart in a shard share no objects, and a world sized for every tile in flight at worst would
    // cost memory in proportion to the thread count)
    PhysicsSettings physicsSettings;
    physicsSettings.mMaxBodies =
        inSettings.mMaxBodiesInWorld != 0
            ? inSettings.mMaxBodiesInWorld
            : uint32_t(std::clamp<uint64_t>(
                  std::min(uint64_t(inSource.GetMaxObjectsNear()) * 2, inSource.GetNumObjects()), 64,
                  1u << 20));
    const size_t maxLive = physicsSettings.mMaxBodies;
    Result<std::unique_ptr<PhysicsSystem>> world = PhysicsSystem::Create(physicsSettings);
    if (!world) return world.GetError();
    PhysicsSystem& physics = *world.Value();
    LiveObjects objects(physics, inSource);
    const navmesh::GeometryCollector collector(physics.GetBodyManager(), physics.GetBroadPhase());
    const float border = float(profile.GetBorderCells()) * profile.mCellSize;
    const TileJobContext context{&inSettings, &grid, &collector, border, SettingsHash(profile, grid),
                                 &linksByTile};
    std::deque<TileInFlight> inFlight; // References stay valid when the ends change
    std::vector<SourceObject> near;
    // On an error, the jobs still running read the tiles: wait for them before anything goes
    struct WaitForJobs
    {
        jobs::JobSystem& mJobs;
        ~WaitForJobs() { (void)mJobs.WaitIdle(); }
    } waitForJobs{jobSystem};

    result.mSummary.mInputs = inSource.GetInputNames();
    result.mSummary.mShard = inSettings.mShard;
    result.mSummary.mShardCount = inSettings.mShardCount;
    result.mSummary.mTilesInWorld = result.mTilesInWorld;
    const Clock::time_point bakeStart = Clock::now();
    size_t next = 0;
    uint32_t leftSinceUpdate = 0;
    bool nearIsNext = false; // near holds the objects of mine[next], which waits for room in the world
    while (next < mine.size() || !inFlight.empty())
    {
        while (next < mine.size() && inFlight.size() < maxInFlight)
        {
            if (!nearIsNext)
            {
                near.clear();
                inSource.FindObjects(grid.GetTileBoundsWithBorder(mine[next], border), near);
                nearIsNext = true;
            }
            // Counts its objects as new even if some are held already: room is never overestimated
            if (!inFlight.empty() && objects.GetNumLive() + near.size() > maxLive) break;
            TileInFlight& tile = inFlight.emplace_back();
            tile.mTile = mine[next++];
            nearIsNext = false;
            Result<std::vector<TileObject>> held = objects.Acquire(near);
            if (!held) return held.GetError();
            tile.mObjects = std::move(held.Value());
            TileInFlight* job = &tile;
            tile.mJob =
                jobSystem.Schedule("bake tile", [&context, job] { BuildTileInFlight(context, *job); });
        }

        // The front tile, written out in order
        TileInFlight& tile = inFlight.front();
        jobSystem.Wait(tile.mJob);
        ++result.mTilesBaked;
        TileRecord& record = tile.mRecord;
        std::span<const unsigned char> data;
        if (!tile.mBuilt.has_value())
        {
            if (tile.mReused != nullptr) data = tile.mReused->mData; // Taken over from the previous bake
        }
        else
        {
            Result<navmesh::BuiltTile>& built = *tile.mBuilt;
            if (!built)
                return MakeError(built.GetError().mCode, "tile (" + std::to_string(tile.mTile.mX) + ", " +
                                                             std::to_string(tile.mTile.mZ) +
                                                             "): " + built.GetError().mMessage);
            ++result.mSummary.mTilesRebuilt;
            record.mPolygons = built.Value().mNumPolygons;
            if (built.Value().mData != nullptr)
            {
                data = {built.Value().mData.get(), size_t(built.Value().mDataSize)};
                record.mBytes = uint32_t(data.size());
                record.mOutputHash = Hash64(data);
            }
        }
        result.mPolygons += uint64_t(record.mPolygons);
        if (data.empty() && linksByTile.contains(tile.mTile))
            return MakeError(ErrorCode::InvalidArgument,
                             "tile (" + std::to_string(tile.mTile.mX) + ", " + std::to_string(tile.mTile.mZ) +
                                 ") has no navmesh for the off-mesh links that start in it");
        if (!data.empty())
        {
            ++result.mTilesWithPolygons;
            if (wholeLevel && IsNearLinks(tile.mTile, linksByTile))
                linkTiles.mTiles.push_back(
                    {tile.mTile, std::vector<unsigned char>(data.begin(), data.end())});
            if (output != nullptr)
            {
                if (Status added = output->Add(tile.mTile, data); !added) return added.GetError();
            }
            else
                result.mNavMesh.mTiles.push_back(
                    {tile.mTile, std::vector<unsigned char>(data.begin(), data.end())});
        }
        result.mSummary.mTiles.push_back(record);
        objects.Release(tile.mObjects);
        inFlight.pop_front();
        if (inSettings.mProgress) inSettings.mProgress(result.mTilesBaked, uint32_t(mine.size()));
        // The broad phase rebuilds what the adds and removes changed and frees the old nodes (a step of a
        // world without moving bodies is only that)
        if (++leftSinceUpdate >= 8)
        {
            leftSinceUpdate = 0;
            if (Status updated = physics.Update(1.0f / 60.0f); !updated) return updated.GetError();
        }
    }
    result.mBakeMs = MillisecondsSince(bakeStart);
    result.mPeakBodies = objects.GetPeakLive();
    result.mBodies = objects.GetNumMade();
    if (output != nullptr)
    {
        if (Status completed = inSettings.mCommitOutput ? output->Commit() : output->Complete(); !completed)
            return completed.GetError();
        if (!inSettings.mCommitOutput) result.mOutput = std::move(output);
    }
    result.mSummary.mBakeMs = result.mBakeMs;
    result.mSummary.mPolygons = result.mPolygons;
    if (wholeLevel)
    {
        Result<std::vector<UnjoinedLink>> unjoined = FindUnjoinedLinks(linkTiles, inSettings.mLinks);
        if (!unjoined) return unjoined.GetError();
        result.mUnjoinedLinks = std::move(unjoined.Value());
        result.mLinksChecked = true;
    }
    return result;
}

Result<BakeResult> Bake(const BakeSettings& inSettings)
{
    if (inSettings.mInputs.empty()) return MakeError(ErrorCode::InvalidArgument, "no input files");
    // Before loading: the source's index of cells is made for the tile size
    if (Status valid = inSettings.mProfile.Validate(); !valid) return valid.GetError();
    const Clock::time_point loadStart = Clock::now();
    Result<std::unique_ptr<FileLevelSource>> source = FileLevelSource::Load(
        inSettings.mInputs, inSettings.mAreas, inSettings.mProfile.mTileSize, inSettings.mLoadLimits);
    if (!source) return source.GetError();
    const double loadMs = MillisecondsSince(loadStart);
    Result<BakeResult> result = BakeSource(*source.Value(), inSettings);
    if (result) result.Value().mLoadMs = loadMs;
    return result;
}

Result<navmesh::NavMeshFileContents> MergeShards(const std::vector<navmesh::NavMeshFileContents>& inShards)
{
    if (inShards.empty()) return MakeError(ErrorCode::InvalidArgument, "merge: no shards");
    navmesh::NavMeshFileContents merged;
    merged.mParams = inShards.front().mParams;
    for (size_t s = 0; s < inShards.size(); ++s)
    {
        if (std::memcmp(&inShards[s].mParams, &merged.mParams, sizeof(dtNavMeshParams)) != 0)
            return MakeError(ErrorCode::InvalidArgument, "merge: shard " + std::to_string(s) +
                                                             " was baked with other navmesh parameters");
        merged.mTiles.insert(merged.mTiles.end(), inShards[s].mTiles.begin(), inShards[s].mTiles.end());
    }
    std::sort(merged.mTiles.begin(), merged.mTiles.end(),
              [](const navmesh::NavMeshFileTile& inL, const navmesh::NavMeshFileTile& inR)
              { return inL.mTile < inR.mTile; });
    for (size_t i = 1; i < merged.mTiles.size(); ++i)
        if (merged.mTiles[i].mTile == merged.mTiles[i - 1].mTile)
            return MakeError(ErrorCode::InvalidArgument,
                             "merge: tile (" + std::to_string(merged.mTiles[i].mTile.mX) + ", " +
                                 std::to_string(merged.mTiles[i].mTile.mZ) + ") is in two shards");
    return merged;
}

} // namespace cairn::bake
