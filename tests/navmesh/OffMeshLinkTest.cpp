// Off-mesh links: a jump across a gap the navmesh cannot cross joins the two sides while it is declared.

#include "NavMeshSceneFixture.h"

namespace cairn::navmesh::test
{
using namespace cairn::physics;
namespace
{

class OffMeshLinkTest : public NavMeshSceneFixture
{
};

TEST_F(OffMeshLinkTest, AJumpAcrossAGapJoinsTheSidesWhileDeclared)
{
    // Two platforms 3 m apart (a gap no agent walks), in different tiles
    AddStaticBox(Vec3(-6, -0.5f, 0), Vec3(4.5f, 0.5f, 4)); // x in [-10.5, -1.5]
    AddStaticBox(Vec3(6, -0.5f, 0), Vec3(4.5f, 0.5f, 4));  // x in [1.5, 10.5]
    MakeNavMesh();
    ASSERT_TRUE(RunUntilIdle());
    const Vec3 start(-8, 0, 0), end(8, 0, 0);
    Result<PathResult> apart = mWorld->FindPath(start, end);
    ASSERT_TRUE(apart) << apart.GetError().mMessage;
    EXPECT_FALSE(apart.Value().mReachedEnd);

    OffMeshLink jump;
    jump.mStart = Vec3(-2.5f, 0, 0);
    jump.mEnd = Vec3(2.5f, 0, 0);
    jump.mRadius = 0.6f;
    const TileScheduler::LinkID link = mScheduler->AddOffMeshLink(jump).Value();
    ASSERT_TRUE(RunUntilIdle());
    Result<PathResult> joined = mWorld->FindPath(start, end);
    ASSERT_TRUE(joined);
    EXPECT_TRUE(joined.Value().mReachedEnd);
    // Back the other way too: the link is bidirectional
    Result<PathResult> back = mWorld->FindPath(end, start);
    ASSERT_TRUE(back);
    EXPECT_TRUE(back.Value().mReachedEnd);

    mScheduler->RemoveOffMeshLink(link);
    ASSERT_TRUE(RunUntilIdle());
    Result<PathResult> again = mWorld->FindPath(start, end);
    ASSERT_TRUE(again);
    EXPECT_FALSE(again.Value().mReachedEnd);
}

TEST_F(OffMeshLinkTest, AOneWayDropIsTakenOneWayOnly)
{
    AddStaticBox(Vec3(-6, -0.5f, 0), Vec3(4.5f, 0.5f, 4));
    AddStaticBox(Vec3(6, -0.5f, 0), Vec3(4.5f, 0.5f, 4));
    MakeNavMesh();
    OffMeshLink drop;
    drop.mStart = Vec3(-2.5f, 0, 0);
    drop.mEnd = Vec3(2.5f, 0, 0);
    drop.mBidirectional = false;
    ASSERT_TRUE(mScheduler->AddOffMeshLink(drop));
    ASSERT_TRUE(RunUntilIdle());
    EXPECT_TRUE(mWorld->FindPath(Vec3(-8, 0, 0), Vec3(8, 0, 0)).Value().mReachedEnd);
    EXPECT_FALSE(mWorld->FindPath(Vec3(8, 0, 0), Vec3(-8, 0, 0)).Value().mReachedEnd);
}

} // namespace
} // namespace cairn::navmesh::test
