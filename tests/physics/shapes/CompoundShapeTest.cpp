#include "cairn/physics/shapes/CompoundShape.h"

#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/SphereShape.h"
#include "cairn/physics/shapes/TriangleMeshShape.h"
#include "common/ShapeExpect.h"

#include <gtest/gtest.h>
#include <limits>

using namespace cairn;
using namespace cairn::physics;

namespace
{
using cairn::test::At;

std::shared_ptr<const CompoundShape> MakeCompound(std::vector<CompoundShape::SubShape> inSubShapes)
{
    auto result = CompoundShape::Create(std::move(inSubShapes));
    EXPECT_TRUE(result.IsOk()) << (result.IsOk() ? "" : result.GetError().mMessage);
    return result.IsOk() ? result.Value() : nullptr;
}

const Quat cQuarterTurnY(Eigen::AngleAxisf(0.5f * cPi, Vec3::UnitY())); // Local x -> -z, local z -> x

} // namespace

TEST(ShapeTest, TypeNames)
{
    EXPECT_STREQ(ToString(ShapeType::Sphere), "Sphere");
    EXPECT_STREQ(ToString(ShapeType::HeightField), "HeightField");
    EXPECT_STREQ(ToString(ShapeType::Compound), "Compound");
}

TEST(CompoundShapeTest, RejectsBadInput)
{
    const ShapeRef sphere = SphereShape::Create(1.0f).Value();
    EXPECT_EQ(CompoundShape::Create({}).GetError().mCode, ErrorCode::DegenerateShape);
    EXPECT_EQ(CompoundShape::Create({{nullptr, Transform()}}).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_EQ(CompoundShape::Create({{sphere, At(Vec3(std::numeric_limits<float>::quiet_NaN(), 0, 0))}})
                  .GetError()
                  .mCode,
              ErrorCode::InvalidArgument);
    EXPECT_EQ(CompoundShape::Create({{sphere, At(Vec3::Zero(), Quat(2, 0, 0, 0))}}).GetError().mCode,
              ErrorCode::InvalidArgument);
    EXPECT_EQ(CompoundShape::Create({{sphere, At(Vec3(2e6f, 0, 0))}}).GetError().mCode,
              ErrorCode::InvalidArgument);
}

// Compounds nested 20,000 deep overflowed the stack in the first query or step that walked them: nesting is
// bounded where the shape is made
TEST(CompoundShapeTest, NestingIsBoundedAtCreation)
{
    ShapeRef shape = SphereShape::Create(1.0f).Value();
    for (uint32_t depth = 1; depth <= CompoundShape::cMaxDepth; ++depth)
    {
        const auto nested = CompoundShape::Create({{shape, Transform()}});
        ASSERT_TRUE(nested) << "depth " << depth;
        EXPECT_EQ(nested.Value()->GetDepth(), depth);
        shape = nested.Value();
    }
    const auto tooDeep =
        CompoundShape::Create({{SphereShape::Create(1.0f).Value(), Transform()}, {shape, Transform()}});
    ASSERT_FALSE(tooDeep);
    EXPECT_EQ(tooDeep.GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_NE(tooDeep.GetError().mMessage.find("sub-shape 1"), std::string::npos)
        << tooDeep.GetError().mMessage;
}

TEST(CompoundShapeTest, TwoSpheresMassProperties)
{
    const float r = 0.5f;
    const float d = 2.0f;
    const ShapeRef sphere = SphereShape::Create(r).Value();
    const auto compound = MakeCompound({{sphere, At(Vec3(-d, 1, 0))}, {sphere, At(Vec3(d, 1, 0))}});
    ASSERT_NE(compound, nullptr);
    const MassProperties props = compound->GetMassProperties(3.0f);
    const float m = 3.0f * 4.0f / 3.0f * cPi * r * r * r;
    const float own = 0.4f * m * r * r;
    EXPECT_NEAR(props.mMass, 2.0f * m, 1e-5f);
    EXPECT_TRUE(props.mCenterOfMass.isApprox(Vec3(0, 1, 0)));
    EXPECT_NEAR(props.mInertia(0, 0), 2.0f * own, 1e-5f);
    EXPECT_NEAR(props.mInertia(1, 1), 2.0f * (own + m * d * d), 1e-4f);
    EXPECT_NEAR(props.mInertia(2, 2), 2.0f * (own + m * d * d), 1e-4f);
    EXPECT_NEAR(props.mInertia(0, 1), 0.0f, 1e-5f);
}

TEST(CompoundShapeTest, UnequalChildrenAndRotation)
{
    // A unit sphere at x = 3 and a rotated 1 x 2 x 3 box at the origin (density 1)
    const ShapeRef sphere = SphereShape::Create(1.0f).Value();
    const auto box = BoxShape::Create(Vec3(0.5f, 1.0f, 1.5f)).Value();
    // A static mesh child adds surface but no mass
    const std::vector<Vec3> vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1)};
    const ShapeRef mesh =
        TriangleMeshShape::Create(vertices, std::vector<std::array<uint32_t, 3>>{{0, 2, 1}}).Value();
    const auto compound = MakeCompound(
        {{sphere, At(Vec3(3, 0, 0))}, {box, At(Vec3::Zero(), cQuarterTurnY)}, {mesh, At(Vec3(0, -5, 0))}});
    ASSERT_NE(compound, nullptr);

    const float ms = 4.0f / 3.0f * cPi;
    const float mb = 6.0f;
    const float total = ms + mb;
    const float comX = 3.0f * ms / total;
    const MassProperties props = compound->GetMassProperties(1.0f);
    EXPECT_NEAR(props.mMass, total, 1e-4f);
    EXPECT_TRUE(props.mCenterOfMass.isApprox(Vec3(comX, 0, 0), 1e-5f));

    // The quarter turn swaps the box's x and z inertia
    const Vec3 boxI(mb / 12.0f * (4 + 9), mb / 12.0f * (1 + 9), mb / 12.0f * (1 + 4));
    const float sphereI = 0.4f * ms;
    const float dS = 3.0f - comX;
    const float dB = comX;
    EXPECT_NEAR(props.mInertia(0, 0), boxI.z() + sphereI, 1e-4f);
    EXPECT_NEAR(props.mInertia(1, 1), boxI.y() + sphereI + ms * dS * dS + mb * dB * dB, 1e-4f);
    EXPECT_NEAR(props.mInertia(2, 2), boxI.x() + sphereI + ms * dS * dS + mb * dB * dB, 1e-4f);
    EXPECT_NEAR(props.mInertia(0, 2), 0.0f, 1e-4f);
}

