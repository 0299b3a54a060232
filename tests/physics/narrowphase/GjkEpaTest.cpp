// GJK distances and EPA penetrations against analytic answers, including touching and degenerate cases.

#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/CapsuleShape.h"
#include "cairn/physics/shapes/ConvexHullShape.h"
#include "cairn/physics/shapes/SphereShape.h"
#include "common/ShapeExpect.h"
#include "narrowphase/ConvexContact.h"
#include "narrowphase/Epa.h"

#include <gtest/gtest.h>
#include <random>
#include <vector>

namespace cairn
{
using namespace cairn::physics;
namespace
{
using cairn::test::ExpectVec;

ConvexSupport Support(const ConvexShape& inShape, const Vec3& inPosition,
                      const Quat& inRotation = Quat::Identity())
{
    return ConvexSupport::FromShape(inShape, {inPosition, inRotation});
}

TEST(GjkTest, BoxBoxDistance)
{
    const auto box = BoxShape::Create(Vec3(1, 1, 1)).Value();
    const GjkResult r = Gjk::ClosestPoints(Support(*box, Vec3::Zero()), 0.0f, Support(*box, Vec3(3, 0.5f, 0)),
                                           0.0f, cLargeFloat);
    ASSERT_FALSE(r.mOverlapping);
    EXPECT_NEAR(r.mDistance, 1.0f, 1.0e-5f);
    EXPECT_NEAR(r.mPointA.x(), 1.0f, 1.0e-5f);
    EXPECT_NEAR(r.mPointB.x(), 2.0f, 1.0e-5f);
    EXPECT_NEAR(r.mPointA.y(), r.mPointB.y(), 1.0e-5f);
}

TEST(GjkTest, RotatedBoxCornerToFaceDistance)
{
    const auto box = BoxShape::Create(Vec3(1, 1, 1)).Value();
    // B turned so that a corner points at A's +x face: the corner is sqrt(3) from B's centre
    const Quat rot = Quat::FromTwoVectors(Vec3(-1, -1, -1).normalized(), -Vec3::UnitX());
    const GjkResult r = Gjk::ClosestPoints(Support(*box, Vec3::Zero()), 0.0f,
                                           Support(*box, Vec3(3.5f, 0, 0), rot), 0.0f, cLargeFloat);
    ASSERT_FALSE(r.mOverlapping);
    EXPECT_NEAR(r.mDistance, 2.5f - std::sqrt(3.0f), 1.0e-4f);
    ExpectVec(r.mPointB, Vec3(3.5f - std::sqrt(3.0f), 0, 0), 1.0e-4f);
}

TEST(GjkTest, CoresOfSpheresAndCapsules)
{
    const auto sphere = SphereShape::Create(0.5f).Value();
    const auto capsule = CapsuleShape::Create(1.0f, 0.25f).Value();
    // Core of the sphere is its centre, core of the capsule its segment: distance centre-to-segment
    const GjkResult r = Gjk::ClosestPoints(Support(*sphere, Vec3(2, 0.5f, 0)), 0.0f,
                                           Support(*capsule, Vec3::Zero()), 0.0f, cLargeFloat);
    EXPECT_NEAR(r.mDistance, 2.0f, 1.0e-5f);
    ExpectVec(r.mPointB, Vec3(0, 0.5f, 0), 1.0e-5f);
    // Inflated to the full shapes the distance drops by both radii
    const GjkResult full = Gjk::ClosestPoints(Support(*sphere, Vec3(2, 0.5f, 0)), 0.5f,
                                              Support(*capsule, Vec3::Zero()), 0.25f, cLargeFloat);
    EXPECT_NEAR(full.mDistance, 1.25f, 1.0e-4f);
}

TEST(GjkTest, EarlyOutBeyondMaxDistanceAndOverlap)
{
    const auto box = BoxShape::Create(Vec3(1, 1, 1)).Value();
    const GjkResult far =
        Gjk::ClosestPoints(Support(*box, Vec3::Zero()), 0.0f, Support(*box, Vec3(10, 0, 0)), 0.0f, 1.0f);
    EXPECT_TRUE(far.mBeyondMaxDistance);
    const GjkResult overlap =
        Gjk::ClosestPoints(Support(*box, Vec3::Zero()), 0.0f, Support(*box, Vec3(1.5f, 0.3f, 0)), 0.0f, 1.0f);
    EXPECT_TRUE(overlap.mOverlapping);
    EXPECT_FALSE(overlap.mBeyondMaxDistance);
}

TEST(EpaTest, AxisAlignedBoxesDepthAndNormal)
{
    const auto box = BoxShape::Create(Vec3(1, 1, 1)).Value();
    ConvexContact c;
    ASSERT_TRUE(
        FindConvexContact(Support(*box, Vec3::Zero()), Support(*box, Vec3(1.7f, 0.2f, 0.1f)), 0.0f, c));
    ExpectVec(c.mNormal, Vec3::UnitX(), 1.0e-4f);
    EXPECT_NEAR(c.mPenetration, 0.3f, 1.0e-4f);
    EXPECT_NEAR(c.mPointA.x(), 1.0f, 1.0e-4f);
    EXPECT_NEAR(c.mPointB.x(), 0.7f, 1.0e-4f);
}

TEST(EpaTest, TouchingBoxesHaveZeroDepth)
{
    const auto box = BoxShape::Create(Vec3(1, 1, 1)).Value();
    ConvexContact c;
    ASSERT_TRUE(
        FindConvexContact(Support(*box, Vec3::Zero()), Support(*box, Vec3(0.3f, 2.0f, -0.4f)), 0.0f, c));
    ExpectVec(c.mNormal, Vec3::UnitY(), 1.0e-4f);
    EXPECT_NEAR(c.mPenetration, 0.0f, 1.0e-4f);
    // Touching corner to corner: GJK stops with a single point, EPA must blow the simplex up
    ASSERT_TRUE(FindConvexContact(Support(*box, Vec3::Zero()), Support(*box, Vec3(2, 2, 2)), 0.0f, c));
    EXPECT_NEAR(c.mPenetration, 0.0f, 1.0e-4f);
    EXPECT_NEAR(c.mNormal.norm(), 1.0f, 1.0e-4f);
}

TEST(EpaTest, CoincidentSpheresUseFullShapes)
{
    const auto a = SphereShape::Create(0.5f).Value();
    const auto b = SphereShape::Create(0.75f).Value();
    ConvexContact c;
    // Same centre: the cores touch, so EPA runs on the full spheres. A sphere is EPA's worst case (every
    // face is equally close), so the answer is only as good as the capped polytope: within 10%
    ASSERT_TRUE(FindConvexContact(Support(*a, Vec3(1, 2, 3)), Support(*b, Vec3(1, 2, 3)), 0.0f, c));
    EXPECT_NEAR(c.mPenetration, 1.25f, 0.125f);
    EXPECT_NEAR(c.mNormal.norm(), 1.0f, 1.0e-4f);
    EXPECT_NEAR(c.mPenetration, (c.mPointA - c.mPointB).dot(c.mNormal), 1.0e-4f);
    // Nearly coincident (cores 1e-5 apart): same rule, no blow-up
    ASSERT_TRUE(FindConvexContact(Support(*a, Vec3(1, 2, 3)), Support(*b, Vec3(1, 2, 3.00001f)), 0.0f, c));
    EXPECT_NEAR(c.mPenetration, 1.25f, 0.125f);
}

TEST(EpaTest, CrossingCapsuleSegments)
{
    const auto capsule = CapsuleShape::Create(1.0f, 0.25f).Value();
    const Quat alongX(Eigen::AngleAxisf(0.5f * cPi, Vec3::UnitZ()));
    ConvexContact c;
    ASSERT_TRUE(FindConvexContact(Support(*capsule, Vec3::Zero()),
                                  Support(*capsule, Vec3(0.2f, 0, 0), alongX), 0.0f, c));
    EXPECT_NEAR(std::abs(c.mNormal.z()), 1.0f, 1.0e-2f);
    EXPECT_NEAR(c.mPenetration, 0.5f, 5.0e-3f);
}

TEST(EpaTest, SphereCentreInTrianglePlane)
{
    // A flat triangle has no volume: the Minkowski difference with a point core would be flat too
    const auto sphere = SphereShape::Create(0.5f).Value();
    const ConvexSupport tri = ConvexSupport::FromTriangle(Vec3(-2, 0, -2), Vec3(0, 0, 3), Vec3(2, 0, -2));
    ConvexContact c;
    ASSERT_TRUE(FindConvexContact(Support(*sphere, Vec3(0, 0, 0)), tri, 0.0f, c));
    EXPECT_NEAR(std::abs(c.mNormal.y()), 1.0f, 1.0e-2f);
    EXPECT_NEAR(c.mPenetration, 0.5f, 5.0e-3f);
}

TEST(EpaTest, HullMatchesBox)
{
    std::vector<Vec3> corners;
    for (const float x : {-1.0f, 1.0f})
        for (const float y : {-0.5f, 0.5f})
            for (const float z : {-2.0f, 2.0f})
                corners.emplace_back(x, y, z);
    const auto hull = ConvexHullShape::Create(corners).Value();
    const auto box = BoxShape::Create(Vec3(1.0f, 0.5f, 2.0f)).Value();
    const Quat rot(Eigen::AngleAxisf(0.4f, Vec3(1, 1, 0).normalized()));
    const Vec3 pos(0.4f, 0.7f, 0.2f);
    ConvexContact viaHull;
    ConvexContact viaBox;
    ASSERT_TRUE(FindConvexContact(Support(*hull, Vec3::Zero()), Support(*hull, pos, rot), 0.0f, viaHull));
    ASSERT_TRUE(FindConvexContact(Support(*box, Vec3::Zero()), Support(*box, pos, rot), 0.0f, viaBox));
    EXPECT_NEAR(viaHull.mPenetration, viaBox.mPenetration, 1.0e-4f);
    EXPECT_GT(viaHull.mNormal.dot(viaBox.mNormal), 0.9999f);
    EXPECT_GT(viaBox.mPenetration, 0.1f);
}

TEST(EpaTest, DeepRandomBoxesHaveValidSeparatingDepth)
{
    // Whatever EPA answers, moving B by normal * depth must leave the boxes just touching: the support
    // distance along the normal equals the depth
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::normal_distribution<float> g;
    const auto randomRotation = [&] { return Quat(g(rng), g(rng), g(rng), g(rng)).normalized(); };
    const auto a = BoxShape::Create(Vec3(0.5f, 1.0f, 0.3f)).Value();
    const auto b = BoxShape::Create(Vec3(0.8f, 0.2f, 0.6f)).Value();
    for (int i = 0; i < 500; ++i)
    {
        const ConvexSupport sa = Support(*a, Vec3(u(rng), u(rng), u(rng)) * 0.3f, randomRotation());
        const ConvexSupport sb = Support(*b, Vec3(u(rng), u(rng), u(rng)) * 0.3f, randomRotation());
        ConvexContact c;
        ASSERT_TRUE(FindConvexContact(sa, sb, 0.0f, c));
        const float supportDepth =
            (sa.GetSupport(c.mNormal, 0.0f) - sb.GetSupport(-c.mNormal, 0.0f)).dot(c.mNormal);
        EXPECT_NEAR(c.mPenetration, supportDepth, 1.0e-3f);
        EXPECT_NEAR(c.mPenetration, (c.mPointA - c.mPointB).dot(c.mNormal), 1.0e-4f);
    }
}

} // namespace
} // namespace cairn
