#include "cairn/physics/shapes/ConvexHullShape.h"

#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/SphereShape.h"

#include <gtest/gtest.h>
#include <limits>
#include <random>

using namespace cairn;
using namespace cairn::physics;

namespace
{

std::vector<Vec3> BoxCorners(const Vec3& inHalfExtent, const Vec3& inOffset = Vec3::Zero())
{
    std::vector<Vec3> corners;
    for (int i = 0; i < 8; ++i)
        corners.push_back(inOffset + Vec3(i & 1 ? 1.0f : -1.0f, i & 2 ? 1.0f : -1.0f, i & 4 ? 1.0f : -1.0f)
                                         .cwiseProduct(inHalfExtent));
    return corners;
}

std::shared_ptr<const ConvexHullShape> MakeHull(const std::vector<Vec3>& inPoints)
{
    auto result = ConvexHullShape::Create(inPoints);
    EXPECT_TRUE(result.IsOk()) << (result.IsOk() ? "" : result.GetError().mMessage);
    return result.IsOk() ? result.Value() : nullptr;
}

/// Checks the invariants every hull must satisfy: planar CCW faces, all vertices behind every face, closed.
void ExpectValidHull(const ConvexHullShape& inHull)
{
    const float tolerance = 1e-4f * inHull.GetLocalBounds().Size().norm();
    for (const ConvexHullShape::Face& face : inHull.GetFaces())
    {
        ASSERT_GE(face.mIndices.size(), 3u);
        EXPECT_NEAR(face.mNormal.norm(), 1.0f, 1e-5f);
        for (uint32_t index : face.mIndices)
            EXPECT_NEAR(face.mNormal.dot(inHull.GetVertices()[index]), face.mPlaneConstant, tolerance);
        for (const Vec3& v : inHull.GetVertices())
            EXPECT_LE(face.mNormal.dot(v), face.mPlaneConstant + tolerance);
        // Counter-clockwise seen from outside: consecutive edges turn around the outward normal
        for (size_t i = 0; i < face.mIndices.size(); ++i)
        {
            const Vec3& a = inHull.GetVertices()[face.mIndices[i]];
            const Vec3& b = inHull.GetVertices()[face.mIndices[(i + 1) % face.mIndices.size()]];
            const Vec3& c = inHull.GetVertices()[face.mIndices[(i + 2) % face.mIndices.size()]];
            EXPECT_GE((b - a).cross(c - b).dot(face.mNormal), -tolerance * tolerance);
        }
    }
    // Euler characteristic of a closed convex polyhedron: V - E + F = 2
    size_t edgeUses = 0;
    for (const ConvexHullShape::Face& face : inHull.GetFaces())
        edgeUses += face.mIndices.size();
    EXPECT_EQ(int(inHull.GetVertices().size()) - int(edgeUses / 2) + int(inHull.GetFaces().size()), 2);
}

} // namespace

