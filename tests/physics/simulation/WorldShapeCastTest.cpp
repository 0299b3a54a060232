// WorldQuery's shape casts: the first body a swept shape touches and every body on its way, the filter, a
// character probing from the floor it stands on, bodies moved since the last step, and bad input.

#include "SimulationFixture.h"
#include "cairn/physics/body/BodyLock.h"
#include "cairn/physics/shapes/CapsuleShape.h"
#include "cairn/physics/shapes/SphereShape.h"
#include "cairn/physics/shapes/TriangleMeshShape.h"

#include <limits>

namespace cairn::test
{
using namespace cairn::physics;

class WorldShapeCastTest : public SimulationFixture
{
protected:
    void SetUp() override
    {
        mFloor = AddFloor();                                     // Top at y = 0
        mSphere = AddStatic(Sphere(1.0f), Vec3(0, 1, 0));        // Top at y = 2
        mWall = AddStatic(Box(Vec3(0.5f, 2, 5)), Vec3(6, 2, 0)); // Its -x face at x = 5.5
    }
    const WorldQuery& Query() { return System().GetWorldQuery(); }

    const SphereShape mProbe{0.25f};
    BodyID mFloor, mSphere, mWall;
};

TEST_F(WorldShapeCastTest, TheClosestHitIsTheFirstBodyTouched)
{
    const std::optional<ShapeCastResult> hit =
        Query().CastShapeClosest(mProbe, {Vec3(0, 10, 0), Quat::Identity()}, Vec3(0, -20, 0)).Value();
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->mBody, mSphere);
    // The probe's centre touches the sphere at y = 2.25: 7.75 m of the 20
    EXPECT_NEAR(hit->mFraction, 7.75f / 20.0f, 1.0e-4f);
    EXPECT_NEAR(hit->mNormal.y(), 1.0f, 1.0e-4f) << "the sphere's surface normal, towards the probe";
    EXPECT_NEAR((hit->mContactPoint - Vec3(0, 2, 0)).norm(), 0.0f, 1.0e-3f);
    EXPECT_NEAR(hit->mPenetration, 0.0f, 1.0e-3f);
}

TEST_F(WorldShapeCastTest, AllHitsAreSortedOnePerBody)
{
    std::vector<ShapeCastResult> hits;
    // A capsule lying along z, swept down past the sphere's side to the floor
    const ShapeRef capsule = CapsuleShape::Create(1.0f, 0.2f).Value();
    const Quat alongZ(Eigen::AngleAxisf(float(M_PI) / 2.0f, Vec3::UnitX()));
    ASSERT_TRUE(Query().CastShapeAll(*capsule, {Vec3(0.5f, 10, 0), alongZ}, Vec3(0, -20, 0), hits).IsOk());
    ASSERT_EQ(hits.size(), 2u);
    EXPECT_EQ(hits[0].mBody, mSphere);
    EXPECT_EQ(hits[1].mBody, mFloor);
    EXPECT_NEAR(hits[1].mFraction, (10.0f - 0.2f) / 20.0f, 1.0e-4f);
    EXPECT_LT(hits[0].mFraction, hits[1].mFraction);
}

TEST_F(WorldShapeCastTest, TheFilterSkipsLayersAndTheIgnoredBody)
{
    const Transform above{Vec3(0, 10, 0), Quat::Identity()};
    QueryFilter ignoreSphere;
    ignoreSphere.mIgnoreBody = mSphere;
    const std::optional<ShapeCastResult> hit =
        Query().CastShapeClosest(mProbe, above, Vec3(0, -20, 0), ignoreSphere).Value();
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->mBody, mFloor);
    QueryFilter noStatic;
    noStatic.mObjectLayers = cAllObjectLayers & ~(ObjectLayerMask(1) << Layers::cStatic);
    EXPECT_FALSE(Query().CastShapeClosest(mProbe, above, Vec3(0, -20, 0), noStatic).Value().has_value());
}

