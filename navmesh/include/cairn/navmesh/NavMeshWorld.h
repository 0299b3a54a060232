#pragma once

// NavMeshWorld: stage 4, the published navmesh. Owns a tiled Detour dtNavMesh on a TileGrid and answers path
// queries from any thread.
//
// Detour's navmesh is not thread-safe, so tiles are published at a sync point: the finished tiles reach the
// world in one hand-off, Publish(changes), called once a frame by the game's sync point (TileScheduler::
// Update collects the tile jobs' results and the tiles it drops, then calls it), which swaps them all in
// under mNavMeshMutex held exclusively. Path queries hold mNavMeshMutex shared for their whole length, so a
// query never sees a half-added tile: it sees the navmesh as of the last Publish. The one other writer is a
// crowd's filter marking the polygons of its excluded areas in their flags (AcquireExclusionFlag), under
// mNavMeshMutex held exclusively as well. Each thread keeps its own dtNavMeshQuery (Detour's query objects
// hold per-query scratch). mNavMeshMutex is never held while a body lock is taken.

#include "cairn/navmesh/TileBuilder.h"
#include "cairn/navmesh/TileGrid.h"
#include "cairn/physics/math/FunctionRef.h"
#include "cairn/physics/math/Result.h"

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <shared_mutex>
#include <span>
#include <string>
#include <vector>

class dtNavMesh;

namespace cairn::navmesh
{
using namespace cairn::physics;

/// Which areas a path may cross and what each costs (a multiplier on distance).
struct PathFilter
{
    PathFilter() { mAreaCost.fill(1.0f); }
    std::array<float, cMaxAreaId + 1> mAreaCost; ///< Per Cairn area id
    uint64_t mExcludedAreas = 0;                 ///< Bit per area id: never crossed
};

struct PathResult
{
    bool mReachedEnd = false; ///< False: the path ends at the reachable point nearest the end
    /// The search ran out of its nodes or its corridor's room before it reached the end: the path goes that
    /// way but may stop short of an end that can be reached (ask again from farther on)
    bool mSearchLimited = false;
    int mNumPolygons = 0;            ///< Length of the polygon corridor
    std::vector<Vec3> mStraightPath; ///< Corner points from start to (reachable) end
    /// The polygon corridor, Detour polygon references from the start's polygon on: valid until a Publish
    /// changes a tile they are in (a crowd follows them; anyone else may ignore them)
    std::vector<uint64_t> mPolygons;
};

/// Where a NavMeshWorld::Raycast stopped.
struct NavRaycastHit
{
    /// True when a wall stopped it short of the end: the navmesh's edge (a wall, a drop, the edge of the
    /// loaded tiles) or the border of an area the filter excludes
    bool mHit = false;
    /// How far it went, as a fraction of the way from the (snapped) start to the end across x and z: 1
    /// without a hit
    float mFraction = 1.0f;
    /// Where it stopped, on the navmesh (at its detail height): the wall's point, or the end's point on the
    /// navmesh under the end
    Vec3 mPosition = Vec3::Zero();
    /// The wall's normal, level and towards the start's side (zero without a hit)
    Vec3 mWallNormal = Vec3::Zero();
};

/// The wall nearest a point on the navmesh, found by NavMeshWorld::FindNearestWall.
struct NavWall
{
    bool mFound = false;           ///< False: no wall within the radius (the rest is then zero)
    float mDistance = 0.0f;        ///< Across x and z, from the (snapped) point
    Vec3 mPosition = Vec3::Zero(); ///< The wall's nearest point, on the navmesh's polygon edge
    Vec3 mNormal = Vec3::Zero();   ///< Level, from the wall towards the point
};

/// Where an off-mesh link stands in the published navmesh (NavMeshWorld::GetOffMeshLinkState).
enum class OffMeshLinkState : uint8_t
{
    /// A TileScheduler's answer only: its start's tile waits for a build that takes the link in
    Pending,
    StartTileMissing, ///< The tile its start lies in is not published
                      /// Its start's tile is published without it: built before it was declared, or Detour's
                      /// tile builder left it out (its start above or below the tile's navmesh)
    LeftOut,
    StartUnjoined,  ///< No polygon of its tile within its radius of its start (and the climb): never taken
    EndTileMissing, ///< Its start joined; the tile its end lies in is not published (joined once it is)
    EndUnjoined,    ///< Its start joined; no polygon within its radius of its end: never taken
    Joined,         ///< Agents can take it
};

class NavMeshWorld
{
public:
    /// inMaxTiles: how many tiles may be loaded at once (a power of two is best).
    static Result<std::unique_ptr<NavMeshWorld>> Create(const TileGrid& inGrid, const AgentProfile& inProfile,
                                                        int inMaxTiles = 4096);
    ~NavMeshWorld();
    NavMeshWorld(const NavMeshWorld&) = delete;
    NavMeshWorld& operator=(const NavMeshWorld&) = delete;