TEST(ConvexHullShapeTest, RejectsBadInput)
{
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();

    auto tooFew = ConvexHullShape::Create(std::vector<Vec3>{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)});
    ASSERT_FALSE(tooFew.IsOk());
    EXPECT_EQ(tooFew.GetError().mCode, ErrorCode::DegenerateShape);
    EXPECT_NE(tooFew.GetError().mMessage.find("at least 4"), std::string::npos);

    std::vector<Vec3> withNaN = BoxCorners(Vec3::Ones());
    withNaN[3].y() = nan;
    EXPECT_EQ(ConvexHullShape::Create(withNaN).GetError().mCode, ErrorCode::InvalidArgument);
    std::vector<Vec3> withInf = BoxCorners(Vec3::Ones());
    withInf[5].x() = inf;
    EXPECT_EQ(ConvexHullShape::Create(withInf).GetError().mCode, ErrorCode::InvalidArgument);

    const std::vector<Vec3> coincident(10, Vec3(1, 2, 3));
    auto c = ConvexHullShape::Create(coincident);
    ASSERT_FALSE(c.IsOk());
    EXPECT_EQ(c.GetError().mCode, ErrorCode::DegenerateShape);
    EXPECT_NE(c.GetError().mMessage.find("coincide"), std::string::npos);

    std::vector<Vec3> collinear;
    for (int i = 0; i < 10; ++i)
        collinear.push_back(Vec3(1, 2, 3) * float(i));
    auto l = ConvexHullShape::Create(collinear);
    ASSERT_FALSE(l.IsOk());
    EXPECT_EQ(l.GetError().mCode, ErrorCode::DegenerateShape);
    EXPECT_NE(l.GetError().mMessage.find("collinear"), std::string::npos);

    // A rotated plane (not axis-aligned) with tiny noise far below the relative tolerance
    std::vector<Vec3> coplanar;
    const Quat rotation(Eigen::AngleAxisf(0.7f, Vec3(1, 2, 3).normalized()));
    for (int i = 0; i < 20; ++i)
        coplanar.push_back(rotation * Vec3(float(i % 5) * 100.0f, float(i / 5) * 100.0f, (i % 2) * 1e-4f));
    auto p = ConvexHullShape::Create(coplanar);
    ASSERT_FALSE(p.IsOk());
    EXPECT_EQ(p.GetError().mCode, ErrorCode::DegenerateShape);
    EXPECT_NE(p.GetError().mMessage.find("coplanar"), std::string::npos);
}

