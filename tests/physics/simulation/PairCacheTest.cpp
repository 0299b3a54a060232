// The body-pair cache: a pair that has not moved relative to itself takes last step's manifolds over instead
// of colliding its shapes again. These tests check that it is used when it should be, and that anything that
// moves a pair makes the narrow phase look again.

#include "SimulationFixture.h"

namespace cairn::test
{
using namespace cairn::physics;
namespace
{

class PairCacheTest : public SimulationFixture
{
protected:
    /// A settled box resting on the default floor, sleeping turned off so that it stays in the step.
    BodyID AddRestingBox(const Vec3& inPosition = Vec3(0, 0.5f, 0))
    {
        PhysicsSettings settings;
        settings.mAllowSleeping = false;
        ResetWorld(settings);
        AddFloor();
        const BodyID box = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), inPosition));
        Step(60);
        return box;
    }

    const StepStatistics& LastStep() { return System().GetLastStepStatistics(); }
};

TEST_F(PairCacheTest, ARestingPairReusesItsManifolds)
{
    const BodyID box = AddRestingBox();
    Step(1);
    EXPECT_EQ(LastStep().mNumBodyPairs, 1u);
    EXPECT_EQ(LastStep().mNumReusedBodyPairs, 1u);
    EXPECT_EQ(LastStep().mNumManifolds, 1u);
    EXPECT_EQ(LastStep().mNumContactPoints, 4u);
    // Reused manifolds still hold the box up, at rest, for a long time
    Step(600);
    EXPECT_NEAR(Position(box).y(), 0.5f, 0.01f);
    EXPECT_LT(Velocity(box).norm(), 0.01f);
    EXPECT_NEAR(Position(box).x(), 0.0f, 0.01f);
}

TEST_F(PairCacheTest, ASlidingPairIsCollidedEveryStep)
{
    const BodyID box = AddRestingBox();
    ASSERT_TRUE(Bodies().SetLinearVelocity(box, Vec3(2, 0, 0)).IsOk());
    for (int i = 0; i < 10; ++i)
    {
        Step(1);
        // 2 m/s is 3 cm a step: far beyond the 1 mm the cache allows. Even in the first step, before the box
        // has moved, the old manifold does not do: it was made with the look-ahead of a box at rest
        EXPECT_EQ(LastStep().mNumReusedBodyPairs, 0u) << "step " << i;
        EXPECT_EQ(LastStep().mNumManifolds, 1u) << "step " << i;
    }
}

TEST_F(PairCacheTest, ATeleportedBodyIsCollidedAtItsNewPlace)
{
    const BodyID box = AddRestingBox();
    // Moved 30 cm along the floor and sunk 5 cm into it: the old manifold would leave the box 5 cm deep
    ASSERT_TRUE(Bodies().SetPosition(box, Vec3(0.3f, 0.45f, 0), Activation::Activate).IsOk());
    Step(1);
    EXPECT_EQ(LastStep().mNumReusedBodyPairs, 0u);
    Step(30);
    EXPECT_NEAR(Position(box).y(), 0.5f, 0.01f);
    EXPECT_NEAR(Position(box).x(), 0.3f, 0.01f);
}

TEST_F(PairCacheTest, SlowDriftIsMeasuredFromWhereTheManifoldsWereMade)
{
    // A box pushed along the floor by 0.4 mm a step: each step alone is under the 1 mm limit, but the pose is
    // compared with the one the manifold was made at, so the pair is collided again at least every third step
    const BodyID box = AddRestingBox();
    int reused = 0, collided = 0;
    for (int i = 0; i < 30; ++i)
    {
        const Vec3 p = Position(box);
        ASSERT_TRUE(Bodies().SetPosition(box, p + Vec3(0.0004f, 0, 0), Activation::Activate).IsOk());
        Step(1);
        (LastStep().mNumReusedBodyPairs == 1 ? reused : collided) += 1;
    }
    EXPECT_GT(reused, 0);
    EXPECT_GE(collided, 30 / 3);
}

TEST_F(PairCacheTest, TurnedOffByAZeroDelta)
{
    PhysicsSettings settings;
    settings.mAllowSleeping = false;
    settings.mPairCacheMaxDeltaPosition = 0.0f;
    ResetWorld(settings);
    AddFloor();
    const BodyID box = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 0.5f, 0)));
    for (int i = 0; i < 60; ++i)
    {
        Step(1);
        EXPECT_EQ(LastStep().mNumReusedBodyPairs, 0u);
    }
    EXPECT_NEAR(Position(box).y(), 0.5f, 0.01f);
}

TEST_F(PairCacheTest, APairThatStaysApartIsNotCollidedAgainButIsFoundWhenItCloses)
{
    PhysicsSettings settings;
    settings.mAllowSleeping = false;
    settings.mGravity = Vec3::Zero();
    ResetWorld(settings);
    // Two boxes 1 cm apart along x: their bounds (with the speculative margin) overlap, the shapes do not
    // touch within the step's look-ahead when at rest
    const BodyID left = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 0, 0)));
    const BodyID right = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(1.03f, 0, 0)));
    // The first step finds the pair (the bounds get their speculative margin at its end), the next reuses it
    Step(3);
    ASSERT_EQ(LastStep().mNumBodyPairs, 1u);
    EXPECT_EQ(LastStep().mNumManifolds, 0u);
    EXPECT_EQ(LastStep().mNumReusedBodyPairs, 1u);
    // Pushed together: the pair is collided again and the boxes do not pass through each other
    ASSERT_TRUE(Bodies().SetLinearVelocity(right, Vec3(-3, 0, 0)).IsOk());
    Step(1);
    EXPECT_EQ(LastStep().mNumReusedBodyPairs, 0u);
    Step(30);
    EXPECT_GT(Position(right).x() - Position(left).x(), 0.98f);
}

} // namespace
} // namespace cairn::test
