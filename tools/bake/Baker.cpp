#include "Baker.h"

#include "cairn/jobs/JobSystem.h"
#include "cairn/navmesh/GeometryCollector.h"
#include "cairn/navmesh/ObjMesh.h"
#include "cairn/navmesh/TileBuilder.h"
#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/shapes/TriangleMeshShape.h"

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

double MillisecondsSince(Clock::time_point inStart)
{
    return std::chrono::duration<double, std::milli>(Clock::now() - inStart).count();
}
} // namespace

Result<BakeResult> Bake(const BakeSettings& inSettings)
{
    if (Status valid = inSettings.mProfile.Validate(); !valid) return valid.GetError();
    if (inSettings.mShardCount == 0 || inSettings.mShard >= inSettings.mShardCount)
        return MakeError(ErrorCode::InvalidArgument, "shard " + std::to_string(inSettings.mShard) + "/" +
                                                         std::to_string(inSettings.mShardCount) +
                                                         ": K must be below N");
    if (inSettings.mInputs.empty()) return MakeError(ErrorCode::InvalidArgument, "no input files");

    // Every object a static mesh body; the level's bounds decide the tiles
    BakeResult result;
    const Clock::time_point loadStart = Clock::now();
    PhysicsSettings physicsSettings;
    physicsSettings.mMaxBodies = 1 << 20;
    PhysicsSystem physics(physicsSettings);
    AABB bounds;
    for (const std::string& input : inSettings.mInputs)
    {
        Result<navmesh::IndexedMesh> mesh = navmesh::LoadObjMesh(input);
        if (!mesh) return mesh.GetError();
        auto shape = TriangleMeshShape::Create(mesh.Value().mVertices, mesh.Value().mTriangles);
        if (!shape) return MakeError(shape.GetError().mCode, input + ": " + shape.GetError().mMessage);
        BodyCreationSettings settings;
        settings.mShape = shape.Value();
        settings.mMotionType = MotionType::Static;
        settings.mObjectLayer = Layers::cStatic;
        if (Result<BodyID> id =
                physics.GetBodyInterface().CreateAndAddBody(settings, Activation::DontActivate);
            !id)
            return MakeError(id.GetError().mCode, input + ": " + id.GetError().mMessage);
        bounds.Encapsulate(mesh.Value().GetBounds());
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
    std::vector<navmesh::TileCoord> mine;
    for (size_t i = 0; i < tiles.size(); ++i)
        if (i % inSettings.mShardCount == inSettings.mShard) mine.push_back(tiles[i]);

    // Each tile alone, on any thread: its own query, triangles and Recast run
    const float border = float(profile.GetBorderCells()) * profile.mCellSize;
    const navmesh::GeometryCollector collector(physics.GetBodyManager(), physics.GetBroadPhase());
    std::vector<std::optional<Result<navmesh::BuiltTile>>> built(mine.size());
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

    for (size_t i = 0; i < mine.size(); ++i)
    {
        Result<navmesh::BuiltTile>& tile = *built[i];
        if (!tile)
            return MakeError(tile.GetError().mCode, "tile (" + std::to_string(mine[i].mX) + ", " +
                                                        std::to_string(mine[i].mZ) +
                                                        "): " + tile.GetError().mMessage);
        ++result.mTilesBaked;
        result.mPolygons += uint64_t(tile.Value().mNumPolygons);
        if (tile.Value().mData == nullptr) continue;
        const unsigned char* data = tile.Value().mData.get();
        result.mNavMesh.mTiles.push_back(
            {mine[i], std::vector<unsigned char>(data, data + tile.Value().mDataSize)});
    }
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
