// Fast bodies against a 0.1 m wall: a body of motion quality LinearCast never passes through it, at any speed
// from 10 to 500 m/s (the default velocity limit), head on or at 45 degrees, for every convex shape kind.

#include "SimulationFixture.h"
#include "cairn/physics/shapes/ConvexHullShape.h"
#include "cairn/physics/shapes/TriangleMeshShape.h"

#include <array>
#include <string>
#include <tuple>

namespace cairn::test
{
using namespace cairn::physics;

namespace
{
enum class ShapeKind
{
    Sphere,
    Box,
    Hull,
};

ShapeRef MakeShape(ShapeKind inKind)
{
    switch (inKind)
    {
    case ShapeKind::Sphere:
        return SphereShape::Create(0.1f).Value();
    case ShapeKind::Box:
        return BoxShape::Create(Vec3(0.1f, 0.1f, 0.1f)).Value();
    case ShapeKind::Hull:
    {
        // A small irregular pebble
        const Vec3 points[] = {{0.1f, 0, 0},     {-0.08f, 0.02f, 0}, {0, 0.09f, 0.01f},    {0.01f, -0.1f, 0},
                               {0, 0.01f, 0.1f}, {0.02f, 0, -0.09f}, {0.05f, 0.05f, 0.05f}};
        return ConvexHullShape::Create(points).Value();
    }
    }
    return nullptr;
}

using TunnelParam = std::tuple<ShapeKind, float, bool>; // Shape, speed (m/s), at 45 degrees

class TunnellingTest : public SimulationFixture, public ::testing::WithParamInterface<TunnelParam>
{
protected:
    /// A world without gravity holding inWall, a static wall in the plane x = 0 facing -x. The body starts 1
    /// m before it (beyond a step's speculative reach at no speed), spinning, and must stay on the near side
    /// (x < 0) for half a second.
    void ExpectNoPassingThrough(const ShapeRef& inWall)
    {
        const auto [kind, speed, oblique] = GetParam();
        PhysicsSettings settings;
        settings.mGravity = Vec3::Zero();
        ResetWorld(settings);
        AddStatic(inWall, Vec3::Zero());
        BodyCreationSettings body =
            DynamicSettings(MakeShape(kind), Vec3(-1.0f, 0.0f, oblique ? -1.0f : 0.0f));
        const Vec3 direction = oblique ? Vec3(1, 0, 1).normalized() : Vec3(1, 0, 0);
        body.mLinearVelocity = speed * direction;
        body.mAngularVelocity = Vec3(20.0f, 30.0f, 40.0f);
        body.mLinearDamping = 0.0f;
        body.mMotionQuality = MotionQuality::LinearCast;
        const BodyID id = AddDynamic(body);
        for (int update = 0; update < 30; ++update)
        {
            Step(1);
            ASSERT_LT(Position(id).x(), 0.0f) << "through the wall after update " << update;
        }
    }
};

// A box wall 0.1 m thick (x in [-0.05, 0.05]), 600 m wide and high (a body glancing off at 500 m/s slides
// along it for the whole test)
TEST_P(TunnellingTest, LinearCastBodyNeverPassesAThinWall)
{
    ExpectNoPassingThrough(Box(Vec3(0.05f, 300.0f, 300.0f)));
}

// A wall of no thickness: two triangles of a mesh in the plane x = 0
TEST_P(TunnellingTest, LinearCastBodyNeverPassesAMeshWall)
{
    const Vec3 corners[] = {{0, -300, -300}, {0, 300, -300}, {0, 300, 300}, {0, -300, 300}};
    const std::array<uint32_t, 3> triangles[] = {{0, 2, 1}, {0, 3, 2}}; // Facing -x, towards the body
    ExpectNoPassingThrough(TriangleMeshShape::Create(corners, triangles).Value());
}

std::string Name(const ::testing::TestParamInfo<TunnelParam>& inInfo)
{
    const auto [kind, speed, oblique] = inInfo.param;
    const char* names[] = {"Sphere", "Box", "Hull"};
    return std::string(names[int(kind)]) + "At" + std::to_string(int(speed)) +
           (oblique ? "Oblique" : "HeadOn");
}

INSTANTIATE_TEST_SUITE_P(
    Speeds, TunnellingTest,
    ::testing::Combine(::testing::Values(ShapeKind::Sphere, ShapeKind::Box, ShapeKind::Hull),
                       ::testing::Values(10.0f, 50.0f, 120.0f, 250.0f, 500.0f), ::testing::Bool()),
    Name);

} // namespace
} // namespace cairn::test
