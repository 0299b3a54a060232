// Off-mesh links: a jump across a gap the navmesh cannot cross joins the two sides while it is declared; each
// link says whether agents can take it (Detour joins its ends, or leaves one unjoined without a word).

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

// Detour says nothing of a link it could not join: the scheduler and the world do. Pending until its tile is
// built with it; then joined, or which end joins nothing, or left out of the tile by Detour's builder
TEST_F(OffMeshLinkTest, EachLinkSaysWhetherAgentsCanTakeIt)
{
    AddStaticBox(Vec3(-6, -0.5f, 0), Vec3(4.5f, 0.5f, 4)); // x in [-10.5, -1.5]
    AddStaticBox(Vec3(6, -0.5f, 0), Vec3(4.5f, 0.5f, 4));  // x in [1.5, 10.5]
    MakeNavMesh();
    ASSERT_TRUE(RunUntilIdle());
    auto link = [](const Vec3& inStart, const Vec3& inEnd)
    {
        OffMeshLink made;
        made.mStart = inStart;
        made.mEnd = inEnd;
        made.mRadius = 0.6f;
        return made;
    };
    const OffMeshLink jump = link(Vec3(-2.5f, 0, 0), Vec3(2.5f, 0, 0));
    const TileScheduler::LinkID joined = mScheduler->AddOffMeshLink(jump).Value();
    const TileScheduler::LinkID endUp =
        mScheduler->AddOffMeshLink(link(Vec3(-2.5f, 0, 2), Vec3(2.5f, 3, 2))).Value();
    const TileScheduler::LinkID endOverGap =
        mScheduler->AddOffMeshLink(link(Vec3(-2.5f, 0, -2), Vec3(0, 0, -2))).Value();
    const TileScheduler::LinkID startUp =
        mScheduler->AddOffMeshLink(link(Vec3(-5, 3, -3), Vec3(2.5f, 0, -3))).Value();
    // Its end in a tile outside the scheduler's area: never built
    const TileScheduler::LinkID endAway =
        mScheduler->AddOffMeshLink(link(Vec3(10, 0, 0), Vec3(14, 0, 0))).Value();
    EXPECT_EQ(mScheduler->GetOffMeshLinkState(joined).Value(), OffMeshLinkState::Pending);
    EXPECT_EQ(mScheduler->GetOffMeshLinkState(endAway).Value(), OffMeshLinkState::Pending);
    EXPECT_EQ(mWorld->GetOffMeshLinkState(jump).Value(), OffMeshLinkState::LeftOut)
        << "its tile built before it";
    ASSERT_TRUE(RunUntilIdle());
    EXPECT_EQ(mScheduler->GetOffMeshLinkState(joined).Value(), OffMeshLinkState::Joined);
    EXPECT_EQ(mScheduler->GetOffMeshLinkState(endUp).Value(), OffMeshLinkState::EndUnjoined);
    EXPECT_EQ(mScheduler->GetOffMeshLinkState(endOverGap).Value(), OffMeshLinkState::EndUnjoined);
    EXPECT_EQ(mScheduler->GetOffMeshLinkState(startUp).Value(), OffMeshLinkState::LeftOut);
    EXPECT_EQ(mScheduler->GetOffMeshLinkState(endAway).Value(), OffMeshLinkState::EndTileMissing);
    // A start with no polygon within its radius: Detour's builder keeps it (within the tile's heights)
    const TileScheduler::LinkID startOverGap =
        mScheduler->AddOffMeshLink(link(Vec3(-0.5f, 0, 3), Vec3(2.5f, 0, 3))).Value();
    ASSERT_TRUE(RunUntilIdle());
    EXPECT_EQ(mScheduler->GetOffMeshLinkState(startOverGap).Value(), OffMeshLinkState::StartUnjoined);
    EXPECT_EQ(mScheduler->GetOffMeshLinkState(joined).Value(), OffMeshLinkState::Joined) << "rebuilt with it";

    mScheduler->RemoveOffMeshLink(joined);
    EXPECT_FALSE(mScheduler->GetOffMeshLinkState(joined)) << "a removed link";
    EXPECT_FALSE(mScheduler->GetOffMeshLinkState(9999)) << "an unknown link";
    ASSERT_TRUE(RunUntilIdle());
    EXPECT_EQ(mWorld->GetOffMeshLinkState(jump).Value(), OffMeshLinkState::LeftOut);
    // Beyond the scheduler's area, no tile is built
    EXPECT_EQ(mWorld->GetOffMeshLinkState(link(Vec3(14, 0, 0), Vec3(16, 0, 0))).Value(),
              OffMeshLinkState::StartTileMissing);
    OffMeshLink bad = jump;
    bad.mEnd.x() = std::nanf("");
    EXPECT_FALSE(mWorld->GetOffMeshLinkState(bad));
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

// A link whose end lies more than a tile from its start's tile is refused: Detour would never join it
TEST_F(OffMeshLinkTest, ALinkLongerThanATileAcrossIsRefused)
{
    AddStaticBox(Vec3(0, -0.5f, 0), Vec3(12, 0.5f, 4));
    MakeNavMesh(2); // Tiles of 12.8 m from x = -25.6
    OffMeshLink far;
    far.mStart = Vec3(-20, 0, 0); // Tile 0 across
    far.mEnd = Vec3(11, 0, 0);    // Tile 2
    const Result<TileScheduler::LinkID> refused = mScheduler->AddOffMeshLink(far);
    ASSERT_FALSE(refused);
    EXPECT_NE(refused.GetError().mMessage.find("more than a tile"), std::string::npos);
    far.mEnd = Vec3(-5, 0, 0); // Tile 1, the next
    EXPECT_TRUE(mScheduler->AddOffMeshLink(far));
}

} // namespace
} // namespace cairn::navmesh::test