// The build grows faster than the point count (100,000 points on a sphere took 38 s): a cloud over the limit
// is refused at once, one at the limit is built
TEST(ConvexHullShapeTest, MorePointsThanTheLimitAreRefused)
{
    std::vector<Vec3> points;
    for (size_t i = 0; i <= ConvexHullShape::cMaxInputPoints; ++i)
        points.push_back(Vec3(float(i % 7), float(i % 11), float(i % 13))); // Inside a 6 x 10 x 12 box
    const auto tooMany = ConvexHullShape::Create(points);
    ASSERT_FALSE(tooMany);
    EXPECT_EQ(tooMany.GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_NE(tooMany.GetError().mMessage.find("16385 points"), std::string::npos)
        << tooMany.GetError().mMessage;
    points.pop_back();
    EXPECT_TRUE(ConvexHullShape::Create(points));
}

TEST(ConvexHullShapeTest, BoxCornersMatchBox)
{
    const Vec3 half(0.5f, 1.0f, 2.0f);
    const Vec3 offset(3, -2, 1);
    std::vector<Vec3> points = BoxCorners(half, offset);
    // Interior points and points on faces/edges must be dropped without changing the hull
    points.push_back(offset);
    points.push_back(offset + Vec3(0.1f, 0.2f, -0.3f));
    points.push_back(offset + Vec3(0.5f, 0.0f, 0.0f));
    points.push_back(offset + Vec3(0.5f, 1.0f, 0.0f));
    const auto hull = MakeHull(points);
    ASSERT_NE(hull, nullptr);
    EXPECT_EQ(hull->GetVertices().size(), 8u);
    EXPECT_EQ(hull->GetFaces().size(), 6u); // Coplanar triangles merged into quads
    for (const ConvexHullShape::Face& face : hull->GetFaces())
        EXPECT_EQ(face.mIndices.size(), 4u);
    ExpectValidHull(*hull);

    const MassProperties expected = BoxShape::Create(half).Value()->GetMassProperties(2.0f);
    const MassProperties actual = hull->GetMassProperties(2.0f);
    EXPECT_NEAR(actual.mMass, expected.mMass, 1e-4f * expected.mMass);
    EXPECT_NEAR((actual.mCenterOfMass - offset).norm(), 0.0f, 1e-5f);
    EXPECT_LT((actual.mInertia - expected.mInertia).norm(), 1e-4f * expected.mInertia.norm());

    EXPECT_TRUE(hull->GetLocalBounds().mMin.isApprox(offset - half));
    EXPECT_TRUE(hull->GetLocalBounds().mMax.isApprox(offset + half));
}

TEST(ConvexHullShapeTest, RotatedBoxInertiaRotates)
{
    const Vec3 half(0.5f, 1.0f, 2.0f);
    const Quat rotation(Eigen::AngleAxisf(0.6f, Vec3(1, 1, 0).normalized()));
    std::vector<Vec3> points = BoxCorners(half);
    for (Vec3& p : points)
        p = rotation * p;
    const auto hull = MakeHull(points);
    ASSERT_NE(hull, nullptr);
    EXPECT_EQ(hull->GetFaces().size(), 6u);
    const Mat3 r = rotation.toRotationMatrix();
    const Mat3 expected =
        r * BoxShape::Create(half).Value()->GetMassProperties(1.0f).mInertia * r.transpose();
    EXPECT_LT((hull->GetMassProperties(1.0f).mInertia - expected).norm(), 1e-4f * expected.norm());
}

TEST(ConvexHullShapeTest, SpherePointsApproachSphere)
{
    std::mt19937 rng(42);
    std::normal_distribution<float> gauss;
    std::uniform_real_distribution<float> uniform(-0.5f, 0.5f);
    std::vector<Vec3> points;
    for (int i = 0; i < 2000; ++i)
        points.push_back(Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized() * 2.0f);
    for (int i = 0; i < 500; ++i) // Interior points are dropped
        points.push_back(Vec3(uniform(rng), uniform(rng), uniform(rng)));
    const auto hull = MakeHull(points);
    ASSERT_NE(hull, nullptr);
    EXPECT_LE(hull->GetVertices().size(), 2000u);
    EXPECT_GT(hull->GetVertices().size(), 1900u);
    for (const Vec3& v : hull->GetVertices())
        EXPECT_NEAR(v.norm(), 2.0f, 1e-4f);
    ExpectValidHull(*hull);

    const MassProperties sphere = SphereShape::Create(2.0f).Value()->GetMassProperties(1.0f);
    const MassProperties props = hull->GetMassProperties(1.0f);
    EXPECT_NEAR(props.mMass, sphere.mMass, 0.02f * sphere.mMass);
    EXPECT_LT(props.mCenterOfMass.norm(), 0.02f);
    for (int i = 0; i < 3; ++i)
        EXPECT_NEAR(props.mInertia(i, i), sphere.mInertia(i, i), 0.04f * sphere.mInertia(i, i));
    EXPECT_LT(std::abs(props.mInertia(0, 1)), 0.01f * sphere.mInertia(0, 0));
}

TEST(ConvexHullShapeTest, TetrahedronMassProperties)
{
    // Unit right tetrahedron: volume 1/6, centroid (1/4, 1/4, 1/4), known products of inertia
    const auto hull = MakeHull({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)});
    ASSERT_NE(hull, nullptr);
    ExpectValidHull(*hull);
    const MassProperties props = hull->GetMassProperties(6.0f);
    EXPECT_NEAR(props.mMass, 1.0f, 1e-5f);
    EXPECT_TRUE(props.mCenterOfMass.isApprox(Vec3::Constant(0.25f), 1e-5f));
    // Per unit mass, E[x^2] = 1/10 and E[xy] = 1/20 about the origin, so about the centroid
    // var(x) = 1/10 - 1/16 = 3/80 and cov(x, y) = 1/20 - 1/16 = -1/80: Ixx = 2 * 3/80, Ixy = -cov = 1/80
    EXPECT_NEAR(props.mInertia(0, 0), 6.0f / 80.0f, 1e-5f);
    EXPECT_NEAR(props.mInertia(0, 1), 1.0f / 80.0f, 1e-5f);
}