    const TileGrid& GetGrid() const { return mGrid; }
    const AgentProfile& GetProfile() const { return mProfile; }

    /// A change for Publish that removes inTile (a BuiltTile without data).
    static BuiltTile Removal(const TileCoord& inTile);
    /// The sync point: swaps inChanges in, each a built tile or a Removal (of tiles listed twice, the last
    /// wins). Returns how many tiles changed (a replaced tile counts its removal and its addition). Any
    /// thread, but meant for one place in the frame; it waits for path queries in progress. A tile Detour
    /// cannot take is refused: data that is not a whole, consistent
    /// Detour tile (CheckTileData), data of another tile than the one it was submitted as, more polygons than
    /// a tile reference holds, or no free tile slot. The tile already there stays, and the refusal is counted
    /// (GetRefusedTiles).
    int Publish(std::vector<BuiltTile>&& inChanges);
    /// Tiles Publish refused so far, and why the last one was. Any thread.
    uint64_t GetRefusedTiles(std::string* outLastReason = nullptr) const;

    /// Largest search extent of FindPath in x and z, in tiles.
    static constexpr float cMaxSearchExtentTiles = 4.0f;

    /// A path for an agent from inStart to inEnd (each snapped to the navmesh within inSearchExtent, at most
    /// cMaxSearchExtentTiles tiles in x and z). Error when either point is off the navmesh or not finite. Any
    /// thread.
    Result<PathResult> FindPath(const Vec3& inStart, const Vec3& inEnd, const PathFilter& inFilter = {},
                                const Vec3& inSearchExtent = Vec3(2.0f, 4.0f, 2.0f)) const;

    /// The navmesh point nearest inPoint within inSearchExtent (half extents; at most cMaxSearchExtentTiles
    /// tiles in x and z), as FindPath snaps its ends: to pick a goal an agent can stand on. Error when no
    /// polygon is within the extent, when the nearest one is in an area inFilter excludes, and for bad
    /// numbers. Any thread.
    Result<Vec3> FindNearestPoint(const Vec3& inPoint, const PathFilter& inFilter = {},
                                  const Vec3& inSearchExtent = Vec3(2.0f, 4.0f, 2.0f)) const;
    /// A random navmesh point reachable from inCenter (snapped within inSearchExtent) through the polygons
    /// that the circle of inRadius around it touches: the wander goal of an agent. Polygons are chosen in
    /// proportion to their area, so the point may lie up to one polygon beyond inRadius (Detour's
    /// findRandomPointAroundCircle). The same inSeed on the same navmesh (same tiles, published in the same
    /// order) gives the same point. With areas inFilter excludes, the point is in none of them and FindPath
    /// reaches it without crossing one, perhaps around them outside the circle (a few draws, each checked by
    /// a path search, then an error); where a crowd's filter has the world mark those areas (Crowd::
    /// SetFilter), Detour's spread keeps out of them itself: one draw, no search, and for a seed another
    /// point than without the marks.
    /// Error when inCenter is off the navmesh or in an excluded area, inRadius is not in (0,
    /// cMaxSearchExtentTiles tiles], or a number is bad. Any thread.
    Result<Vec3> FindRandomPointAround(const Vec3& inCenter, float inRadius, uint64_t inSeed,
                                       const PathFilter& inFilter = {},
                                       const Vec3& inSearchExtent = Vec3(2.0f, 4.0f, 2.0f)) const;

