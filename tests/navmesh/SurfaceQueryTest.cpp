// Queries across the navmesh's surface: a straight walk (Raycast) stops at the navmesh's edge and at an
// excluded area's border, follows the surface's height and crosses tile borders; the nearest wall
// (FindNearestWall) is Detour's wall where no area is excluded and the excluded area's border where one is;
// bad input is an error.

#include "RiverSceneFixture.h"

#include <DetourNavMesh.h>
#include <DetourNavMeshQuery.h>
#include <limits>
#include <memory>
#include <random>
#include <vector>

namespace cairn::navmesh::test
{
using namespace cairn::physics;
namespace
{

class SurfaceQueryTest : public RiverSceneFixture
{
protected:
    /// Ground from x = -10 to 10 and z = -4 to 4 (top at y = 0), a pillar at x in [-2.5, -1.5], z in
    /// [1.5, 2.5], and a block to climb, 0.4 m high, from x = 2 to 10.
    void BuildYard()
    {
        AddStaticBox(Vec3(0, -0.5f, 0), Vec3(10, 0.5f, 4));
        AddStaticBox(Vec3(-2, 1, 2), Vec3(0.5f, 1, 0.5f));
        AddStaticBox(Vec3(6, 0.2f, 0), Vec3(4, 0.2f, 4));
        MakeNavMesh();
        ASSERT_TRUE(RunUntilIdle());
    }