TEST(ConvexHullShapeTest, RayCast)
{
    const auto hull = MakeHull(BoxCorners(Vec3(1, 2, 3)));
    ASSERT_NE(hull, nullptr);

    RayHit hit;
    ASSERT_TRUE(hull->CastRay({Vec3(0, 10, 0), Vec3(0, -10, 0)}, hit));
    EXPECT_NEAR(hit.mFraction, 0.8f, 1e-6f);
    EXPECT_TRUE(hit.mNormal.isApprox(Vec3(0, 1, 0), 1e-6f));

    RayHit oblique;
    ASSERT_TRUE(hull->CastRay({Vec3(-3, 0.5f, 0.5f), Vec3(4, 1, 0)}, oblique));
    EXPECT_NEAR(oblique.mFraction, 0.5f, 1e-6f);
    EXPECT_TRUE(oblique.mNormal.isApprox(Vec3(-1, 0, 0), 1e-6f));

    RayHit miss;
    EXPECT_FALSE(hull->CastRay({Vec3(-3, 2.1f, 0), Vec3(6, 0, 0)}, miss));
    EXPECT_FALSE(hull->CastRay({Vec3(-3, 0, 0), Vec3(1, 0, 0)}, miss));
    EXPECT_FALSE(hull->CastRay({Vec3(-3, 0, 0), Vec3::Zero()}, miss));
    EXPECT_FALSE(hull->CastRay({Vec3(-3, 0, 0), Vec3(-1, 0, 0)}, miss));

    RayHit inside;
    ASSERT_TRUE(hull->CastRay({Vec3(0.5f, 0, 0), Vec3(0, 3, 4)}, inside));
    EXPECT_EQ(inside.mFraction, 0.0f);
    EXPECT_TRUE(inside.mNormal.isApprox(Vec3(0, -0.6f, -0.8f), 1e-6f));

    RayHit insideZero;
    ASSERT_TRUE(hull->CastRay({Vec3(0.5f, 0, 0), Vec3::Zero()}, insideZero));
    EXPECT_TRUE(IsFinite(insideZero.mNormal));

    // Random rays agree with the analytic box
    const auto box = BoxShape::Create(Vec3(1, 2, 3)).Value();
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> uniform(-6.0f, 6.0f);
    for (int i = 0; i < 500; ++i)
    {
        const RayCast ray{Vec3(uniform(rng), uniform(rng), uniform(rng)),
                          Vec3(uniform(rng), uniform(rng), uniform(rng))};
        RayHit boxHit, hullHit;
        const bool boxResult = box->CastRay(ray, boxHit);
        ASSERT_EQ(hull->CastRay(ray, hullHit), boxResult) << i;
        if (boxResult)
        {
            EXPECT_NEAR(hullHit.mFraction, boxHit.mFraction, 1e-5f);
            EXPECT_TRUE(hullHit.mNormal.isApprox(boxHit.mNormal, 1e-5f));
        }
    }
}

TEST(ConvexHullShapeTest, SupportAndSupportingFace)
{
    const auto hull = MakeHull(BoxCorners(Vec3(1, 2, 3)));
    ASSERT_NE(hull, nullptr);
    EXPECT_TRUE(hull->GetSupport(Vec3(1, -1, 1)).isApprox(Vec3(1, -2, 3)));
    EXPECT_TRUE(IsFinite(hull->GetSupport(Vec3::Zero())));

    SupportingFace face;
    hull->GetSupportingFace(Vec3(0.1f, -0.9f, 0.2f), face);
    ASSERT_EQ(face.mCount, 4);
    for (int i = 0; i < 4; ++i)
        EXPECT_FLOAT_EQ(face.mVertices[i].y(), -2.0f);
    const Vec3 n = (face.mVertices[1] - face.mVertices[0]).cross(face.mVertices[2] - face.mVertices[0]);
    EXPECT_LT(n.y(), 0.0f); // Counter-clockwise seen from outside (from -Y)

    // A 64-gon prism: its caps have more vertices than a supporting face holds; the face is an evenly
    // subsampled convex polygon on the cap
    std::vector<Vec3> prism;
    for (int i = 0; i < 64; ++i)
    {
        const float angle = 2.0f * cPi * float(i) / 64.0f;
        prism.push_back(Vec3(std::cos(angle), -1.0f, std::sin(angle)));
        prism.push_back(Vec3(std::cos(angle), 1.0f, std::sin(angle)));
    }
    const auto cylinder = MakeHull(prism);
    ASSERT_NE(cylinder, nullptr);
    EXPECT_EQ(cylinder->GetFaces().size(), 66u);
    ExpectValidHull(*cylinder);
    SupportingFace cap;
    cylinder->GetSupportingFace(Vec3(0, 1, 0), cap);
    ASSERT_EQ(cap.mCount, SupportingFace::cMaxVertices);
    AABB capBounds;
    for (int i = 0; i < cap.mCount; ++i)
    {
        EXPECT_FLOAT_EQ(cap.mVertices[i].y(), 1.0f);
        capBounds.Encapsulate(cap.mVertices[i]);
    }
    EXPECT_GT(capBounds.Size().x(), 1.9f); // Spans the whole cap
    EXPECT_GT(capBounds.Size().z(), 1.9f);
}

