// Hand-made capsule-capsule cases with analytic answers.

#include "common/ShapeExpect.h"
#include "narrowphase/CollideCapsuleCapsule.h"

#include <algorithm>
#include <gtest/gtest.h>

namespace cairn
{
using namespace cairn::physics;
namespace
{
using cairn::test::cEps;
using cairn::test::ExpectVec;

const Quat cAlongX(Eigen::AngleAxisf(0.5f * cPi, Vec3::UnitZ()));

TEST(CapsuleCapsuleTest, CrossingAtRightAngle)
{
    const auto c = CapsuleShape::Create(1.0f, 0.5f).Value();
    ContactManifold m;
    ASSERT_TRUE(CollideCapsuleCapsule(*c, {}, *c, {Vec3(0, 0, 0.9f), cAlongX}, {}, m));
    ASSERT_EQ(m.mNumPoints, 1);
    ExpectVec(m.mNormal, Vec3::UnitZ());
    EXPECT_NEAR(m.mPoints[0].mPenetration, 0.1f, cEps);
    ExpectVec(m.mPoints[0].mPositionOnA, Vec3(0, 0, 0.5f));
    ExpectVec(m.mPoints[0].mPositionOnB, Vec3(0, 0, 0.4f));
}

TEST(CapsuleCapsuleTest, IntersectingAxesPushAlongCommonPerpendicular)
{
    const auto c = CapsuleShape::Create(1.0f, 0.5f).Value();
    ContactManifold m;
    // Segments cross exactly: the only sensible normal is perpendicular to both axes
    ASSERT_TRUE(CollideCapsuleCapsule(*c, {}, *c, {Vec3(0.3f, 0, 0), cAlongX}, {}, m));
    ASSERT_EQ(m.mNumPoints, 1);
    EXPECT_NEAR(std::abs(m.mNormal.z()), 1.0f, cEps);
    EXPECT_NEAR(m.mPoints[0].mPenetration, 1.0f, cEps);
    // B slightly towards -z: pushed further that way
    ASSERT_TRUE(CollideCapsuleCapsule(*c, {}, *c, {Vec3(0.3f, 0, -1.0e-3f), cAlongX}, {}, m));
    EXPECT_NEAR(m.mNormal.z(), -1.0f, cEps);
    EXPECT_NEAR(m.mPoints[0].mPenetration, 1.0f - 1.0e-3f, cEps);
}

TEST(CapsuleCapsuleTest, ParallelGivesTwoPoints)
{
    const auto c = CapsuleShape::Create(1.0f, 0.5f).Value();
    ContactManifold m;
    ASSERT_TRUE(
        CollideCapsuleCapsule(*c, {Vec3::Zero(), cAlongX}, *c, {Vec3(0.5f, 0.9f, 0), cAlongX}, {}, m));
    ASSERT_EQ(m.mNumPoints, 2);
    ExpectVec(m.mNormal, Vec3::UnitY());
    // The overlap of the two segments along x is [-0.5, 1]
    float xs[2] = {m.mPoints[0].mPositionOnB.x(), m.mPoints[1].mPositionOnB.x()};
    std::sort(xs, xs + 2);
    EXPECT_NEAR(xs[0], -0.5f, cEps);
    EXPECT_NEAR(xs[1], 1.0f, cEps);
    for (int i = 0; i < 2; ++i)
    {
        EXPECT_NEAR(m.mPoints[i].mPenetration, 0.1f, cEps);
        EXPECT_NEAR(m.mPoints[i].mPositionOnA.y(), 0.5f, cEps);
        EXPECT_NEAR(m.mPoints[i].mPositionOnB.y(), 0.4f, cEps);
    }
}

TEST(CapsuleCapsuleTest, NearlyParallelTiltedGivesTwoDifferentDepths)
{
    const auto c = CapsuleShape::Create(1.0f, 0.5f).Value();
    const Quat tilted = Quat(Eigen::AngleAxisf(0.02f, Vec3::UnitZ())) * cAlongX;
    ContactManifold m;
    ASSERT_TRUE(CollideCapsuleCapsule(*c, {Vec3::Zero(), cAlongX}, *c, {Vec3(0, 0.95f, 0), tilted}, {}, m));
    ASSERT_EQ(m.mNumPoints, 2);
    // The end of B that dips lower is deeper
    const float p0 = m.mPoints[0].mPenetration;
    const float p1 = m.mPoints[1].mPenetration;
    EXPECT_GT(std::abs(p0 - p1), 0.03f);
    EXPECT_NEAR(std::max(p0, p1), 0.05f + 0.02f, 2.0e-3f);
}

TEST(CapsuleCapsuleTest, EndToEndGivesOnePoint)
{
    const auto c = CapsuleShape::Create(1.0f, 0.5f).Value();
    ContactManifold m;
    ASSERT_TRUE(CollideCapsuleCapsule(*c, {}, *c, {Vec3(0, 2.9f, 0), Quat::Identity()}, {}, m));
    EXPECT_EQ(m.mNumPoints, 1);
    ExpectVec(m.mNormal, Vec3::UnitY());
    EXPECT_NEAR(m.mPoints[0].mPenetration, 0.1f, cEps);
}

TEST(CapsuleCapsuleTest, SpeculativeAndBeyond)
{
    const auto c = CapsuleShape::Create(1.0f, 0.5f).Value();
    ContactManifold m;
    ASSERT_TRUE(CollideCapsuleCapsule(*c, {}, *c, {Vec3(0, 0, 1.01f), cAlongX}, {}, m));
    EXPECT_NEAR(m.mPoints[0].mPenetration, -0.01f, cEps);
    EXPECT_FALSE(CollideCapsuleCapsule(*c, {}, *c, {Vec3(0, 0, 1.03f), cAlongX}, {}, m));
}

} // namespace
} // namespace cairn
