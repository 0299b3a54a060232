// Hand-made box-box cases with analytic answers: face-face manifolds, edge-edge, rotations, touching and
// separated boxes, a nearly flat landing box over an edge, and the reduction of a clipped octagon to 4
// points.

#include "common/ShapeExpect.h"
#include "narrowphase/CollideBoxBox.h"
#include "narrowphase/ConvexContact.h"

#include <algorithm>
#include <gtest/gtest.h>

namespace cairn
{
using namespace cairn::physics;
namespace
{
using cairn::test::cEps;
using cairn::test::ExpectVec;
using cairn::test::MaxPenetration;

// True when some point of the manifold has mPositionOnB at inPoint
bool HasPointOnB(const ContactManifold& inManifold, const Vec3& inPoint, float inTolerance = 1.0e-4f)
{
    for (int i = 0; i < inManifold.mNumPoints; ++i)
        if ((inManifold.mPoints[i].mPositionOnB - inPoint).norm() < inTolerance) return true;
    return false;
}

void ExpectConsistentPoints(const ContactManifold& inManifold)
{
    for (int i = 0; i < inManifold.mNumPoints; ++i)
    {
        const ContactPoint& p = inManifold.mPoints[i];
        EXPECT_NEAR(p.mPenetration, (p.mPositionOnA - p.mPositionOnB).dot(inManifold.mNormal), 1.0e-5f);
    }
}

TEST(BoxBoxTest, RestingFaceToFaceGivesFourCorners)
{
    const auto floor = BoxShape::Create(Vec3(1.0f, 0.5f, 1.0f)).Value();
    const auto cube = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
    ContactManifold m;
    BoxBoxAxis axis;
    ASSERT_TRUE(CollideBoxBox(*floor, {}, *cube, {Vec3(0, 0.99f, 0), Quat::Identity()}, {}, m, &axis));
    EXPECT_EQ(axis, BoxBoxAxis::FaceA);
    ExpectVec(m.mNormal, Vec3::UnitY());
    ASSERT_EQ(m.mNumPoints, 4);
    for (const float x : {-0.5f, 0.5f})
        for (const float z : {-0.5f, 0.5f})
            EXPECT_TRUE(HasPointOnB(m, Vec3(x, 0.49f, z))) << x << " " << z;
    for (int i = 0; i < 4; ++i)
    {
        EXPECT_NEAR(m.mPoints[i].mPenetration, 0.01f, cEps);
        EXPECT_NEAR(m.mPoints[i].mPositionOnA.y(), 0.5f, cEps);
    }
    ExpectConsistentPoints(m);
}

TEST(BoxBoxTest, SwappedOrderFlipsNormal)
{
    const auto floor = BoxShape::Create(Vec3(1.0f, 0.5f, 1.0f)).Value();
    const auto cube = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
    ContactManifold m;
    ASSERT_TRUE(CollideBoxBox(*cube, {Vec3(0, 0.99f, 0), Quat::Identity()}, *floor, {}, {}, m));
    ExpectVec(m.mNormal, -Vec3::UnitY());
    ASSERT_EQ(m.mNumPoints, 4);
    for (int i = 0; i < 4; ++i)
        EXPECT_NEAR(m.mPoints[i].mPenetration, 0.01f, cEps);
}

TEST(BoxBoxTest, RotatedAboutNormalOnTop)
{
    const auto floor = BoxShape::Create(Vec3(2.0f, 0.5f, 2.0f)).Value();
    const auto cube = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
    const Quat rot(Eigen::AngleAxisf(0.25f * cPi, Vec3::UnitY()));
    const Transform top{Vec3(0.3f, 0.98f, -0.2f), rot};
    ContactManifold m;
    ASSERT_TRUE(CollideBoxBox(*floor, {}, *cube, top, {}, m));
    ExpectVec(m.mNormal, Vec3::UnitY());
    ASSERT_EQ(m.mNumPoints, 4);
    for (const float x : {-0.5f, 0.5f})
        for (const float z : {-0.5f, 0.5f})
            EXPECT_TRUE(HasPointOnB(m, top * Vec3(x, -0.5f, z)));
    for (int i = 0; i < 4; ++i)
        EXPECT_NEAR(m.mPoints[i].mPenetration, 0.02f, cEps);
}

TEST(BoxBoxTest, WholeWorldRotationGivesSameManifold)
{
    const auto floor = BoxShape::Create(Vec3(1.0f, 0.5f, 1.0f)).Value();
    const auto cube = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
    const Quat world(Eigen::AngleAxisf(1.1f, Vec3(0.3f, -0.5f, 0.8f).normalized()));
    const Transform frame{Vec3(10, -3, 7), world};
    ContactManifold m;
    ASSERT_TRUE(CollideBoxBox(*floor, frame, *cube,
                              frame * Transform{Vec3(0.2f, 0.97f, 0.1f), Quat::Identity()}, {}, m));
    ExpectVec(m.mNormal, world * Vec3::UnitY());
    ASSERT_EQ(m.mNumPoints, 4);
    for (int i = 0; i < 4; ++i)
        EXPECT_NEAR(m.mPoints[i].mPenetration, 0.03f, 1.0e-4f);
    EXPECT_TRUE(HasPointOnB(m, frame * Vec3(0.7f, 0.47f, 0.6f)));
}

TEST(BoxBoxTest, EdgeOnFaceGivesTwoPoints)
{
    const auto floor = BoxShape::Create(Vec3(5.0f, 0.5f, 5.0f)).Value();
    const auto cube = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
    // Standing on its edge along z: the lowest edge is 0.5 * sqrt(2) below the centre
    const Quat rot(Eigen::AngleAxisf(0.25f * cPi, Vec3::UnitZ()));
    const Transform t{Vec3(0, 0.5f + 0.5f * std::sqrt(2.0f) - 0.02f, 0), rot};
    ContactManifold m;
    ASSERT_TRUE(CollideBoxBox(*floor, {}, *cube, t, {}, m));
    ExpectVec(m.mNormal, Vec3::UnitY());
    ASSERT_EQ(m.mNumPoints, 2);
    EXPECT_TRUE(HasPointOnB(m, Vec3(0, 0.48f, 0.5f)));
    EXPECT_TRUE(HasPointOnB(m, Vec3(0, 0.48f, -0.5f)));
    for (int i = 0; i < 2; ++i)
        EXPECT_NEAR(m.mPoints[i].mPenetration, 0.02f, 1.0e-4f);
}

TEST(BoxBoxTest, EdgeEdgeCrossing)
{
    const auto cube = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
    // A stands on an edge along x (top edge at y = h), B hangs on an edge along z (bottom edge at y = c - h)
    const float h = 0.5f * std::sqrt(2.0f);
    const Transform ta{Vec3::Zero(), Quat(Eigen::AngleAxisf(0.25f * cPi, Vec3::UnitX()))};
    const Transform tb{Vec3(0, 2.0f * h - 0.05f, 0), Quat(Eigen::AngleAxisf(0.25f * cPi, Vec3::UnitZ()))};
    ContactManifold m;
    BoxBoxAxis axis;
    ASSERT_TRUE(CollideBoxBox(*cube, ta, *cube, tb, {}, m, &axis));
    EXPECT_EQ(axis, BoxBoxAxis::Edge);
    ASSERT_EQ(m.mNumPoints, 1);
    ExpectVec(m.mNormal, Vec3::UnitY());
    EXPECT_NEAR(m.mPoints[0].mPenetration, 0.05f, cEps);
    ExpectVec(m.mPoints[0].mPositionOnA, Vec3(0, h, 0));
    ExpectVec(m.mPoints[0].mPositionOnB, Vec3(0, h - 0.05f, 0));
}

TEST(BoxBoxTest, ANearlyFlatLandingBoxIsHeldByItsFaceNotByOneCorner)
{
    // step_pile2k's case, in the static box's frame: a falling cube, turned about the vertical against the
    // box under it and tilted by a tenth of a degree, over that box's edge, its lowest corner a millimetre
    // into it. The edges crossing under it make an axis a shade shallower than the face axis by more than the
    // bias, whose single point once carried the cube on one corner: it spun 21 cm into the box
    const auto slab = BoxShape::Create(Vec3(0.914f, 0.53f, 0.737f)).Value();
    const auto cube = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
    const Transform tb{Vec3(-0.342219591f, 1.029356f, -0.786708057f),
                       Quat(0.139192805f, 0.000346043205f, 0.990265012f, -0.000745627272f).normalized()};
    CollideSettings settings;
    settings.mMaxSeparation = 0.02f; // The step's speculative distance
    ContactManifold m;
    BoxBoxAxis axis;
    ASSERT_TRUE(CollideBoxBox(*slab, {}, *cube, tb, settings, m, &axis));
    ASSERT_EQ(axis, BoxBoxAxis::Edge) << "the case must reach the edge axis it is about";
    EXPECT_GT(m.mNormal.y(), 0.9999f);
    // The cube's face over the slab holds it: points spread over that face, not a corner alone
    ASSERT_GE(m.mNumPoints, 3);
    float spread = 0.0f;
    for (int i = 0; i < m.mNumPoints; ++i)
        for (int j = 0; j < i; ++j)
            spread = std::max(spread, (m.mPoints[i].mPositionOnB - m.mPoints[j].mPositionOnB).norm());
    EXPECT_GT(spread, 0.5f);
    // As deep as the edge axis (the lowest corner's millimetre), every point within the speculative distance
    EXPECT_NEAR(MaxPenetration(m), 0.0009f, 0.0003f);
    for (int i = 0; i < m.mNumPoints; ++i)
        EXPECT_GE(m.mPoints[i].mPenetration, -settings.mMaxSeparation);
    ExpectConsistentPoints(m);

    // The other way round: the same points, the normal turned
    ContactManifold swapped;
    ASSERT_TRUE(CollideBoxBox(*cube, tb, *slab, {}, settings, swapped, &axis));
    EXPECT_EQ(axis, BoxBoxAxis::Edge);
    EXPECT_LT(swapped.mNormal.y(), -0.9999f);
    EXPECT_EQ(swapped.mNumPoints, m.mNumPoints);
    EXPECT_NEAR(MaxPenetration(swapped), MaxPenetration(m), 1.0e-5f);
    ExpectConsistentPoints(swapped);
}

TEST(BoxBoxTest, TouchingSpeculativeAndBeyond)
{
    const auto cube = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
    CollideSettings settings;
    settings.mMaxSeparation = 0.02f;
    ContactManifold m;
    // Exactly touching
    ASSERT_TRUE(CollideBoxBox(*cube, {}, *cube, {Vec3(1.0f, 0.2f, 0), Quat::Identity()}, settings, m));
    ExpectVec(m.mNormal, Vec3::UnitX());
    ASSERT_EQ(m.mNumPoints, 4);
    for (int i = 0; i < 4; ++i)
        EXPECT_NEAR(m.mPoints[i].mPenetration, 0.0f, cEps);
    // Gap of 0.01: speculative contacts with negative penetration
    ASSERT_TRUE(CollideBoxBox(*cube, {}, *cube, {Vec3(1.01f, 0.2f, 0), Quat::Identity()}, settings, m));
    ASSERT_EQ(m.mNumPoints, 4);
    for (int i = 0; i < 4; ++i)
        EXPECT_NEAR(m.mPoints[i].mPenetration, -0.01f, cEps);
    // Gap of 0.03: nothing
    EXPECT_FALSE(CollideBoxBox(*cube, {}, *cube, {Vec3(1.03f, 0.2f, 0), Quat::Identity()}, settings, m));
}

TEST(BoxBoxTest, OctagonIsReducedToFourKeepingTheDeepest)
{
    const auto cube = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
    // Same-size boxes, B turned 45 degrees about the normal: the clipped polygon is an octagon; a slight
    // tilt makes one side deeper
    const Quat rot =
        Quat(Eigen::AngleAxisf(0.01f, Vec3::UnitX())) * Quat(Eigen::AngleAxisf(0.25f * cPi, Vec3::UnitY()));
    const Transform t{Vec3(0, 0.98f, 0), rot};
    ContactManifold m;
    ASSERT_TRUE(CollideBoxBox(*cube, {}, *cube, t, {}, m));
    ASSERT_EQ(m.mNumPoints, 4);
    ExpectConsistentPoints(m);
    ConvexContact reference;
    ASSERT_TRUE(FindConvexContact(ConvexSupport::FromShape(*cube, {}), ConvexSupport::FromShape(*cube, t),
                                  0.0f, reference));
    EXPECT_NEAR(MaxPenetration(m), reference.mPenetration, 1.0e-4f);
    // The 4 kept points span a large part of the octagon (area of the unit square overlap is ~0.83)
    // Area of a convex quadrilateral is half the cross product of its diagonals; the point order is unknown
    const auto p = [&](int inI) { return m.mPoints[inI].mPositionOnB; };
    const float area = 0.5f * std::max({std::abs((p(2) - p(0)).cross(p(3) - p(1)).y()),
                                        std::abs((p(1) - p(0)).cross(p(3) - p(2)).y()),
                                        std::abs((p(1) - p(0)).cross(p(2) - p(3)).y())});
    EXPECT_GT(area, 0.5f);
}

} // namespace
} // namespace cairn
