// Path queries: area types from the bodies' navmesh area, priced and excluded by the path filter; errors for
// points off the navmesh and for bad numbers.

#include "RiverSceneFixture.h"

namespace cairn::navmesh::test
{
using namespace cairn::physics;
namespace
{

class PathQueryTest : public RiverSceneFixture
{
protected:
    static float Length(const PathResult& inPath)
    {
        float length = 0.0f;
        for (size_t i = 0; i + 1 < inPath.mStraightPath.size(); ++i)
            length += (inPath.mStraightPath[i + 1] - inPath.mStraightPath[i]).norm();
        return length;
    }
};

TEST_F(PathQueryTest, AreaCostsAndExclusionsChooseTheWay)
{
    BuildRiver();
    Result<PathResult> swim = mWorld->FindPath(mStart, mEnd);
    ASSERT_TRUE(swim) << swim.GetError().mMessage;
    EXPECT_TRUE(swim.Value().mReachedEnd);
    EXPECT_LT(Length(swim.Value()), 14.0f); // Straight across the water

    PathFilter dear;
    dear.mAreaCost[cWater] = 50.0f;
    Result<PathResult> around = mWorld->FindPath(mStart, mEnd, dear);
    ASSERT_TRUE(around);
    EXPECT_TRUE(around.Value().mReachedEnd);
    EXPECT_GT(Length(around.Value()), 30.0f); // Over the bridge, 16 m away

    PathFilter noSwimming;
    noSwimming.mExcludedAreas = uint64_t(1) << cWater;
    Result<PathResult> dry = mWorld->FindPath(mStart, mEnd, noSwimming);
    ASSERT_TRUE(dry);
    EXPECT_TRUE(dry.Value().mReachedEnd);
    EXPECT_GT(Length(dry.Value()), 30.0f);
}

TEST_F(PathQueryTest, AnExcludedAreaThatIsTheOnlyWayCutsThePathShort)
{
    AddStaticBox(Vec3(0, -0.5f, -5.5f), Vec3(10, 0.5f, 4.5f));
    AddStaticBox(Vec3(0, -0.5f, 5.5f), Vec3(10, 0.5f, 4.5f));
    AddStaticBox(Vec3(0, -0.5f, 0), Vec3(10, 0.5f, 1), cWater); // No bridge
    MakeNavMesh();
    ASSERT_TRUE(RunUntilIdle());
    PathFilter noSwimming;
    noSwimming.mExcludedAreas = uint64_t(1) << cWater;
    Result<PathResult> path = mWorld->FindPath(mStart, mEnd, noSwimming);
    ASSERT_TRUE(path);
    EXPECT_FALSE(path.Value().mReachedEnd);
    ASSERT_FALSE(path.Value().mStraightPath.empty());
    EXPECT_LT(path.Value().mStraightPath.back().z(), -0.5f); // Stops on the south bank
}

TEST_F(PathQueryTest, BadQueriesGetClearErrors)
{
    BuildRiver();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(mWorld->FindPath(Vec3(nan, 0, 0), mEnd).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_EQ(mWorld->FindPath(mStart, Vec3(0, 0, 1.0e9f)).GetError().mCode, ErrorCode::InvalidArgument);
    // Far above the navmesh: not on it
    Result<PathResult> off = mWorld->FindPath(Vec3(0, 50, -6), mEnd);
    ASSERT_FALSE(off);
    EXPECT_NE(off.GetError().mMessage.find("not on the navmesh"), std::string::npos);
    PathFilter bad;
    bad.mAreaCost[0] = -1.0f;
    EXPECT_EQ(mWorld->FindPath(mStart, mEnd, bad).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_EQ(mWorld->FindPath(mStart, mEnd, {}, Vec3(0, 0, 0)).GetError().mCode, ErrorCode::InvalidArgument);
}

TEST_F(PathQueryTest, NearestPointSnapsOntoTheNavMesh)
{
    BuildRiver();
    Result<Vec3> onBank = mWorld->FindNearestPoint(Vec3(-8, 1.5f, -6));
    ASSERT_TRUE(onBank) << onBank.GetError().mMessage;
    EXPECT_NEAR(onBank.Value().x(), -8.0f, 0.01f);
    EXPECT_NEAR(onBank.Value().z(), -6.0f, 0.01f);
    EXPECT_NEAR(onBank.Value().y(), 0.0f, 0.5f); // The ground's top, within Recast's cell height
    // Beyond the edge of the ground (x = 10, less the agent radius): pulled back onto it
    Result<Vec3> beyond = mWorld->FindNearestPoint(Vec3(11.0f, 0, -6));
    ASSERT_TRUE(beyond);
    EXPECT_LT(beyond.Value().x(), 10.0f);
    EXPECT_GT(beyond.Value().x(), 9.0f);

    Result<Vec3> high = mWorld->FindNearestPoint(Vec3(-8, 50, -6));
    ASSERT_FALSE(high);
    EXPECT_NE(high.GetError().mMessage.find("no navmesh"), std::string::npos);
    // In the water: found, unless water is excluded
    EXPECT_TRUE(mWorld->FindNearestPoint(Vec3(-5, 0, 0)));
    PathFilter noSwimming;
    noSwimming.mExcludedAreas = uint64_t(1) << cWater;
    Result<Vec3> wet = mWorld->FindNearestPoint(Vec3(-5, 0, 0), noSwimming);
    ASSERT_FALSE(wet);
    EXPECT_NE(wet.GetError().mMessage.find("excluded"), std::string::npos);
}

TEST_F(PathQueryTest, RandomPointsAreReachableRepeatableAndAvoidExcludedAreas)
{
    BuildRiver();
    PathFilter noSwimming;
    noSwimming.mExcludedAreas = uint64_t(1) << cWater;
    std::vector<Vec3> points;
    int inWater = 0;
    for (uint64_t seed = 1; seed <= 40; ++seed)
    {
        Result<Vec3> any = mWorld->FindRandomPointAround(mStart, 8.0f, seed);
        ASSERT_TRUE(any) << any.GetError().mMessage;
        inWater += std::abs(any.Value().z()) < 1.0f && any.Value().x() < 8.0f ? 1 : 0;
        Result<PathResult> path = mWorld->FindPath(mStart, any.Value());
        ASSERT_TRUE(path);
        EXPECT_TRUE(path.Value().mReachedEnd) << "seed " << seed;

        Result<Vec3> dry = mWorld->FindRandomPointAround(mStart, 8.0f, seed, noSwimming);
        ASSERT_TRUE(dry) << dry.GetError().mMessage;
        EXPECT_FALSE(std::abs(dry.Value().z()) < 0.9f && dry.Value().x() < 7.9f)
            << "a point in the excluded water: " << dry.Value().transpose();
        points.push_back(dry.Value());

        Result<PathResult> dryPath = mWorld->FindPath(mStart, dry.Value(), noSwimming);
        ASSERT_TRUE(dryPath);
        EXPECT_TRUE(dryPath.Value().mReachedEnd) << "seed " << seed << ": " << dry.Value().transpose();

        Result<Vec3> again = mWorld->FindRandomPointAround(mStart, 8.0f, seed, noSwimming);
        ASSERT_TRUE(again);
        EXPECT_EQ(again.Value(), dry.Value()) << "the same seed gives the same point";
    }
    EXPECT_GT(inWater, 0) << "the circle reaches the water: some points should fall in it when it is allowed";
    int distinct = 0;
    for (size_t i = 1; i < points.size(); ++i)
        distinct += (points[i] - points[0]).norm() > 0.1f ? 1 : 0;
    EXPECT_GT(distinct, 30);
}

TEST_F(PathQueryTest, RandomPointsBeyondAnExcludedAreaWithNoWayAroundAreNotDrawn)
{
    // As AnExcludedAreaThatIsTheOnlyWayCutsThePathShort: no bridge. The circle reaches over the water to the
    // north bank, which can only be reached by swimming
    AddStaticBox(Vec3(0, -0.5f, -5.5f), Vec3(10, 0.5f, 4.5f));
    AddStaticBox(Vec3(0, -0.5f, 5.5f), Vec3(10, 0.5f, 4.5f));
    AddStaticBox(Vec3(0, -0.5f, 0), Vec3(10, 0.5f, 1), cWater);
    MakeNavMesh();
    ASSERT_TRUE(RunUntilIdle());
    PathFilter noSwimming;
    noSwimming.mExcludedAreas = uint64_t(1) << cWater;
    int northWithWater = 0;
    for (uint64_t seed = 1; seed <= 40; ++seed)
    {
        Result<Vec3> any = mWorld->FindRandomPointAround(mStart, 9.0f, seed);
        ASSERT_TRUE(any);
        northWithWater += any.Value().z() > 1.0f ? 1 : 0;
        Result<Vec3> dry = mWorld->FindRandomPointAround(mStart, 9.0f, seed, noSwimming);
        ASSERT_TRUE(dry) << dry.GetError().mMessage;
        EXPECT_LT(dry.Value().z(), -0.9f) << "seed " << seed << ": only the south bank is reachable dry";
    }
    EXPECT_GT(northWithWater, 0) << "the circle reaches the north bank: swimming, some points are there";
    // From the water itself: refused, as FindPath refuses such a start
    Result<Vec3> wet = mWorld->FindRandomPointAround(Vec3(-5, 0, 0), 5.0f, 1, noSwimming);
    ASSERT_FALSE(wet);
    EXPECT_NE(wet.GetError().mMessage.find("excluded"), std::string::npos);
}

TEST_F(PathQueryTest, BadPointQueriesGetClearErrors)
{
    BuildRiver();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(mWorld->FindNearestPoint(Vec3(nan, 0, 0)).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_EQ(mWorld->FindNearestPoint(mStart, {}, Vec3(1.0e6f, 1, 1)).GetError().mCode,
              ErrorCode::InvalidArgument);
    EXPECT_EQ(mWorld->FindNearestPoint(mStart, {}, Vec3(-1, 1, 1)).GetError().mCode,
              ErrorCode::InvalidArgument);
    for (const float radius : {0.0f, -1.0f, nan, 1.0e6f})
        EXPECT_EQ(mWorld->FindRandomPointAround(mStart, radius, 1).GetError().mCode,
                  ErrorCode::InvalidArgument)
            << radius;
    EXPECT_EQ(mWorld->FindRandomPointAround(Vec3(0, nan, 0), 5.0f, 1).GetError().mCode,
              ErrorCode::InvalidArgument);
    Result<Vec3> off = mWorld->FindRandomPointAround(Vec3(-8, 50, -6), 5.0f, 1);
    ASSERT_FALSE(off);
    EXPECT_NE(off.GetError().mMessage.find("not on the navmesh"), std::string::npos);
    PathFilter bad;
    bad.mAreaCost[0] = std::numeric_limits<float>::infinity();
    EXPECT_EQ(mWorld->FindRandomPointAround(mStart, 5.0f, 1, bad).GetError().mCode,
              ErrorCode::InvalidArgument);
}

} // namespace
} // namespace cairn::navmesh::test
