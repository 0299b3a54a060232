#include "cairn/navmesh/NavMeshWorld.h"

#include "DetourPaths.h"
#include "DetourSurface.h"
#include "cairn/navmesh/OffMeshLinkJoins.h"
#include "cairn/navmesh/TileData.h"

#include <DetourNavMesh.h>
#include <DetourNavMeshQuery.h>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace cairn::navmesh
{
using namespace cairn::physics;

namespace
{
std::atomic<uint64_t> sNextSerial{1}; // Relaxed: only uniqueness matters

/// This thread's query object for a world, made on first use.
dtNavMeshQuery* QueryFor(uint64_t inSerial, const dtNavMesh* inNavMesh)
{
    struct PerThread
    {
        uint64_t mSerial = 0;
        std::unique_ptr<dtNavMeshQuery, void (*)(dtNavMeshQuery*)> mQuery{nullptr, dtFreeNavMeshQuery};
    };
    thread_local PerThread perThread;
    if (perThread.mSerial != inSerial || perThread.mQuery == nullptr)
    {
        perThread.mQuery.reset(dtAllocNavMeshQuery());
        if (perThread.mQuery == nullptr || dtStatusFailed(perThread.mQuery->init(inNavMesh, cMaxQueryNodes)))
        {
            perThread.mQuery.reset();
            perThread.mSerial = 0;
            return nullptr;
        }
        perThread.mSerial = inSerial;
    }
    return perThread.mQuery.get();
}

/// Detour takes its random numbers from a plain function: this thread's generator state while a query runs.
thread_local uint64_t tRandomState = 0;

float NextRandomFloat()
{
    // SplitMix64: a fixed, portable sequence (std::uniform_real_distribution is not the same everywhere)
    uint64_t z = (tRandomState += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return float(z >> 40) * (1.0f / 16777216.0f); // 24 bits: in [0, 1)
}
/// Marks inTile's polygons with the exclusion flags in inFlags: flag 2 << b set where inAreasByFlag[b] holds
/// the polygon's area, cleared elsewhere (in one pass over the polygons, whatever the flags).
template <size_t N>
void MarkTile(dtNavMesh& ioNavMesh, const dtMeshTile& inTile, uint16_t inFlags,
              const std::array<uint64_t, N>& inAreasByFlag)
{
    const dtPolyRef base = ioNavMesh.getPolyRefBase(&inTile);
    for (int p = 0; p < inTile.header->polyCount; ++p)
    {
        const dtPoly& polygon = inTile.polys[p];
        const int area = FromDetourArea(polygon.getArea());
        uint16_t flags = polygon.flags & ~inFlags;
        for (size_t b = 0; b < N; ++b)
            if ((inFlags & (2u << b)) != 0 && ((inAreasByFlag[b] >> area) & 1u) != 0)
                flags |= uint16_t(2u << b);
        ioNavMesh.setPolyFlags(base | dtPolyRef(p), flags);
    }
}

/// The checks of a query from one point before the navmesh is locked: the point, the search extent and the
/// filter, made Detour's. inRole names the point in the errors ("the centre").
Result<dtQueryFilter> CheckPointQuery(const Vec3& inPoint, const Vec3& inSearchExtent,
                                      const PathFilter& inFilter, float inTileSize, const std::string& inWhat,
                                      const std::string& inRole)
{
    if (!IsValidWorldPosition(inPoint))
        return MakeError(ErrorCode::InvalidArgument, inWhat + ": " + inRole + " must be finite");
    if (Status extent = CheckSearchExtent(inSearchExtent, inTileSize, inWhat.c_str()); !extent)
        return extent.GetError();
    return MakeDetourFilter(inFilter, inWhat.c_str());
}

/// A search radius in (0, NavMeshWorld::cMaxSearchExtentTiles tiles]: the query's node pool bounds the search
/// either way, the limit keeps the radius meaningful.
Status CheckRadius(float inRadius, float inTileSize, const std::string& inWhat)
{
    const float maxRadius = NavMeshWorld::cMaxSearchExtentTiles * inTileSize;
    if (!(inRadius > 0.0f && inRadius <= maxRadius))
        return MakeError(ErrorCode::InvalidArgument,
                         inWhat + ": the radius must be in (0, " + std::to_string(maxRadius) + "] m");
    return {};
}

/// A query's point snapped onto the navmesh, the navmesh locked: its polygon, not in an excluded area, and
/// this thread's query object.
struct SnappedPoint
{
    dtNavMeshQuery* mQuery = nullptr;
    dtPolyRef mPolygon = 0;
    Vec3 mPoint = Vec3::Zero();
};

Result<SnappedPoint> SnapQueryPoint(uint64_t inSerial, const dtNavMesh& inNavMesh, const Vec3& inPoint,
                                    const Vec3& inSearchExtent, const dtQueryFilter& inDetourFilter,
                                    const PathFilter& inFilter, const std::string& inWhat,
                                    const std::string& inRole)
{
    SnappedPoint snapped;
    snapped.mQuery = QueryFor(inSerial, &inNavMesh);
    if (snapped.mQuery == nullptr)
        return MakeError(ErrorCode::OutOfCapacity, inWhat + ": Detour could not make a query object");
    snapped.mQuery->findNearestPoly(inPoint.data(), inSearchExtent.data(), &inDetourFilter, &snapped.mPolygon,
                                    snapped.mPoint.data());
    if (snapped.mPolygon == 0)
        return MakeError(ErrorCode::InvalidArgument, inWhat + ": " + inRole + " is not on the navmesh");
    if (IsExcluded(inNavMesh, snapped.mPolygon, inFilter))
        return MakeError(ErrorCode::InvalidArgument, inWhat + ": " + inRole + " is in an excluded area");
    return snapped;
}
} // namespace

NavMeshWorld::NavMeshWorld(const TileGrid& inGrid, const AgentProfile& inProfile)
    : mGrid(inGrid), mProfile(inProfile), mSerial(sNextSerial.fetch_add(1, std::memory_order_relaxed))
{
}

Result<std::unique_ptr<NavMeshWorld>> NavMeshWorld::Create(const TileGrid& inGrid,
                                                           const AgentProfile& inProfile, int inMaxTiles)
{
    // The same check as BuildTile's: every tile built on a grid this world takes is one it can hold
    if (Status valid = ValidateProfileAndGrid(inProfile, inGrid); !valid) return valid.GetError();
    Result<dtNavMeshParams> params = MakeNavMeshParams(inGrid, inMaxTiles);
    if (!params) return params.GetError();
    std::unique_ptr<NavMeshWorld> world(new NavMeshWorld(inGrid, inProfile));
    world->mMaxTilePolygons = params.Value().maxPolys;
    world->mNavMesh = dtAllocNavMesh();
    if (world->mNavMesh == nullptr || dtStatusFailed(world->mNavMesh->init(&params.Value())))
        return MakeError(ErrorCode::OutOfCapacity, "navmesh: Detour could not allocate the navmesh");
    return world;
}

NavMeshWorld::~NavMeshWorld()
{
    // Before mTiles frees the tiles' data: the navmesh points into it to the end
    dtFreeNavMesh(mNavMesh);
}

BuiltTile NavMeshWorld::Removal(const TileCoord& inTile)
{
    BuiltTile empty;
    empty.mTile = inTile;
    return empty;
}

int NavMeshWorld::Publish(std::vector<BuiltTile>&& inChanges)
{
    if (inChanges.empty()) return 0;
    struct Pending
    {
        BuiltTile mTile;      ///< mData null: remove
        std::string mProblem; ///< Why Detour can not take mTile (CheckTile), empty when it can
    };
    std::map<TileCoord, Pending> pending; // By tile, the last change wins; applied in tile order
    for (BuiltTile& change : inChanges)
    {
        const TileCoord tile = change.mTile;
        pending[tile] = Pending{std::move(change), {}};
    }
    inChanges.clear();
    // Checked before the navmesh mutex is taken (the checks walk every polygon; path queries need not wait
    // for them) and before the old tile goes: a refused tile must not leave a hole where a good one was
    for (auto& [coord, entry] : pending)
        if (entry.mTile.mData != nullptr) entry.mProblem = CheckTile(coord, entry.mTile);
    std::unique_lock lock(mNavMeshMutex);
    int changed = 0;
    for (auto& [coord, entry] : pending)
    {
        if (entry.mTile.mData == nullptr)
            changed += RemoveTileLocked(coord);
        else if (!entry.mProblem.empty())
            RefuseLocked(coord, entry.mProblem);
        else
            changed += ReplaceTileLocked(coord, entry.mTile);
    }
    return changed;
}

std::string NavMeshWorld::CheckTile(const TileCoord& inCoord, const BuiltTile& inTile) const
{
    if (inTile.mDataSize <= 0) return "its data size is " + std::to_string(inTile.mDataSize);
    // Detour's addTile trusts the header's counts and indices: corrupt data would be read past its end
    const std::span<const unsigned char> data(inTile.mData.get(), size_t(inTile.mDataSize));
    if (std::string problem = CheckTileData(data); !problem.empty()) return problem;
    dtMeshHeader header;
    std::memcpy(&header, data.data(), sizeof(header));
    // Detour places a tile by its header: one handed in under another coordinate (or layer) would sit where
    // this world's bookkeeping does not look, and could never be replaced or removed
    if (header.x != inCoord.mX || header.y != inCoord.mZ || header.layer != 0)
        return "its data is tile " + std::to_string(header.x) + "," + std::to_string(header.y) + " (layer " +
               std::to_string(header.layer) + ")";
    // Detour also places a tile's polygons by the header's box: a tile built on another grid (another origin
    // or tile size) under this coordinate would answer queries far from where it is listed. The box is the
    // tile's own area and its border (BuildTile); a cell of slack either way
    const AABB bounds = mGrid.GetTileBounds(inCoord);
    const float border = float(mProfile.GetBorderCells()) * mProfile.mCellSize, slack = mProfile.mCellSize;
    auto spans = [&](float inMin, float inMax, float inTileMin, float inTileMax)
    {
        return inMin >= inTileMin - border - slack && inMin <= inTileMin + slack &&
               inMax >= inTileMax - slack && inMax <= inTileMax + border + slack;
    };
    if (!spans(header.bmin[0], header.bmax[0], bounds.mMin.x(), bounds.mMax.x()) ||
        !spans(header.bmin[2], header.bmax[2], bounds.mMin.z(), bounds.mMax.z()))
        return "its box (x " + std::to_string(header.bmin[0]) + " to " + std::to_string(header.bmax[0]) +
               ", z " + std::to_string(header.bmin[2]) + " to " + std::to_string(header.bmax[2]) +
               ") is not that tile's on this world's grid (built on another grid?)";
    const int maxPolygons = mMaxTilePolygons;
    const int polygons = std::max(inTile.mNumPolygons, header.polyCount);
    if (polygons > maxPolygons)
        return std::to_string(polygons) + " polygons, over the " + std::to_string(maxPolygons) +
               " a tile reference holds";
    return {};
}

int NavMeshWorld::RemoveTileLocked(const TileCoord& inCoord)
{
    auto it = mTiles.find(inCoord);
    if (it == mTiles.end()) return 0;
    // Added without DT_TILE_FREE_DATA: Detour lets go of the data, and erasing the entry frees it. Should
    // Detour not let go, the data must stay: it would still point into it
    if (dtStatusFailed(mNavMesh->removeTile(dtTileRef(it->second.mRef), nullptr, nullptr)))
    {
        RefuseLocked(inCoord, "Detour could not remove it (its tile reference is wrong); it stays");
        return 0;
    }
    mTiles.erase(it);
    return 1;
}

int NavMeshWorld::ReplaceTileLocked(const TileCoord& inCoord, BuiltTile& ioTile)
{
    // The map's node first: once Detour has taken the data, nothing may throw before the world keeps it
    auto [entry, isNew] = mTiles.try_emplace(inCoord);
    // Detour holds one tile per place, so the old one leaves first; its data stays ours until the new tile is
    // in, to go back if Detour refuses the new one after all
    PublishedTile old;
    if (!isNew)
    {
        if (dtStatusFailed(mNavMesh->removeTile(dtTileRef(entry->second.mRef), nullptr, nullptr)))
        {
            RefuseLocked(inCoord, "Detour could not remove the tile there (its tile reference is wrong); it "
                                  "stays");
            return 0;
        }
        old = std::move(entry->second);
    }
    dtTileRef ref = 0;
    const dtStatus added = mNavMesh->addTile(ioTile.mData.get(), ioTile.mDataSize, 0, 0, &ref);
    if (dtStatusSucceed(added))
    {
        entry->second = {ref, ioTile.mNumPolygons, ioTile.mDataSize, std::move(ioTile.mData)};
        // Whatever flags the data came with, its polygons are marked as every flag given says (held or not:
        // a flag no one holds keeps its marks, for a filter that asks for its areas again)
        std::array<uint64_t, cMaxExclusionFlags> areas;
        for (int b = 0; b < cMaxExclusionFlags; ++b)
            areas[size_t(b)] = mExclusionFlags[size_t(b)].mAreas;
        MarkTile(*mNavMesh, *mNavMesh->getTileByRef(ref), cExclusionFlagBits, areas);
        return isNew ? 1 : 2;
    }
    const std::string why = dtStatusDetail(added, DT_OUT_OF_MEMORY) ? "no free tile slot" : "invalid data";
    if (isNew)
    {
        mTiles.erase(entry);
        RefuseLocked(inCoord, "Detour refused it (" + why + ")");
        return 0;
    }
    // Back under its old reference (Detour restores the salt): polygon references taken before stay valid.
    // The slot it left is free and Detour took its data before, so this fails only with a bug in Detour
    if (dtStatusSucceed(mNavMesh->addTile(old.mData.get(), old.mDataSize, 0, dtTileRef(old.mRef), nullptr)))
    {
        entry->second = std::move(old);
        RefuseLocked(inCoord, "Detour refused it (" + why + "); the old tile stays");
        return 0;
    }
    mTiles.erase(entry);
    RefuseLocked(inCoord, "Detour refused it (" + why + "), and the old tile could not go back: a hole");
    return 1; // The old tile's removal
}

Result<uint16_t> NavMeshWorld::AcquireExclusionFlag(uint64_t inAreas, uint16_t inReleased) const
{
    inAreas &= cAllAreas; // The bits of no area would take a flag that marks nothing
    if (inAreas == 0 && inReleased == 0) return uint16_t(0);
    std::unique_lock lock(mNavMeshMutex);
    ExclusionFlag* released = nullptr;
    for (int b = 0; b < cMaxExclusionFlags; ++b)
        if (inReleased == uint16_t(2u << b) && mExclusionFlags[size_t(b)].mHolders > 0)
            released = &mExclusionFlags[size_t(b)];
    if (released != nullptr) --released->mHolders;
    if (inAreas == 0) return uint16_t(0);
    // The bit of these areas if one has them (held or not); else one never given; else one no one holds
    int chosen = -1;
    for (int b = 0; b < cMaxExclusionFlags && chosen < 0; ++b)
        if (mExclusionFlags[size_t(b)].mAreas == inAreas) chosen = b;
    for (int b = 0; b < cMaxExclusionFlags && chosen < 0; ++b)
        if (mExclusionFlags[size_t(b)].mAreas == 0) chosen = b;
    for (int b = 0; b < cMaxExclusionFlags && chosen < 0; ++b)
        if (mExclusionFlags[size_t(b)].mHolders == 0) chosen = b;
    if (chosen < 0)
    {
        if (released != nullptr) ++released->mHolders; // Still held: nothing changed
        return MakeError(ErrorCode::OutOfCapacity, "navmesh: " + std::to_string(cMaxExclusionFlags) +
                                                       " other sets of excluded areas are in use already");
    }
    ExclusionFlag& flag = mExclusionFlags[size_t(chosen)];
    const uint16_t bit = uint16_t(2u << chosen);
    if (flag.mAreas != inAreas)
    {
        flag.mAreas = inAreas;
        std::array<uint64_t, cMaxExclusionFlags> areas{};
        areas[size_t(chosen)] = inAreas;
        for (int i = 0; i < mNavMesh->getMaxTiles(); ++i)
        {
            const dtMeshTile* tile = static_cast<const dtNavMesh*>(mNavMesh)->getTile(i);
            if (tile->header != nullptr) MarkTile(*mNavMesh, *tile, bit, areas);
        }
    }
    ++flag.mHolders;
    return bit;
}

uint16_t NavMeshWorld::MarkedExclusionFlagLocked(uint64_t inAreas) const
{
    inAreas &= cAllAreas;
    for (int b = 0; b < cMaxExclusionFlags && inAreas != 0; ++b)
        if (mExclusionFlags[size_t(b)].mAreas == inAreas) return uint16_t(2u << b);
    return 0;
}

void NavMeshWorld::ReleaseExclusionFlag(uint16_t inFlag) const
{
    if (inFlag == 0) return;
    std::unique_lock lock(mNavMeshMutex);
    for (int b = 0; b < cMaxExclusionFlags; ++b)
        if (inFlag == uint16_t(2u << b) && mExclusionFlags[size_t(b)].mHolders > 0)
            --mExclusionFlags[size_t(b)].mHolders;
}

void NavMeshWorld::RefuseLocked(const TileCoord& inCoord, const std::string& inWhy)
{
    ++mRefusedTiles;
    mLastRefusal = "tile " + std::to_string(inCoord.mX) + "," + std::to_string(inCoord.mZ) + ": " + inWhy;
}

uint64_t NavMeshWorld::GetRefusedTiles(std::string* outLastReason) const
{
    std::shared_lock lock(mNavMeshMutex);
    if (outLastReason != nullptr) *outLastReason = mLastRefusal;
    return mRefusedTiles;
}

Result<PathResult> NavMeshWorld::FindPath(const Vec3& inStart, const Vec3& inEnd, const PathFilter& inFilter,
                                          const Vec3& inSearchExtent) const
{
    if (!IsValidWorldPosition(inStart) || !IsValidWorldPosition(inEnd))
        return MakeError(ErrorCode::InvalidArgument, "path: start and end must be finite");
    if (Status extent = CheckSearchExtent(inSearchExtent, mGrid.GetTileSize(), "path"); !extent)
        return extent.GetError();
    // An excluded area costs so much that the search avoids it when any other way exists; a path that must
    // cross it is cut short below
    Result<dtQueryFilter> detourFilter = MakeDetourFilter(inFilter, "path");
    if (!detourFilter) return detourFilter.GetError();
    const dtQueryFilter& filter = detourFilter.Value();

    std::shared_lock lock(mNavMeshMutex);
    dtNavMeshQuery* query = QueryFor(mSerial, mNavMesh);
    if (query == nullptr)
        return MakeError(ErrorCode::OutOfCapacity, "path: Detour could not make a query object");
    dtPolyRef startRef = 0, endRef = 0;
    float startPoint[3], endPoint[3];
    query->findNearestPoly(inStart.data(), inSearchExtent.data(), &filter, &startRef, startPoint);
    query->findNearestPoly(inEnd.data(), inSearchExtent.data(), &filter, &endRef, endPoint);
    if (startRef == 0) return MakeError(ErrorCode::InvalidArgument, "path: the start is not on the navmesh");
    if (endRef == 0) return MakeError(ErrorCode::InvalidArgument, "path: the end is not on the navmesh");

    dtPolyRef corridor[cMaxPathPolygons];
    int numPolygons = 0;
    const dtStatus status = query->findPath(startRef, endRef, startPoint, endPoint, &filter, corridor,
                                            &numPolygons, cMaxPathPolygons);
    if (dtStatusFailed(status) || numPolygons == 0)
        return MakeError(ErrorCode::InvalidArgument, "path: no path");
    return FinishPath(*query, *mNavMesh, corridor, numPolygons, endRef, startPoint, endPoint, inFilter,
                      status);
}

Result<Vec3> NavMeshWorld::FindNearestPoint(const Vec3& inPoint, const PathFilter& inFilter,
                                            const Vec3& inSearchExtent) const
{
    Result<dtQueryFilter> filter =
        CheckPointQuery(inPoint, inSearchExtent, inFilter, mGrid.GetTileSize(), "nearest point", "the point");
    if (!filter) return filter.GetError();

    std::shared_lock lock(mNavMeshMutex);
    dtNavMeshQuery* query = QueryFor(mSerial, mNavMesh);
    if (query == nullptr)
        return MakeError(ErrorCode::OutOfCapacity, "nearest point: Detour could not make a query object");
    dtPolyRef polygon = 0;
    Vec3 nearest;
    query->findNearestPoly(inPoint.data(), inSearchExtent.data(), &filter.Value(), &polygon, nearest.data());
    if (polygon == 0)
        return MakeError(ErrorCode::InvalidArgument, "nearest point: no navmesh within the search extent");
    if (IsExcluded(*mNavMesh, polygon, inFilter))
        return MakeError(ErrorCode::InvalidArgument,
                         "nearest point: the nearest navmesh is in an excluded area");
    return nearest;
}

Result<Vec3> NavMeshWorld::FindRandomPointAround(const Vec3& inCenter, float inRadius, uint64_t inSeed,
                                                 const PathFilter& inFilter, const Vec3& inSearchExtent) const
{
    Result<dtQueryFilter> filter = CheckPointQuery(inCenter, inSearchExtent, inFilter, mGrid.GetTileSize(),
                                                   "random point", "the centre");
    if (!filter) return filter.GetError();
    if (Status radius = CheckRadius(inRadius, mGrid.GetTileSize(), "random point"); !radius)
        return radius.GetError();

    std::shared_lock lock(mNavMeshMutex);
    Result<SnappedPoint> centre = SnapQueryPoint(mSerial, *mNavMesh, inCenter, inSearchExtent, filter.Value(),
                                                 inFilter, "random point", "the centre");
    if (!centre) return centre.GetError();
    dtNavMeshQuery* query = centre.Value().mQuery;
    const dtPolyRef start = centre.Value().mPolygon;
    const float* startPoint = centre.Value().mPoint.data();
    // Detour spreads through every polygon the circle touches, excluded areas included (its filter knows only
    // flags, and its spread no costs): a point in an excluded area, or one that can only be reached through
    // one, is drawn again. Unless a crowd's filter has the world mark these areas: the spread then keeps out
    // of them, so every point it draws is reachable without crossing one, and the first draw is taken
    const uint16_t marked = MarkedExclusionFlagLocked(inFilter.mExcludedAreas);
    dtQueryFilter spread = filter.Value();
    spread.setExcludeFlags(marked);
    constexpr int cMaxTries = 16;
    tRandomState = inSeed;
    for (int attempt = 0; attempt < cMaxTries; ++attempt)
    {
        dtPolyRef polygon = 0;
        Vec3 point;
        if (dtStatusFailed(query->findRandomPointAroundCircle(start, startPoint, inRadius, &spread,
                                                              NextRandomFloat, &polygon, point.data())) ||
            polygon == 0)
            return MakeError(ErrorCode::InvalidArgument,
                             "random point: Detour found no polygon around the centre");
        if (IsExcluded(*mNavMesh, polygon, inFilter)) continue;
        if ((inFilter.mExcludedAreas & cAllAreas) == 0 || marked != 0)
            return point; // Detour's spread went there: reachable
        // An excluded area costs so much that the search goes around it if it can; a way that must cross
        // one ends at or before it
        dtPolyRef corridor[cMaxPathPolygons];
        int numPolygons = 0;
        if (dtStatusFailed(query->findPath(start, polygon, startPoint, point.data(), &filter.Value(),
                                           corridor, &numPolygons, cMaxPathPolygons)) ||
            numPolygons == 0 || corridor[numPolygons - 1] != polygon)
            continue;
        if (std::none_of(corridor, corridor + numPolygons,
                         [&](dtPolyRef inPolygon) { return IsExcluded(*mNavMesh, inPolygon, inFilter); }))
            return point;
    }
    return MakeError(ErrorCode::InvalidArgument,
                     "random point: every point drawn was in an excluded area or reachable only through one");
}

Result<NavRaycastHit> NavMeshWorld::Raycast(const Vec3& inStart, const Vec3& inEnd,
                                            const PathFilter& inFilter, const Vec3& inSearchExtent) const
{
    Result<dtQueryFilter> filter =
        CheckPointQuery(inStart, inSearchExtent, inFilter, mGrid.GetTileSize(), "raycast", "the start");
    if (!filter) return filter.GetError();
    if (!IsValidWorldPosition(inEnd))
        return MakeError(ErrorCode::InvalidArgument, "raycast: the end must be finite");

    std::shared_lock lock(mNavMeshMutex);
    Result<SnappedPoint> start = SnapQueryPoint(mSerial, *mNavMesh, inStart, inSearchExtent, filter.Value(),
                                                inFilter, "raycast", "the start");
    if (!start) return start.GetError();
    // The walk's length bounds how long the navmesh stays locked, as the search extent does
    const float maxLength = cMaxSearchExtentTiles * mGrid.GetTileSize();
    const Vec3& from = start.Value().mPoint;
    if (Vec3(inEnd.x() - from.x(), 0.0f, inEnd.z() - from.z()).norm() > maxLength)
        return MakeError(ErrorCode::InvalidArgument, "raycast: the line may be at most " +
                                                         std::to_string(maxLength) +
                                                         " m long across x and z");
    return CastAcrossSurface(*start.Value().mQuery, *mNavMesh, start.Value().mPolygon, from, inEnd,
                             filter.Value(), inFilter);
}

Result<NavWall> NavMeshWorld::FindNearestWall(const Vec3& inPoint, float inMaxRadius,
                                              const PathFilter& inFilter, const Vec3& inSearchExtent) const
{
    Result<dtQueryFilter> filter =
        CheckPointQuery(inPoint, inSearchExtent, inFilter, mGrid.GetTileSize(), "nearest wall", "the point");
    if (!filter) return filter.GetError();
    if (Status radius = CheckRadius(inMaxRadius, mGrid.GetTileSize(), "nearest wall"); !radius)
        return radius.GetError();

    std::shared_lock lock(mNavMeshMutex);
    Result<SnappedPoint> point = SnapQueryPoint(mSerial, *mNavMesh, inPoint, inSearchExtent, filter.Value(),
                                                inFilter, "nearest wall", "the point");
    if (!point) return point.GetError();
    return FindWallAround(*point.Value().mQuery, *mNavMesh, point.Value().mPolygon, point.Value().mPoint,
                          inMaxRadius, filter.Value(), inFilter);
}

Result<OffMeshLinkState> NavMeshWorld::GetOffMeshLinkState(const OffMeshLink& inLink) const
{
    if (!IsValidWorldPosition(inLink.mStart) || !IsValidWorldPosition(inLink.mEnd))
        return MakeError(ErrorCode::InvalidArgument,
                         "off-mesh link state: an end is NaN or outside the world");
    const TileCoord startTile = mGrid.TileAt(inLink.mStart.x(), inLink.mStart.z());
    const TileCoord endTile = mGrid.TileAt(inLink.mEnd.x(), inLink.mEnd.z());
    std::shared_lock lock(mNavMeshMutex);
    const dtNavMesh& navMesh = *mNavMesh;
    const dtMeshTile* tile = navMesh.getTileAt(startTile.mX, startTile.mZ, 0);
    if (tile == nullptr || tile->header == nullptr) return OffMeshLinkState::StartTileMissing;
    const int connection = FindOffMeshConnection(*tile, inLink.mStart, inLink.mEnd);
    if (connection < 0) return OffMeshLinkState::LeftOut;
    const OffMeshLinkJoins joins = GetOffMeshLinkJoins(*tile, connection);
    if (!joins.mStart) return OffMeshLinkState::StartUnjoined;
    if (joins.mEnd) return OffMeshLinkState::Joined;
    const dtMeshTile* end = navMesh.getTileAt(endTile.mX, endTile.mZ, 0);
    return end != nullptr && end->header != nullptr ? OffMeshLinkState::EndUnjoined
                                                    : OffMeshLinkState::EndTileMissing;
}

int NavMeshWorld::GetNumTiles() const
{
    std::shared_lock lock(mNavMeshMutex);
    return int(mTiles.size());
}

bool NavMeshWorld::HasTile(const TileCoord& inTile) const
{
    std::shared_lock lock(mNavMeshMutex);
    return mTiles.contains(inTile);
}

int NavMeshWorld::GetTilePolygonCount(const TileCoord& inTile) const
{
    std::shared_lock lock(mNavMeshMutex);
    auto it = mTiles.find(inTile);
    return it == mTiles.end() ? 0 : it->second.mNumPolygons;
}

void NavMeshWorld::Read(FunctionRef<void(const dtNavMesh&)> inRead) const
{
    std::shared_lock lock(mNavMeshMutex);
    inRead(*mNavMesh);
}

std::map<TileCoord, std::vector<unsigned char>> NavMeshWorld::SnapshotTiles() const
{
    std::shared_lock lock(mNavMeshMutex);
    std::map<TileCoord, std::vector<unsigned char>> tiles;
    const dtNavMesh& navMesh = *mNavMesh;
    for (int i = 0; i < navMesh.getMaxTiles(); ++i)
    {
        const dtMeshTile* tile = navMesh.getTile(i);
        if (tile == nullptr || tile->header == nullptr) continue;
        // The data as built; the navmesh links tiles in place (links, neighbours), so only the part Detour's
        // builder wrote before linking is compared: header, vertices, polygons without their links
        const dtMeshHeader& h = *tile->header;
        std::vector<unsigned char>& out = tiles[{h.x, h.y}];
        const auto* verts = reinterpret_cast<const unsigned char*>(tile->verts);
        out.assign(verts, verts + sizeof(float) * 3 * size_t(h.vertCount));
        for (int p = 0; p < h.polyCount; ++p)
        {
            const dtPoly& poly = tile->polys[p];
            const unsigned char* bytes = reinterpret_cast<const unsigned char*>(poly.verts);
            out.insert(out.end(), bytes, bytes + sizeof(poly.verts));
            out.push_back(poly.vertCount);
            out.push_back(poly.areaAndtype);
        }
    }
    return tiles;
}

} // namespace cairn::navmesh
