#include "Baker.h"

#include "cairn/jobs/JobSystem.h"
#include "cairn/navmesh/GeometryCollector.h"
#include "cairn/navmesh/ObjMesh.h"
#include "cairn/navmesh/TileBuilder.h"
#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/shapes/TriangleMeshShape.h"
#include "common/FrameTimes.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <mutex>
#include <optional>

namespace cairn::bake
{

namespace
{
using Clock = std::chrono::steady_clock;
using tools::MillisecondsSince;

/// Bodies a bake may make (objects times their areas): far beyond any level, well inside the body ids
constexpr size_t cMaxObjects = size_t(1) << 24;

} // namespace

Result<BakeResult> Bake(const BakeSettings& inSettings)
{
    if (Status valid = inSettings.mProfile.Validate(); !valid) return valid.GetError();
    if (inSettings.mShardCount == 0 || inSettings.mShard >= inSettings.mShardCount)
        return MakeError(ErrorCode::InvalidArgument, "shard " + std::to_string(inSettings.mShard) + "/" +
                                                         std::to_string(inSettings.mShardCount) +
                                                         ": K must be below N");
    if (inSettings.mInputs.empty()) return MakeError(ErrorCode::InvalidArgument, "no input files");
    if ((inSettings.mPrevious == nullptr) != (inSettings.mPreviousNavMesh == nullptr))
        return MakeError(ErrorCode::InvalidArgument,
                         "an incremental bake needs the previous summary and navmesh");

    // Every object a static mesh body; the level's bounds decide the tiles
    BakeResult result;
    const Clock::time_point loadStart = Clock::now();
    if (Status valid = inSettings.mAreas.Validate(); !valid) return valid.GetError();
    // A body per object and area: an edited object changes only the tiles it touches, and each body carries
    // the area its materials map to. All parts first, so that the world is made for their number
    struct NamedPart
    {
        std::string mWhere; ///< File and object, for errors
        navmesh::LevelPart mPart;
    };
    std::vector<NamedPart> parts;
    AABB bounds;
    for (const std::string& input : inSettings.mInputs)
    {
        Result<navmesh::IndexedMesh> mesh = navmesh::LoadLevelMesh(input);
        if (!mesh) return mesh.GetError();
        bounds.Encapsulate(mesh.Value().GetBounds());
        for (navmesh::LevelPart& part : navmesh::SplitIntoParts(mesh.Value(), inSettings.mAreas))
        {
            std::string where = input + (part.mName.empty() ? "" : ": object '" + part.mName + "'");
            parts.push_back({std::move(where), std::move(part)});
        }
    }
    PhysicsSettings physicsSettings;
    physicsSettings.mMaxBodies = uint32_t(std::max<size_t>(parts.size(), 1));
    if (parts.size() > cMaxObjects)
        return MakeError(ErrorCode::OutOfCapacity, "the level has " + std::to_string(parts.size()) +
                                                       " objects, more than a physics world holds");
    PhysicsSystem physics(physicsSettings);
    for (NamedPart& named : parts)
    {
        const navmesh::LevelPart& part = named.mPart;
        auto shape = TriangleMeshShape::Create(part.mMesh.mVertices, part.mMesh.mTriangles);
        if (!shape) return MakeError(shape.GetError().mCode, named.mWhere + ": " + shape.GetError().mMessage);
        BodyCreationSettings settings;
        settings.mShape = shape.Value();
        settings.mMotionType = MotionType::Static;
        settings.mObjectLayer = Layers::cStatic;
        settings.mNavMeshArea = part.mArea;
        if (Result<BodyID> id =
                physics.GetBodyInterface().CreateAndAddBody(settings, Activation::DontActivate);
            !id)
            return MakeError(id.GetError().mCode, named.mWhere + ": " + id.GetError().mMessage);
        ++result.mBodies;
        named.mPart.mMesh = {}; // The shape holds its own copy
    }
    result.mLoadMs = MillisecondsSince(loadStart);

    // Tiles on a grid anchored at the world origin, so that every shard and every bake agree on them
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
    std::vector<navmesh::TileCoord> mine;
    for (size_t i = 0; i < tiles.size(); ++i)
        if (i % inSettings.mShardCount == inSettings.mShard) mine.push_back(tiles[i]);

    // Each tile alone, on any thread: its own query, triangles and Recast run
    const float border = float(profile.GetBorderCells()) * profile.mCellSize;
    const navmesh::GeometryCollector collector(physics.GetBodyManager(), physics.GetBroadPhase());
    std::vector<std::optional<Result<navmesh::BuiltTile>>> built(mine.size());
    std::vector<TileRecord> records(mine.size());
    std::vector<const navmesh::NavMeshFileTile*> reused(mine.size(), nullptr);
    // Everything besides the triangles that decides a tile: the settings
    const navmesh::AgentProfile& p = profile;
    const float settingsValues[] = {p.mHeight,
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
                                    grid.GetTileBounds({0, 0}).mMin.y(),
                                    grid.GetTileBounds({0, 0}).mMax.y()};
    const uint64_t settingsHash = Hash64Of(std::span<const float>(settingsValues), Hash64({}));
    auto previousTile = [&](const navmesh::TileCoord& inTile) -> const navmesh::NavMeshFileTile*
    {
        const std::vector<navmesh::NavMeshFileTile>& tiles = inSettings.mPreviousNavMesh->mTiles;
        auto it = std::lower_bound(tiles.begin(), tiles.end(), inTile,
                                   [](const navmesh::NavMeshFileTile& inT, const navmesh::TileCoord& inC)
                                   { return inT.mTile < inC; });
        return it != tiles.end() && it->mTile == inTile ? &*it : nullptr;
    };
    jobs::JobSystem::Settings jobSettings;
    jobSettings.mNumThreads = inSettings.mThreads;
    jobs::JobSystem jobSystem(jobSettings);
    std::mutex progressMutex;
    uint32_t done = 0; ///< Guarded by progressMutex
    const Clock::time_point bakeStart = Clock::now();
    jobSystem.ParallelFor(uint32_t(mine.size()), 1,
                          [&](uint32_t inBegin, uint32_t inEnd)
                          {
                              for (uint32_t i = inBegin; i < inEnd; ++i)
                              {
                                  const AABB box = grid.GetTileBoundsWithBorder(mine[i], border);
                                  std::vector<BodyID> bodies, busy;
                                  navmesh::TileGeometry geometry;
                                  navmesh::CollectStats stats;
                                  collector.FindBodies(box, {}, bodies);
                                  collector.CollectTriangles(box, {}, bodies, geometry, busy, stats);
                                  uint64_t hash =
                                      Hash64Of(std::span<const int32_t>(&mine[i].mX, 1), settingsHash);
                                  hash = Hash64Of(std::span<const int32_t>(&mine[i].mZ, 1), hash);
                                  hash = Hash64Of(std::span<const float>(geometry.mVertices), hash);
                                  hash = Hash64Of(std::span<const int>(geometry.mTriangles), hash);
                                  hash = Hash64Of(std::span<const uint8_t>(geometry.mAreas), hash);
                                  records[i].mTile = mine[i];
                                  records[i].mInputHash = hash;
                                  // Unchanged input: the previous output, built or empty, is this tile's
                                  const TileRecord* before = inSettings.mPrevious != nullptr
                                                                 ? inSettings.mPrevious->Find(mine[i])
                                                                 : nullptr;
                                  const navmesh::NavMeshFileTile* beforeTile =
                                      before != nullptr ? previousTile(mine[i]) : nullptr;
                                  if (before != nullptr && before->mInputHash == hash &&
                                      (beforeTile != nullptr) == (before->mBytes > 0))
                                  {
                                      reused[i] = beforeTile;
                                      records[i] = *before;
                                  }
                                  else
                                      built[i] = navmesh::BuildTile(profile, grid, mine[i], geometry);
                                  if (inSettings.mProgress)
                                  {
                                      // One call at a time: the callback need not be thread-safe
                                      std::lock_guard lock(progressMutex);
                                      inSettings.mProgress(++done, uint32_t(mine.size()));
                                  }
                              }
                          });
    result.mBakeMs = MillisecondsSince(bakeStart);

    result.mSummary.mInputs = inSettings.mInputs;
    result.mSummary.mShard = inSettings.mShard;
    result.mSummary.mShardCount = inSettings.mShardCount;
    result.mSummary.mTilesInWorld = result.mTilesInWorld;
    result.mSummary.mBakeMs = result.mBakeMs;
    for (size_t i = 0; i < mine.size(); ++i)
    {
        if (!built[i].has_value())
        {
            // Taken over from the previous bake
            ++result.mTilesBaked;
            result.mPolygons += uint64_t(records[i].mPolygons);
            result.mSummary.mTiles.push_back(records[i]);
            if (reused[i] != nullptr) result.mNavMesh.mTiles.push_back(*reused[i]);
            continue;
        }
        Result<navmesh::BuiltTile>& tile = *built[i];
        if (!tile)
            return MakeError(tile.GetError().mCode, "tile (" + std::to_string(mine[i].mX) + ", " +
                                                        std::to_string(mine[i].mZ) +
                                                        "): " + tile.GetError().mMessage);
        ++result.mTilesBaked;
        ++result.mSummary.mTilesRebuilt;
        result.mPolygons += uint64_t(tile.Value().mNumPolygons);
        TileRecord& record = records[i];
        record.mPolygons = tile.Value().mNumPolygons;
        if (tile.Value().mData != nullptr)
        {
            const unsigned char* data = tile.Value().mData.get();
            result.mNavMesh.mTiles.push_back(
                {mine[i], std::vector<unsigned char>(data, data + tile.Value().mDataSize)});
            record.mBytes = uint32_t(tile.Value().mDataSize);
            record.mOutputHash = Hash64(result.mNavMesh.mTiles.back().mData);
        }
        result.mSummary.mTiles.push_back(record);
    }
    result.mSummary.mPolygons = result.mPolygons;
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
