#pragma once

// TileScheduler: decides which navmesh tiles exist and keeps them up to date with the physics world.
//  - Needed tiles: those within the radius of an invoker (an AI agent asking for navmesh around itself) and
//    those of kept areas (a streamed-in region, a level being baked). Nearest to an invoker first.
//  - Dirty tiles: a body that matters to the navmesh (see NavMeshInclusion) added, removed, moved by hand,
//    falling asleep or waking makes the tiles its old and new bounds touch dirty (it listens to the physics
//    world's BodyChangeListener). A tile that turns dirty while its job runs is built again afterwards.
//  - Jobs: one per tile on the jobs' BackgroundQueue, at most Settings::mMaxConcurrentJobs at once, over
//    several chunks: (1) broad-phase query and the static bodies' triangles, (2) the other bodies' triangles,
//    retried in a later chunk while the physics step holds them, (3) Recast and Detour. No chunk waits for a
//    lock held by the step.
//  - Update, once a frame at the game's sync point: starts jobs, takes finished tiles and drops tiles no
//    invoker needed for mDropDelayFrames frames (tiles of a removed area at once), and hands both to the
//    NavMeshWorld in one call (NavMeshWorld::Publish).
//
// Threads: Update on one thread (the game's), never inside the physics step; invokers, areas and MarkDirty
// from any thread; OnBodyChanged on whatever thread changes a body (the physics listener contract).
// mMutex guards every member below it; it is a leaf lock (held while a body lock is held, never the other
// way round), held only for bookkeeping, never while waiting for a job or for the navmesh.
// The scheduler registers itself as the body manager's change listener: create and destroy it while no other
// thread is changing bodies.

#include "cairn/jobs/BackgroundQueue.h"
#include "cairn/navmesh/GeometryCollector.h"
#include "cairn/navmesh/NavMeshWorld.h"
#include "cairn/physics/PhysicsSystem.h"

#include <memory>
#include <mutex>
#include <optional>
#include <unordered_map>
#include <vector>

namespace cairn::navmesh
{
using namespace cairn::physics;

class TileJob;

class TileScheduler final : public BodyChangeListener
{
public:
    struct Settings
    {
        NavMeshInclusion mInclusion;
        uint32_t mMaxConcurrentJobs = 2; ///< Tile jobs running at once (the job budget; 0 counts as 1)
        uint32_t mDropDelayFrames = 120; ///< A tile no invoker needs is dropped after this many frames
        int mJobPriority = 0;            ///< On the background queue (higher runs first)
    };

    struct Stats
    {
        uint64_t mJobsStarted = 0;
        uint64_t mJobsFailed = 0;
        uint64_t mTilesPublished = 0; ///< Tiles swapped into the navmesh (built or emptied)
        uint64_t mTilesDropped = 0;
        uint64_t mRebuilds = 0; ///< Builds of a tile that was already built (dirty again)
        double mCollectMs = 0;  ///< Summed over jobs: query and triangle copies
        double mBuildMs = 0;    ///< Summed over jobs: Recast and Detour
        /// Frames from a tile being needed to its first publication, one entry per tile
        std::vector<uint32_t> mFirstPublishFrames;
        std::vector<TileCoord> mFirstPublishTiles; ///< The tile of each entry above
        std::string mLastError;
    };

    using InvokerID = uint32_t;
    using AreaID = uint32_t;

    TileScheduler(PhysicsSystem& ioPhysics, NavMeshWorld& ioWorld, jobs::BackgroundQueue& ioQueue,
                  const Settings& inSettings);
    /// Cancels running jobs and waits for them; unregisters the listener.
    ~TileScheduler() override;
    TileScheduler(const TileScheduler&) = delete;
    TileScheduler& operator=(const TileScheduler&) = delete;

    /// The tiles an invoker needs are looked for in a square around the tile it stands in, at most this many
    /// tiles across (4096 tiles) wherever it moves: a real engine's budget, and what AddInvoker's radius
    /// limit keeps to.
    static constexpr int cMaxInvokerTilesAcross = 64;
    /// Tiles an invoker's radius may reach from the tile it stands in, rounded up: the square has one more
    /// on each side for a radius ending on a tile's edge. 30 tiles: 384 m on the default 12.8 m tiles.
    static constexpr int cMaxInvokerReachTiles = (cMaxInvokerTilesAcross - 3) / 2;
    /// The most tiles one kept area may overlap (256 x 256); a larger area is refused, not cut off.
    static constexpr uint64_t cMaxAreaTiles = 65536;

    /// Invokers: the tiles within inRadius (x-z distance from inPosition) are kept built. Any thread. Error
    /// for a position outside the world, a radius that is not in [0, 1e5] m, or one that reaches more than
    /// cMaxInvokerReachTiles tiles (the error names the limit in metres).
    Result<InvokerID> AddInvoker(const Vec3& inPosition, float inRadius);
    /// Error (and the invoker stays where it was) for an unknown invoker or a position that is NaN or outside
    /// the world. The radius keeps to the limit wherever the invoker goes: it never needs more tiles than are
    /// looked for.
    Status MoveInvoker(InvokerID inInvoker, const Vec3& inPosition);
    /// Error for an unknown invoker (never added, or removed already).
    Status RemoveInvoker(InvokerID inInvoker);
    /// Areas: every tile overlapping inBounds is kept built until RemoveArea, which drops them at once
    /// (unless an invoker or another area still needs them). Any thread.
    /// Error for bounds outside the world, empty, or overlapping more than cMaxAreaTiles tiles.
    Result<AreaID> AddArea(const AABB& inBounds);
    /// Error for an unknown area (never added, or removed already).
    Status RemoveArea(AreaID inArea);

