#include "cairn/navmesh/PathRequestQueue.h"

#include "DetourPaths.h"

#include <algorithm>

namespace cairn::navmesh
{

PathRequestQueue::PathRequestQueue(const NavMeshWorld& inWorld, const Settings& inSettings)
    : mWorld(inWorld), mSettings(inSettings)
{
}

PathRequestQueue::~PathRequestQueue()
{
    dtFreeNavMeshQuery(mQuery);
}

Result<std::unique_ptr<PathRequestQueue>> PathRequestQueue::Create(const NavMeshWorld& inWorld,
                                                                   const Settings& inSettings)
{
    if (!(inSettings.mIterationsPerUpdate >= 1 && inSettings.mIterationsPerUpdate <= 1000000))
        return MakeError(ErrorCode::InvalidArgument, "path queue: iterations per update must be in [1, 1e6]");
    if (!(inSettings.mMaxPending >= 1 && inSettings.mMaxPending <= 1 << 24))
        return MakeError(ErrorCode::InvalidArgument, "path queue: max pending must be in [1, 2^24]");
    if (!(inSettings.mMaxRestarts >= 0 && inSettings.mMaxRestarts <= 100))
        return MakeError(ErrorCode::InvalidArgument, "path queue: max restarts must be in [0, 100]");
    std::unique_ptr<PathRequestQueue> queue(new PathRequestQueue(inWorld, inSettings));
    queue->mQuery = dtAllocNavMeshQuery();
    bool initialised = false;
    // The query keeps a pointer to Detour's navmesh, which lives as long as the world
    inWorld.Read(
        [&](const dtNavMesh& inNavMesh)
        {
            initialised =
                queue->mQuery != nullptr && dtStatusSucceed(queue->mQuery->init(&inNavMesh, cMaxQueryNodes));
        });
    if (!initialised)
        return MakeError(ErrorCode::OutOfCapacity, "path queue: Detour could not make its query");
    return queue;
}

Result<PathTicket> PathRequestQueue::Request(const Vec3& inStart, const Vec3& inEnd,
                                             const PathFilter& inFilter, const Vec3& inSearchExtent,
                                             uint64_t inStartPolygon)
{
    if (!IsValidWorldPosition(inStart) || !IsValidWorldPosition(inEnd))
        return MakeError(ErrorCode::InvalidArgument, "path request: start and end must be finite");
    if (Status extent = CheckSearchExtent(inSearchExtent, mWorld.GetGrid().GetTileSize(), "path request");
        !extent)
        return extent.GetError();
    if (Result<dtQueryFilter> filter = MakeDetourFilter(inFilter, "path request"); !filter)
        return filter.GetError();
    const std::lock_guard lock(mMutex);
    if (mStatistics.mPending >= mSettings.mMaxPending)
        return MakeError(ErrorCode::OutOfCapacity, "path request: the queue is full");
    const PathTicket ticket{mNextTicket++};
    mPending.push_back(
        {ticket, inStart, inEnd, inSearchExtent, inFilter, inStartPolygon, mStatistics.mUpdates, 0});
    ++mStatistics.mRequested;
    ++mStatistics.mPending;
    return ticket;
}

int PathRequestQueue::Update()
{
    int finished = 0;
    mWorld.Read([&](const dtNavMesh& inNavMesh) { finished = UpdateWithin(inNavMesh).Value(); });
    return finished;
}

Result<int> PathRequestQueue::UpdateWithin(const dtNavMesh& inNavMesh)
{
    // The queue's polygon references are its own world's: another world's navmesh would be read through them
    if (&inNavMesh != mQuery->getAttachedNavMesh())
        return MakeError(ErrorCode::InvalidArgument,
                         "PathRequestQueue::UpdateWithin: the navmesh is not the queue's world's");
    const int finished = Search(inNavMesh);
    const std::lock_guard lock(mMutex);
    ++mStatistics.mUpdates;
    return finished;
}

int PathRequestQueue::Search(const dtNavMesh& inNavMesh)
{
    int budget = mSettings.mIterationsPerUpdate;
    int finished = 0;
    while (budget > 0)
    {
        if (!mActive.has_value())
        {
            const std::lock_guard lock(mMutex);
            if (mPending.empty()) break;
            mActive = std::move(mPending.front());
            mPending.pop_front();
            mSearchStarted = false;
        }
        {
            // A request cancelled while searched is dropped here, between two slices
            const std::lock_guard lock(mMutex);
            if (mCancelledActive == mActive->mTicket.mValue)
            {
                mCancelledActive = 0;
                mActive.reset();
                continue;
            }
        }
        const PendingRequest& request = *mActive;
        if (!mSearchStarted)
        {
            // Checked by Request. Kept: Detour's sliced search reads it through a pointer in every Update
            mFilter =
                std::make_unique<dtQueryFilter>(MakeDetourFilter(request.mFilter, "path request").Value());
            const dtQueryFilter& filter = *mFilter;
            // The ends snap as the navmesh is now; a restart snaps them again
            dtPolyRef startRef = 0, endRef = 0;
            mQuery->findNearestPoly(request.mStart.data(), request.mSearchExtent.data(), &filter, &startRef,
                                    mStartPoint);
            mQuery->findNearestPoly(request.mEnd.data(), request.mSearchExtent.data(), &filter, &endRef,
                                    mEndPoint);
            // A start polygon the caller knows, while it exists, over the snapped one
            const dtNavMesh& navMesh = *mQuery->getAttachedNavMesh();
            if (request.mStartPolygon != 0 && navMesh.isValidPolyRef(dtPolyRef(request.mStartPolygon)))
            {
                startRef = dtPolyRef(request.mStartPolygon);
                mQuery->closestPointOnPoly(startRef, request.mStart.data(), mStartPoint, nullptr);
            }
            mStartRef = startRef;
            mEndRef = endRef;
            if (mStartRef == 0 || mEndRef == 0)
            {
                const std::lock_guard lock(mMutex);
                finished += FinishActiveLocked(
                    MakeError(ErrorCode::InvalidArgument,
                              mStartRef == 0 ? "path request: the start is not on the navmesh"
                                             : "path request: the end is not on the navmesh"));
                continue;
            }
            mQuery->initSlicedFindPath(dtPolyRef(mStartRef), dtPolyRef(mEndRef), mStartPoint, mEndPoint,
                                       &filter);
            mSearchStarted = true;
        }
        int done = 0;
        const dtStatus status = mQuery->updateSlicedFindPath(budget, &done);
        budget -= std::max(done, 1);
        {
            const std::lock_guard lock(mMutex);
            mStatistics.mIterations += uint64_t(std::max(done, 0));
        }
        if (dtStatusInProgress(status)) continue; // The budget ran out: the search goes on next Update
        dtPolyRef corridor[cMaxPathPolygons];
        int numPolygons = 0;
        const dtStatus finalized =
            dtStatusSucceed(status) ? mQuery->finalizeSlicedFindPath(corridor, &numPolygons, cMaxPathPolygons)
                                    : status;
        const bool found = dtStatusSucceed(finalized) && numPolygons > 0;
        const std::lock_guard lock(mMutex);
        if (!found && mActive->mRestarts < mSettings.mMaxRestarts && dtStatusFailed(status))
        {
            // A tile under the search went away between two Updates (Detour fails on a polygon that has
            // disappeared): the same request again, from its ends as they snap now
            ++mActive->mRestarts;
            ++mStatistics.mRestarts;
            mSearchStarted = false;
            continue;
        }
        finished += FinishActiveLocked(
            found ? FinishPath(*mQuery, inNavMesh, corridor, numPolygons, dtPolyRef(mEndRef), mStartPoint,
                               mEndPoint, request.mFilter, finalized)
                  : Result<PathResult>(MakeError(ErrorCode::InvalidArgument, "path request: no path")));
    }
    return finished;
}

bool PathRequestQueue::FinishActiveLocked(Result<PathResult>&& inResult)
{
    // Cancelled during its last slice, which runs without the mutex: Cancel has counted it already, and its
    // caller must not find a result for it
    if (mCancelledActive == mActive->mTicket.mValue)
    {
        mCancelledActive = 0;
        mActive.reset();
        return false;
    }
    const uint64_t wait = mStatistics.mUpdates - mActive->mRequestedAtUpdate;
    mStatistics.mWaitUpdatesSum += wait;
    mStatistics.mWaitUpdatesMax = std::max(mStatistics.mWaitUpdatesMax, wait);
    ++mStatistics.mWaitHistogram[std::min<uint64_t>(wait, 64)];
    ++(inResult ? mStatistics.mServed : mStatistics.mFailed);
    --mStatistics.mPending;
    mFinished.emplace(mActive->mTicket.mValue, std::move(inResult));
    mActive.reset();
    return true;
}

std::optional<Result<PathResult>> PathRequestQueue::TakeResult(PathTicket inTicket)
{
    const std::lock_guard lock(mMutex);
    const auto found = mFinished.find(inTicket.mValue);
    if (found == mFinished.end()) return std::nullopt;
    Result<PathResult> result = std::move(found->second);
    mFinished.erase(found);
    return result;
}

bool PathRequestQueue::IsPending(PathTicket inTicket) const
{
    const std::lock_guard lock(mMutex);
    if (mActive.has_value() && mActive->mTicket == inTicket) return mCancelledActive != inTicket.mValue;
    return std::any_of(mPending.begin(), mPending.end(),
                       [&](const PendingRequest& inRequest) { return inRequest.mTicket == inTicket; });
}

bool PathRequestQueue::Cancel(PathTicket inTicket)
{
    const std::lock_guard lock(mMutex);
    if (mFinished.erase(inTicket.mValue) != 0)
    {
        ++mStatistics.mCancelled;
        return true;
    }
    const auto waiting =
        std::find_if(mPending.begin(), mPending.end(),
                     [&](const PendingRequest& inRequest) { return inRequest.mTicket == inTicket; });
    if (waiting != mPending.end())
    {
        mPending.erase(waiting);
    }
    else if (mActive.has_value() && mActive->mTicket == inTicket && mCancelledActive != inTicket.mValue)
        mCancelledActive = inTicket.mValue; // The Update thread drops it between two slices
    else
        return false;
    ++mStatistics.mCancelled;
    --mStatistics.mPending;
    return true;
}

PathRequestQueue::Statistics PathRequestQueue::GetStatistics() const
{
    const std::lock_guard lock(mMutex);
    return mStatistics;
}

} // namespace cairn::navmesh