    /// Walks a straight line across the navmesh's surface from inStart (snapped within inSearchExtent)
    /// towards inEnd, as an agent walking straight there would, and says where it stops: whether an agent can
    /// walk straight from one to the other (line of sight across the surface, on Detour's raycast). The line
    /// is cast across x and z and follows the surface over slopes and up steps; inEnd's height picks nothing.
    /// It stops at the navmesh's edge and at the border of an area inFilter excludes, never takes an off-mesh
    /// link, and goes on where Detour's own raycast stops for no wall (a line along a tile's border or
    /// through its corner). It may be at most cMaxSearchExtentTiles tiles long across x and z. Error when
    /// inStart is off the navmesh or in an excluded area, the line is too long or crosses more polygons than
    /// a path holds, or a number is bad. Any thread.
    Result<NavRaycastHit> Raycast(const Vec3& inStart, const Vec3& inEnd, const PathFilter& inFilter = {},
                                  const Vec3& inSearchExtent = Vec3(2.0f, 4.0f, 2.0f)) const;
    /// The wall nearest inPoint (snapped within inSearchExtent) across x and z, within inMaxRadius: the
    /// navmesh's edge or the border of an area inFilter excludes. Only the navmesh an agent there could walk
    /// to inside the circle counts (Detour's findPolysAroundCircle from the point's polygon), never what lies
    /// past an excluded area or an off-mesh link: a roof above the point, reached by a jump, has no wall for
    /// it. Where no area is excluded it answers as Detour's findDistanceToWall. Not found (mFound false) when
    /// no wall is within inMaxRadius. Error when inPoint is off the navmesh or in an excluded area,
    /// inMaxRadius is not in (0, cMaxSearchExtentTiles tiles], the circle holds more polygons than a query
    /// can visit, or a number is bad. Any thread.
    Result<NavWall> FindNearestWall(const Vec3& inPoint, float inMaxRadius, const PathFilter& inFilter = {},
                                    const Vec3& inSearchExtent = Vec3(2.0f, 4.0f, 2.0f)) const;

    /// Whether inLink, as declared for a tile build (TileScheduler::AddOffMeshLink), is in the navmesh and
    /// joined at both ends (OffMeshLinkJoins.h): Detour says nothing of a link it left unjoined. Error for a
    /// position that is not a valid world position. Any thread.
    Result<OffMeshLinkState> GetOffMeshLinkState(const OffMeshLink& inLink) const;

    /// Published tiles.
    int GetNumTiles() const;
    bool HasTile(const TileCoord& inTile) const;
    /// Polygons of a published tile (0 when absent).
    int GetTilePolygonCount(const TileCoord& inTile) const;
    /// Calls inRead with the published Detour navmesh, under the navmesh mutex held shared (a Publish waits
    /// for it): to draw or export it (NavMeshPreview's NavMeshToObj, NavMeshToSvg). inRead must not call
    /// this world. Any thread.
    void Read(FunctionRef<void(const dtNavMesh&)> inRead) const;
    /// A copy of every published tile's Detour data, by tile: to compare two navmeshes.
    std::map<TileCoord, std::vector<unsigned char>> SnapshotTiles() const;

private:
    /// A tile Detour holds. Its data is added without DT_TILE_FREE_DATA, so the world frees it, after Detour
    /// has let go: a replaced tile's data can go back when Detour refuses its successor.
    struct PublishedTile
    {
        uint64_t mRef = 0; ///< Its dtTileRef (whose width is Detour's build option)
        int mNumPolygons = 0;
        int mDataSize = 0;
        TileDataPtr mData; ///< Null only in a moved-from tile
    };

    NavMeshWorld(const TileGrid& inGrid, const AgentProfile& inProfile);

