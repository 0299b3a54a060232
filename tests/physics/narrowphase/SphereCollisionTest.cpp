// Hand-made cases with analytic answers for sphere-sphere, sphere-box and sphere-capsule.

#include "common/ShapeExpect.h"
#include "narrowphase/CollideSphereBox.h"
#include "narrowphase/CollideSphereCapsule.h"
#include "narrowphase/CollideSphereSphere.h"

#include <gtest/gtest.h>

namespace cairn
{
using namespace cairn::physics;
namespace
{
using cairn::test::At;
using cairn::test::cEps;
using cairn::test::ExpectVec;

TEST(SphereSphereTest, OverlapAlongX)
{
    const auto s = SphereShape::Create(1.0f).Value();
    ContactManifold m;
    ASSERT_TRUE(CollideSphereSphere(*s, At(Vec3::Zero()), *s, At(Vec3(1.5f, 0, 0)), {}, m));
    ASSERT_EQ(m.mNumPoints, 1);
    ExpectVec(m.mNormal, Vec3::UnitX());
    EXPECT_NEAR(m.mPoints[0].mPenetration, 0.5f, cEps);
    ExpectVec(m.mPoints[0].mPositionOnA, Vec3(1.0f, 0, 0));
    ExpectVec(m.mPoints[0].mPositionOnB, Vec3(0.5f, 0, 0));
}

TEST(SphereSphereTest, SpeculativeAndBeyond)
{
    const auto a = SphereShape::Create(0.5f).Value();
    const auto b = SphereShape::Create(0.25f).Value();
    CollideSettings settings;
    settings.mMaxSeparation = 0.02f;
    ContactManifold m;
    // Gap 0.01 < max separation: a contact with negative penetration
    ASSERT_TRUE(CollideSphereSphere(*a, At(Vec3(1, 2, 3)), *b, At(Vec3(1, 2, 3.76f)), settings, m));
    EXPECT_NEAR(m.mPoints[0].mPenetration, -0.01f, cEps);
    ExpectVec(m.mNormal, Vec3::UnitZ());
    // Gap 0.03: nothing
    EXPECT_FALSE(CollideSphereSphere(*a, At(Vec3(1, 2, 3)), *b, At(Vec3(1, 2, 3.78f)), settings, m));
}

TEST(SphereSphereTest, CoincidentCentresGiveUnitNormal)
{
    const auto s = SphereShape::Create(1.0f).Value();
    ContactManifold m;
    ASSERT_TRUE(CollideSphereSphere(*s, At(Vec3(2, 2, 2)), *s, At(Vec3(2, 2, 2)), {}, m));
    EXPECT_NEAR(m.mNormal.norm(), 1.0f, cEps);
    EXPECT_NEAR(m.mPoints[0].mPenetration, 2.0f, cEps);
}

TEST(SphereBoxTest, RestingOnFace)
{
    const auto sphere = SphereShape::Create(0.5f).Value();
    const auto box = BoxShape::Create(Vec3(1, 1, 1)).Value();
    ContactManifold m;
    ASSERT_TRUE(CollideSphereBox(*sphere, At(Vec3(0.3f, 1.4f, -0.2f)), *box, At(Vec3::Zero()), {}, m));
    ASSERT_EQ(m.mNumPoints, 1);
    ExpectVec(m.mNormal, -Vec3::UnitY()); // From the sphere (A) down into the box (B)
    EXPECT_NEAR(m.mPoints[0].mPenetration, 0.1f, cEps);
    ExpectVec(m.mPoints[0].mPositionOnB, Vec3(0.3f, 1.0f, -0.2f));
    ExpectVec(m.mPoints[0].mPositionOnA, Vec3(0.3f, 0.9f, -0.2f));
}

TEST(SphereBoxTest, NearCorner)
{
    const auto sphere = SphereShape::Create(1.0f).Value();
    const auto box = BoxShape::Create(Vec3(1, 1, 1)).Value();
    ContactManifold m;
    ASSERT_TRUE(CollideSphereBox(*sphere, At(Vec3(1.3f, 1.4f, 1.0f)), *box, At(Vec3::Zero()), {}, m));
    ExpectVec(m.mNormal, -Vec3(0.6f, 0.8f, 0.0f));
    EXPECT_NEAR(m.mPoints[0].mPenetration, 0.5f, cEps);
    ExpectVec(m.mPoints[0].mPositionOnB, Vec3(1, 1, 1));
}

TEST(SphereBoxTest, CentreInsideUsesLeastPenetrationFace)
{
    const auto sphere = SphereShape::Create(0.25f).Value();
    const auto box = BoxShape::Create(Vec3(1, 2, 3)).Value();
    // Distances to the faces: +x 0.2, +y 1.5, +z 2.9: the +x face wins
    const Quat rot(Eigen::AngleAxisf(0.7f, Vec3(1, 2, 3).normalized()));
    const Transform boxTransform = At(Vec3(5, -1, 2), rot);
    const Vec3 centre = boxTransform * Vec3(0.8f, 0.5f, 0.1f);
    ContactManifold m;
    ASSERT_TRUE(CollideSphereBox(*sphere, At(centre), *box, boxTransform, {}, m));
    ExpectVec(m.mNormal, rot * -Vec3::UnitX());
    EXPECT_NEAR(m.mPoints[0].mPenetration, 0.45f, cEps);
    ExpectVec(m.mPoints[0].mPositionOnB, boxTransform * Vec3(1.0f, 0.5f, 0.1f));
    // The -z face is nearest now
    ASSERT_TRUE(
        CollideSphereBox(*sphere, At(boxTransform * Vec3(0.1f, 0.2f, -2.95f)), *box, boxTransform, {}, m));
    ExpectVec(m.mNormal, rot * Vec3::UnitZ());
    EXPECT_NEAR(m.mPoints[0].mPenetration, 0.3f, cEps);
}

TEST(SphereBoxTest, SeparatedWithinAndBeyondMaxSeparation)
{
    const auto sphere = SphereShape::Create(0.5f).Value();
    const auto box = BoxShape::Create(Vec3(1, 1, 1)).Value();
    ContactManifold m;
    ASSERT_TRUE(CollideSphereBox(*sphere, At(Vec3(0, 0, 1.51f)), *box, At(Vec3::Zero()), {}, m));
    EXPECT_NEAR(m.mPoints[0].mPenetration, -0.01f, cEps);
    EXPECT_FALSE(CollideSphereBox(*sphere, At(Vec3(0, 0, 1.53f)), *box, At(Vec3::Zero()), {}, m));
    // Exactly touching
    ASSERT_TRUE(CollideSphereBox(*sphere, At(Vec3(0, -1.5f, 0)), *box, At(Vec3::Zero()), {}, m));
    EXPECT_NEAR(m.mPoints[0].mPenetration, 0.0f, cEps);
    ExpectVec(m.mNormal, Vec3::UnitY());
}

TEST(SphereCapsuleTest, SideAndCap)
{
    const auto sphere = SphereShape::Create(0.5f).Value();
    const auto capsule = CapsuleShape::Create(1.0f, 0.5f).Value();
    ContactManifold m;
    // Beside the cylinder part: closest segment point (0, 0.5, 0)
    ASSERT_TRUE(CollideSphereCapsule(*sphere, At(Vec3(0.8f, 0.5f, 0)), *capsule, At(Vec3::Zero()), {}, m));
    ExpectVec(m.mNormal, -Vec3::UnitX());
    EXPECT_NEAR(m.mPoints[0].mPenetration, 0.2f, cEps);
    ExpectVec(m.mPoints[0].mPositionOnB, Vec3(0.5f, 0.5f, 0));
    ExpectVec(m.mPoints[0].mPositionOnA, Vec3(0.3f, 0.5f, 0));
    // Above the top cap
    ASSERT_TRUE(CollideSphereCapsule(*sphere, At(Vec3(0, 1.9f, 0)), *capsule, At(Vec3::Zero()), {}, m));
    ExpectVec(m.mNormal, -Vec3::UnitY());
    EXPECT_NEAR(m.mPoints[0].mPenetration, 0.1f, cEps);
    EXPECT_FALSE(CollideSphereCapsule(*sphere, At(Vec3(0, 2.2f, 0)), *capsule, At(Vec3::Zero()), {}, m));
    // Rotated capsule lying along x
    const Quat lying(Eigen::AngleAxisf(0.5f * cPi, Vec3::UnitZ()));
    ASSERT_TRUE(
        CollideSphereCapsule(*sphere, At(Vec3(0.7f, 0.9f, 0)), *capsule, At(Vec3::Zero(), lying), {}, m));
    ExpectVec(m.mNormal, -Vec3::UnitY());
    EXPECT_NEAR(m.mPoints[0].mPenetration, 0.1f, cEps);
}

} // namespace
} // namespace cairn
