// Convex shapes against triangle meshes and height fields: face contacts, one-sidedness, internal edges
// (a sphere or box moving across a flat grid only ever sees up normals) and active border edges.

#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/CapsuleShape.h"
#include "cairn/physics/shapes/HeightFieldShape.h"
#include "cairn/physics/shapes/SphereShape.h"
#include "cairn/physics/shapes/TriangleMeshShape.h"
#include "common/ShapeExpect.h"
#include "narrowphase/CollideConvexTriangles.h"

#include <array>
#include <gtest/gtest.h>
#include <vector>

namespace cairn
{
using namespace cairn::physics;
namespace
{
using cairn::test::Collide;
using cairn::test::MaxPenetration;

// A flat grid in the XZ plane at height 0, inCells x inCells cells of size inCellSize, facing +Y
std::shared_ptr<const TriangleMeshShape> MakeGrid(int inCells, float inCellSize)
{
    std::vector<Vec3> vertices;
    std::vector<std::array<uint32_t, 3>> triangles;
    const auto index = [inCells](int inX, int inZ) { return uint32_t(inX + inZ * (inCells + 1)); };
    for (int z = 0; z <= inCells; ++z)
        for (int x = 0; x <= inCells; ++x)
            vertices.emplace_back(float(x) * inCellSize, 0.0f, float(z) * inCellSize);
    for (int z = 0; z < inCells; ++z)
        for (int x = 0; x < inCells; ++x)
        {
            triangles.push_back({index(x, z), index(x, z + 1), index(x + 1, z)});
            triangles.push_back({index(x + 1, z), index(x, z + 1), index(x + 1, z + 1)});
        }
    return TriangleMeshShape::Create(vertices, triangles).Value();
}

TEST(ConvexTrianglesTest, BoxOnFlatQuad)
{
    const auto quad = MakeGrid(1, 4.0f);
    const auto box = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
    // Over the diagonal so that both triangles touch it
    const auto manifolds = Collide(*quad, {}, *box, {Vec3(2.0f, 0.49f, 2.0f), Quat::Identity()});
    ASSERT_EQ(manifolds.size(), 2u);
    int points = 0;
    for (const ContactManifold& m : manifolds)
    {
        EXPECT_GT(m.mNormal.dot(Vec3::UnitY()), 0.9999f); // Mesh is A: normal from the mesh up into the box
        for (int i = 0; i < m.mNumPoints; ++i)
        {
            EXPECT_NEAR(m.mPoints[i].mPenetration, 0.01f, 1.0e-4f);
            EXPECT_NEAR(m.mPoints[i].mPositionOnA.y(), 0.0f, 1.0e-4f);
        }
        points += m.mNumPoints;
        EXPECT_LT(m.mSubShapeA, 2u);
    }
    EXPECT_GE(points, 4);
    EXPECT_NE(manifolds[0].mSubShapeA, manifolds[1].mSubShapeA);
}

TEST(ConvexTrianglesTest, SphereAcrossInternalEdgesAndVerticesSeesOnlyUpNormals)
{
    const auto grid = MakeGrid(8, 1.0f);
    const auto sphere = SphereShape::Create(0.5f).Value();
    int manifoldCount = 0;
    // Exactly over vertices, edges, diagonals, and everything in between, with a little penetration
    for (int i = 0; i <= 80; ++i)
        for (const float z : {2.0f, 2.5f, 3.0f, 3.25f})
        {
            const float x = 2.0f + 0.05f * float(i);
            for (const ContactManifold& m :
                 Collide(*sphere, {Vec3(x, 0.49f, z), Quat::Identity()}, *grid, {}))
            {
                ++manifoldCount;
                EXPECT_GT(-m.mNormal.y(), 0.9999f) << "x " << x << " z " << z << " triangle " << m.mSubShapeB;
                EXPECT_LE(MaxPenetration(m), 0.01f + 1.0e-5f);
            }
        }
    EXPECT_GT(manifoldCount, 81 * 4);
}

TEST(ConvexTrianglesTest, BoxAndCapsuleSlidingAcrossGridSeeOnlyUpNormals)
{
    const auto grid = MakeGrid(8, 1.0f);
    const auto box = BoxShape::Create(Vec3(0.4f, 0.4f, 0.4f)).Value();
    const auto capsule = CapsuleShape::Create(0.5f, 0.3f).Value();
    const Quat yaw(Eigen::AngleAxisf(0.3f, Vec3::UnitY()));
    const Quat lying(Eigen::AngleAxisf(0.5f * cPi, Vec3::UnitX()));
    int manifoldCount = 0;
    for (int i = 0; i <= 60; ++i)
    {
        const float x = 2.0f + 0.05f * float(i);
        for (const ContactManifold& m : Collide(*box, {Vec3(x, 0.39f, 3.0f), yaw}, *grid, {}))
        {
            ++manifoldCount;
            EXPECT_GT(-m.mNormal.y(), 0.9999f) << "box x " << x;
        }
        for (const ContactManifold& m : Collide(*capsule, {Vec3(x, 0.29f, 3.0f), yaw * lying}, *grid, {}))
        {
            ++manifoldCount;
            EXPECT_GT(-m.mNormal.y(), 0.9999f) << "capsule x " << x;
        }
    }
    EXPECT_GT(manifoldCount, 61 * 2);
}

TEST(ConvexTrianglesTest, BorderEdgeKeepsItsRealNormal)
{
    const auto quad = MakeGrid(1, 2.0f);
    const auto sphere = SphereShape::Create(0.5f).Value();
    // Beyond the -x border, slightly above the plane: the border is active, the normal points at the edge
    const Vec3 centre(-0.3f, 0.3f, 1.0f);
    const auto manifolds = Collide(*sphere, {centre, Quat::Identity()}, *quad, {});
    ASSERT_FALSE(manifolds.empty());
    const Vec3 expected = (Vec3(0.0f, 0.0f, 1.0f) - centre).normalized();
    for (const ContactManifold& m : manifolds)
    {
        EXPECT_GT(m.mNormal.dot(expected), 0.9999f);
        EXPECT_NEAR(MaxPenetration(m), 0.5f - std::sqrt(0.18f), 1.0e-4f);
    }
}

TEST(ConvexTrianglesTest, OneSided)
{
    const auto quad = MakeGrid(1, 2.0f);
    const auto sphere = SphereShape::Create(0.5f).Value();
    const auto box = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
    // Centres below the surface: the back of a one-sided mesh does not collide
    EXPECT_TRUE(Collide(*sphere, {Vec3(1.0f, -0.3f, 1.0f), Quat::Identity()}, *quad, {}).empty());
    EXPECT_TRUE(Collide(*box, {Vec3(1.0f, -0.3f, 1.0f), Quat::Identity()}, *quad, {}).empty());
    // Above it, the same overlap does
    EXPECT_FALSE(Collide(*sphere, {Vec3(1.0f, 0.3f, 1.0f), Quat::Identity()}, *quad, {}).empty());
    EXPECT_FALSE(Collide(*box, {Vec3(1.0f, 0.3f, 1.0f), Quat::Identity()}, *quad, {}).empty());
}

TEST(ConvexTrianglesTest, SpeculativeAndBeyond)
{
    const auto grid = MakeGrid(2, 1.0f);
    const auto box = BoxShape::Create(Vec3(0.3f, 0.3f, 0.3f)).Value();
    const auto near = Collide(*box, {Vec3(0.6f, 0.31f, 0.7f), Quat::Identity()}, *grid, {});
    ASSERT_FALSE(near.empty());
    for (const ContactManifold& m : near)
        EXPECT_NEAR(MaxPenetration(m), -0.01f, 1.0e-4f);
    EXPECT_TRUE(Collide(*box, {Vec3(0.6f, 0.33f, 0.7f), Quat::Identity()}, *grid, {}).empty());
}

TEST(ConvexTrianglesTest, MeshTransformIsApplied)
{
    const auto grid = MakeGrid(2, 1.0f);
    const auto sphere = SphereShape::Create(0.5f).Value();
    // Mesh turned upside down and raised: its front now faces -Y
    const Transform meshTransform{Vec3(0, 5, 0), Quat(Eigen::AngleAxisf(cPi, Vec3::UnitX()))};
    const Vec3 centre = meshTransform * Vec3(1.0f, 0.45f, 1.0f);
    const auto manifolds = Collide(*sphere, {centre, Quat::Identity()}, *grid, meshTransform);
    ASSERT_FALSE(manifolds.empty());
    for (const ContactManifold& m : manifolds)
    {
        EXPECT_GT(m.mNormal.y(), 0.9999f); // From the sphere (below) up into the mesh
        EXPECT_NEAR(MaxPenetration(m), 0.05f, 1.0e-4f);
        EXPECT_NEAR(m.mPoints[0].mPositionOnB.y(), 5.0f, 1.0e-4f);
    }
}

TEST(ConvexTrianglesTest, BoxOnHeightField)
{
    // Flat at height 1, then a box resting on it; and a slope where the normal follows the terrain
    std::vector<float> flat(5 * 5, 1.0f);
    const auto field = HeightFieldShape::Create(5, 5, 1.0f, flat).Value();
    const auto box = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
    const auto manifolds = Collide(*box, {Vec3(2.2f, 1.48f, 1.7f), Quat::Identity()}, *field, {});
    ASSERT_FALSE(manifolds.empty());
    int points = 0;
    for (const ContactManifold& m : manifolds)
    {
        EXPECT_GT(-m.mNormal.y(), 0.9999f);
        for (int i = 0; i < m.mNumPoints; ++i)
            EXPECT_NEAR(m.mPoints[i].mPenetration, 0.02f, 1.0e-4f);
        points += m.mNumPoints;
    }
    EXPECT_GE(points, 4);

    std::vector<float> slope(5 * 5);
    for (uint32_t z = 0; z < 5; ++z)
        for (uint32_t x = 0; x < 5; ++x)
            slope[x + z * 5] = 0.5f * float(x);
    const auto sloped = HeightFieldShape::Create(5, 5, 1.0f, slope).Value();
    const Vec3 up = Vec3(-0.5f, 1.0f, 0.0f).normalized();
    const Vec3 centre = Vec3(2.0f, 1.0f, 2.0f) + up * 0.49f;
    const auto onSlope = Collide(*box, {centre, Quat::FromTwoVectors(Vec3::UnitY(), up)}, *sloped, {});
    ASSERT_FALSE(onSlope.empty());
    for (const ContactManifold& m : onSlope)
    {
        EXPECT_GT(-m.mNormal.dot(up), 0.9999f);
        EXPECT_NEAR(MaxPenetration(m), 0.01f, 1.0e-4f);
    }
}

} // namespace
} // namespace cairn
