// Path requests served over later frames within a budget (PathRequestQueue): the same paths as the
// synchronous FindPath, the budget kept, the same results in the same Updates for the same requests, a
// search that survives a tile removed under it, and clear errors.

#include "cairn/navmesh/PathRequestQueue.h"

#include "NavMeshSceneFixture.h"
#include "TileChanges.h"
#include "cairn/navmesh/TileBuilder.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <optional>
#include <random>
#include <thread>

namespace cairn::navmesh::test
{
using namespace cairn::physics;
namespace
{

class PathRequestQueueTest : public NavMeshSceneFixture
{
protected:
    /// Ground over 2 x 2 tiles each side of the origin (51.2 m across) with walls that make the paths bend.
    void BuildMaze()
    {
        AddStaticBox(Vec3(0, -0.5f, 0), Vec3(25, 0.5f, 25));
        for (int i = -2; i <= 2; ++i)
            AddStaticBox(Vec3(float(i) * 9.0f, 1.0f, float(i % 2 == 0 ? 6 : -6)), Vec3(0.5f, 1.5f, 17.0f));
        MakeNavMesh(2);
        ASSERT_TRUE(RunUntilIdle());
    }

    /// inCount random pairs of points on the ground (a fixed seed).
    static std::vector<std::pair<Vec3, Vec3>> RandomEnds(int inCount)
    {
        std::mt19937 random(11);
        std::uniform_real_distribution<float> coordinate(-23.0f, 23.0f);
        std::vector<std::pair<Vec3, Vec3>> ends;
        for (int i = 0; i < inCount; ++i)
            ends.push_back({Vec3(coordinate(random), 0, coordinate(random)),
                            Vec3(coordinate(random), 0, coordinate(random))});
        return ends;
    }

