#include "SimulationFixture.h"

#include <thread>

namespace cairn::test
{

class WorldQueryTest : public SimulationFixture
{
protected:
    void SetUp() override
    {
        mFloor = AddFloor();
        mSphere = AddStatic(Sphere(1.0f), Vec3(0, 1, 0));
        BodyCreationSettings trigger = DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(5, 0.5f, 0));
        trigger.mObjectLayer = Layers::cTrigger;
        trigger.mMotionType = MotionType::Kinematic;
        mTrigger = AddDynamic(trigger);
    }
    const WorldQuery& Query() { return System().GetWorldQuery(); }

    BodyID mFloor, mSphere, mTrigger;
};

TEST_F(WorldQueryTest, ClosestRayHitsTheNearestSurface)
{
    const std::optional<RayCastResult> hit = Query().CastRayClosest({Vec3(0, 10, 0), Vec3(0, -20, 0)});
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->mBody, mSphere);
    EXPECT_NEAR(hit->mFraction, 8.0f / 20.0f, 1.0e-4f);
    EXPECT_NEAR(hit->mNormal.y(), 1.0f, 1.0e-4f);
}

TEST_F(WorldQueryTest, AllHitsAreSortedAndFiltered)
{
    std::vector<RayCastResult> hits;
    Query().CastRayAll({Vec3(0, 10, 0), Vec3(0, -20, 0)}, hits);
    ASSERT_EQ(hits.size(), 2u);
    EXPECT_EQ(hits[0].mBody, mSphere);
    EXPECT_EQ(hits[1].mBody, mFloor);
    EXPECT_NEAR(hits[1].mFraction, 0.5f, 1.0e-4f);

    QueryFilter noStatic;
    noStatic.mObjectLayers = cAllObjectLayers & ~(ObjectLayerMask(1) << Layers::cStatic);
    Query().CastRayAll({Vec3(0, 10, 0), Vec3(0, -20, 0)}, hits, noStatic);
    EXPECT_TRUE(hits.empty());

    QueryFilter ignoreSphere;
    ignoreSphere.mIgnoreBody = mSphere;
    const std::optional<RayCastResult> hit =
        Query().CastRayClosest({Vec3(0, 10, 0), Vec3(0, -20, 0)}, ignoreSphere);
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->mBody, mFloor);
}

TEST_F(WorldQueryTest, AnyRayAndMisses)
{
    EXPECT_TRUE(Query().CastRayAny({Vec3(0, 10, 0), Vec3(0, -20, 0)}));
    EXPECT_FALSE(Query().CastRayAny({Vec3(0, 10, 0), Vec3(0, 5, 0)}));
    EXPECT_FALSE(Query().CastRayClosest({Vec3(0, 10, 0), Vec3(0, -5, 0)}).has_value())
        << "segment ends above the sphere";
}

TEST_F(WorldQueryTest, OverlapQueriesUseExactShapes)
{
    std::vector<BodyID> bodies;
    // A point inside the sphere's AABB corner but outside the sphere itself
    Query().CollidePoint(Vec3(0.9f, 1.9f, 0.0f), bodies);
    EXPECT_TRUE(bodies.empty());
    Query().CollidePoint(Vec3(0.0f, 1.5f, 0.0f), bodies);
    ASSERT_EQ(bodies.size(), 1u);
    EXPECT_EQ(bodies[0], mSphere);

    Query().CollideSphere(Vec3(0, 3.2f, 0), 0.25f, bodies);
    EXPECT_TRUE(bodies.empty());
    Query().CollideSphere(Vec3(0, 2.1f, 0), 0.25f, bodies);
    ASSERT_EQ(bodies.size(), 1u);

    Query().CollideAABox(AABB(Vec3(4, 0.2f, -1), Vec3(6, 2, 1)), bodies);
    ASSERT_EQ(bodies.size(), 1u) << "the trigger box only, not the floor below y = 0";
    EXPECT_EQ(bodies[0], mTrigger);
}

TEST_F(WorldQueryTest, QueriesFromOtherThreadsWhileStepping)
{
    AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(-5, 3, 0)));
    std::atomic<bool> stop{false};
    std::atomic<int> misses{0};
    std::thread querier(
        [&]
        {
            while (!stop.load(std::memory_order_relaxed))
                if (!Query().CastRayClosest({Vec3(0, 10, 0), Vec3(0, -20, 0)}).has_value())
                    misses.fetch_add(1, std::memory_order_relaxed);
        });
    Step(60);
    stop.store(true, std::memory_order_relaxed);
    querier.join();
    EXPECT_EQ(misses.load(), 0);
}

} // namespace cairn::test
