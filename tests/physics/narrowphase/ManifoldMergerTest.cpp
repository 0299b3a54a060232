// One body pair's manifolds merged where their normals agree (ManifoldMerger): a box on two triangles of a
// flat quad becomes one manifold of four points; normals further apart than the tolerance stay apart; a
// point two triangles both report is kept once; the merged points are measured along the merged normal.

#include "narrowphase/ManifoldMerger.h"

#include "cairn/physics/narrowphase/CollideShapes.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/TriangleMeshShape.h"
#include "common/ShapeExpect.h"

#include <array>
#include <cmath>
#include <gtest/gtest.h>
#include <vector>

namespace cairn
{
using namespace cairn::physics;
namespace
{
using cairn::test::MaxPenetration;

/// A one-point manifold: B's point inDepth below A's along inNormal (A's point at inOnA).
ContactManifold OnePoint(const Vec3& inNormal, const Vec3& inOnA, float inDepth, SubShapeID inSubShapeB)
{
    ContactManifold m;
    m.mNormal = inNormal.normalized();
    m.mNumPoints = 1;
    m.mPoints[0].mPositionOnA = inOnA;
    m.mPoints[0].mPositionOnB = inOnA - inDepth * m.mNormal;
    m.mPoints[0].mPenetration = inDepth;
    m.mSubShapeB = inSubShapeB;
    return m;
}

std::vector<ContactManifold> Merged(ManifoldMerger& ioMerger)
{
    std::vector<ContactManifold> out;
    ioMerger.ForEach([&](const ContactManifold& inM) { out.push_back(inM); });
    return out;
}

Vec3 TiltedUp(float inDegrees)
{
    const float r = inDegrees * 3.14159265f / 180.0f;
    return Vec3(std::sin(r), std::cos(r), 0.0f);
}

TEST(ManifoldMergerTest, NormalsWithinTheToleranceBecomeOneManifoldAlongTheirMeanNormal)
{
    ManifoldMerger merger;
    ASSERT_TRUE(merger.Add(OnePoint(TiltedUp(2.0f), Vec3(0, 0, 0), 0.01f, 7)));
    ASSERT_TRUE(merger.Add(OnePoint(TiltedUp(-2.0f), Vec3(1, 0, 0), 0.02f, 8)));
    const std::vector<ContactManifold> out = Merged(merger);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_NEAR(out[0].mNormal.dot(Vec3::UnitY()), 1.0f, 1.0e-6f); // The mean of +2 and -2 degrees
    EXPECT_EQ(out[0].mSubShapeB, 7u);                              // The first one's: its warm start key
    ASSERT_EQ(out[0].mNumPoints, 2);
    for (int i = 0; i < 2; ++i)
    {
        const ContactPoint& p = out[0].mPoints[i];
        // Re-measured along the mean normal: cos(2 degrees) of the depth along the point's own normal
        EXPECT_NEAR(p.mPenetration, (p.mPositionOnA - p.mPositionOnB).dot(out[0].mNormal), 1.0e-7f);
        EXPECT_LT(p.mPenetration, 0.0201f * std::cos(2.0f * 3.14159265f / 180.0f) + 1.0e-6f);
    }
}

TEST(ManifoldMergerTest, NormalsFurtherApartStayApartAndUnchanged)
{
    ManifoldMerger merger;
    const ContactManifold a = OnePoint(TiltedUp(4.0f), Vec3(0, 0, 0), 0.01f, 1);
    const ContactManifold b = OnePoint(TiltedUp(-4.0f), Vec3(1, 0, 0), 0.02f, 2); // 8 degrees from a
    ASSERT_TRUE(merger.Add(a));
    ASSERT_TRUE(merger.Add(b));
    const std::vector<ContactManifold> out = Merged(merger);
    ASSERT_EQ(out.size(), 2u);
    EXPECT_EQ(out[0].mNormal, a.mNormal);
    EXPECT_EQ(out[1].mNormal, b.mNormal);
    EXPECT_EQ(out[0].mPoints[0].mPenetration, 0.01f);
    EXPECT_EQ(out[1].mSubShapeB, 2u);
}

TEST(ManifoldMergerTest, APointTwoTrianglesBothReportIsKeptOnceAtItsDeeperDepth)
{
    ManifoldMerger merger;
    ASSERT_TRUE(merger.Add(OnePoint(Vec3::UnitY(), Vec3(0.5f, 0, 0), 0.010f, 1)));
    ASSERT_TRUE(merger.Add(OnePoint(Vec3::UnitY(), Vec3(0.5f, 0, 0.0002f), 0.0105f, 2))); // The shared edge
    const std::vector<ContactManifold> out = Merged(merger);
    ASSERT_EQ(out.size(), 1u);
    ASSERT_EQ(out[0].mNumPoints, 1);
    EXPECT_NEAR(out[0].mPoints[0].mPenetration, 0.0105f, 1.0e-6f);
}

TEST(ManifoldMergerTest, ManyPointsAreReducedToFourKeepingTheDeepest)
{
    ManifoldMerger merger;
    // 20 one-point manifolds on a circle, all facing up; the deepest is number 13
    for (int i = 0; i < 20; ++i)
    {
        const float angle = 2.0f * 3.14159265f * float(i) / 20.0f;
        ASSERT_TRUE(merger.Add(OnePoint(Vec3::UnitY(), Vec3(std::cos(angle), 0, std::sin(angle)),
                                        i == 13 ? 0.05f : 0.01f, SubShapeID(i))));
    }
    const std::vector<ContactManifold> out = Merged(merger);
    ASSERT_EQ(out.size(), 1u);
    ASSERT_EQ(out[0].mNumPoints, ContactManifold::cMaxPoints);
    EXPECT_NEAR(MaxPenetration(out[0]), 0.05f, 1.0e-6f);
}

TEST(ManifoldMergerTest, GroupsBeyondItsRoomAreHandedBack)
{
    ManifoldMerger merger;
    for (int g = 0; g < ManifoldMerger::cMaxGroups; ++g)
        ASSERT_TRUE(merger.Add(OnePoint(TiltedUp(20.0f * float(g)), Vec3::Zero(), 0.01f, SubShapeID(g))));
    EXPECT_FALSE(merger.Add(OnePoint(TiltedUp(-30.0f), Vec3::Zero(), 0.01f, 99)));
    EXPECT_TRUE(merger.Add(OnePoint(TiltedUp(1.0f), Vec3(1, 0, 0), 0.01f, 100))); // Joins the first group
    EXPECT_EQ(merger.GetNumGroups(), ManifoldMerger::cMaxGroups);
}

TEST(ManifoldMergerTest, ABoxOnTwoTrianglesOfAFlatQuadGetsOneManifoldOfFourPoints)
{
    const std::vector<Vec3> vertices{{0, 0, 0}, {0, 0, 4}, {4, 0, 0}, {4, 0, 4}};
    const std::vector<std::array<uint32_t, 3>> triangles{{0, 1, 2}, {2, 1, 3}};
    const auto quad = TriangleMeshShape::Create(vertices, triangles).Value();
    const auto box = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
    ManifoldMerger merger;
    int reported = 0;
    // Over the diagonal, so that both triangles touch it
    CollideShapes(*quad, {}, *box, {Vec3(2.0f, 0.49f, 2.0f), Quat::Identity()}, {},
                  [&](const ContactManifold& inM)
                  {
                      ++reported;
                      EXPECT_TRUE(merger.Add(inM));
                  });
    EXPECT_EQ(reported, 2);
    const std::vector<ContactManifold> out = Merged(merger);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_GT(out[0].mNormal.dot(Vec3::UnitY()), 0.9999f);
    ASSERT_EQ(out[0].mNumPoints, 4);
    for (int i = 0; i < 4; ++i)
        EXPECT_NEAR(out[0].mPoints[i].mPenetration, 0.01f, 1.0e-4f);
}

} // namespace
} // namespace cairn
