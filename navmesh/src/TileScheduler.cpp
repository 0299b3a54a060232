#include "cairn/navmesh/TileScheduler.h"

#include "TileJob.h"

#include <algorithm>
#include <cmath>

namespace cairn::navmesh
{
using namespace cairn::physics;

namespace
{
/// Tiles an invoker's radius reaches from the tile it stands in, rounded up (in double: a tiny tile size
/// would overflow an int).
double ReachInTiles(float inRadius, float inTileSize)
{
    return std::ceil(double(inRadius) / double(inTileSize));
}

Error InvalidInvokerPosition()
{
    return MakeError(ErrorCode::InvalidArgument, "navmesh invoker: position is NaN or outside the world");
}

Error UnknownInvoker(TileScheduler::InvokerID inInvoker)
{
    return MakeError(ErrorCode::InvalidArgument, "navmesh invoker " + std::to_string(inInvoker) +
                                                     " is unknown (never added, or removed)");
}
} // namespace

TileScheduler::TileScheduler(PhysicsSystem& ioPhysics, NavMeshWorld& ioWorld, jobs::BackgroundQueue& ioQueue,
                             const Settings& inSettings)
    : mPhysics(ioPhysics), mWorld(ioWorld), mQueue(ioQueue), mSettings(inSettings),
      mCollector(ioPhysics.GetBodyManager(), ioPhysics.GetBroadPhase()),
      mBorder(float(ioWorld.GetProfile().GetBorderCells()) * ioWorld.GetProfile().mCellSize)
{
    // Several schedulers (a navmesh per agent profile) may listen to one world: each adds itself
    if (!mPhysics.AddBodyChangeListener(this))
        mStats.mLastError = "the physics world has no room for another body change listener: bodies that "
                            "change will not make their tiles dirty";
}

TileScheduler::~TileScheduler()
{
    mPhysics.RemoveBodyChangeListener(this);
    std::vector<std::shared_ptr<jobs::BackgroundTask>> tasks;
    {
        std::lock_guard lock(mMutex);
        for (auto& [tile, state] : mTiles)
            if (state.mTask != nullptr) tasks.push_back(state.mTask);
    }
    // The jobs read the physics world and this scheduler's collector: they must be over before either goes
    for (const std::shared_ptr<jobs::BackgroundTask>& task : tasks)
        task->Cancel();
    for (const std::shared_ptr<jobs::BackgroundTask>& task : tasks)
        while (!task->Wait(std::chrono::milliseconds(100)))
        {
        }
}

Result<TileScheduler::InvokerID> TileScheduler::AddInvoker(const Vec3& inPosition, float inRadius)
{
    if (!IsValidWorldPosition(inPosition)) return InvalidInvokerPosition();
    if (!(inRadius >= 0.0f && inRadius <= 1e5f))
        return MakeError(ErrorCode::InvalidArgument, "navmesh invoker: radius must be in [0, 1e5] m");
    // Checked here, not where the tiles are looked for: a radius that reached further would silently need
    // none of the tiles past the square, or, cut off, none at all
    // In double, where 30 tile sizes are exact: a radius at the limit is taken, and then reaches 30 tiles
    const double maxRadius = double(cMaxInvokerReachTiles) * double(mWorld.GetGrid().GetTileSize());
    if (double(inRadius) > maxRadius)
        return MakeError(ErrorCode::InvalidArgument,
                         "navmesh invoker: a radius of " + std::to_string(inRadius) + " m is over the " +
                             std::to_string(maxRadius) + " m (" + std::to_string(cMaxInvokerReachTiles) +
                             " tiles) an invoker may reach: its tiles are looked for in at most " +
                             std::to_string(cMaxInvokerTilesAcross) + " x " +
                             std::to_string(cMaxInvokerTilesAcross) + " tiles");
    std::lock_guard lock(mMutex);
    const InvokerID id = mNextID++;
    mInvokers[id] = {inPosition, inRadius};
    return id;
}

Status TileScheduler::MoveInvoker(InvokerID inInvoker, const Vec3& inPosition)
{
    if (!IsValidWorldPosition(inPosition)) return InvalidInvokerPosition();
    std::lock_guard lock(mMutex);
    auto it = mInvokers.find(inInvoker);
    if (it == mInvokers.end()) return UnknownInvoker(inInvoker);
    it->second.mPosition = inPosition;
    return Status::Ok();
}

Status TileScheduler::RemoveInvoker(InvokerID inInvoker)
{
    std::lock_guard lock(mMutex);
    if (mInvokers.erase(inInvoker) == 0) return UnknownInvoker(inInvoker);
    return Status::Ok();
}

Result<TileScheduler::AreaID> TileScheduler::AddArea(const AABB& inBounds)
{
    if (!IsValidWorldPosition(inBounds.mMin) || !IsValidWorldPosition(inBounds.mMax) || inBounds.IsEmpty())
        return MakeError(ErrorCode::InvalidArgument,
                         "navmesh area: bounds must be inside the world, min <= max");
    // Its tiles are listed with this cut-off (CollectNeeded, RemoveArea): a larger area would need none
    if (const uint64_t tiles = mWorld.GetGrid().CountTilesOverlapping(inBounds, 0.0f); tiles > cMaxAreaTiles)
        return MakeError(ErrorCode::InvalidArgument,
                         "navmesh area: it overlaps " + std::to_string(tiles) + " tiles, more than the " +
                             std::to_string(cMaxAreaTiles) + " one area may keep: split it");
    std::lock_guard lock(mMutex);
    const AreaID id = mNextID++;
    mAreas[id] = inBounds;
    return id;
}

Status TileScheduler::RemoveArea(AreaID inArea)
{
    std::lock_guard lock(mMutex);
    auto it = mAreas.find(inArea);
    if (it == mAreas.end())
        return MakeError(ErrorCode::InvalidArgument,
                         "navmesh area " + std::to_string(inArea) + " is unknown (never added, or removed)");
    (void)mWorld.GetGrid().TilesOverlapping(it->second, 0.0f, mDropNow, cMaxAreaTiles); // AddArea checked
    mAreas.erase(it);
    return Status::Ok();
}

Result<TileScheduler::LinkID> TileScheduler::AddOffMeshLink(const OffMeshLink& inLink)
{
    if (!IsValidWorldPosition(inLink.mStart) || !IsValidWorldPosition(inLink.mEnd))
        return MakeError(ErrorCode::InvalidArgument, "off-mesh link: an end is NaN or outside the world");
    if (!(inLink.mRadius > 0.0f && inLink.mRadius <= 1e3f))
        return MakeError(ErrorCode::InvalidArgument, "off-mesh link: radius must be in (0, 1e3] m");
    if (inLink.mArea > cMaxAreaId)
        return MakeError(ErrorCode::InvalidArgument, "off-mesh link: area " + std::to_string(inLink.mArea) +
                                                         " is over " + std::to_string(cMaxAreaId));
    // Detour joins a link's end in its start's tile and the eight around it only: farther, it never would
    const TileGrid& grid = mWorld.GetGrid();
    if (!TileGrid::AreNeighbours(grid.TileAt(inLink.mStart.x(), inLink.mStart.z()),
                                 grid.TileAt(inLink.mEnd.x(), inLink.mEnd.z())))
        return MakeError(
            ErrorCode::InvalidArgument,
            "off-mesh link: its end is more than a tile from its start's tile, where Detour never "
            "joins it");
    std::lock_guard lock(mMutex);
    const LinkID id = mNextID++;
    mLinks[id] = inLink;
    if (auto it = mTiles.find(mWorld.GetGrid().TileAt(inLink.mStart.x(), inLink.mStart.z()));
        it != mTiles.end())
        it->second.mDirty = true;
    return id;
}

void TileScheduler::RemoveOffMeshLink(LinkID inLink)
{
    std::lock_guard lock(mMutex);
    auto link = mLinks.find(inLink);
    if (link == mLinks.end()) return;
    if (auto it = mTiles.find(mWorld.GetGrid().TileAt(link->second.mStart.x(), link->second.mStart.z()));
        it != mTiles.end())
        it->second.mDirty = true;
    mLinks.erase(link);
}

Result<OffMeshLinkState> TileScheduler::GetOffMeshLinkState(LinkID inLink) const
{
    OffMeshLink link;
    {
        std::lock_guard lock(mMutex);
        auto found = mLinks.find(inLink);
        if (found == mLinks.end())
            return MakeError(ErrorCode::InvalidArgument, "off-mesh link: no such link");
        link = found->second;
        auto tile = mTiles.find(mWorld.GetGrid().TileAt(link.mStart.x(), link.mStart.z()));
        if (tile != mTiles.end() && (tile->second.mDirty || tile->second.mJob != nullptr))
            return OffMeshLinkState::Pending;
    }
    // The navmesh's lock is never taken under mMutex
    return mWorld.GetOffMeshLinkState(link);
}

void TileScheduler::MarkDirty(const AABB& inBounds)
{
    std::lock_guard lock(mMutex);
    MarkDirtyLocked(inBounds);
}

void TileScheduler::MarkDirtyLocked(const AABB& inBounds)
{
    if (inBounds.IsEmpty()) return;
    thread_local std::vector<TileCoord> touched;
    touched.clear();
    // A body changes every tile whose build reads its geometry: those whose bordered box it overlaps
    if (!mWorld.GetGrid().TilesOverlapping(inBounds, mBorder, touched))
    {
        // Bounds too large to list (a huge body): every known tile is dirty
        for (auto& [tile, state] : mTiles)
            state.mDirty = true;
        return;
    }
    for (const TileCoord& tile : touched)
        if (auto it = mTiles.find(tile); it != mTiles.end()) it->second.mDirty = true;
}

void TileScheduler::OnBodyChanged(const BodyChange& inChange)
{
    const NavMeshInclusion& inclusion = mSettings.mInclusion;
    if ((inclusion.mObjectLayers & ObjectLayerMask(1) << inChange.mObjectLayer) == 0) return;
    // Dynamic bodies: falling asleep, waking, or being placed or removed changes the navmesh of the tiles
    // that take sleeping ones, or awake ones too
    const bool matters = inChange.mMotionType == MotionType::Static ||
                         (inChange.mMotionType == MotionType::Dynamic &&
                          (inclusion.mSleepingDynamic || inclusion.mAwakeDynamic)) ||
                         (inChange.mMotionType == MotionType::Kinematic && inclusion.mKinematic);
    if (!matters) return;
    std::lock_guard lock(mMutex);
    MarkDirtyLocked(inChange.mOldBounds);
    MarkDirtyLocked(inChange.mNewBounds);
}

void TileScheduler::CollectNeeded(std::unordered_map<TileCoord, float>& outNeeded) const
{
    for (const auto& [id, invoker] : mInvokers)
        CollectInvokerTiles(invoker, outNeeded);
    std::vector<TileCoord> tiles;
    for (const auto& [id, bounds] : mAreas)
    {
        tiles.clear();
        (void)mWorld.GetGrid().TilesOverlapping(bounds, 0.0f, tiles, cMaxAreaTiles); // AddArea checked
        for (const TileCoord& tile : tiles)
            outNeeded[tile] = 0.0f;
    }
}

void TileScheduler::CollectInvokerTiles(const Invoker& inInvoker,
                                        std::unordered_map<TileCoord, float>& ioNeeded) const
{
    const TileGrid& grid = mWorld.GetGrid();
    // A tile within the radius is at most ceil(radius / tile size) tiles from the invoker's own on each axis,
    // one more below where the radius ends on a tile's edge: the square takes one more on each side. Sized by
    // the radius alone, not by where the invoker stands, so AddInvoker's limit holds wherever MoveInvoker
    // takes it, and no list is cut off
    const int32_t reach = int32_t(ReachInTiles(inInvoker.mRadius, grid.GetTileSize())) + 1;
    const TileCoord centre = grid.TileAt(inInvoker.mPosition.x(), inInvoker.mPosition.z());
    for (int32_t z = centre.mZ - reach; z <= centre.mZ + reach; ++z) // TileAt clamps to +-2^30: no overflow
        for (int32_t x = centre.mX - reach; x <= centre.mX + reach; ++x)
        {
            // x-z distance from the invoker to the tile's area: within the radius, the tile is needed
            const AABB box = grid.GetTileBounds({x, z});
            const Vec3& position = inInvoker.mPosition;
            const float dx = std::max({box.mMin.x() - position.x(), 0.0f, position.x() - box.mMax.x()});
            const float dz = std::max({box.mMin.z() - position.z(), 0.0f, position.z() - box.mMax.z()});
            const float distance = std::sqrt(dx * dx + dz * dz);
            if (distance > inInvoker.mRadius) continue;
            auto [it, inserted] = ioNeeded.try_emplace({x, z}, distance);
            if (!inserted) it->second = std::min(it->second, distance);
        }
}

void TileScheduler::StartJob(const TileCoord& inTile, TileState& ioState)
{
    // The links starting in the tile, by id: the same links in the same order whatever the map's order
    std::vector<std::pair<LinkID, OffMeshLink>> byID;
    for (const auto& [id, link] : mLinks)
        if (mWorld.GetGrid().TileAt(link.mStart.x(), link.mStart.z()) == inTile) byID.push_back({id, link});
    std::sort(byID.begin(), byID.end(),
              [](const auto& inL, const auto& inR) { return inL.first < inR.first; });
    std::vector<OffMeshLink> links;
    for (const auto& [id, link] : byID)
        links.push_back(link);
    auto job = std::make_shared<TileJob>(mCollector, mWorld.GetProfile(), mWorld.GetGrid(),
                                         mSettings.mInclusion, inTile, mBorder, std::move(links));
    ioState.mJob = job;
    ioState.mJobStartFrame = mFrame;
    ioState.mDirty = false; // Dirt from now on means this job's result is already stale: build again after
    ioState.mTask = mQueue.Submit(
        "navmesh tile " + std::to_string(inTile.mX) + "," + std::to_string(inTile.mZ), mSettings.mJobPriority,
        [job](jobs::BackgroundTaskContext& ioContext) { return job->Step(ioContext); });
    if (ioState.mEverPublished) ++mStats.mRebuilds;
    ++mStats.mJobsStarted;
}

bool TileScheduler::CollectFinished(const TileCoord& inTile, TileState& ioState,
                                    std::vector<BuiltTile>& ioChanges)
{
    TileJob& job = *ioState.mJob;
    if (!job.IsFinished())
    {
        if (!ioState.mTask->IsFinished()) return false;
        if (ioState.mTask->GetState() == jobs::BackgroundTaskState::Failed)
        {
            // The job threw (out of memory in Recast, say): a failure like a refused tile, not built again by
            // itself every frame; a later change to the tile (dirty) retries it
            ++mStats.mJobsFailed;
            mStats.mLastError = "tile " + std::to_string(inTile.mX) + "," + std::to_string(inTile.mZ) + ": " +
                                ioState.mTask->GetError();
            ioState.mJob.reset();
            ioState.mTask.reset();
            return true;
        }
        // Cancelled before it ever ran: no result, build again if still needed
        ioState.mDirty = true;
        ioState.mJob.reset();
        ioState.mTask.reset();
        return true;
    }
    const CollectStats& stats = job.GetCollectStats();
    mStats.mCollectMs += stats.mCollectMs;
    std::optional<Result<BuiltTile>>& result = job.GetResult();
    if (!result.has_value())
        ioState.mDirty = true;
    else if (!result->IsOk())
    {
        ++mStats.mJobsFailed;
        mStats.mLastError = "tile " + std::to_string(inTile.mX) + "," + std::to_string(inTile.mZ) + ": " +
                            result->GetError().mMessage;
    }
    else
    {
        mStats.mBuildMs += result->Value().mBuildMs;
        ioChanges.push_back(std::move(result->Value()));
        if (!ioState.mEverPublished)
        {
            mStats.mFirstPublishFrames.push_back(uint32_t(mFrame - ioState.mNeededSinceFrame));
            mStats.mFirstPublishTiles.push_back(inTile);
        }
        ioState.mEverPublished = true;
        ioState.mPublication = Publication{ioState.mJobStartFrame, mFrame};
        ++mStats.mTilesPublished;
    }
    ioState.mJob.reset();
    ioState.mTask.reset();
    return true;
}

int TileScheduler::Update()
{
    std::unordered_map<TileCoord, float> needed;
    std::vector<BuiltTile> changes; // The one hand-off to the navmesh: finished tiles and dropped ones
    {
        std::lock_guard lock(mMutex);
        ++mFrame;
        CollectNeeded(needed);

        // Finished jobs first: their tiles are this frame's changes
        for (auto& [tile, state] : mTiles)
            if (state.mJob != nullptr) CollectFinished(tile, state, changes);

        // Newly needed tiles; needed ones are kept
        for (const auto& [tile, distance] : needed)
        {
            auto [it, inserted] = mTiles.try_emplace(tile);
            if (inserted) it->second.mNeededSinceFrame = mFrame;
            it->second.mLastNeededFrame = mFrame;
        }
        // Drop tiles no longer needed: those of removed areas at once, the others after the delay
        for (const TileCoord& tile : mDropNow)
            if (auto it = mTiles.find(tile); it != mTiles.end() && !needed.contains(tile))
                it->second.mLastNeededFrame = 0;
        mDropNow.clear();
        for (auto it = mTiles.begin(); it != mTiles.end();)
        {
            TileState& state = it->second;
            const bool expired =
                !needed.contains(it->first) &&
                (state.mLastNeededFrame == 0 || mFrame - state.mLastNeededFrame > mSettings.mDropDelayFrames);
            if (!expired)
            {
                ++it;
                continue;
            }
            if (state.mTask != nullptr)
            {
                state.mTask->Cancel(); // Collected (and dropped) when it has stopped
                state.mLastNeededFrame = 0;
                ++it;
                continue;
            }
            if (state.mEverPublished) changes.push_back(NavMeshWorld::Removal(it->first));
            ++mStats.mTilesDropped;
            it = mTiles.erase(it);
        }

        // Start jobs for dirty needed tiles, nearest to an invoker first, within the budget
        uint32_t running = 0;
        std::vector<std::pair<float, TileCoord>> candidates;
        for (const auto& [tile, state] : mTiles)
        {
            if (state.mJob != nullptr)
                ++running;
            else if (state.mDirty && needed.contains(tile))
                candidates.push_back({needed[tile], tile});
        }
        std::sort(candidates.begin(), candidates.end());
        for (const auto& [distance, tile] : candidates)
        {
            // A budget of 0 would never build anything, and a caller waiting for IsIdle would wait forever
            if (running >= std::max(1u, mSettings.mMaxConcurrentJobs)) break;
            StartJob(tile, mTiles[tile]);
            ++running;
        }
    }
    // The sync point: outside mMutex, since it waits for path queries in progress
    const int changed = mWorld.Publish(std::move(changes));
    std::string reason;
    if (const uint64_t refused = mWorld.GetRefusedTiles(&reason); refused != mRefusedSeen)
    {
        std::lock_guard lock(mMutex);
        mStats.mJobsFailed += refused - mRefusedSeen;
        mStats.mLastError = "publish: " + reason;
        mRefusedSeen = refused;
    }
    return changed;
}

uint64_t TileScheduler::GetFrame() const
{
    std::lock_guard lock(mMutex);
    return mFrame;
}

std::optional<TileScheduler::Publication> TileScheduler::GetLastPublication(const TileCoord& inTile) const
{
    std::lock_guard lock(mMutex);
    const auto it = mTiles.find(inTile);
    return it == mTiles.end() ? std::nullopt : it->second.mPublication;
}

bool TileScheduler::IsIdle() const
{
    std::lock_guard lock(mMutex);
    std::unordered_map<TileCoord, float> needed;
    CollectNeeded(needed);
    for (const auto& [tile, distance] : needed)
    {
        auto it = mTiles.find(tile);
        if (it == mTiles.end() || it->second.mDirty || it->second.mJob != nullptr) return false;
    }
    for (const auto& [tile, state] : mTiles)
        if (state.mJob != nullptr) return false;
    return true;
}

uint32_t TileScheduler::CountNeededNeverPublished() const
{
    std::lock_guard lock(mMutex);
    std::unordered_map<TileCoord, float> needed;
    CollectNeeded(needed);
    uint32_t count = 0;
    for (const auto& [tile, distance] : needed)
        if (auto it = mTiles.find(tile); it == mTiles.end() || !it->second.mEverPublished) ++count;
    return count;
}

uint32_t TileScheduler::GetNumRunningJobs() const
{
    std::lock_guard lock(mMutex);
    uint32_t running = 0;
    for (const auto& [tile, state] : mTiles)
        running += state.mJob != nullptr ? 1 : 0;
    return running;
}

bool TileScheduler::HasFinishedJobs() const
{
    std::lock_guard lock(mMutex);
    for (const auto& [tile, state] : mTiles)
        if (state.mJob != nullptr && state.mJob->IsFinished()) return true;
    return false;
}

TileScheduler::Stats TileScheduler::GetStats() const
{
    std::lock_guard lock(mMutex);
    return mStats;
}

} // namespace cairn::navmesh
