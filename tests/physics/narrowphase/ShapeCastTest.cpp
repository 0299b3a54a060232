// CastShapeAgainst: where a translated shape first meets another. Exact cases against hand-worked fractions,
// the cases it must not stop (leaving or sliding along an overlapped shape), the iteration limit, and two
// properties over random casts: a sphere against a box, checked against the exact distance along the path,
// and any convex pair, checked to never end inside the other shape nor pass through it.

#include "narrowphase/ShapeCast.h"

#include "cairn/physics/narrowphase/CollideShapes.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/CapsuleShape.h"
#include "cairn/physics/shapes/HeightFieldShape.h"
#include "cairn/physics/shapes/SphereShape.h"
#include "cairn/physics/shapes/TriangleMeshShape.h"

#include <array>
#include <cmath>
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>
#include <vector>

namespace cairn::shape_cast_test // Named: a unity build puts this beside other tests' anonymous helpers
{
using namespace cairn::physics;
namespace
{
constexpr float cTolerance = ShapeCastSettings{}.mTolerance;

std::shared_ptr<const TriangleMeshShape> MakeQuad(float inHalfSize)
{
    const float s = inHalfSize;
    const std::vector<Vec3> vertices = {Vec3(-s, 0, -s), Vec3(s, 0, -s), Vec3(-s, 0, s), Vec3(s, 0, s)};
    const std::vector<std::array<uint32_t, 3>> triangles = {{0, 2, 1}, {1, 2, 3}};
    return TriangleMeshShape::Create(vertices, triangles).Value();
}

std::optional<ShapeCastHit> Cast(const Shape& inA, const Vec3& inStart, const Vec3& inDisplacement,
                                 const Shape& inB, const Transform& inTransformB = {},
                                 const ShapeCastSettings& inSettings = {},
                                 const Quat& inRotationA = Quat::Identity())
{
    return CastShapeAgainst(inA, {inStart, inRotationA}, inDisplacement, inB, inTransformB, inSettings);
}

/// The deepest penetration of A at inTransformA into B (negative: the gap), or -inMaxGap when farther apart.
float Penetration(const Shape& inA, const Transform& inTransformA, const Shape& inB,
                  const Transform& inTransformB, float inMaxGap)
{
    CollideSettings settings;
    settings.mMaxSeparation = inMaxGap;
    float deepest = -inMaxGap;
    CollideShapes(inA, inTransformA, inB, inTransformB, settings,
                  [&](const ContactManifold& inManifold)
                  {
                      for (int i = 0; i < inManifold.mNumPoints; ++i)
                          deepest = std::max(deepest, inManifold.mPoints[i].mPenetration);
                  });
    return deepest;
}

TEST(ShapeCastTest, ASphereDroppedOnABoxStopsAtTheTouch)
{
    const SphereShape sphere(0.5f);
    const BoxShape box(Vec3(2, 1, 2));
    const std::optional<ShapeCastHit> hit = Cast(sphere, Vec3(0, 5, 0), Vec3(0, -10, 0), box);
    ASSERT_TRUE(hit.has_value());
    // The centre touches at y = 1.5: 3.5 m of the 10, short by at most the tolerance
    EXPECT_LE(hit->mFraction, 0.35f + 1.0e-6f);
    EXPECT_GE(hit->mFraction, 0.35f - cTolerance / 10.0f - 1.0e-6f);
    EXPECT_NEAR(hit->mManifold.mNormal.y(), -1.0f, 1.0e-5f) << "from the sphere towards the box";
    const ContactPoint& point = hit->mManifold.mPoints[hit->mDeepestPoint];
    EXPECT_NEAR(point.mPositionOnB.y(), 1.0f, 1.0e-4f);
    EXPECT_NEAR(point.mPositionOnB.x(), 0.0f, 1.0e-4f);
}

TEST(ShapeCastTest, ARotatedBoxOntoAMeshAndAHeightField)
{
    // A cube turned 45 degrees about z stands on an edge 0.5 * sqrt(2) below its centre
    const BoxShape cube(Vec3(0.5f, 0.5f, 0.5f));
    const Quat turned(Eigen::AngleAxisf(float(M_PI) / 4.0f, Vec3::UnitZ()));
    const float edge = 0.5f * std::sqrt(2.0f);
    const std::shared_ptr<const TriangleMeshShape> quad = MakeQuad(10.0f);
    const std::optional<ShapeCastHit> onMesh =
        Cast(cube, Vec3(0.3f, 3, 0.2f), Vec3(0, -3, 0), *quad, {}, {}, turned);
    ASSERT_TRUE(onMesh.has_value());
    EXPECT_NEAR(onMesh->mFraction, (3.0f - edge) / 3.0f, cTolerance);
    EXPECT_NEAR(onMesh->mManifold.mNormal.y(), -1.0f, 1.0e-4f);

    const std::vector<float> heights(9 * 9, 0.25f);
    const std::shared_ptr<const HeightFieldShape> field =
        HeightFieldShape::Create(9, 9, 1.0f, heights).Value();
    const std::optional<ShapeCastHit> onField = Cast(cube, Vec3(0.3f, 3, 0.2f), Vec3(0, -3, 0), *field,
                                                     {Vec3(-4, 0, -4), Quat::Identity()}, {}, turned);
    ASSERT_TRUE(onField.has_value());
    EXPECT_NEAR(onField->mFraction, (3.0f - 0.25f - edge) / 3.0f, cTolerance);
}

TEST(ShapeCastTest, AFastThinCastDoesNotPassThroughAThinMesh)
{
    const SphereShape pellet(0.01f);
    const std::shared_ptr<const TriangleMeshShape> quad = MakeQuad(1.0f);
    const std::optional<ShapeCastHit> hit = Cast(pellet, Vec3(0.2f, 500, 0.1f), Vec3(0, -1000, 0), *quad);
    ASSERT_TRUE(hit.has_value());
    EXPECT_NEAR(hit->mFraction * 1000.0f, 500.0f - 0.01f, 1.0e-2f);
}

TEST(ShapeCastTest, LeavingOrSlidingAlongAnOverlappedShapeIsNotStopped)
{
    const SphereShape sphere(0.5f);
    const BoxShape box(Vec3(2, 1, 2));
    const Vec3 sunk(0, 1.4f, 0); // 0.1 m into the top face
    EXPECT_FALSE(Cast(sphere, sunk, Vec3(0, 5, 0), box).has_value()) << "leaving";
    EXPECT_FALSE(Cast(sphere, sunk, Vec3(1, 0, 0), box).has_value()) << "sliding along the face";
    const std::optional<ShapeCastHit> deeper = Cast(sphere, sunk, Vec3(0, -1, 0), box);
    ASSERT_TRUE(deeper.has_value()) << "moving deeper";
    EXPECT_EQ(deeper->mFraction, 0.0f);
    EXPECT_NEAR(deeper->mManifold.mPoints[deeper->mDeepestPoint].mPenetration, 0.1f, 1.0e-4f);
    // Sliding along it into a wall that stands on it is stopped by the wall
    const BoxShape wall(Vec3(0.1f, 2, 2));
    const std::optional<ShapeCastHit> atWall =
        Cast(sphere, Vec3(0, 0, 0), Vec3(2, 0, 0), wall, {Vec3(1.6f, 0, 0), Quat::Identity()});
    ASSERT_TRUE(atWall.has_value());
    EXPECT_NEAR(atWall->mFraction, 0.5f, cTolerance);
}

// A flat quad rising along x (y = x / 2, x and z in [0, 2]) of two triangles whose shared diagonal, from
// (2, 1, 0) to (0, 0, 2), is an internal edge. The sphere is off the quad's far corner, a little above its
// plane extended: of the first triangle its nearest feature is that diagonal, and the face-normal rule there
// would take the depth below the plane, 0.32 m, as a contact the sphere is not in
TEST(ShapeCastTest, AShapeBesideAMeshIsNotStoppedByATrianglesPlane)
{
    const std::vector<Vec3> vertices = {Vec3(0, 0, 0), Vec3(0, 0, 2), Vec3(2, 1, 0), Vec3(2, 1, 2)};
    const std::vector<std::array<uint32_t, 3>> triangles = {{0, 1, 2}, {2, 1, 3}};
    const std::shared_ptr<const TriangleMeshShape> quad =
        TriangleMeshShape::Create(vertices, triangles).Value();
    const SphereShape sphere(0.5f);
    for (const Vec3& beside : {Vec3(2.5f, 1.45f, 2.5f), Vec3(4.0f, 2.2f, 4.0f)})
    {
        EXPECT_FALSE(Cast(sphere, beside, Vec3(3, 0, 3), *quad).has_value())
            << "moving away, from x " << beside.x();
        EXPECT_FALSE(Cast(sphere, beside, Vec3(3, 1.5f, 0), *quad).has_value())
            << "along the plane, from x " << beside.x();
    }
    // Dropped onto the quad: the centre stops the radius over the plane
    const std::optional<ShapeCastHit> dropped = Cast(sphere, Vec3(1, 4, 1), Vec3(0, -8, 0), *quad);
    ASSERT_TRUE(dropped.has_value());
    const float touchY = 0.5f + 0.5f / std::cos(std::atan(0.5f));
    EXPECT_NEAR(4.0f - 8.0f * dropped->mFraction, touchY, 1.0e-3f);
}

TEST(ShapeCastTest, AZeroDisplacementReportsATouchAtTheStart)
{
    const SphereShape sphere(0.5f);
    const BoxShape box(Vec3(2, 1, 2));
    const std::optional<ShapeCastHit> overlapping = Cast(sphere, Vec3(0, 1.4f, 0), Vec3::Zero(), box);
    ASSERT_TRUE(overlapping.has_value());
    EXPECT_EQ(overlapping->mFraction, 0.0f);
    EXPECT_FALSE(Cast(sphere, Vec3(0, 1.6f, 0), Vec3::Zero(), box).has_value());
}

TEST(ShapeCastTest, ACastPassingBesideAShapeMissesIt)
{
    const SphereShape sphere(0.5f);
    const BoxShape box(Vec3(1, 1, 1));
    // The sphere's side passes 1 mm beside the box's +x face, then 1 mm into it
    EXPECT_FALSE(Cast(sphere, Vec3(1.501f, 5, 0), Vec3(0, -10, 0), box).has_value());
    const std::optional<ShapeCastHit> grazing = Cast(sphere, Vec3(1.499f, 5, 0), Vec3(0, -10, 0), box);
    ASSERT_TRUE(grazing.has_value());
    EXPECT_GT(grazing->mFraction, 0.3f);
    EXPECT_LT(grazing->mFraction, 0.4f);
    // Beyond the displacement's end
    EXPECT_FALSE(Cast(sphere, Vec3(0, 5, 0), Vec3(0, -3.4f, 0), box).has_value());
    ShapeCastSettings shorter;
    shorter.mMaxFraction = 0.3f;
    EXPECT_FALSE(Cast(sphere, Vec3(0, 5, 0), Vec3(0, -10, 0), box, {}, shorter).has_value());
}

TEST(ShapeCastTest, OutOfIterationsItStopsShortNeverPast)
{
    // A sphere passing over a box's top edge, 0.3 m above it: each advance along the turning closest-point
    // normal falls short, so the touch takes several. It touches where its centre is 0.5 m from the edge
    const SphereShape sphere(0.5f);
    const BoxShape box(Vec3(1, 1, 1));
    const Vec3 start(-4, 1.3f, 0);
    const Vec3 displacement(8, 0, 0);
    const float touch = (3.0f - std::sqrt(0.25f - 0.09f)) / 8.0f;
    const std::optional<ShapeCastHit> exact = Cast(sphere, start, displacement, box);
    ASSERT_TRUE(exact.has_value());
    EXPECT_NEAR(exact->mFraction, touch, 1.0e-3f);
    ShapeCastSettings once;
    once.mMaxIterations = 1;
    const std::optional<ShapeCastHit> cut = Cast(sphere, start, displacement, box, {}, once);
    ASSERT_TRUE(cut.has_value()) << "a cast that runs out of advances is a hit where it stopped";
    EXPECT_LT(cut->mFraction, exact->mFraction - 1.0e-3f);
    EXPECT_LT(Penetration(sphere, {start + cut->mFraction * displacement, Quat::Identity()}, box, {}, 1.0f),
              0.0f);
}

/// The distance from inPoint to the box of half extents inHalf at inBox.
float DistanceToBox(const Vec3& inPoint, const Vec3& inHalf, const Transform& inBox)
{
    const Vec3 local = inBox.InverseTransformPoint(inPoint);
    return (local - local.cwiseMax(-inHalf).cwiseMin(inHalf)).norm();
}

/// The properties' values: a vector whose coordinates are steps of a 10,000-step grid over [inLow, inHigh],
/// and a rotation about the axis such a vector of [-1, 1] gives, by inAngle hundredths of a radian.
Vec3 GridVec(int inX, int inY, int inZ, float inLow, float inHigh)
{
    const auto coordinate = [&](int inStep) { return inLow + (inHigh - inLow) * float(inStep) / 10000.0f; };
    return Vec3(coordinate(inX), coordinate(inY), coordinate(inZ));
}
Quat GridRotation(int inX, int inY, int inZ, int inAngle)
{
    const Vec3 axis = GridVec(inX, inY, inZ, -1.0f, 1.0f);
    return axis.norm() < 1.0e-3f ? Quat::Identity()
                                 : Quat(Eigen::AngleAxisf(float(inAngle) / 100.0f, axis.normalized()));
}

int GenStep()
{
    return *rc::gen::inRange(0, 10001);
}
Vec3 GenVec(float inLow, float inHigh)
{
    const int x = GenStep(), y = GenStep(), z = GenStep();
    return GridVec(x, y, z, inLow, inHigh);
}
Quat GenRotation()
{
    const int x = GenStep(), y = GenStep(), z = GenStep();
    return GridRotation(x, y, z, *rc::gen::inRange(0, 629));
}

/// A cast of A from inStart along inDisplacement against B at inTransformB that starts clear: true when it
/// ends no deeper than inSlack in B, and a cast reported clear overlaps B by no more than that anywhere on
/// the way (400 samples).
bool StopsAtTheTouch(const Shape& inA, const Quat& inRotationA, const Vec3& inStart,
                     const Vec3& inDisplacement, const Shape& inB, const Transform& inTransformB,
                     float inSlack, float* outFraction = nullptr)
{
    const auto depthAt = [&](float inT) {
        return Penetration(inA, {inStart + inT * inDisplacement, inRotationA}, inB, inTransformB, 0.01f);
    };
    const std::optional<ShapeCastHit> hit =
        Cast(inA, inStart, inDisplacement, inB, inTransformB, {}, inRotationA);
    if (outFraction != nullptr) *outFraction = hit.has_value() ? hit->mFraction : 1.0f;
    if (hit.has_value()) return depthAt(hit->mFraction) <= inSlack;
    for (int i = 0; i <= 400; ++i)
        if (depthAt(float(i) / 400.0f) > inSlack) return false;
    return true;
}

// Casts the properties below once found going past the touch, each by another way: a box's clipped face
// points claiming a wider gap than the boxes have (the advance then went past the touch, or right through the
// other box), advances landing inside where the only manifold faces away (caught by the bisection), and a box
// whose clipped points beside a capsule claimed clearance while the capsule's core was already inside it
TEST(ShapeCastTest, CastsThatOnceWentPastTheTouchStopAtIt)
{
    struct Case
    {
        Vec3 mHalfA;
        ShapeRef mB;
        Quat mRotationA;
        Transform mTransformB;
        Vec3 mStart, mDisplacement;
    };
    const ShapeRef capsule = CapsuleShape::Create(0.23f, 0.43f).Value();
    const Case cases[] = {
        {GridVec(5554, 5874, 1654, 0.1f, 1.0f),
         BoxShape::Create(GridVec(4266, 8275, 636, 0.1f, 1.0f)).Value(),
         GridRotation(5380, 5244, 6410, 173),
         {GridVec(5698, 7719, 7510, -1, 1), GridRotation(7032, 618, 3370, 325)},
         GridVec(5302, 8038, 8002, -4, 4),
         GridVec(7757, 2184, 180, -8, 8)},
        {GridVec(0, 0, 5579, 0.1f, 1.0f),
         BoxShape::Create(GridVec(6010, 1698, 5365, 0.1f, 1.0f)).Value(),
         GridRotation(65, 3447, 4806, 342),
         {GridVec(1369, 1770, 6596, -1, 1), GridRotation(0, 0, 2853, 127)},
         GridVec(1541, 6641, 3576, -4, 4),
         GridVec(6952, 2260, 5976, -8, 8)},
        {GridVec(4765, 1020, 6336, 0.1f, 1.0f),
         BoxShape::Create(GridVec(7016, 2716, 5792, 0.1f, 1.0f)).Value(),
         GridRotation(5613, 4443, 0, 92),
         {GridVec(595, 1321, 126, -1, 1), GridRotation(0, 4493, 2697, 221)},
         GridVec(6137, 6855, 1336, -4, 4),
         GridVec(2578, 3870, 5992, -8, 8)},
        {GridVec(2976, 3850, 1324, 0.1f, 1.0f),
         BoxShape::Create(GridVec(1825, 1065, 4311, 0.1f, 1.0f)).Value(),
         GridRotation(4244, 6638, 0, 27),
         {GridVec(3001, 2470, 2735, -1, 1), GridRotation(4619, 3292, 632, 291)},
         GridVec(4364, 5467, 5821, -4, 4),
         GridVec(5421, 1287, 73, -8, 8)},
        {GridVec(0, 371, 4044, 0.1f, 1.0f),
         capsule,
         GridRotation(5545, 6314, 2528, 125),
         {GridVec(5571, 4922, 9177, -1, 1), GridRotation(8608, 4356, 3910, 127)},
         GridVec(5487, 1659, 5424, -4, 4),
         GridVec(5002, 8836, 7227, -8, 8)},
    };
    for (size_t i = 0; i < std::size(cases); ++i)
    {
        const Case& c = cases[i];
        const BoxShape a(c.mHalfA);
        float fraction = 0.0f;
        EXPECT_TRUE(StopsAtTheTouch(a, c.mRotationA, c.mStart, c.mDisplacement, *c.mB, c.mTransformB, 1.0e-4f,
                                    &fraction))
            << "case " << i << ", stopped at " << fraction;
        EXPECT_LT(fraction, 1.0f) << "case " << i << ": every one of them meets B";
    }
}

// The sphere's centre path meets the box grown by the radius first where the distance to the box (convex
// along a line) first falls to the radius
RC_GTEST_PROP(ShapeCastProperty, ASphereAgainstABoxStopsWhereTheExactDistanceReachesTheRadius, ())
{
    const float radius = *rc::gen::inRange(5, 101) / 100.0f;
    const Vec3 half = GenVec(0.05f, 1.5f);
    const Transform box{GenVec(-1, 1), GenRotation()};
    const Vec3 start = GenVec(-4, 4);
    const Vec3 displacement = GenVec(-8, 8);
    const auto gap = [&](float inT) { return DistanceToBox(start + inT * displacement, half, box) - radius; };
    RC_PRE(gap(0.0f) > 0.01f);
    // The least gap along the path (ternary search: the gap is convex in t)
    float low = 0.0f, high = 1.0f;
    for (int i = 0; i < 100; ++i)
    {
        const float a = low + (high - low) / 3.0f, b = high - (high - low) / 3.0f;
        (gap(a) < gap(b) ? high : low) = gap(a) < gap(b) ? b : a;
    }
    const float closest = 0.5f * (low + high);
    const SphereShape sphere(radius);
    const BoxShape boxShape(half);
    const std::optional<ShapeCastHit> hit = Cast(sphere, start, displacement, boxShape, box);
    const float slack = 2.0e-5f * (1.0f + displacement.norm()); // Float steps of the distances involved
    if (!hit.has_value())
    {
        RC_ASSERT(gap(closest) > -slack);
        return;
    }
    // Never past the touch, and touching to within the tolerance there
    RC_ASSERT(gap(hit->mFraction) > -slack);
    RC_ASSERT(gap(hit->mFraction) <= cTolerance + slack);
    // The first touch: bisect the first crossing on [0, closest]
    float before = 0.0f, after = closest;
    for (int i = 0; i < 60; ++i)
    {
        const float mid = 0.5f * (before + after);
        (gap(mid) > 0.0f ? before : after) = mid;
    }
    RC_ASSERT(hit->mFraction <= after + slack);
}

// Whatever the pair, the cast ends outside the other shape, and a cast reported clear never overlaps it on
// the way
RC_GTEST_PROP(ShapeCastProperty, AnyConvexPairNeverEndsInsideNorPassesThrough, ())
{
    const auto genShape = [](int inKind) -> ShapeRef
    {
        const int size = *rc::gen::inRange(10, 81);
        switch (inKind)
        {
        case 0:
            return SphereShape::Create(float(size) / 100.0f).Value();
        case 1:
            return BoxShape::Create(GenVec(0.1f, 1.0f)).Value();
        default:
            return CapsuleShape::Create(float(*rc::gen::inRange(10, 51)) / 100.0f, float(size) / 100.0f)
                .Value();
        }
    };
    const ShapeRef a = genShape(*rc::gen::inRange(0, 3));
    const ShapeRef b = genShape(*rc::gen::inRange(0, 3));
    const Quat rotationA = GenRotation();
    const Vec3 positionB = GenVec(-1, 1);
    const Transform transformB{positionB, GenRotation()};
    const Vec3 start = GenVec(-4, 4);
    const Vec3 displacement = GenVec(-8, 8);
    RC_PRE(Penetration(*a, {start, rotationA}, *b, transformB, 0.01f) < -0.005f);
    RC_ASSERT(StopsAtTheTouch(*a, rotationA, start, displacement, *b, transformB, 1.0e-4f));
}

} // namespace
} // namespace cairn::shape_cast_test
