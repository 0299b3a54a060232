#pragma once

// PathRequestQueue: path requests answered in later frames, within a budget of Detour search iterations per
// Update, so that the frame's cost of path finding is bounded whatever the number of agents. A request gets a
// ticket at once; Update serves the requests in ticket order with Detour's sliced search (one search carried
// from one Update to the next when the budget runs out), and finished results wait to be taken. The same
// requests, Updates and published tiles give the same results in the same Updates: nothing depends on threads
// or timing.
//
// The navmesh may change between two Updates (NavMeshWorld::Publish): a search whose polygons went away fails
// in Detour and starts again from the request (up to Settings::mMaxRestarts times), through the same budget.
//
// Threads. Request, Cancel, TakeResult, IsPending and GetStatistics: any thread, under the queue's mutex (a
// leaf, held for microseconds, never while searching). Update: one thread at a time (a frame job, the game
// thread); it searches under the navmesh's mutex held shared (NavMeshWorld::Read), so a Publish waits for at
// most one Update's budget. The world must outlive the queue.

#include "cairn/navmesh/NavMeshWorld.h"

#include <array>
#include <compare>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <unordered_map>

class dtNavMeshQuery;
class dtQueryFilter;

namespace cairn::navmesh
{

struct PathTicket
{
    uint64_t mValue = 0; ///< 0: none; tickets count up from 1 in request order
    auto operator<=>(const PathTicket&) const = default;
};

class PathRequestQueue
{
public:
    struct Settings
    {
        int mIterationsPerUpdate = 2048; ///< Detour's sliced-search iterations (node expansions) per Update
        int mMaxPending = 65536;         ///< Requests waiting or searched at once; more are OutOfCapacity
        int mMaxRestarts = 3;            ///< Times a search the navmesh changed under starts again
    };
    struct Statistics
    {
        uint64_t mRequested = 0;
        uint64_t mServed = 0; ///< Finished with a path (whole or partial)
        uint64_t mFailed = 0; ///< Finished with an error (an end off the navmesh, no path, restarts spent)
        uint64_t mCancelled = 0;
        uint64_t mRestarts = 0; ///< Searches started again after a tile under them changed
        uint64_t mIterations = 0;
        uint64_t mUpdates = 0;
        uint64_t mWaitUpdatesSum = 0; ///< Over finished requests: Updates from request to result
        uint64_t mWaitUpdatesMax = 0;
        /// Finished requests by their wait in Updates: [w] for w < 64, [64] for 64 and more (percentiles)
        std::array<uint64_t, 65> mWaitHistogram{};
        int mPending = 0; ///< Waiting or being searched now
    };

    /// Errors: settings out of range, or Detour could not allocate its query.
    static Result<std::unique_ptr<PathRequestQueue>> Create(const NavMeshWorld& inWorld,
                                                            const Settings& inSettings);
    static Result<std::unique_ptr<PathRequestQueue>> Create(const NavMeshWorld& inWorld)
    {
        return Create(inWorld, Settings{});
    }
    ~PathRequestQueue();
    PathRequestQueue(const PathRequestQueue&) = delete;
    PathRequestQueue& operator=(const PathRequestQueue&) = delete;

    /// Queues a path from inStart to inEnd (snapped to the navmesh within inSearchExtent when its search
    /// starts, as NavMeshWorld::FindPath snaps them). inStartPolygon (optional): the Detour polygon the start
    /// is known to be on (a crowd agent's), used instead of snapping while it exists: on an edge between two
    /// polygons snapping may choose the other. Errors now: bad numbers, a filter or extent FindPath refuses,
    /// a full queue (OutOfCapacity).
    Result<PathTicket> Request(const Vec3& inStart, const Vec3& inEnd, const PathFilter& inFilter = {},
                               const Vec3& inSearchExtent = Vec3(2.0f, 4.0f, 2.0f),
                               uint64_t inStartPolygon = 0);
    /// Searches for up to the budget, the requests in ticket order; returns how many finished.
    int Update();
    /// Update for a caller that already reads the queue's world (inside its NavMeshWorld::Read, inNavMesh
    /// the navmesh it was handed), on any thread while that Read lasts: a crowd searches on a job thread
    /// beside its steering that way. Returns how many finished; an InvalidArgument error, searching nothing,
    /// for another world's navmesh.
    Result<int> UpdateWithin(const dtNavMesh& inNavMesh);
    /// A finished request's result, taken out (the ticket is forgotten); nothing while the request waits or
    /// is searched, nor for a ticket the queue does not know (never given, cancelled, or taken).
    std::optional<Result<PathResult>> TakeResult(PathTicket inTicket);
    /// Whether the request waits or is searched.
    bool IsPending(PathTicket inTicket) const;
    /// Drops a request, waiting, searched or finished; false for a ticket the queue does not know.
    bool Cancel(PathTicket inTicket);
    Statistics GetStatistics() const;

private:
    struct PendingRequest
    {
        PathTicket mTicket;
        Vec3 mStart;
        Vec3 mEnd;
        Vec3 mSearchExtent;
        PathFilter mFilter;
        uint64_t mStartPolygon = 0;
        uint64_t mRequestedAtUpdate = 0;
        int mRestarts = 0;
    };

    PathRequestQueue(const NavMeshWorld& inWorld, const Settings& inSettings);
    /// The search's part of an Update (under the navmesh's shared lock); returns how many finished.
    int Search(const dtNavMesh& inNavMesh);
    /// Ends the active request with inResult (under mMutex); false, storing nothing, when Cancel dropped it
    /// while it was searched.
    bool FinishActiveLocked(Result<PathResult>&& inResult);

    const NavMeshWorld& mWorld;
    const Settings mSettings;
    dtNavMeshQuery* mQuery = nullptr; ///< The Update thread's: its sliced search spans Updates

    /// The request being searched: written by the Update thread under mMutex, read by it without (no other
    /// thread writes it) and by the others under mMutex
    std::optional<PendingRequest> mActive;
    // The Update thread's only: mActive's search
    bool mSearchStarted = false; ///< Its sliced search is initialised in mQuery
    /// Its Detour filter: the sliced search keeps a pointer to it from one Update to the next
    std::unique_ptr<dtQueryFilter> mFilter;
    uint64_t mStartRef = 0; ///< Its ends as snapped when the search started (dtPolyRef)
    uint64_t mEndRef = 0;
    float mStartPoint[3] = {};
    float mEndPoint[3] = {};

    mutable std::mutex mMutex;                                  ///< A leaf: guards what follows
    std::deque<PendingRequest> mPending;                        ///< In ticket order
    std::unordered_map<uint64_t, Result<PathResult>> mFinished; ///< By ticket
    uint64_t mNextTicket = 1;
    uint64_t mCancelledActive = 0; ///< The active request's ticket when Cancel dropped it
    Statistics mStatistics;
};

} // namespace cairn::navmesh
