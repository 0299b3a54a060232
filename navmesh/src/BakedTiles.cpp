#include "cairn/navmesh/BakedTiles.h"

#include <DetourAlloc.h>
#include <cmath>
#include <cstring>

namespace cairn::navmesh
{

Result<std::vector<BuiltTile>> MakeBakedTileChanges(const NavMeshFileContents& inContents,
                                                    const NavMeshWorld& inWorld,
                                                    const std::optional<AABB>& inRegion)
{
    const TileGrid& grid = inWorld.GetGrid();
    const AgentProfile& profile = inWorld.GetProfile();
    if (inRegion.has_value() && !TileGrid::IsRegion(*inRegion))
        return MakeError(ErrorCode::InvalidArgument,
                         "baked navmesh: the region is not a box of finite numbers");
    const dtNavMeshParams& params = inContents.mParams;
    // Detour places a tile by the navmesh's origin and tile size: the world's must be the bake's, to the bit
    // (both come from the same numbers, and a tile built a hair off is a seam agents cannot cross)
    if (params.orig[0] != grid.GetOriginX() || params.orig[2] != grid.GetOriginZ() ||
        params.tileWidth != grid.GetTileSize() || params.tileHeight != grid.GetTileSize())
        return MakeError(ErrorCode::InvalidArgument,
                         "baked navmesh: baked on a grid of origin (" + std::to_string(params.orig[0]) +
                             ", " + std::to_string(params.orig[2]) + ") and " +
                             std::to_string(params.tileWidth) + " m tiles, the world's is (" +
                             std::to_string(grid.GetOriginX()) + ", " + std::to_string(grid.GetOriginZ()) +
                             ") and " + std::to_string(grid.GetTileSize()) + " m");
    std::vector<BuiltTile> changes;
    for (const NavMeshFileTile& tile : inContents.mTiles)
    {
        if (inRegion.has_value() && !grid.TileMeetsRegion(tile.mTile, *inRegion)) continue;
        if (tile.mData.size() < sizeof(dtMeshHeader))
            return MakeError(ErrorCode::InvalidArgument,
                             "baked navmesh: tile (" + std::to_string(tile.mTile.mX) + ", " +
                                 std::to_string(tile.mTile.mZ) + ") is shorter than its header");
        BuiltTile change;
        change.mTile = tile.mTile;
        change.mData.reset(static_cast<unsigned char*>(dtAlloc(tile.mData.size(), DT_ALLOC_PERM)));
        if (change.mData == nullptr)
            return MakeError(ErrorCode::OutOfCapacity, "baked navmesh: out of memory");
        std::memcpy(change.mData.get(), tile.mData.data(), tile.mData.size());
        change.mDataSize = int(tile.mData.size());
        dtMeshHeader header;
        std::memcpy(&header, tile.mData.data(), sizeof(header));
        // The bake's agent, as BuildTile writes it into each tile
        const auto same = [](float inBaked, float inOurs) { return std::abs(inBaked - inOurs) <= 1.0e-4f; };
        if (!same(header.walkableHeight, profile.mHeight) || !same(header.walkableRadius, profile.mRadius) ||
            !same(header.walkableClimb, profile.mMaxClimb))
            return MakeError(ErrorCode::InvalidArgument,
                             "baked navmesh: tile (" + std::to_string(tile.mTile.mX) + ", " +
                                 std::to_string(tile.mTile.mZ) + ") was baked for an agent of height " +
                                 std::to_string(header.walkableHeight) + ", radius " +
                                 std::to_string(header.walkableRadius) + " and climb " +
                                 std::to_string(header.walkableClimb) + " m, not the world's");
        change.mNumPolygons = header.polyCount;
        change.mNumVertices = header.vertCount;
        changes.push_back(std::move(change));
    }
    return changes;
}

} // namespace cairn::navmesh