TEST_F(WorldShapeCastTest, ACharacterOnTheFloorProbesSidewaysToTheWall)
{
    // Standing on the floor, a hair into it, as a character resting there is
    const Transform standing{Vec3(-3, 0.249f, 3), Quat::Identity()}; // Clear of the sphere
    const std::optional<ShapeCastResult> wall =
        Query().CastShapeClosest(mProbe, standing, Vec3(10, 0, 0)).Value();
    ASSERT_TRUE(wall.has_value());
    EXPECT_EQ(wall->mBody, mWall) << "not the floor it slides along";
    EXPECT_NEAR(wall->mFraction, (5.5f - 0.25f + 3.0f) / 10.0f, 1.0e-4f);
    EXPECT_NEAR(wall->mNormal.x(), -1.0f, 1.0e-4f);
    // Stepping down into the floor meets it at once
    const std::optional<ShapeCastResult> down =
        Query().CastShapeClosest(mProbe, standing, Vec3(0, -1, 0)).Value();
    ASSERT_TRUE(down.has_value());
    EXPECT_EQ(down->mBody, mFloor);
    EXPECT_EQ(down->mFraction, 0.0f);
    // Standing still: what it touches
    std::vector<ShapeCastResult> touching;
    ASSERT_TRUE(Query().CastShapeAll(mProbe, standing, Vec3::Zero(), touching).IsOk());
    ASSERT_EQ(touching.size(), 1u);
    EXPECT_EQ(touching[0].mBody, mFloor);
}

TEST_F(WorldShapeCastTest, ABodyMovedSinceTheLastStepIsMetWhereItIsNow)
{
    const BodyID crate = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(-20, 0.5f, 3)));
    ASSERT_TRUE(Bodies().SetPosition(crate, Vec3(3, 0.5f, 3), Activation::DontActivate).IsOk());
    const std::optional<ShapeCastResult> hit =
        Query().CastShapeClosest(mProbe, {Vec3(-3, 0.5f, 3), Quat::Identity()}, Vec3(10, 0, 0)).Value();
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->mBody, crate);
    EXPECT_NEAR(hit->mFraction, (2.5f - 0.25f + 3.0f) / 10.0f, 1.0e-4f);
    ASSERT_TRUE(Bodies().RemoveBody(crate).IsOk());
    const std::optional<ShapeCastResult> gone =
        Query().CastShapeClosest(mProbe, {Vec3(-3, 0.5f, 3), Quat::Identity()}, Vec3(10, 0, 0)).Value();
    ASSERT_TRUE(gone.has_value());
    EXPECT_EQ(gone->mBody, mWall) << "a removed body is no longer met";
}

TEST_F(WorldShapeCastTest, BadInputIsAnErrorNotAMiss)
{
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    auto code = [](const auto& inResult) { return inResult.GetError().mCode; };
    const Transform above{Vec3(0, 10, 0), Quat::Identity()};
    EXPECT_EQ(code(Query().CastShapeClosest(mProbe, {Vec3(nan, 10, 0), Quat::Identity()}, Vec3(0, -1, 0))),
              ErrorCode::InvalidArgument);
    EXPECT_EQ(code(Query().CastShapeClosest(mProbe, {Vec3(0, 2e6f, 0), Quat::Identity()}, Vec3(0, -1, 0))),
              ErrorCode::InvalidArgument);
    EXPECT_EQ(code(Query().CastShapeClosest(mProbe, {Vec3(0, 10, 0), Quat(2, 0, 0, 0)}, Vec3(0, -1, 0))),
              ErrorCode::InvalidArgument);
    EXPECT_EQ(code(Query().CastShapeClosest(mProbe, above, Vec3(0, nan, 0))), ErrorCode::InvalidArgument);
    EXPECT_EQ(code(Query().CastShapeClosest(mProbe, above, Vec3(inf, 0, 0))), ErrorCode::InvalidArgument);
    EXPECT_EQ(code(Query().CastShapeClosest(mProbe, above, Vec3(0, -1e7f, 0))), ErrorCode::InvalidArgument);
    const std::vector<Vec3> vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1)};
    const std::vector<std::array<uint32_t, 3>> triangles = {{0, 2, 1}};
    const ShapeRef mesh = TriangleMeshShape::Create(vertices, triangles).Value();
    std::vector<ShapeCastResult> hits;
    EXPECT_EQ(code(Query().CastShapeAll(*mesh, above, Vec3(0, -20, 0), hits)), ErrorCode::InvalidArgument)
        << "a mesh collides with no mesh or height field: it would answer 'clear'";
}

TEST_F(WorldShapeCastTest, ABodyLockCastWhileHoldingABodyLockIsRefusedNotEmpty)
{
    PhysicsSettings settings;
    settings.mQueryReads = QueryReads::BodyLocks;
    ResetWorld(settings);
    SetUp();
    const Transform above{Vec3(0, 10, 0), Quat::Identity()};
    ASSERT_TRUE(Query().CastShapeClosest(mProbe, above, Vec3(0, -20, 0)).Value().has_value());
    BodyLockRead lock(System().GetBodyManager(), mFloor);
    ASSERT_TRUE(lock.Succeeded());
    EXPECT_EQ(Query().CastShapeClosest(mProbe, above, Vec3(0, -20, 0)).GetError().mCode,
              ErrorCode::WrongThread);
}

} // namespace cairn::test
