#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/CapsuleShape.h"
#include "cairn/physics/shapes/SphereShape.h"

#include <cmath>
#include <gtest/gtest.h>
#include <limits>

using namespace cairn;
using namespace cairn::physics;

namespace
{

constexpr float cNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float cInf = std::numeric_limits<float>::infinity();

void ExpectVecNear(const Vec3& inActual, const Vec3& inExpected, float inTolerance)
{
    EXPECT_NEAR(inActual.x(), inExpected.x(), inTolerance) << "actual " << inActual.transpose();
    EXPECT_NEAR(inActual.y(), inExpected.y(), inTolerance) << "actual " << inActual.transpose();
    EXPECT_NEAR(inActual.z(), inExpected.z(), inTolerance) << "actual " << inActual.transpose();
}

void ExpectDiagonalInertia(const Mat3& inInertia, const Vec3& inDiagonal, float inRelTolerance)
{
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
        {
            const float expected = i == j ? inDiagonal[i] : 0.0f;
            EXPECT_NEAR(inInertia(i, j), expected, inRelTolerance * inDiagonal.maxCoeff()) << i << "," << j;
        }
}

RayCast Ray(const Vec3& inOrigin, const Vec3& inDirection)
{
    return {inOrigin, inDirection};
}

/// Checks that every visited triangle faces away from the shape's centre and that the visitor sees some.
int CountOutwardTriangles(const Shape& inShape)
{
    int count = 0;
    inShape.VisitTriangles(
        inShape.GetLocalBounds(),
        [&](const Triangle& inTriangle)
        {
            const Vec3 n = (inTriangle.mV[1] - inTriangle.mV[0]).cross(inTriangle.mV[2] - inTriangle.mV[0]);
            const Vec3 centroid = (inTriangle.mV[0] + inTriangle.mV[1] + inTriangle.mV[2]) / 3.0f;
            EXPECT_GT(n.dot(centroid), 0.0f) << "triangle faces inwards at " << centroid.transpose();
            EXPECT_GT(n.norm(), 0.0f);
            ++count;
        });
    return count;
}

} // namespace

