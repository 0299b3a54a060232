// Shape::CastRay on rays no world query sends (NaN, infinite, or beyond the float range the ray tests'
// squares hold): no hit, never a made-up one, for every kind of shape. Before the check, a NaN origin hit a
// box at fraction 0.4, an infinite direction hit a capsule with a NaN normal, and a capsule reported an
// infinite origin as inside it.

#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/CapsuleShape.h"
#include "cairn/physics/shapes/CompoundShape.h"
#include "cairn/physics/shapes/ConvexHullShape.h"
#include "cairn/physics/shapes/HeightFieldShape.h"
#include "cairn/physics/shapes/SphereShape.h"
#include "cairn/physics/shapes/TriangleMeshShape.h"

#include <gtest/gtest.h>
#include <limits>
#include <string>
#include <vector>

namespace cairn::test
{
using namespace cairn::physics;
namespace
{

struct NamedShape
{
    std::string mName;
    ShapeRef mShape;
};

std::vector<NamedShape> EveryKindOfShape()
{
    std::vector<NamedShape> shapes;
    shapes.push_back({"box", BoxShape::Create(Vec3(1, 1, 1)).Value()});
    shapes.push_back({"sphere", SphereShape::Create(1).Value()});
    shapes.push_back({"capsule", CapsuleShape::Create(1, 0.5f).Value()});
    const std::vector<Vec3> corners{{-1, -1, -1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}, {1, 1, 1}};
    shapes.push_back({"hull", ConvexHullShape::Create(corners).Value()});
    const std::vector<Vec3> vertices{{-5, 0, -5}, {5, 0, -5}, {0, 0, 5}};
    const std::vector<std::array<uint32_t, 3>> triangles{{0, 1, 2}};
    shapes.push_back({"mesh", TriangleMeshShape::Create(vertices, triangles).Value()});
    const std::vector<float> heights(16, 0.0f);
    shapes.push_back({"height field", HeightFieldShape::Create(4, 4, 1.0f, heights).Value()});
    shapes.push_back({"compound", CompoundShape::Create({{shapes[2].mShape, Transform{}}}).Value()});
    return shapes;
}

TEST(ShapeRayInputTest, RaysOutsideTheCastableRangeHitNothing)
{
    constexpr float cInf = std::numeric_limits<float>::infinity();
    constexpr float cNaN = std::numeric_limits<float>::quiet_NaN();
    const float beyond = 1.01f * cMaxLocalRayCoordinate;
    // Each would cross the shapes' surfaces if its maths held
    const std::vector<std::pair<std::string, RayCast>> rays{
        {"infinite direction", {Vec3(0.3f, 5, 0.2f), Vec3(0, -cInf, 0)}},
        {"infinite direction, two axes", {Vec3(0.3f, 5, 0.2f), Vec3(cInf, -cInf, 0)}},
        {"NaN direction", {Vec3(0.3f, 5, 0.2f), Vec3(0, cNaN, 0)}},
        {"infinite origin", {Vec3(0.3f, cInf, 0.2f), Vec3(0, -10, 0)}},
        {"NaN origin", {Vec3(cNaN, 5, 0.2f), Vec3(0, -10, 0)}},
        {"direction beyond the range", {Vec3(0.3f, 5, 0.2f), Vec3(0, -3e38f, 0)}},
        {"origin beyond the range", {Vec3(0.3f, beyond, 0.2f), Vec3(0, -beyond, 0)}},
    };
    for (const NamedShape& shape : EveryKindOfShape())
        for (const auto& [name, ray] : rays)
        {
            EXPECT_FALSE(IsCastableRay(ray)) << name;
            RayHit hit;
            EXPECT_FALSE(shape.mShape->CastRay(ray, hit)) << shape.mName << ", " << name;
            EXPECT_EQ(hit.mFraction, RayHit().mFraction) << shape.mName << ", " << name << ": hit changed";
        }
}

TEST(ShapeRayInputTest, TheLongestRaysOfTheRangeStillHit)
{
    // From the range's edge, as far as it goes: each shape is on the way, and the check lets it through
    const RayCast fromAbove{Vec3(0.3f, cMaxLocalRayCoordinate, 0.2f), Vec3(0, -cMaxLocalRayCoordinate, 0)};
    const RayCast longest{Vec3(0.3f, 5, 0.2f), Vec3(0, -cMaxLocalRayCoordinate, 0)};
    ASSERT_TRUE(IsCastableRay(fromAbove) && IsCastableRay(longest));
    for (const NamedShape& shape : EveryKindOfShape())
    {
        RayHit hit;
        EXPECT_TRUE(shape.mShape->CastRay(fromAbove, hit)) << shape.mName;
        EXPECT_NEAR(hit.mFraction, 1.0f, 1e-6f) << shape.mName;
        RayHit shortHit;
        EXPECT_TRUE(shape.mShape->CastRay(longest, shortHit)) << shape.mName;
        EXPECT_GT(shortHit.mFraction, 0.0f) << shape.mName << ": it starts outside";
        EXPECT_LT(shortHit.mFraction, 1e-6f) << shape.mName;
        EXPECT_TRUE(shortHit.mNormal.allFinite()) << shape.mName;
    }
}

TEST(ShapeRayInputTest, ARayThroughADeepCompoundFarFromItsLevelsOriginsStillHits)
{
    // Nine levels each 950 km further out, then nine back: the ray meets the middle levels almost 9,000 km
    // from their origins, beyond twice the longest world ray, though the sphere it hits is at the compound's
    // origin. A world query sends such a ray, and a bound of the local ray at the world's scale missed the
    // sphere. The offsets and the ray are exact in float, so every level sees the ray exactly.
    constexpr float cStep = 950000.0f;
    constexpr int cLevels = 9;
    ShapeRef shape = SphereShape::Create(0.5f).Value();
    for (int level = 0; level < 2 * cLevels; ++level)
    {
        Transform inward;
        inward.mPosition = Vec3(level < cLevels ? -cStep : cStep, 0.0f, 0.0f);
        shape = CompoundShape::Create({{shape, inward}}).Value();
    }
    ASSERT_EQ(std::static_pointer_cast<const CompoundShape>(shape)->GetDepth(), uint32_t(2 * cLevels));
    RayHit hit;
    ASSERT_TRUE(shape->CastRay({Vec3(0, 5, 0), Vec3(0, -10, 0)}, hit));
    EXPECT_NEAR(hit.mFraction, 0.45f, 1e-6f);
}

} // namespace
} // namespace cairn::test