TEST(CompoundShapeTest, BoundsAndRayCast)
{
    const ShapeRef sphere = SphereShape::Create(1.0f).Value();
    const ShapeRef box = BoxShape::Create(Vec3(1, 2, 3)).Value();
    const auto compound = MakeCompound({{sphere, At(Vec3(5, 0, 0))}, {box, At(Vec3::Zero(), cQuarterTurnY)}});
    ASSERT_NE(compound, nullptr);

    EXPECT_TRUE(compound->GetLocalBounds().mMin.isApprox(Vec3(-3, -2, -1), 1e-5f));
    EXPECT_TRUE(compound->GetLocalBounds().mMax.isApprox(Vec3(6, 2, 1), 1e-5f));
    const AABB world = compound->GetWorldBounds(At(Vec3(0, 10, 0), cQuarterTurnY));
    // The compound turned again: box (3 x 2 x 1 half extents) back to 1 x 2 x 3, sphere at z = -5
    EXPECT_TRUE(world.mMin.isApprox(Vec3(-1, 8, -6), 1e-5f)) << world.mMin.transpose();
    EXPECT_TRUE(world.mMax.isApprox(Vec3(1, 12, 3), 1e-5f)) << world.mMax.transpose();

    RayHit fromLeft;
    ASSERT_TRUE(compound->CastRay({Vec3(-10, 0, 0), Vec3(20, 0, 0)}, fromLeft));
    EXPECT_NEAR(fromLeft.mFraction, 7.0f / 20.0f, 1e-5f); // The box's local z half extent 3 lies along x
    EXPECT_TRUE(fromLeft.mNormal.isApprox(Vec3(-1, 0, 0), 1e-5f));
    EXPECT_EQ(fromLeft.mSubShape, 1u);

    RayHit fromRight;
    ASSERT_TRUE(compound->CastRay({Vec3(10, 0, 0), Vec3(-20, 0, 0)}, fromRight));
    EXPECT_NEAR(fromRight.mFraction, 4.0f / 20.0f, 1e-5f);
    EXPECT_TRUE(fromRight.mNormal.isApprox(Vec3(1, 0, 0), 1e-5f));
    EXPECT_EQ(fromRight.mSubShape, 0u);

    RayHit side; // Along z through the box: its local x half extent 1 lies along z
    ASSERT_TRUE(compound->CastRay({Vec3(0, 0, 10), Vec3(0, 0, -20)}, side));
    EXPECT_NEAR(side.mFraction, 9.0f / 20.0f, 1e-5f);
    EXPECT_TRUE(side.mNormal.isApprox(Vec3(0, 0, 1), 1e-5f));

    RayHit miss;
    EXPECT_FALSE(compound->CastRay({Vec3(-10, 3, 0), Vec3(20, 0, 0)}, miss));
    EXPECT_FALSE(compound->CastRay({Vec3(-10, 0, 0), Vec3(5, 0, 0)}, miss));

    RayHit inside;
    ASSERT_TRUE(compound->CastRay({Vec3(5, 0.5f, 0), Vec3(0, 1, 0)}, inside));
    EXPECT_EQ(inside.mFraction, 0.0f);
    EXPECT_EQ(inside.mSubShape, 0u);
}

