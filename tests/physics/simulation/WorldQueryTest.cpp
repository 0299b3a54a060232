#include "SimulationFixture.h"
#include "cairn/physics/body/BodyLock.h"
#include "cairn/physics/shapes/SphereShape.h"

#include <limits>
#include <thread>

namespace cairn::test
{
using namespace cairn::physics;

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
    const std::optional<RayCastResult> hit =
        Query().CastRayClosest({Vec3(0, 10, 0), Vec3(0, -20, 0)}).Value();
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->mBody, mSphere);
    EXPECT_NEAR(hit->mFraction, 8.0f / 20.0f, 1.0e-4f);
    EXPECT_NEAR(hit->mNormal.y(), 1.0f, 1.0e-4f);
}

TEST_F(WorldQueryTest, AllHitsAreSortedAndFiltered)
{
    std::vector<RayCastResult> hits;
    ASSERT_TRUE(Query().CastRayAll({Vec3(0, 10, 0), Vec3(0, -20, 0)}, hits).IsOk());
    ASSERT_EQ(hits.size(), 2u);
    EXPECT_EQ(hits[0].mBody, mSphere);
    EXPECT_EQ(hits[1].mBody, mFloor);
    EXPECT_NEAR(hits[1].mFraction, 0.5f, 1.0e-4f);

    QueryFilter noStatic;
    noStatic.mObjectLayers = cAllObjectLayers & ~(ObjectLayerMask(1) << Layers::cStatic);
    ASSERT_TRUE(Query().CastRayAll({Vec3(0, 10, 0), Vec3(0, -20, 0)}, hits, noStatic).IsOk());
    EXPECT_TRUE(hits.empty());

    QueryFilter ignoreSphere;
    ignoreSphere.mIgnoreBody = mSphere;
    const std::optional<RayCastResult> hit =
        Query().CastRayClosest({Vec3(0, 10, 0), Vec3(0, -20, 0)}, ignoreSphere).Value();
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->mBody, mFloor);
}

TEST_F(WorldQueryTest, AnyRayAndMisses)
{
    EXPECT_TRUE(Query().CastRayAny({Vec3(0, 10, 0), Vec3(0, -20, 0)}).Value());
    EXPECT_FALSE(Query().CastRayAny({Vec3(0, 10, 0), Vec3(0, 5, 0)}).Value());
    EXPECT_FALSE(Query().CastRayClosest({Vec3(0, 10, 0), Vec3(0, -5, 0)}).Value().has_value())
        << "segment ends above the sphere";
}

TEST_F(WorldQueryTest, OverlapQueriesUseExactShapes)
{
    std::vector<BodyID> bodies;
    // A point inside the sphere's AABB corner but outside the sphere itself
    ASSERT_TRUE(Query().CollidePoint(Vec3(0.9f, 1.9f, 0.0f), bodies).IsOk());
    EXPECT_TRUE(bodies.empty());
    ASSERT_TRUE(Query().CollidePoint(Vec3(0.0f, 1.5f, 0.0f), bodies).IsOk());
    ASSERT_EQ(bodies.size(), 1u);
    EXPECT_EQ(bodies[0], mSphere);

    ASSERT_TRUE(Query().CollideSphere(Vec3(0, 3.2f, 0), 0.25f, bodies).IsOk());
    EXPECT_TRUE(bodies.empty());
    ASSERT_TRUE(Query().CollideSphere(Vec3(0, 2.1f, 0), 0.25f, bodies).IsOk());
    ASSERT_EQ(bodies.size(), 1u);

    ASSERT_TRUE(Query().CollideAABox(AABB(Vec3(4, 0.2f, -1), Vec3(6, 2, 1)), bodies).IsOk());
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
            {
                const Result<std::optional<RayCastResult>> hit =
                    Query().CastRayClosest({Vec3(0, 10, 0), Vec3(0, -20, 0)});
                if (!hit.IsOk() || !hit.Value().has_value()) misses.fetch_add(1, std::memory_order_relaxed);
            }
        });
    Step(60);
    stop.store(true, std::memory_order_relaxed);
    querier.join();
    EXPECT_EQ(misses.load(), 0);
}