    /// Off-mesh links (jumps, ladders): built into the tile that holds the start; adding or removing one
    /// makes that tile dirty. Any thread.
    using LinkID = uint32_t;
    /// Error for an end outside the world, an end more than a tile from the start's tile (Detour would never
    /// join it), a radius not in (0, 1e3] m or an area over cMaxAreaId (the tile build would refuse the whole
    /// tile).
    Result<LinkID> AddOffMeshLink(const OffMeshLink& inLink);
    void RemoveOffMeshLink(LinkID inLink);
    /// Where a link stands in the world's navmesh (NavMeshWorld::GetOffMeshLinkState), or Pending while its
    /// start's tile waits for a build that takes it in (dirty, or its job not yet published): a link no agent
    /// can take, since an end joins no polygon, is otherwise never told. Error for an unknown link. Any
    /// thread.
    Result<OffMeshLinkState> GetOffMeshLinkState(LinkID inLink) const;

    /// Marks the tiles inBounds touches dirty (for changes the physics world does not report). Any thread.
    void MarkDirty(const AABB& inBounds);
    /// BodyChangeListener: marks the tiles of a body that matters dirty.
    void OnBodyChanged(const BodyChange& inChange) override;

    /// Once a frame, outside the physics step: see above. Returns the number of tiles published.
    int Update();
    /// True when every needed tile is built, clean and published, and no job runs.
    bool IsIdle() const;
    /// Needed tiles that have never been published (being built, or waiting for the budget).
    uint32_t CountNeededNeverPublished() const;
    Stats GetStats() const;
    /// Update calls so far: the scheduler's frame. Any thread.
    uint64_t GetFrame() const;
    /// A tile's last publication: the frame whose Update started the build that was published, and the frame
    /// whose Update published it. A build collects its geometry after the Update that starts it, so a change
    /// made before Update N (by the step before it, or by a call) is in every build started at frame N or
    /// later: its latency to the navmesh is to the first publication with mBuildStartFrame >= N.
    struct Publication
    {
        uint64_t mBuildStartFrame = 0;
        uint64_t mPublishFrame = 0;
    };
    /// Nothing for a tile not kept (never needed, or dropped) or never published. Any thread.
    std::optional<Publication> GetLastPublication(const TileCoord& inTile) const;
    /// Jobs started and not yet taken in by Update.
    uint32_t GetNumRunningJobs() const;
    /// True when a job has finished and waits for the next Update to publish its tile.
    bool HasFinishedJobs() const;
    const Settings& GetSettings() const { return mSettings; }

private:
    struct TileState
    {
        bool mDirty = true; ///< Needs a build (set again while a job runs: built once more)
        bool mEverPublished = false;
        uint64_t mNeededSinceFrame = 0; ///< For the first-publication latency
        uint64_t mLastNeededFrame = 0;
        uint64_t mJobStartFrame = 0;             ///< Of the running job
        std::optional<Publication> mPublication; ///< The last one
        std::shared_ptr<TileJob> mJob;           ///< Running job, or null
        std::shared_ptr<jobs::BackgroundTask> mTask;
    };
    struct Invoker
    {
        Vec3 mPosition;
        float mRadius;
    };

    /// Tiles the invokers and areas need now, with the x-z distance to the nearest invoker (areas: 0).
    void CollectNeeded(std::unordered_map<TileCoord, float>& outNeeded) const;
    /// The tiles within an invoker's radius, each with its x-z distance (the nearest invoker's is kept).
    void CollectInvokerTiles(const Invoker& inInvoker, std::unordered_map<TileCoord, float>& ioNeeded) const;
    void MarkDirtyLocked(const AABB& inBounds);
    void StartJob(const TileCoord& inTile, TileState& ioState);
    /// Adds a finished job's tile to ioChanges (this frame's Publish); false while the job still runs.
    bool CollectFinished(const TileCoord& inTile, TileState& ioState, std::vector<BuiltTile>& ioChanges);

    PhysicsSystem& mPhysics;
    NavMeshWorld& mWorld;
    jobs::BackgroundQueue& mQueue;
    const Settings mSettings;
    const GeometryCollector mCollector;
    const float mBorder; ///< m of geometry around a tile that its build reads

    mutable std::mutex mMutex;
    uint64_t mFrame = 0;
    std::unordered_map<TileCoord, TileState> mTiles;
    std::unordered_map<InvokerID, Invoker> mInvokers;
    std::unordered_map<AreaID, AABB> mAreas;
    std::unordered_map<LinkID, OffMeshLink> mLinks;
    uint32_t mNextID = 1;
    std::vector<TileCoord> mDropNow; ///< Tiles of removed areas, checked at the next Update
    Stats mStats;
    uint64_t mRefusedSeen = 0; ///< NavMeshWorld's refused tiles already counted in mStats; Update's thread
};

} // namespace cairn::navmesh
