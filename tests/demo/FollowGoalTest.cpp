// The goal of a demo agent that follows the player: the navmesh under the player when it is built, and until
// then the navmesh the player's way from the agent, so that the agent walks after the player instead of
// standing where it is (41 % of the demo's path queries failed that way before).

#include "../navmesh/NavMeshSceneFixture.h"
#include "Agents.h"

namespace cairn::demo
{
using namespace cairn::physics;
namespace
{

class FollowGoalTest : public navmesh::test::NavMeshSceneFixture
{
protected:
    /// Flat ground at y = 0 over the navmesh's 4 x 4 tiles (x and z in [-25.6, 25.6]), all of them built.
    void SetUp() override
    {
        AddStaticBox(Vec3(0, -0.5f, 0), Vec3(25.6f, 0.5f, 25.6f));
        MakeNavMesh(2);
        ASSERT_TRUE(RunUntilIdle());
    }

    Result<Vec3> Goal(const Vec3& inAgent, const Vec3& inPlayer, float inReach = 15.0f) const
    {
        return FollowGoal(*mWorld, inAgent, inPlayer, inReach, [](float, float) { return 0.0f; });
    }
};

TEST_F(FollowGoalTest, APlayerOnTheNavMeshIsTheGoal)
{
    const Result<Vec3> goal = Goal(Vec3(-20, 0, 0), Vec3(18, 0, 5));
    ASSERT_TRUE(goal) << goal.GetError().mMessage;
    EXPECT_NEAR(goal.Value().x(), 18.0f, 0.5f);
    EXPECT_NEAR(goal.Value().z(), 5.0f, 0.5f);
}

TEST_F(FollowGoalTest, BeforeThePlayersNavMeshIsBuiltTheAgentHeadsItsWay)
{
    // The player 40 m east, 15 m beyond the built tiles: no navmesh within the search's 4 m of it
    const Vec3 agent(0, 0, 0), player(40, 0, 0);
    ASSERT_FALSE(mWorld->FindNearestPoint(player, {}, Vec3(4, 8, 4)));
    const Result<Vec3> goal = Goal(agent, player);
    ASSERT_TRUE(goal) << goal.GetError().mMessage;
    EXPECT_NEAR(goal.Value().x(), 15.0f, 0.5f);
    EXPECT_NEAR(goal.Value().z(), 0.0f, 0.5f);
    // And the agent can walk there
    const Result<navmesh::PathResult> path = mWorld->FindPath(agent, goal.Value());
    ASSERT_TRUE(path) << path.GetError().mMessage;
    EXPECT_TRUE(path.Value().mReachedEnd);
}

TEST_F(FollowGoalTest, TheWayIsAlongTheGroundTowardsThePlayer)
{
    // Diagonal, with the player high above: only the ground plane's direction counts
    const Result<Vec3> goal = Goal(Vec3(0, 0, 0), Vec3(-30, 50, -40), 10.0f);
    ASSERT_TRUE(goal) << goal.GetError().mMessage;
    EXPECT_NEAR(goal.Value().x(), -6.0f, 0.5f);
    EXPECT_NEAR(goal.Value().z(), -8.0f, 0.5f);
    EXPECT_NEAR(goal.Value().y(), 0.0f, 0.5f);
}

TEST_F(FollowGoalTest, NoNavMeshEitherWayIsAnError)
{
    // From the navmesh's east edge the point 15 m further east is off it too
    EXPECT_FALSE(Goal(Vec3(25, 0, 0), Vec3(60, 0, 0)));
}

TEST_F(FollowGoalTest, APlayerWithinReachWithNoNavMeshUnderItIsAnError)
{
    // The player stands on a roof 50 m up, 5 m from the agent: nothing is within the search's 8 m of it. The
    // point 15 m on is on the ground's navmesh, but it is past the player: the agent is as close as it gets
    auto roof = [](float inX, float) { return inX > 4.0f && inX < 6.0f ? 50.0f : 0.0f; };
    const Result<Vec3> goal = FollowGoal(*mWorld, Vec3(0, 0, 0), Vec3(5, 50, 0), 15.0f, roof);
    EXPECT_FALSE(goal) << "goal at x " << goal.Value().x();
}

} // namespace
} // namespace cairn::demo
