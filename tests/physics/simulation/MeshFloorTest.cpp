#include "SimulationFixture.h"
#include "cairn/physics/shapes/HeightFieldShape.h"
#include "cairn/physics/shapes/TriangleMeshShape.h"

#include <array>
#include <vector>

namespace cairn::test
{
using namespace cairn::physics;

namespace
{
/// A flat grid mesh in the y = 0 plane from -inHalfSize to +inHalfSize, inCells x inCells quads.
ShapeRef FlatGridMesh(float inHalfSize, int inCells)
{
    std::vector<Vec3> vertices;
    std::vector<std::array<uint32_t, 3>> triangles;
    const float cell = 2.0f * inHalfSize / float(inCells);
    for (int z = 0; z <= inCells; ++z)
        for (int x = 0; x <= inCells; ++x)
            vertices.emplace_back(-inHalfSize + cell * float(x), 0.0f, -inHalfSize + cell * float(z));
    auto index = [&](int inX, int inZ) { return uint32_t(inX + inZ * (inCells + 1)); };
    for (int z = 0; z < inCells; ++z)
        for (int x = 0; x < inCells; ++x)
        {
            // Counter-clockwise seen from above, so the normals point up
            triangles.push_back({index(x, z), index(x, z + 1), index(x + 1, z + 1)});
            triangles.push_back({index(x, z), index(x + 1, z + 1), index(x + 1, z)});
        }
    return TriangleMeshShape::Create(vertices, triangles).Value();
}
} // namespace

using MeshFloorTest = SimulationFixture;

TEST_F(MeshFloorTest, BoxComesToRestOnTriangleMesh)
{
    AddStatic(FlatGridMesh(10.0f, 10), Vec3::Zero());
    const BodyID box = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0.3f, 2.0f, 0.2f)));
    Step(240);
    EXPECT_NEAR(Position(box).y(), 0.5f, 0.01f);
    EXPECT_LT(Velocity(box).norm(), 1.0e-3f);
    EXPECT_FALSE(IsActive(box));
}

TEST_F(MeshFloorTest, BoxComesToRestOnHeightField)
{
    const uint32_t samples = 21;
    std::vector<float> heights(samples * samples, 0.0f);
    const ShapeRef terrain = HeightFieldShape::Create(samples, samples, 1.0f, heights).Value();
    AddStatic(terrain, Vec3(-10, 0, -10));
    const BodyID box = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0.5f, 2.0f, 0.5f)));
    Step(240);
    EXPECT_NEAR(Position(box).y(), 0.5f, 0.01f);
    EXPECT_FALSE(IsActive(box));
}

TEST_F(MeshFloorTest, SphereRollsAcrossInternalEdgesWithoutBouncing)
{
    // 1,600 triangles of 0.5 m: the sphere crosses dozens of internal edges and vertices
    AddStatic(FlatGridMesh(10.0f, 40), Vec3::Zero(), Quat::Identity(), 0.5f);
    BodyCreationSettings settings = DynamicSettings(Sphere(0.3f), Vec3(-8.0f, 0.3f, 0.13f));
    settings.mLinearVelocity = Vec3(6.0f, 0.0f, 0.5f);
    settings.mAngularVelocity = Vec3(0.5f / 0.3f, 0.0f, -6.0f / 0.3f); // already rolling
    settings.mFriction = 0.5f;
    settings.mAllowSleeping = false;
    const BodyID sphere = AddDynamic(settings);
    Step(10); // settle onto the mesh
    float worstVertical = 0.0f;
    for (int i = 0; i < 120 && Position(sphere).x() < 9.0f; ++i)
    {
        Step(1);
        worstVertical = std::max(worstVertical, std::abs(Velocity(sphere).y()));
    }
    EXPECT_GT(Position(sphere).x(), 0.0f) << "the sphere should have rolled across the mesh";
    EXPECT_LT(worstVertical, 0.05f);
}

} // namespace cairn::test