TEST(CompoundShapeTest, VisitAndCollectTriangles)
{
    const ShapeRef box = BoxShape::Create(Vec3(1, 1, 1)).Value();
    const auto compound = MakeCompound({{box, At(Vec3(-5, 0, 0))}, {box, At(Vec3(5, 0, 0), cQuarterTurnY)}});
    ASSERT_NE(compound, nullptr);

    int left = 0, right = 0;
    compound->VisitTriangles(compound->GetLocalBounds(),
                             [&](const Triangle& t)
                             {
                                 const Vec3 center = t.mSubShape == 0 ? Vec3(-5, 0, 0) : Vec3(5, 0, 0);
                                 (t.mSubShape == 0 ? left : right)++;
                                 const Vec3 n = (t.mV[1] - t.mV[0]).cross(t.mV[2] - t.mV[0]);
                                 EXPECT_GT(n.dot((t.mV[0] + t.mV[1] + t.mV[2]) / 3.0f - center), 0.0f);
                                 for (const Vec3& v : t.mV)
                                     EXPECT_NEAR((v - center).cwiseAbs().maxCoeff(), 1.0f, 1e-5f);
                             });
    EXPECT_EQ(left, 12);
    EXPECT_EQ(right, 12);

    int onlyRight = 0;
    compound->VisitTriangles(AABB(Vec3(3, -2, -2), Vec3(7, 2, 2)),
                             [&](const Triangle& t)
                             {
                                 EXPECT_EQ(t.mSubShape, 1u);
                                 ++onlyRight;
                             });
    EXPECT_EQ(onlyRight, 12);

    // World triangles near the top face of the right box, with the compound raised by 10
    std::vector<Vec3> world;
    compound->CollectTriangles(AABB(Vec3(4.5f, 10.9f, -0.5f), Vec3(5.5f, 11.5f, 0.5f)), At(Vec3(0, 10, 0)),
                               world);
    ASSERT_FALSE(world.empty());
    ASSERT_EQ(world.size() % 3, 0u);
    for (size_t i = 0; i < world.size(); i += 3)
    {
        AABB bounds;
        for (size_t k = 0; k < 3; ++k)
            bounds.Encapsulate(world[i + k]);
        EXPECT_TRUE(bounds.Overlaps(AABB(Vec3(4.5f, 10.9f, -0.5f), Vec3(5.5f, 11.5f, 0.5f))));
    }
    EXPECT_LE(world.size(), 3u * 12u);
}
