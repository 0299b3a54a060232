#pragma once

// TileGrid: the world cut into square navmesh tiles on the x-z plane, from an origin. Tile (x, z) covers
// [origin + x * size, origin + (x + 1) * size) on each axis. Plain value type.

#include "cairn/physics/math/AABB.h"

#include <algorithm>
#include <cmath>
#include <compare>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <vector>

namespace cairn::navmesh
{
using namespace cairn::physics;

struct TileCoord
{
    int32_t mX = 0;
    int32_t mZ = 0;
    auto operator<=>(const TileCoord&) const = default;
};

class TileGrid
{
public:
    /// inMinY, inMaxY: the height range every tile covers (the world's).
    TileGrid(float inOriginX, float inOriginZ, float inTileSize, float inMinY, float inMaxY)
        : mOriginX(inOriginX), mOriginZ(inOriginZ), mTileSize(inTileSize), mMinY(inMinY), mMaxY(inMaxY)
    {
    }

    float GetTileSize() const { return mTileSize; }
    float GetOriginX() const { return mOriginX; }
    float GetOriginZ() const { return mOriginZ; }
    float GetMinY() const { return mMinY; }
    float GetMaxY() const { return mMaxY; }

    /// The tile under (inX, inZ). Coordinates far outside the world clamp to +-2^30 tiles instead of
    /// overflowing the integers (NaN gives tile 0).
    TileCoord TileAt(float inX, float inZ) const { return {ToTile(inX - mOriginX), ToTile(inZ - mOriginZ)}; }

    /// The tile's own area over the height range.
    AABB GetTileBounds(const TileCoord& inTile) const
    {
        const float x = mOriginX + float(inTile.mX) * mTileSize, z = mOriginZ + float(inTile.mZ) * mTileSize;
        return AABB(Vec3(x, mMinY, z), Vec3(x + mTileSize, mMaxY, z + mTileSize));
    }

    /// Whether inB is inA or one of the eight tiles around it: where Detour joins an off-mesh link's end to
    /// the tile of its start.
    static bool AreNeighbours(const TileCoord& inA, const TileCoord& inB)
    {
        return std::abs(int64_t(inA.mX) - inB.mX) <= 1 && std::abs(int64_t(inA.mZ) - inB.mZ) <= 1;
    }

    /// Whether inRegion is a box of finite numbers across x and z: a region of the world to load or bake.
    static bool IsRegion(const AABB& inRegion)
    {
        return inRegion.mMin.allFinite() && inRegion.mMax.allFinite() &&
               inRegion.mMin.x() <= inRegion.mMax.x() && inRegion.mMin.z() <= inRegion.mMax.z();
    }
    /// Whether inTile's area meets inRegion across x and z (its heights not asked).
    bool TileMeetsRegion(const TileCoord& inTile, const AABB& inRegion) const
    {
        const AABB bounds = GetTileBounds(inTile);
        return bounds.mMax.x() >= inRegion.mMin.x() && bounds.mMin.x() <= inRegion.mMax.x() &&
               bounds.mMax.z() >= inRegion.mMin.z() && bounds.mMin.z() <= inRegion.mMax.z();
    }

    /// The tile's area grown by inBorder on the four sides: the geometry a tile build needs.
    AABB GetTileBoundsWithBorder(const TileCoord& inTile, float inBorder) const
    {
        AABB box = GetTileBounds(inTile);
        box.mMin.x() -= inBorder;
        box.mMin.z() -= inBorder;
        box.mMax.x() += inBorder;
        box.mMax.z() += inBorder;
        return box;
    }

    /// Every tile whose bordered area (inBorder) overlaps inBox, appended to outTiles. At most inMaxTiles (a
    /// huge box gives a clear cut-off rather than millions of tiles); returns false when it cut off.
    bool TilesOverlapping(const AABB& inBox, float inBorder, std::vector<TileCoord>& outTiles,
                          size_t inMaxTiles = 65536) const
    {
        TileCoord lo, hi;
        if (!TileRange(inBox, inBorder, lo, hi)) return true;
        if (CountTiles(lo, hi) > inMaxTiles) return false;
        for (int32_t z = lo.mZ; z <= hi.mZ; ++z)
            for (int32_t x = lo.mX; x <= hi.mX; ++x)
                outTiles.push_back({x, z});
        return true;
    }

    /// How many tiles TilesOverlapping would list without a cut-off: to refuse a box before keeping it.
    uint64_t CountTilesOverlapping(const AABB& inBox, float inBorder) const
    {
        TileCoord lo, hi;
        return TileRange(inBox, inBorder, lo, hi) ? CountTiles(lo, hi) : 0;
    }

private:
    /// The first and last tile on each axis of TilesOverlapping; false when there is none (an empty or
    /// non-finite box).
    bool TileRange(const AABB& inBox, float inBorder, TileCoord& outLo, TileCoord& outHi) const
    {
        if (inBox.IsEmpty() || !std::isfinite(inBox.mMin.x()) || !std::isfinite(inBox.mMax.x()) ||
            !std::isfinite(inBox.mMin.z()) || !std::isfinite(inBox.mMax.z()))
            return false;
        outLo = TileAt(inBox.mMin.x() - inBorder, inBox.mMin.z() - inBorder);
        outHi = TileAt(inBox.mMax.x() + inBorder, inBox.mMax.z() + inBorder);
        return outLo.mX <= outHi.mX && outLo.mZ <= outHi.mZ; // A negative border can shrink a box to nothing
    }

    static uint64_t CountTiles(const TileCoord& inLo, const TileCoord& inHi)
    {
        // In 64 bits: a box of 5e10 m spans more tiles than an int32 difference holds (at most (2^31 + 1)^2,
        // as TileAt clamps to +-2^30)
        return uint64_t(int64_t(inHi.mX) - inLo.mX + 1) * uint64_t(int64_t(inHi.mZ) - inLo.mZ + 1);
    }

    int32_t ToTile(float inOffset) const
    {
        const double tile = std::floor(double(inOffset) / double(mTileSize));
        if (std::isnan(tile)) return 0;
        constexpr double cLimit = double(1 << 30);
        return int32_t(std::clamp(tile, -cLimit, cLimit));
    }

    float mOriginX;
    float mOriginZ;
    float mTileSize;
    float mMinY;
    float mMaxY;
};

} // namespace cairn::navmesh

template <> struct std::hash<cairn::navmesh::TileCoord>
{
    size_t operator()(const cairn::navmesh::TileCoord& inTile) const noexcept
    {
        return std::hash<uint64_t>()((uint64_t(uint32_t(inTile.mX)) << 32) | uint32_t(inTile.mZ));
    }
};
