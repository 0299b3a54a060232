// Path requests served over later frames within a budget (PathRequestQueue): the same paths as the
// synchronous FindPath, the budget kept, the same results in the same Updates for the same requests, a
// search that survives a tile removed under it, and clear errors.

#include "cairn/navmesh/PathRequestQueue.h"

#include "NavMeshSceneFixture.h"
#include "TileChanges.h"

#include <algorithm>
#include <random>

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

} // namespace
} // namespace cairn::navmesh::test