    /// Updates until every ticket has finished (at most inMaxUpdates); the Update each finished in.
    static std::vector<int> ServeAll(PathRequestQueue& ioQueue, const std::vector<PathTicket>& inTickets,
                                     std::vector<Result<PathResult>>& outResults, int inMaxUpdates = 100000)
    {
        std::vector<int> finishedAt(inTickets.size(), -1);
        outResults.assign(inTickets.size(), MakeError(ErrorCode::InvalidArgument, "not served"));
        size_t left = inTickets.size();
        for (int update = 0; update < inMaxUpdates && left > 0; ++update)
        {
            ioQueue.Update();
            for (size_t i = 0; i < inTickets.size(); ++i)
            {
                if (finishedAt[i] >= 0) continue;
                std::optional<Result<PathResult>> result = ioQueue.TakeResult(inTickets[i]);
                if (!result) continue;
                outResults[i] = std::move(*result);
                finishedAt[i] = update;
                --left;
            }
        }
        return finishedAt;
    }
};

// A budget only spreads the work: 60 searches with 64 iterations an Update give the results of the same
// searches each done in one Update, corner for corner, and no Update spends more than its budget. Every
// request FindPath answers, the queue answers, and no other: Detour's sliced search (A* over polygon edge
// midpoints, as its one-call search) may take another corridor than FindPath where costs nearly tie, so the
// corners are compared between queues
TEST_F(PathRequestQueueTest, ABudgetSpreadsTheSearchesWithoutChangingThem)
{
    BuildMaze();
    PathRequestQueue::Settings small, unlimited;
    small.mIterationsPerUpdate = 64;
    unlimited.mIterationsPerUpdate = 1000000;
    std::unique_ptr<PathRequestQueue> budgeted = PathRequestQueue::Create(*mWorld, small).Value();
    std::unique_ptr<PathRequestQueue> whole = PathRequestQueue::Create(*mWorld, unlimited).Value();
    const std::vector<std::pair<Vec3, Vec3>> ends = RandomEnds(60);
    std::vector<PathTicket> budgetedTickets, wholeTickets;
    for (const auto& [start, end] : ends)
    {
        budgetedTickets.push_back(budgeted->Request(start, end).Value());
        wholeTickets.push_back(whole->Request(start, end).Value());
    }
    EXPECT_EQ(budgeted->GetStatistics().mPending, 60);
    std::vector<Result<PathResult>> results(ends.size(), MakeError(ErrorCode::InvalidArgument, "not served"));
    uint64_t iterationsBefore = 0;
    for (int update = 0; update < 10000 && budgeted->GetStatistics().mPending > 0; ++update)
    {
        budgeted->Update();
        const uint64_t iterations = budgeted->GetStatistics().mIterations;
        ASSERT_LE(iterations - iterationsBefore, uint64_t(small.mIterationsPerUpdate)) << "update " << update;
        iterationsBefore = iterations;
        for (size_t i = 0; i < budgetedTickets.size(); ++i)
            if (std::optional<Result<PathResult>> result = budgeted->TakeResult(budgetedTickets[i]))
                results[i] = std::move(*result);
    }
    const PathRequestQueue::Statistics statistics = budgeted->GetStatistics();
    EXPECT_EQ(statistics.mPending, 0);
    EXPECT_EQ(statistics.mServed + statistics.mFailed, 60u);
    EXPECT_GT(statistics.mWaitUpdatesMax, 5u) << "a budget of 64 iterations spreads 60 searches over Updates";
    std::vector<Result<PathResult>> wholeResults;
    const std::vector<int> wholeAt = ServeAll(*whole, wholeTickets, wholeResults);
    EXPECT_EQ(*std::max_element(wholeAt.begin(), wholeAt.end()), 0) << "all in one Update";
    int served = 0;
    for (size_t i = 0; i < ends.size(); ++i)
    {
        ASSERT_EQ(bool(results[i]), bool(wholeResults[i])) << "request " << i;
        ASSERT_EQ(bool(results[i]), bool(mWorld->FindPath(ends[i].first, ends[i].second))) << "request " << i;
        if (!results[i]) continue;
        ++served;
        EXPECT_EQ(results[i].Value().mReachedEnd, wholeResults[i].Value().mReachedEnd);
        EXPECT_EQ(results[i].Value().mStraightPath, wholeResults[i].Value().mStraightPath) << "request " << i;
    }
    EXPECT_GT(served, 50) << "most random ends are on the ground";
}

// Two queues given the same requests finish each in the same Update with the same result
TEST_F(PathRequestQueueTest, TheSameRequestsFinishInTheSameUpdates)
{
    BuildMaze();
    PathRequestQueue::Settings settings;
    settings.mIterationsPerUpdate = 100;
    std::unique_ptr<PathRequestQueue> first = PathRequestQueue::Create(*mWorld, settings).Value();
    std::unique_ptr<PathRequestQueue> second = PathRequestQueue::Create(*mWorld, settings).Value();
    std::vector<PathTicket> firstTickets, secondTickets;
    for (const auto& [start, end] : RandomEnds(40))
    {
        firstTickets.push_back(first->Request(start, end).Value());
        secondTickets.push_back(second->Request(start, end).Value());
    }
    std::vector<Result<PathResult>> firstResults, secondResults;
    const std::vector<int> firstAt = ServeAll(*first, firstTickets, firstResults);
    const std::vector<int> secondAt = ServeAll(*second, secondTickets, secondResults);
    EXPECT_EQ(firstAt, secondAt);
    for (size_t i = 0; i < firstResults.size(); ++i)
    {
        ASSERT_EQ(bool(firstResults[i]), bool(secondResults[i]));
        if (!firstResults[i]) continue;
        EXPECT_EQ(firstResults[i].Value().mStraightPath, secondResults[i].Value().mStraightPath);
    }
}

// The tile of a search's end rebuilt while the search runs (its polygons get new references): Detour fails
// the search, which starts again on the navmesh as it is and finds the path. The tile removed instead: the
// search starts again and ends with the error of an end off the navmesh
TEST_F(PathRequestQueueTest, ASearchStartsAgainWhenTheNavMeshChangesUnderIt)
{
    BuildMaze();
    PathRequestQueue::Settings settings;
    settings.mIterationsPerUpdate = 8;
    std::unique_ptr<PathRequestQueue> queue = PathRequestQueue::Create(*mWorld, settings).Value();
    const Vec3 start(-22, 0, -22), end(22, 0, 22);
    const PathTicket rebuilt = queue->Request(start, end).Value();
    queue->Update(); // Searching, far from done
    ASSERT_TRUE(queue->IsPending(rebuilt));
    const TileCoord endTile = mWorld->GetGrid().TileAt(end.x(), end.z());
    const AABB endBounds = mWorld->GetGrid().GetTileBounds(endTile);
    mScheduler->MarkDirty(AABB(endBounds.mMin + Vec3(1, 0, 1), endBounds.mMax - Vec3(1, 0, 1)));
    ASSERT_TRUE(RunUntilIdle()); // The end's tile rebuilt and published again
    std::vector<Result<PathResult>> results;
    ServeAll(*queue, {rebuilt}, results);
    EXPECT_EQ(queue->GetStatistics().mRestarts, 1u);
    ASSERT_TRUE(results[0]) << results[0].GetError().mMessage;
    EXPECT_TRUE(results[0].Value().mReachedEnd);

    const PathTicket removed = queue->Request(start, end).Value();
    queue->Update();
    ASSERT_TRUE(queue->IsPending(removed));
    mWorld->Publish(Changes(NavMeshWorld::Removal(endTile)));
    ServeAll(*queue, {removed}, results);
    EXPECT_EQ(queue->GetStatistics().mRestarts, 2u);
    ASSERT_FALSE(results[0]);
    EXPECT_NE(results[0].GetError().mMessage.find("end is not on the navmesh"), std::string::npos)
        << results[0].GetError().mMessage;
}

TEST_F(PathRequestQueueTest, CancelTakeAndBadRequests)
{
    BuildMaze();
    PathRequestQueue::Settings settings;
    settings.mMaxPending = 3;
    std::unique_ptr<PathRequestQueue> queue = PathRequestQueue::Create(*mWorld, settings).Value();
    const PathTicket a = queue->Request(Vec3(-20, 0, -20), Vec3(20, 0, 20)).Value();
    const PathTicket b = queue->Request(Vec3(-20, 0, 20), Vec3(20, 0, -20)).Value();
    const PathTicket offMesh = queue->Request(Vec3(-20, 0, -20), Vec3(500, 0, 500)).Value();
    EXPECT_EQ(queue->Request(Vec3::Zero(), Vec3::Ones()).GetError().mCode, ErrorCode::OutOfCapacity);
    EXPECT_TRUE(queue->Cancel(b));
    EXPECT_FALSE(queue->Cancel(b)) << "cancelled twice";
    EXPECT_FALSE(queue->IsPending(b));
    std::vector<Result<PathResult>> results;
    ServeAll(*queue, {a, offMesh}, results);
    EXPECT_TRUE(results[0]);
    ASSERT_FALSE(results[1]);
    EXPECT_EQ(results[1].GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_FALSE(queue->TakeResult(a).has_value()) << "taken once";
    EXPECT_FALSE(queue->TakeResult(PathTicket{12345}).has_value());
    EXPECT_FALSE(queue->TakeResult(b).has_value()) << "cancelled";

    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(queue->Request(Vec3(nan, 0, 0), Vec3::Zero()).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_EQ(queue->Request(Vec3::Zero(), Vec3::Zero(), {}, Vec3(1e6f, 1, 1)).GetError().mCode,
              ErrorCode::InvalidArgument);
    PathFilter negative;
    negative.mAreaCost[0] = -1.0f;
    EXPECT_EQ(queue->Request(Vec3::Zero(), Vec3::Zero(), negative).GetError().mCode,
              ErrorCode::InvalidArgument);
    settings.mIterationsPerUpdate = 0;
    EXPECT_FALSE(PathRequestQueue::Create(*mWorld, settings));
}

// UpdateWithin searches with the queue's own polygon references: handed another world's navmesh (a caller
// inside the wrong world's Read) it refuses and searches nothing, and the request is served later as usual
TEST_F(PathRequestQueueTest, UpdateWithinAnotherWorldsNavMeshIsRefused)
{
    BuildMaze();
    std::unique_ptr<PathRequestQueue> queue = PathRequestQueue::Create(*mWorld).Value();
    const PathTicket ticket = queue->Request(Vec3(-20, 0, -20), Vec3(20, 0, 20)).Value();
    const std::unique_ptr<NavMeshWorld> other =
        NavMeshWorld::Create(mWorld->GetGrid(), mWorld->GetProfile()).Value();
    std::optional<Result<int>> refused;
    other->Read([&](const dtNavMesh& inNavMesh) { refused = queue->UpdateWithin(inNavMesh); });
    ASSERT_TRUE(refused.has_value());
    ASSERT_FALSE(*refused);
    EXPECT_EQ(refused->GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_TRUE(queue->IsPending(ticket));
    EXPECT_EQ(queue->GetStatistics().mIterations, 0u);
    std::vector<Result<PathResult>> results;
    ServeAll(*queue, {ticket}, results);
    EXPECT_TRUE(results[0]);
}

/// A navmesh of inTiles x inTiles tiles of flat ground (from the origin) with a 0.6 m pillar every 3 m, built
/// straight from triangles: a path across it takes Detour thousands of iterations, the maze's a few dozen.
std::unique_ptr<NavMeshWorld> MakePillarField(int inTiles)
{
    const AgentProfile profile;
    const TileGrid grid(0, 0, profile.mTileSize, -5, 20);
    std::unique_ptr<NavMeshWorld> world = NavMeshWorld::Create(grid, profile).Value();
    auto quad =
        [](TileGeometry& ioGeometry, const Vec3& inA, const Vec3& inB, const Vec3& inC, const Vec3& inD)
    {
        ioGeometry.AddTriangle(inA, inB, inC, cDefaultArea);
        ioGeometry.AddTriangle(inA, inC, inD, cDefaultArea);
    };
    std::vector<BuiltTile> tiles;
    for (int z = 0; z < inTiles; ++z)
        for (int x = 0; x < inTiles; ++x)
        {
            TileGeometry geometry;
            const AABB bounds = grid.GetTileBoundsWithBorder({x, z}, 2.0f);
            const float x0 = bounds.mMin.x(), x1 = bounds.mMax.x(), z0 = bounds.mMin.z(),
                        z1 = bounds.mMax.z();
            quad(geometry, Vec3(x0, 0, z0), Vec3(x0, 0, z1), Vec3(x1, 0, z1), Vec3(x1, 0, z0));
            // Only a pillar's top, 1.2 m up (under the agent's headroom, over its climb): the ground under it
            // is unwalkable, and the top too small to stand on
            for (float px = 3.0f * std::ceil(x0 / 3.0f); px <= x1; px += 3.0f)
                for (float pz = 3.0f * std::ceil(z0 / 3.0f); pz <= z1; pz += 3.0f)
                    quad(geometry, Vec3(px - 0.3f, 1.2f, pz - 0.3f), Vec3(px - 0.3f, 1.2f, pz + 0.3f),
                         Vec3(px + 0.3f, 1.2f, pz + 0.3f), Vec3(px + 0.3f, 1.2f, pz - 0.3f));
            tiles.push_back(BuildTile(profile, grid, {x, z}, geometry).Value());
        }
    world->Publish(std::move(tiles));
    return world;
}

// Cancel (any thread) lands while Update searches the request, often during its last slice, which runs
// without the queue's mutex: a cancelled request leaves no result and the pending count never goes negative
// (it once did: the request was counted as cancelled and as finished, and the queue then held one more
// request than mMaxPending each time)
TEST(PathRequestQueueCancelTest, CancelWhileSearchedLeavesNoResult)
{
    const std::unique_ptr<NavMeshWorld> world = MakePillarField(8);
    PathRequestQueue::Settings settings;
    settings.mIterationsPerUpdate = 1000000; // Each search in one Update: its last slice is all of it
    std::unique_ptr<PathRequestQueue> queue = PathRequestQueue::Create(*world, settings).Value();
    int cancelledWhileSearched = 0;
    for (int trial = 0; trial < 300; ++trial)
    {
        // Corner to corner between the pillars, which needs thousands of iterations
        const PathTicket ticket = queue->Request(Vec3(1.5f, 0, 1.5f), Vec3(100.5f, 0, 100.5f)).Value();
        const uint64_t iterationsBefore = queue->GetStatistics().mIterations;
        std::atomic<bool> updating{false};
        bool cancelled = false;
        std::thread canceller(
            [&]
            {
                while (!updating.load(std::memory_order_acquire)) // Acquire: pairs with the store below
                    std::this_thread::yield();
                // Spread over the search: from at once to some way in
                const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(trial % 60);
                while (std::chrono::steady_clock::now() < until)
                {
                }
                cancelled = queue->Cancel(ticket);
            });
        updating.store(true, std::memory_order_release); // Release: the ticket is queued before
        queue->Update();
        canceller.join();
        const std::optional<Result<PathResult>> result = queue->TakeResult(ticket);
        const PathRequestQueue::Statistics stats = queue->GetStatistics();
        if (cancelled)
        {
            EXPECT_FALSE(result.has_value()) << "trial " << trial << ": a result for a cancelled request";
            // Cancelled once the search had begun (it counted iterations), not while the request waited
            cancelledWhileSearched += stats.mIterations > iterationsBefore ? 1 : 0;
        }
        else
            EXPECT_TRUE(result.has_value()) << "trial " << trial << ": finished but no result";
        // Each request ended once: finished, cancelled, or both (cancelled after it finished, which drops
        // its result)
        ASSERT_EQ(stats.mPending, 0) << "trial " << trial;
        ASSERT_GE(stats.mServed + stats.mFailed + stats.mCancelled, stats.mRequested) << "trial " << trial;
        ASSERT_LE(stats.mServed + stats.mFailed, stats.mRequested) << "trial " << trial;
        if (HasFailure()) break;
    }
    EXPECT_GT(cancelledWhileSearched, 0) << "no Cancel landed: the test tested nothing";
}

} // namespace
} // namespace cairn::navmesh::test