    friend class Crowd; // Its path filters' excluded areas become polygon flags (AcquireExclusionFlag)
    /// The polygon flag bit that marks the polygons of the areas inAreas (0: none, for no areas). A Detour
    /// filter that excludes the bit keeps every Detour call out of those areas (a move along the surface, a
    /// raycast, the walls gathered), where the prohibitive cost MakeDetourFilter gives them binds the
    /// searches alone. The same areas get the same bit, counted; other areas a bit no one holds, marked on
    /// every published polygon at once under the exclusive lock (as a Publish marks the polygons it adds).
    /// Const: the navmesh keeps its shape; only the bit's holders and FindRandomPointAround's draws for these
    /// areas see the marks. inAreas' bits above cMaxAreaId are no area's, ignored. inReleased: a bit the
    /// caller lets go of first (0: none), in the same step, so a filter replaced when every bit is held can
    /// take its own; kept when there is no bit for inAreas. OutOfCapacity when cMaxExclusionFlags other area
    /// sets are held. Any thread, never inside a Read.
    Result<uint16_t> AcquireExclusionFlag(uint64_t inAreas, uint16_t inReleased = 0) const;
    /// Lets go of a bit AcquireExclusionFlag gave (0: nothing). Any thread, never inside a Read.
    void ReleaseExclusionFlag(uint16_t inFlag) const;
    /// The flag marking exactly inAreas' polygons now, held or not (0: none). The mutex held, shared or
    /// exclusive: a query may exclude it while it holds the mutex.
    uint16_t MarkedExclusionFlagLocked(uint64_t inAreas) const;
    /// Polygon flag bits 1 to 15: bit 0 is cPolyFlagWalk, which every polygon has
    static constexpr int cMaxExclusionFlags = 15;
    static constexpr uint16_t cExclusionFlagBits = 0xfffe;
    static constexpr uint64_t cAllAreas = (uint64_t(1) << (cMaxAreaId + 1)) - 1;
    struct ExclusionFlag
    {
        uint64_t mAreas = 0; ///< The areas its bit marks (0: never given); kept after the last holder goes
        int mHolders = 0;
    };

    /// Empty when Detour can take inTile (data not null) at inCoord, else why not. No lock: it reads the tile
    /// and mMaxTilePolygons only.
    std::string CheckTile(const TileCoord& inCoord, const BuiltTile& inTile) const;
    // Publish's steps, with mNavMeshMutex held exclusively. Each returns how many tiles changed.
    int RemoveTileLocked(const TileCoord& inCoord);
    /// Swaps a checked tile in for the one at inCoord; when Detour refuses it, the old one goes back.
    int ReplaceTileLocked(const TileCoord& inCoord, BuiltTile& ioTile);
    void RefuseLocked(const TileCoord& inCoord, const std::string& inWhy);

    const TileGrid mGrid;
    const AgentProfile mProfile;
    const uint64_t mSerial;                  ///< Tells apart worlds for the per-thread query objects
    mutable std::shared_mutex mNavMeshMutex; ///< Exclusive: Publish, exclusion flags; shared: queries
    dtNavMesh* mNavMesh = nullptr;           ///< Guarded by mNavMeshMutex
    int mMaxTilePolygons = 0; ///< Detour's polygons per tile reference: set by Create, read-only after
    /// Guarded by mNavMeshMutex; exactly the tiles mNavMesh holds (each at its own coordinate, layer 0)
    std::map<TileCoord, PublishedTile> mTiles;
    uint64_t mRefusedTiles = 0; ///< Guarded by mNavMeshMutex
    /// Bit b + 1 of a published polygon's flags is set exactly where [b].mAreas holds its area. Guarded by
    /// mNavMeshMutex: written exclusively (acquire, release), read by Publish
    mutable std::array<ExclusionFlag, cMaxExclusionFlags> mExclusionFlags{};
    std::string mLastRefusal; ///< Guarded by mNavMeshMutex
};

} // namespace cairn::navmesh
