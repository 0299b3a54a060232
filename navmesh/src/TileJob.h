#pragma once

// TileJob: one tile's build, run chunk by chunk on a BackgroundQueue thread (see TileScheduler.h):
//   chunk 1: broad-phase query of the bordered tile box, then the bodies' triangles at their published poses
//            (no lock: never waits for the step, never tries again);
//   chunk 2: Recast and Detour.
// Its fields are written only by the queue thread running it; the scheduler reads the result after seeing
// mFinished (acquire, paired with the release that sets it).

#include "cairn/jobs/BackgroundQueue.h"
#include "cairn/navmesh/GeometryCollector.h"
#include "cairn/navmesh/TileBuilder.h"

#include <atomic>
#include <optional>

namespace cairn::navmesh
{
using namespace cairn::physics;

class TileJob
{
public:
    /// inLinks: the off-mesh links that start in the tile (copied: the job owns what it reads).
    TileJob(const GeometryCollector& inCollector, const AgentProfile& inProfile, const TileGrid& inGrid,
            const NavMeshInclusion& inInclusion, const TileCoord& inTile, float inBorder,
            std::vector<OffMeshLink> inLinks)
        : mCollector(inCollector), mProfile(inProfile), mGrid(inGrid), mInclusion(inInclusion), mTile(inTile),
          mBox(inGrid.GetTileBoundsWithBorder(inTile, inBorder)), mLinks(std::move(inLinks))
    {
    }

    /// The BackgroundQueue step function.
    jobs::BackgroundStep Step(jobs::BackgroundTaskContext& ioContext);

    bool IsFinished() const { return mFinished.load(std::memory_order_acquire); } // Pairs with Finish
    /// After IsFinished: the tile, or why it failed (empty optional: cancelled).
    std::optional<Result<BuiltTile>>& GetResult() { return mResult; }
    const CollectStats& GetCollectStats() const { return mStats; }

private:
    enum class Stage : uint8_t
    {
        Collect,
        Build,
    };
    jobs::BackgroundStep Finish(std::optional<Result<BuiltTile>> inResult, jobs::BackgroundStep inStep);

    const GeometryCollector& mCollector;
    const AgentProfile& mProfile;
    const TileGrid& mGrid;
    const NavMeshInclusion mInclusion;
    const TileCoord mTile;
    const AABB mBox;
    const std::vector<OffMeshLink> mLinks;
    Stage mStage = Stage::Collect;
    std::vector<BodyID> mBodies;
    TileGeometry mGeometry;
    CollectStats mStats;
    std::optional<Result<BuiltTile>> mResult;
    std::atomic<bool> mFinished{false};
};

} // namespace cairn::navmesh