    /// The agent's radius: how far the navmesh keeps from walls.
    float Radius() const { return mWorld->GetProfile().mRadius; }
    /// Recast's cells: how far off a wall of the navmesh may lie from the geometry's.
    float Cell() const { return mWorld->GetProfile().mCellSize; }
};

TEST_F(SurfaceQueryTest, AStraightWalkStopsAtTheNavMeshEdgeFacingTheStart)
{
    BuildYard();
    // Into the pillar
    Result<NavRaycastHit> blocked = mWorld->Raycast(Vec3(-6, 0, 2), Vec3(2, 0, 2));
    ASSERT_TRUE(blocked) << blocked.GetError().mMessage;
    EXPECT_TRUE(blocked.Value().mHit);
    const float wallX = -2.5f - Radius();
    EXPECT_NEAR(blocked.Value().mPosition.x(), wallX, 2 * Cell());
    EXPECT_NEAR(blocked.Value().mPosition.z(), 2.0f, 0.01f);
    EXPECT_NEAR(blocked.Value().mPosition.y(), 0.0f, 0.3f);
    EXPECT_NEAR(blocked.Value().mFraction, (blocked.Value().mPosition.x() + 6) / 8, 1.0e-3f);
    EXPECT_NEAR(blocked.Value().mWallNormal.x(), -1.0f, 0.05f);
    EXPECT_NEAR(blocked.Value().mWallNormal.norm(), 1.0f, 1.0e-4f);
    EXPECT_EQ(blocked.Value().mWallNormal.y(), 0.0f);

    // Off the ground's south edge, the other way
    Result<NavRaycastHit> edge = mWorld->Raycast(Vec3(0, 0, 0), Vec3(0, 0, -8));
    ASSERT_TRUE(edge);
    EXPECT_TRUE(edge.Value().mHit);
    EXPECT_NEAR(edge.Value().mPosition.z(), -4.0f + Radius(), 2 * Cell());
    EXPECT_NEAR(edge.Value().mWallNormal.z(), 1.0f, 0.05f);

    // Beside the pillar: nothing in the way, and it ends at the end
    Result<NavRaycastHit> clear = mWorld->Raycast(Vec3(-6, 0, -1), Vec3(-1, 0, -1));
    ASSERT_TRUE(clear);
    EXPECT_FALSE(clear.Value().mHit);
    EXPECT_EQ(clear.Value().mFraction, 1.0f);
    EXPECT_NEAR(clear.Value().mPosition.x(), -1.0f, 1.0e-3f);
    EXPECT_NEAR(clear.Value().mPosition.z(), -1.0f, 1.0e-3f);
    EXPECT_EQ(clear.Value().mWallNormal, Vec3::Zero());
}

TEST_F(SurfaceQueryTest, AStraightWalkClimbsWithTheSurfaceAndCrossesTileBorders)
{
    BuildYard();
    // From x = -6 (one tile) onto the block at x = 7 (the other), the end given at the ground's height
    Result<NavRaycastHit> up = mWorld->Raycast(Vec3(-6, 0, -1), Vec3(7, 0, -1));
    ASSERT_TRUE(up) << up.GetError().mMessage;
    EXPECT_FALSE(up.Value().mHit);
    // The navmesh's point on the block's top (Recast's cells put it up to a cell and a half above the top)
    Result<Vec3> onBlock = mWorld->FindNearestPoint(Vec3(7, 0.4f, -1));
    ASSERT_TRUE(onBlock);
    EXPECT_GT(onBlock.Value().y(), 0.3f);
    EXPECT_NEAR((up.Value().mPosition - onBlock.Value()).norm(), 0.0f, 1.0e-3f);
    // The same from the block down
    Result<NavRaycastHit> down = mWorld->Raycast(Vec3(7, 0.4f, -1), Vec3(-6, 0.4f, -1));
    ASSERT_TRUE(down);
    EXPECT_FALSE(down.Value().mHit);
    Result<Vec3> onGround = mWorld->FindNearestPoint(Vec3(-6, 0, -1));
    ASSERT_TRUE(onGround);
    EXPECT_LT(onGround.Value().y(), 0.3f);
    EXPECT_NEAR((down.Value().mPosition - onGround.Value()).norm(), 0.0f, 1.0e-3f);
}

TEST_F(SurfaceQueryTest, EveryStraightWalkStopsOnTheNavMeshWithAWallNormalAtAHit)
{
    BuildYard();
    std::mt19937 random(3);
    std::uniform_real_distribution<float> x(-9.5f, 9.5f), z(-3.5f, 3.5f);
    const Vec3 extent(0.5f, 1.0f, 0.5f);
    int hits = 0, walks = 0;
    for (int i = 0; i < 4000; ++i)
    {
        // Some along the tiles' border (x = 0 or z = 0) and through their corner
        const float along = i % 4 == 0 ? 0.0f : z(random);
        const Vec3 from(x(random), 0, i % 8 == 1 ? 0.0f : along), to(i % 8 == 2 ? 0.0f : x(random), 0, along);
        Result<NavRaycastHit> walk = mWorld->Raycast(from, to, {}, extent);
        if (!walk) continue; // The start is off the navmesh (the pillar, the edge)
        ++walks;
        const NavRaycastHit& hit = walk.Value();
        ASSERT_GE(hit.mFraction, 0.0f);
        ASSERT_LE(hit.mFraction, 1.0f);
        Result<Vec3> onNavMesh = mWorld->FindNearestPoint(hit.mPosition, {}, Vec3(0.05f, 0.05f, 0.05f));
        ASSERT_TRUE(onNavMesh) << "walk " << i << " stopped off the navmesh";
        if (!hit.mHit)
        {
            EXPECT_EQ(hit.mFraction, 1.0f);
            continue;
        }
        ++hits;
        ASSERT_NEAR(hit.mWallNormal.norm(), 1.0f, 1.0e-4f)
            << "walk " << i << " " << from.transpose() << " -> " << to.transpose() << " at "
            << hit.mPosition.transpose();
        EXPECT_EQ(hit.mWallNormal.y(), 0.0f);
        // A walk stops at a wall, never inside the navmesh (Detour's own raycast stops at tile corners)
        Result<NavWall> wall = mWorld->FindNearestWall(hit.mPosition, 0.05f);
        ASSERT_TRUE(wall) << wall.GetError().mMessage;
        EXPECT_TRUE(wall.Value().mFound)
            << "walk " << i << " " << from.transpose() << " -> " << to.transpose() << " stopped at "
            << hit.mPosition.transpose() << ", away from any wall";
        // Towards the start as snapped onto the navmesh (a start in the pillar's margin is moved out of it)
        const Vec3 start = mWorld->FindNearestPoint(from, {}, extent).Value();
        EXPECT_LE(hit.mWallNormal.dot(to - start), 0.0f) << "walk " << i << ": the normal faces away";
    }
    EXPECT_GT(walks, 3000);
    EXPECT_GT(hits, 300);
}

TEST_F(SurfaceQueryTest, AStraightWalkAlongATileBorderGoesOnThroughTheCorner)
{
    BuildYard();
    // The four tiles meet at x = z = 0, where nothing is in the way
    const std::pair<Vec3, Vec3> lines[] = {{Vec3(-9, 0, 0), Vec3(9, 0, 0)},
                                           {Vec3(9, 0.4f, 0), Vec3(-9, 0, 0)},
                                           {Vec3(0, 0, -3), Vec3(0, 0, 3)},
                                           {Vec3(0, 0, 3), Vec3(0, 0, -3)},
                                           {Vec3(-3, 0, -3), Vec3(3, 0, 3)},
                                           {Vec3(-1, 0, 0), Vec3(1, 0, 0)},
                                           {Vec3(8.96044921875f, 0, 0), Vec3(-3.4295945167541504f, 0, 0)}};
    for (const auto& [from, to] : lines)
    {
        Result<NavRaycastHit> walk = mWorld->Raycast(from, to);
        ASSERT_TRUE(walk) << walk.GetError().mMessage;
        EXPECT_FALSE(walk.Value().mHit) << from.transpose() << " -> " << to.transpose() << " stopped at "
                                        << walk.Value().mPosition.transpose();
        EXPECT_NEAR(walk.Value().mPosition.x(), to.x(), 1.0e-3f);
        EXPECT_NEAR(walk.Value().mPosition.z(), to.z(), 1.0e-3f);
    }
}

TEST_F(SurfaceQueryTest, AStraightWalkStopsAtAnExcludedAreaAndCrossesItOtherwise)
{
    BuildRiver();
    Result<NavRaycastHit> swim = mWorld->Raycast(mStart, mEnd);
    ASSERT_TRUE(swim) << swim.GetError().mMessage;
    EXPECT_FALSE(swim.Value().mHit);
    EXPECT_NEAR(swim.Value().mPosition.z(), 6.0f, 1.0e-3f);

    Result<NavRaycastHit> dry = mWorld->Raycast(mStart, mEnd, NoSwimming());
    ASSERT_TRUE(dry) << dry.GetError().mMessage;
    EXPECT_TRUE(dry.Value().mHit);
    EXPECT_NEAR(dry.Value().mPosition.z(), -1.0f, 2 * Cell()); // The water's south border
    EXPECT_NEAR(dry.Value().mPosition.x(), -8.0f, 1.0e-3f);
    EXPECT_NEAR(dry.Value().mFraction, (dry.Value().mPosition.z() + 6) / 12, 1.0e-3f);
    EXPECT_NEAR(dry.Value().mWallNormal.z(), -1.0f, 0.05f); // Back towards the south bank
    // The same from the north: the water's north border, facing north
    Result<NavRaycastHit> fromNorth = mWorld->Raycast(mEnd, mStart, NoSwimming());
    ASSERT_TRUE(fromNorth);
    EXPECT_TRUE(fromNorth.Value().mHit);
    EXPECT_NEAR(fromNorth.Value().mPosition.z(), 1.0f, 2 * Cell());
    EXPECT_NEAR(fromNorth.Value().mWallNormal.z(), 1.0f, 0.05f);

    // Over the bridge, which is dry
    Result<NavRaycastHit> bridge = mWorld->Raycast(Vec3(9, 0, -6), Vec3(9, 0, 6), NoSwimming());
    ASSERT_TRUE(bridge);
    EXPECT_FALSE(bridge.Value().mHit);
    EXPECT_NEAR(bridge.Value().mPosition.z(), 6.0f, 1.0e-3f);

    // From the water itself, when water is excluded: an error, as for a path
    Result<NavRaycastHit> wet = mWorld->Raycast(Vec3(-5, 0, 0), mEnd, NoSwimming());
    ASSERT_FALSE(wet);
    EXPECT_NE(wet.GetError().mMessage.find("excluded"), std::string::npos);
}

TEST_F(SurfaceQueryTest, TheNearestWallIsTheNavMeshEdgeOrAnExcludedAreasBorder)
{
    BuildRiver();
    const Vec3 nearWater(-5, 0, -2);
    // The ground's west edge, 5 m away less the agent's radius
    Result<NavWall> edge = mWorld->FindNearestWall(nearWater, 8.0f);
    ASSERT_TRUE(edge) << edge.GetError().mMessage;
    ASSERT_TRUE(edge.Value().mFound);
    EXPECT_NEAR(edge.Value().mDistance, 5.0f - Radius(), 2 * Cell());
    EXPECT_NEAR(edge.Value().mPosition.x(), -10.0f + Radius(), 2 * Cell());
    EXPECT_NEAR(edge.Value().mPosition.z(), -2.0f, 0.01f);
    EXPECT_NEAR(edge.Value().mNormal.x(), 1.0f, 1.0e-3f);
    EXPECT_NEAR(edge.Value().mDistance,
                (Vec3(edge.Value().mPosition.x(), 0, edge.Value().mPosition.z()) - nearWater).norm(),
                1.0e-3f);
    // Not within 3 m
    Result<NavWall> none = mWorld->FindNearestWall(nearWater, 3.0f);
    ASSERT_TRUE(none);
    EXPECT_FALSE(none.Value().mFound);
    // With water excluded, its border is 1 m away
    Result<NavWall> water = mWorld->FindNearestWall(nearWater, 8.0f, NoSwimming());
    ASSERT_TRUE(water) << water.GetError().mMessage;
    ASSERT_TRUE(water.Value().mFound);
    EXPECT_NEAR(water.Value().mDistance, 1.0f, 2 * Cell());
    EXPECT_NEAR(water.Value().mPosition.z(), -1.0f, 2 * Cell());
    EXPECT_NEAR(water.Value().mNormal.z(), -1.0f, 1.0e-3f);
    // On the bridge, the water beside it is the wall (the bridge's east edge is about 1 m away)
    Result<NavWall> bridge = mWorld->FindNearestWall(Vec3(8.4f, 0, 0), 8.0f, NoSwimming());
    ASSERT_TRUE(bridge);
    ASSERT_TRUE(bridge.Value().mFound);
    EXPECT_NEAR(bridge.Value().mPosition.x(), 8.0f, 2 * Cell());
    EXPECT_NEAR(bridge.Value().mNormal.x(), 1.0f, 1.0e-3f);
}

TEST_F(SurfaceQueryTest, AWallReachedOnlyByAJumpIsNotTheNearest)
{
    // A roof over the ground, at x in [-2, 2], high enough to walk under, joined to the ground by a jump link
    AddStaticBox(Vec3(0, -0.5f, 0), Vec3(10, 0.5f, 4));
    AddStaticBox(Vec3(0, 2.8f, 0), Vec3(2, 0.2f, 4));
    MakeNavMesh();
    OffMeshLink jump;
    jump.mStart = Vec3(-4, 0, 0);
    jump.mEnd = Vec3(-1, 3, 0);
    ASSERT_TRUE(mScheduler->AddOffMeshLink(jump));
    ASSERT_TRUE(RunUntilIdle());
    ASSERT_TRUE(mWorld->FindPath(Vec3(-6, 0, 0), Vec3(0, 3, 0)).Value().mReachedEnd);
    // Under the roof the ground's own walls are its sides, 3.4 m away; the roof's edges above are 1.4 m away
    // across x and z, but only by the jump
    Result<NavWall> under = mWorld->FindNearestWall(Vec3(0, 0, 0), 8.0f);
    ASSERT_TRUE(under) << under.GetError().mMessage;
    ASSERT_TRUE(under.Value().mFound);
    EXPECT_NEAR(under.Value().mDistance, 4.0f - Radius(), 2 * Cell());
    EXPECT_NEAR(under.Value().mPosition.y(), 0.0f, 0.5f);
    // On the roof they are its own
    Result<NavWall> onRoof = mWorld->FindNearestWall(Vec3(0, 3, 0), 8.0f);
    ASSERT_TRUE(onRoof);
    ASSERT_TRUE(onRoof.Value().mFound);
    EXPECT_NEAR(onRoof.Value().mDistance, 2.0f - Radius(), 2 * Cell());
}

TEST_F(SurfaceQueryTest, TheNearestWallIsDetoursWhereNoAreaIsExcluded)
{
    BuildYard();
    struct Answer
    {
        Vec3 mPoint;
        float mDistance;
        Vec3 mWall;
    };
    std::vector<Answer> detours;
    const Vec3 extent(0.1f, 1.0f, 0.1f);
    mWorld->Read(
        [&](const dtNavMesh& inNavMesh)
        {
            const std::unique_ptr<dtNavMeshQuery, void (*)(dtNavMeshQuery*)> query(dtAllocNavMeshQuery(),
                                                                                   dtFreeNavMeshQuery);
            ASSERT_TRUE(dtStatusSucceed(query->init(&inNavMesh, 4096)));
            const dtQueryFilter filter;
            for (float x = -9.0f; x <= 9.0f; x += 0.7f)
                for (float z = -3.3f; z <= 3.3f; z += 0.55f)
                {
                    const Vec3 point(x, 0.2f, z);
                    dtPolyRef polygon = 0;
                    Vec3 onNavMesh;
                    query->findNearestPoly(point.data(), extent.data(), &filter, &polygon, onNavMesh.data());
                    if (polygon == 0) continue; // In the pillar or at the edge
                    Answer answer{point, 0.0f, Vec3::Zero()};
                    Vec3 normal;
                    ASSERT_TRUE(dtStatusSucceed(
                        query->findDistanceToWall(polygon, onNavMesh.data(), 8.0f, &filter, &answer.mDistance,
                                                  answer.mWall.data(), normal.data())));
                    detours.push_back(answer);
                }
        });
    ASSERT_GT(detours.size(), 200u);
    for (const Answer& detour : detours)
    {
        Result<NavWall> ours = mWorld->FindNearestWall(detour.mPoint, 8.0f, {}, extent);
        ASSERT_TRUE(ours) << ours.GetError().mMessage;
        ASSERT_TRUE(ours.Value().mFound) << detour.mPoint.transpose();
        EXPECT_NEAR(ours.Value().mDistance, detour.mDistance, 1.0e-3f) << detour.mPoint.transpose();
        EXPECT_NEAR(ours.Value().mPosition.x(), detour.mWall.x(), 1.0e-3f) << detour.mPoint.transpose();
        EXPECT_NEAR(ours.Value().mPosition.z(), detour.mWall.z(), 1.0e-3f) << detour.mPoint.transpose();
    }
}

TEST_F(SurfaceQueryTest, BadSurfaceQueriesGetClearErrors)
{
    BuildRiver();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float tiles = NavMeshWorld::cMaxSearchExtentTiles * mWorld->GetGrid().GetTileSize();
    EXPECT_EQ(mWorld->Raycast(Vec3(nan, 0, 0), mEnd).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_EQ(mWorld->Raycast(mStart, Vec3(0, 0, 1.0e9f)).GetError().mCode, ErrorCode::InvalidArgument);
    Result<NavRaycastHit> far = mWorld->Raycast(mStart, mStart + Vec3(tiles + 1.0f, 0, 0));
    ASSERT_FALSE(far);
    EXPECT_NE(far.GetError().mMessage.find("at most"), std::string::npos);
    Result<NavRaycastHit> high = mWorld->Raycast(Vec3(-8, 50, -6), mEnd);
    ASSERT_FALSE(high);
    EXPECT_NE(high.GetError().mMessage.find("not on the navmesh"), std::string::npos);
    EXPECT_EQ(mWorld->Raycast(mStart, mEnd, {}, Vec3(0, 0, 0)).GetError().mCode, ErrorCode::InvalidArgument);
    PathFilter badCost;
    badCost.mAreaCost[0] = nan;
    EXPECT_EQ(mWorld->Raycast(mStart, mEnd, badCost).GetError().mCode, ErrorCode::InvalidArgument);

    EXPECT_EQ(mWorld->FindNearestWall(Vec3(nan, 0, 0), 4.0f).GetError().mCode, ErrorCode::InvalidArgument);
    for (float radius : {0.0f, -1.0f, nan, tiles * 2.0f})
        EXPECT_EQ(mWorld->FindNearestWall(mStart, radius).GetError().mCode, ErrorCode::InvalidArgument)
            << radius;
    EXPECT_TRUE(mWorld->FindNearestWall(mStart, tiles)); // The limit itself
    EXPECT_FALSE(mWorld->FindNearestWall(Vec3(-8, 50, -6), 4.0f));
    Result<NavWall> wet = mWorld->FindNearestWall(Vec3(-5, 0, 0), 4.0f, NoSwimming());
    ASSERT_FALSE(wet);
    EXPECT_NE(wet.GetError().mMessage.find("excluded"), std::string::npos);
    EXPECT_EQ(mWorld->FindNearestWall(mStart, 4.0f, badCost).GetError().mCode, ErrorCode::InvalidArgument);
}

} // namespace
} // namespace cairn::navmesh::test