TEST_F(WorldQueryTest, BadInputIsAnErrorNotAMiss)
{
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    std::vector<RayCastResult> hits;
    std::vector<BodyID> bodies;
    auto code = [](const auto& inResult) { return inResult.GetError().mCode; };
    EXPECT_EQ(code(Query().CastRayClosest({Vec3(nan, 10, 0), Vec3(0, -20, 0)})), ErrorCode::InvalidArgument);
    EXPECT_EQ(code(Query().CastRayAny({Vec3(0, 10, 0), Vec3(0, inf, 0)})), ErrorCode::InvalidArgument);
    EXPECT_EQ(code(Query().CastRayAll({Vec3(0, 2e6f, 0), Vec3(0, -20, 0)}, hits)),
              ErrorCode::InvalidArgument);
    EXPECT_EQ(code(Query().CollideSphere(Vec3(0, 2, 0), nan, bodies)), ErrorCode::InvalidArgument);
    EXPECT_EQ(code(Query().CollideSphere(Vec3(0, 2, 0), 0.0f, bodies)), ErrorCode::InvalidArgument);
    EXPECT_EQ(code(Query().CollidePoint(Vec3(0, nan, 0), bodies)), ErrorCode::InvalidArgument);
    EXPECT_EQ(code(Query().CollideAABox(AABB(Vec3(1, 1, 1), Vec3(0, 0, 0)), bodies)),
              ErrorCode::InvalidArgument);
    const SphereShape probe(1.0f);
    std::vector<ShapeQueryHit> shapeHits;
    EXPECT_EQ(code(Query().CollideShape(probe, {Vec3(0, 2, 0), Quat(2, 0, 0, 0)}, shapeHits)),
              ErrorCode::InvalidArgument)
        << "a rotation that is not a unit quaternion";
    EXPECT_EQ(code(Query().CollideShape(probe, {Vec3(0, 2, 0), Quat::Identity()}, shapeHits, {}, nan)),
              ErrorCode::InvalidArgument);
}

TEST_F(WorldQueryTest, AQueryWhileHoldingABodyLockReadsPublishedPoses)
{
    BodyLockRead lock(System().GetBodyManager(), mFloor);
    ASSERT_TRUE(lock.Succeeded());
    // Published poses take no lock, so holding one is no reason to refuse (or to answer "nothing there")
    const Result<std::optional<RayCastResult>> hit =
        Query().CastRayClosest({Vec3(0, 10, 0), Vec3(0, -20, 0)});
    ASSERT_TRUE(hit.IsOk());
    ASSERT_TRUE(hit.Value().has_value());
    EXPECT_EQ(hit.Value()->mBody, mSphere);
    std::vector<BodyID> bodies;
    ASSERT_TRUE(Query().CollidePoint(Vec3(0.0f, 1.5f, 0.0f), bodies).IsOk());
    EXPECT_EQ(bodies, std::vector<BodyID>{mSphere});
}

TEST_F(WorldQueryTest, ABodyLockQueryWhileHoldingABodyLockIsRefusedNotEmpty)
{
    PhysicsSettings settings;
    settings.mQueryReads = QueryReads::BodyLocks;
    ResetWorld(settings);
    SetUp();
    BodyLockRead lock(System().GetBodyManager(), mFloor);
    ASSERT_TRUE(lock.Succeeded());
    // It could not read the bodies under their locks: before, it returned no hits as if the way were clear
    const Result<bool> any = Query().CastRayAny({Vec3(0, 10, 0), Vec3(0, -20, 0)});
    ASSERT_FALSE(any.IsOk());
    EXPECT_EQ(any.GetError().mCode, ErrorCode::WrongThread);
    std::vector<BodyID> bodies;
    EXPECT_EQ(Query().CollidePoint(Vec3(0.0f, 1.5f, 0.0f), bodies).GetError().mCode, ErrorCode::WrongThread);
}

} // namespace cairn::test