TEST(ConvexHullShapeTest, VisitTrianglesFanTriangulatesOutward)
{
    const auto hull = MakeHull(BoxCorners(Vec3(1, 2, 3), Vec3(5, 0, 0)));
    ASSERT_NE(hull, nullptr);
    int count = 0;
    hull->VisitTriangles(
        hull->GetLocalBounds(),
        [&](const Triangle& inTriangle)
        {
            const Vec3 n = (inTriangle.mV[1] - inTriangle.mV[0]).cross(inTriangle.mV[2] - inTriangle.mV[0]);
            const Vec3 centroid = (inTriangle.mV[0] + inTriangle.mV[1] + inTriangle.mV[2]) / 3.0f;
            EXPECT_GT(n.dot(centroid - Vec3(5, 0, 0)), 0.0f);
            ++count;
        });
    EXPECT_EQ(count, 12);
    int top = 0;
    hull->VisitTriangles(AABB(Vec3(4, 1.9f, -1), Vec3(6, 3, 1)), [&](const Triangle&) { ++top; });
    EXPECT_GE(top, 2);
    EXPECT_LT(top, 12);
}

TEST(ConvexHullShapeTest, GridCloudKeepsOnlyCorners)
{
    // 6 x 6 x 6 lattice: most points lie on faces or edges (coplanar / collinear with hull features)
    std::vector<Vec3> points;
    for (int x = 0; x < 6; ++x)
        for (int y = 0; y < 6; ++y)
            for (int z = 0; z < 6; ++z)
                points.push_back(Vec3(float(x), float(y), float(z)) * 0.2f);
    const auto hull = MakeHull(points);
    ASSERT_NE(hull, nullptr);
    EXPECT_EQ(hull->GetVertices().size(), 8u);
    EXPECT_EQ(hull->GetFaces().size(), 6u);
    ExpectValidHull(*hull);
    EXPECT_NEAR(hull->GetMassProperties(1.0f).mMass, 1.0f, 1e-4f);
}

TEST(ConvexHullShapeTest, FarFromOriginAndTinyScale)
{
    // The tolerance follows the cloud's size, so a millimetre hull works as well as a kilometre one, even
    // at 100 times its size from the origin (as far as float input keeps the corners distinct)
    for (const float scale : {1e-3f, 1.0f, 1e3f})
    {
        const Vec3 offset = Vec3(100.0f, -200.0f, 50.0f) * scale;
        std::vector<Vec3> points = BoxCorners(Vec3(1, 2, 3) * scale, offset);
        const auto hull = MakeHull(points);
        ASSERT_NE(hull, nullptr) << scale;
        EXPECT_EQ(hull->GetVertices().size(), 8u) << scale;
        EXPECT_EQ(hull->GetFaces().size(), 6u) << scale;
        const float volume = 48.0f * scale * scale * scale;
        EXPECT_NEAR(hull->GetMassProperties(1.0f).mMass, volume, 1e-3f * volume) << scale;
    }
}