TEST(SphereShapeTest, CreateRejectsBadRadius)
{
    EXPECT_EQ(SphereShape::Create(0.0f).GetError().mCode, ErrorCode::DegenerateShape);
    EXPECT_EQ(SphereShape::Create(-1.0f).GetError().mCode, ErrorCode::DegenerateShape);
    EXPECT_EQ(SphereShape::Create(cNaN).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_EQ(SphereShape::Create(cInf).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_FALSE(SphereShape::Create(0.0f).GetError().mMessage.empty());
    ASSERT_TRUE(SphereShape::Create(0.5f).IsOk());
    EXPECT_EQ(SphereShape::Create(0.5f).Value()->GetType(), ShapeType::Sphere);
}

TEST(SphereShapeTest, MassProperties)
{
    const auto sphere = SphereShape::Create(2.0f).Value();
    const MassProperties props = sphere->GetMassProperties(3.0f);
    const float mass = 3.0f * 4.0f / 3.0f * cPi * 8.0f;
    EXPECT_NEAR(props.mMass, mass, 1e-4f * mass);
    ExpectVecNear(props.mCenterOfMass, Vec3::Zero(), 0.0f);
    ExpectDiagonalInertia(props.mInertia, Vec3::Constant(0.4f * mass * 4.0f), 1e-5f);
}

TEST(SphereShapeTest, RayCast)
{
    const auto sphere = SphereShape::Create(1.0f).Value();

    RayHit hit;
    ASSERT_TRUE(sphere->CastRay(Ray(Vec3(-3, 0, 0), Vec3(4, 0, 0)), hit));
    EXPECT_NEAR(hit.mFraction, 0.5f, 1e-6f);
    ExpectVecNear(hit.mNormal, Vec3(-1, 0, 0), 1e-6f);

    // Only closer hits replace the current one
    RayHit closer;
    closer.mFraction = 0.25f;
    EXPECT_FALSE(sphere->CastRay(Ray(Vec3(-3, 0, 0), Vec3(4, 0, 0)), closer));
    EXPECT_EQ(closer.mFraction, 0.25f);

    RayHit miss;
    EXPECT_FALSE(sphere->CastRay(Ray(Vec3(-3, 1.01f, 0), Vec3(6, 0, 0)), miss)); // Passes above
    EXPECT_FALSE(sphere->CastRay(Ray(Vec3(-3, 0, 0), Vec3(1.5f, 0, 0)), miss));  // Too short
    EXPECT_FALSE(sphere->CastRay(Ray(Vec3(-3, 0, 0), Vec3(-4, 0, 0)), miss));    // Away from it
    EXPECT_FALSE(sphere->CastRay(Ray(Vec3(-3, 0, 0), Vec3::Zero()), miss));      // Zero length outside
    EXPECT_EQ(miss.mFraction, cLargeFloat);

    RayHit inside;
    ASSERT_TRUE(sphere->CastRay(Ray(Vec3(0.2f, 0, 0), Vec3(0, 0, 5)), inside));
    EXPECT_EQ(inside.mFraction, 0.0f);
    ExpectVecNear(inside.mNormal, Vec3(0, 0, -1), 1e-6f);

    RayHit insideZero;
    ASSERT_TRUE(sphere->CastRay(Ray(Vec3(0.2f, 0, 0), Vec3::Zero()), insideZero));
    EXPECT_EQ(insideZero.mFraction, 0.0f);
    EXPECT_TRUE(IsFinite(insideZero.mNormal));
    EXPECT_NEAR(insideZero.mNormal.norm(), 1.0f, 1e-6f);

    // Oblique hit: the normal is the radial direction at the hit point
    RayHit oblique;
    ASSERT_TRUE(sphere->CastRay(Ray(Vec3(-2, 0.6f, 0), Vec3(2, 0, 0)), oblique));
    EXPECT_NEAR(oblique.mFraction, (2.0f - 0.8f) / 2.0f, 1e-5f);
    ExpectVecNear(oblique.mNormal, Vec3(-0.8f, 0.6f, 0), 1e-5f);
}

TEST(SphereShapeTest, SupportAndTriangles)
{
    const auto sphere = SphereShape::Create(1.5f).Value();
    ExpectVecNear(sphere->GetSupport(Vec3(0, 0, 10)), Vec3(0, 0, 1.5f), 1e-6f);
    EXPECT_TRUE(IsFinite(sphere->GetSupport(Vec3::Zero())));
    EXPECT_EQ(CountOutwardTriangles(*sphere), 2 * 16 * 8 - 2 * 16);

    // Every tessellation vertex is on the sphere
    sphere->VisitTriangles(sphere->GetLocalBounds(),
                           [](const Triangle& inTriangle)
                           {
                               for (const Vec3& v : inTriangle.mV)
                                   EXPECT_NEAR(v.norm(), 1.5f, 1e-5f);
                           });

    // A box away from the sphere visits nothing, a small box on its surface visits a few triangles
    int far = 0;
    sphere->VisitTriangles(AABB(Vec3::Constant(2.0f), Vec3::Constant(3.0f)), [&](const Triangle&) { ++far; });
    EXPECT_EQ(far, 0);
    int near = 0;
    sphere->VisitTriangles(AABB::FromCenterExtent(Vec3(1.5f, 0, 0), Vec3::Constant(0.1f)),
                           [&](const Triangle&) { ++near; });
    EXPECT_GT(near, 0);
    EXPECT_LT(near, 16);
}

TEST(BoxShapeTest, CreateRejectsBadExtents)
{
    EXPECT_EQ(BoxShape::Create(Vec3(1, 0, 1)).GetError().mCode, ErrorCode::DegenerateShape);
    EXPECT_EQ(BoxShape::Create(Vec3(1, -1, 1)).GetError().mCode, ErrorCode::DegenerateShape);
    EXPECT_EQ(BoxShape::Create(Vec3(1, cNaN, 1)).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_EQ(BoxShape::Create(Vec3(cInf, 1, 1)).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_TRUE(BoxShape::Create(Vec3(1, 2, 3)).IsOk());
}

TEST(BoxShapeTest, MassProperties)
{
    const auto box = BoxShape::Create(Vec3(0.5f, 1.0f, 1.5f)).Value();
    const MassProperties props = box->GetMassProperties(2.0f);
    const float mass = 2.0f * 1.0f * 2.0f * 3.0f;
    EXPECT_NEAR(props.mMass, mass, 1e-5f);
    ExpectDiagonalInertia(
        props.mInertia,
        Vec3(mass / 12.0f * (4.0f + 9.0f), mass / 12.0f * (1.0f + 9.0f), mass / 12.0f * (1.0f + 4.0f)),
        1e-5f);
}

TEST(BoxShapeTest, RayCast)
{
    const auto box = BoxShape::Create(Vec3(1, 2, 3)).Value();

    RayHit hit;
    ASSERT_TRUE(box->CastRay(Ray(Vec3(0, 10, 0), Vec3(0, -10, 0)), hit));
    EXPECT_NEAR(hit.mFraction, 0.8f, 1e-6f);
    ExpectVecNear(hit.mNormal, Vec3(0, 1, 0), 0.0f);

    RayHit diagonal;
    ASSERT_TRUE(box->CastRay(Ray(Vec3(-3, 0.5f, 0.5f), Vec3(4, 1, 0)), diagonal));
    EXPECT_NEAR(diagonal.mFraction, 0.5f, 1e-6f);
    ExpectVecNear(diagonal.mNormal, Vec3(-1, 0, 0), 0.0f);

    RayHit miss;
    EXPECT_FALSE(box->CastRay(Ray(Vec3(-3, 2.1f, 0), Vec3(6, 0, 0)), miss)); // Parallel, just above
    EXPECT_FALSE(box->CastRay(Ray(Vec3(-3, 0, 0), Vec3(1, 0, 0)), miss));    // Too short
    EXPECT_FALSE(box->CastRay(Ray(Vec3(-3, 0, 0), Vec3(0, 0, 0)), miss));    // Zero length outside
    EXPECT_FALSE(box->CastRay(Ray(Vec3(-3, 0, 0), Vec3(-1, 0, 0)), miss));   // Away

    RayHit inside;
    ASSERT_TRUE(box->CastRay(Ray(Vec3(0.5f, 0, 0), Vec3(0, 3, 4)), inside));
    EXPECT_EQ(inside.mFraction, 0.0f);
    ExpectVecNear(inside.mNormal, Vec3(0, -0.6f, -0.8f), 1e-6f);

    RayHit insideZero;
    ASSERT_TRUE(box->CastRay(Ray(Vec3(0.5f, 0, 0), Vec3::Zero()), insideZero));
    EXPECT_TRUE(IsFinite(insideZero.mNormal));
}

TEST(BoxShapeTest, SupportAndFaces)
{
    const Vec3 half(1, 2, 3);
    const auto box = BoxShape::Create(half).Value();
    ExpectVecNear(box->GetSupport(Vec3(1, -1, 1)), Vec3(1, -2, 3), 0.0f);

    const Vec3 directions[] = {Vec3(0.1f, 0.9f, 0.2f), Vec3(-5, 1, 1), Vec3(0, 0, -1),
                               Vec3(0.3f, 0.2f, 0.4f)};
    for (const Vec3& dir : directions)
    {
        SupportingFace face;
        box->GetSupportingFace(dir, face);
        ASSERT_EQ(face.mCount, 4);
        int axis = 0;
        dir.cwiseAbs().maxCoeff(&axis);
        Vec3 normal = Vec3::Zero();
        normal[axis] = dir[axis] > 0.0f ? 1.0f : -1.0f;
        for (int i = 0; i < 4; ++i)
            EXPECT_FLOAT_EQ(face.mVertices[i].dot(normal), half[axis]);
        // Counter-clockwise seen from outside: the polygon normal points along the face normal
        const Vec3 n = (face.mVertices[1] - face.mVertices[0]).cross(face.mVertices[2] - face.mVertices[0]);
        EXPECT_GT(n.dot(normal), 0.0f) << dir.transpose();
        const Vec3 n2 = (face.mVertices[2] - face.mVertices[0]).cross(face.mVertices[3] - face.mVertices[0]);
        EXPECT_GT(n2.dot(normal), 0.0f) << dir.transpose();
    }
    EXPECT_EQ(CountOutwardTriangles(*box), 12);
}

TEST(CapsuleShapeTest, CreateRejectsBadSizes)
{
    EXPECT_EQ(CapsuleShape::Create(1.0f, 0.0f).GetError().mCode, ErrorCode::DegenerateShape);
    EXPECT_EQ(CapsuleShape::Create(-1.0f, 1.0f).GetError().mCode, ErrorCode::DegenerateShape);
    EXPECT_EQ(CapsuleShape::Create(cNaN, 1.0f).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_EQ(CapsuleShape::Create(1.0f, cInf).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_TRUE(CapsuleShape::Create(0.0f, 1.0f).IsOk());
}

TEST(CapsuleShapeTest, MassProperties)
{
    const float h = 1.0f;
    const float r = 0.5f;
    const float density = 2.0f;
    const auto capsule = CapsuleShape::Create(h, r).Value();
    const MassProperties props = capsule->GetMassProperties(density);

    const float cylinderMass = density * cPi * r * r * 2.0f * h;
    const float sphereMass = density * 4.0f / 3.0f * cPi * r * r * r;
    EXPECT_NEAR(props.mMass, cylinderMass + sphereMass, 1e-5f);

    // Independent derivation: the hemispheres' centres of mass sit 3r/8 beyond the segment ends
    const float hemiMass = 0.5f * sphereMass;
    const float hemiOwn = (0.4f - 9.0f / 64.0f) * hemiMass * r * r;
    const float d = h + 3.0f * r / 8.0f;
    const float transverse =
        cylinderMass * (3.0f * r * r + 4.0f * h * h) / 12.0f + 2.0f * (hemiOwn + hemiMass * d * d);
    const float axial = 0.5f * cylinderMass * r * r + 0.4f * sphereMass * r * r;
    ExpectDiagonalInertia(props.mInertia, Vec3(transverse, axial, transverse), 1e-5f);

    // Without a segment the capsule is a sphere
    const MassProperties asSphere = CapsuleShape::Create(0.0f, r).Value()->GetMassProperties(density);
    const MassProperties sphere = SphereShape::Create(r).Value()->GetMassProperties(density);
    EXPECT_NEAR(asSphere.mMass, sphere.mMass, 1e-6f);
    EXPECT_NEAR(asSphere.mInertia(0, 0), sphere.mInertia(0, 0), 1e-6f);
}

TEST(CapsuleShapeTest, RayCast)
{
    const auto capsule = CapsuleShape::Create(1.0f, 0.5f).Value();

    RayHit side;
    ASSERT_TRUE(capsule->CastRay(Ray(Vec3(-2, 0.5f, 0), Vec3(4, 0, 0)), side));
    EXPECT_NEAR(side.mFraction, 1.5f / 4.0f, 1e-6f);
    ExpectVecNear(side.mNormal, Vec3(-1, 0, 0), 1e-6f);

    RayHit top;
    ASSERT_TRUE(capsule->CastRay(Ray(Vec3(0, 3, 0), Vec3(0, -3, 0)), top));
    EXPECT_NEAR(top.mFraction, 1.5f / 3.0f, 1e-6f);
    ExpectVecNear(top.mNormal, Vec3(0, 1, 0), 1e-6f);

    // Hits the bottom cap off-axis: the normal is radial from the bottom segment end
    RayHit cap;
    ASSERT_TRUE(capsule->CastRay(Ray(Vec3(0.3f, -5, 0), Vec3(0, 5, 0)), cap));
    const float capY = -1.0f - std::sqrt(0.25f - 0.09f);
    EXPECT_NEAR(cap.mFraction, (capY + 5.0f) / 5.0f, 1e-5f);
    ExpectVecNear(cap.mNormal, Vec3(0.3f, capY + 1.0f, 0) / 0.5f, 1e-5f);

    RayHit miss;
    EXPECT_FALSE(capsule->CastRay(Ray(Vec3(-2, 1.55f, 0.3f), Vec3(4, 0, 0)), miss));
    EXPECT_FALSE(capsule->CastRay(Ray(Vec3(0.6f, -5, 0), Vec3(0, 10, 0)), miss));
    EXPECT_FALSE(capsule->CastRay(Ray(Vec3(0, 3, 0), Vec3::Zero()), miss));

    RayHit inside;
    ASSERT_TRUE(capsule->CastRay(Ray(Vec3(0, 1.2f, 0), Vec3(1, 0, 0)), inside));
    EXPECT_EQ(inside.mFraction, 0.0f);
    ExpectVecNear(inside.mNormal, Vec3(-1, 0, 0), 1e-6f);
}

TEST(CapsuleShapeTest, SupportAndFaces)
{
    const auto capsule = CapsuleShape::Create(1.0f, 0.5f).Value();
    ExpectVecNear(capsule->GetSupport(Vec3(0, 2, 0)), Vec3(0, 1.5f, 0), 1e-6f);
    ExpectVecNear(capsule->GetSupport(Vec3(3, -4, 0)), Vec3(0.3f, -1.4f, 0), 1e-6f);
    EXPECT_TRUE(IsFinite(capsule->GetSupport(Vec3::Zero())));

    SupportingFace side;
    capsule->GetSupportingFace(Vec3(0, 0.01f, -2), side);
    ASSERT_EQ(side.mCount, 2);
    ExpectVecNear(side.mVertices[0], Vec3(0, 1, -0.5f), 1e-6f);
    ExpectVecNear(side.mVertices[1], Vec3(0, -1, -0.5f), 1e-6f);

    SupportingFace tilted;
    capsule->GetSupportingFace(Vec3(1, 1, 0), tilted);
    ASSERT_EQ(tilted.mCount, 1);
    ExpectVecNear(tilted.mVertices[0], capsule->GetSupport(Vec3(1, 1, 0)), 0.0f);

    EXPECT_EQ(CountOutwardTriangles(*capsule), 2 * 16 * 9 - 2 * 16);
    capsule->VisitTriangles(capsule->GetLocalBounds(),
                            [](const Triangle& inTriangle)
                            {
                                for (const Vec3& v : inTriangle.mV)
                                {
                                    const Vec3 axis(0, std::clamp(v.y(), -1.0f, 1.0f), 0);
                                    EXPECT_NEAR((v - axis).norm(), 0.5f, 1e-5f);
                                }
                            });
}

namespace
{
/// The world box a convex shape's surface spans at inTransform, from its support points along the six axes:
/// the tightest box there is.
AABB SupportBox(const ConvexShape& inShape, const Transform& inTransform)
{
    AABB box;
    for (int axis = 0; axis < 3; ++axis)
        for (const float sign : {-1.0f, 1.0f})
        {
            const Vec3 direction = sign * Vec3::Unit(axis);
            const Vec3 local = inShape.GetSupport(inTransform.mRotation.conjugate() * direction);
            box.Encapsulate(AABB(inTransform * local, inTransform * local));
        }
    return box;
}

const Quat cTurns[] = {Quat::Identity(), Quat(Eigen::AngleAxisf(0.785398f, Vec3::UnitZ())),
                       Quat(Eigen::AngleAxisf(1.1f, Vec3(1, 2, 3).normalized())),
                       Quat(Eigen::AngleAxisf(2.9f, Vec3(-3, 1, 0.5f).normalized()))};
} // namespace

TEST(SphereShapeTest, WorldBoundsAreTheCentreGrownByTheRadiusAtAnyTurn)
{
    const auto sphere = SphereShape::Create(0.3f).Value();
    for (const Quat& turn : cTurns)
    {
        const AABB box = sphere->GetWorldBounds({Vec3(1, 2, 3), turn});
        ExpectVecNear(box.mMin, Vec3(0.7f, 1.7f, 2.7f), 1e-6f);
        ExpectVecNear(box.mMax, Vec3(1.3f, 2.3f, 3.3f), 1e-6f);
    }
}

TEST(CapsuleShapeTest, WorldBoundsAreTightAtAnyTurn)
{
    // The turned local box would be up to 1.7 times as wide; the support points bound the capsule exactly
    const auto capsule = CapsuleShape::Create(0.4f, 0.1f).Value();
    for (const Quat& turn : cTurns)
    {
        const Transform at{Vec3(-2, 0.5f, 4), turn};
        const AABB box = capsule->GetWorldBounds(at);
        const AABB tight = SupportBox(*capsule, at);
        ExpectVecNear(box.mMin, tight.mMin, 1e-5f);
        ExpectVecNear(box.mMax, tight.mMax, 1e-5f);
    }
    // A capsule made around Create keeps its inverted box, which bodies and queries refuse
    const CapsuleShape inverted(-5.0f, 1.0f);
    EXPECT_TRUE(inverted.GetWorldBounds({Vec3::Zero(), cTurns[2]}).IsEmpty());
}
