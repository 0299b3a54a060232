// Long rays past round shapes: a hit where the ray meets the shape, at the right distance to within a few
// float steps of the ray's length, and no hit where it passes beside. The textbook discriminant b^2 - a c
// lost the difference between the two in the rounding of its terms: a 10 km ray passing 2 m beside a
// half-metre sphere hit it, as did one past a capsule (shapes/RayQuadratic.h).

#include "cairn/physics/shapes/CapsuleShape.h"
#include "cairn/physics/shapes/SphereShape.h"

#include <cmath>
#include <gtest/gtest.h>

namespace cairn::test
{
using namespace cairn::physics;
namespace
{

constexpr float cRadius = 0.5f;
constexpr float cLengths[] = {1e2f, 1e3f, 1e4f, 1e5f, 1e6f, 3e6f};

/// A ray of inLength along +x, starting inLength / 2 before x = 0, at height inY and offset inZ
RayCast RayPast(float inLength, float inY, float inZ)
{
    return {Vec3(-0.5f * inLength, inY, inZ), Vec3(inLength, 0.0f, 0.0f)};
}

/// Checks a ray through a circle of radius inCircleRadius around the x = 0 axis at the ray's height: a hit
/// inside it, at the entry, and a miss outside
void ExpectRaysMeetTheCircle(const Shape& inShape, const char* inWhat, float inY, float inCircleRadius)
{
    for (float length : cLengths)
    {
        const float start = 0.5f * length;
        // A few float steps of the start's distance, the precision its fraction has; and 0.1 mm at short
        // range
        const float tolerance = 4.0f * std::ldexp(1.0f, std::ilogb(start) - 23) + 1e-4f;
        for (float offset : {0.0f, 0.6f * inCircleRadius, 0.95f * inCircleRadius})
        {
            RayHit hit;
            ASSERT_TRUE(inShape.CastRay(RayPast(length, inY, offset), hit))
                << inWhat << ": a " << length << " m ray through it, " << offset << " m off its axis";
            const float expected = start - std::sqrt(inCircleRadius * inCircleRadius - offset * offset);
            EXPECT_NEAR(hit.mFraction * length, expected, tolerance)
                << inWhat << ": the entry of a " << length << " m ray, " << offset << " m off its axis";
            EXPECT_TRUE(hit.mNormal.allFinite());
        }
        for (float offset : {1.05f * inCircleRadius, 1.2f * inCircleRadius, 2.0f, 4.0f})
        {
            RayHit hit;
            EXPECT_FALSE(inShape.CastRay(RayPast(length, inY, offset), hit))
                << inWhat << ": a " << length << " m ray passing " << offset << " m from its axis hit it";
        }
    }
}

TEST(ShapeRayPrecisionTest, SlantedRaysHitASphereWhereTheyMeetItAndMissItBeside)
{
    // Off every axis, so b / a and the closest point are rounded too. The origin's own rounding (a float step
    // of its distance) moves the ray by up to a few mm at 50 km: the offsets keep clear of the surface by
    // more
    const ShapeRef sphere = SphereShape::Create(cRadius).Value();
    const Vec3 along = Vec3(1.0f, 2.0f, 3.0f).normalized();
    const Vec3 across = along.cross(Vec3::UnitX()).normalized();
    for (float length : {1e2f, 1e3f, 1e4f, 1e5f})
    {
        const float start = 0.5f * length;
        const float tolerance = 8.0f * std::ldexp(1.0f, std::ilogb(start) - 23) + 1e-4f;
        for (float offset : {0.0f, 0.3f, 0.45f})
        {
            RayHit hit;
            ASSERT_TRUE(sphere->CastRay({-start * along + offset * across, length * along}, hit))
                << length << " m, " << offset << " m off";
            EXPECT_NEAR(hit.mFraction * length, start - std::sqrt(cRadius * cRadius - offset * offset),
                        tolerance)
                << length << " m, " << offset << " m off";
        }
        for (float offset : {0.55f, 0.6f, 2.0f})
        {
            RayHit hit;
            EXPECT_FALSE(sphere->CastRay({-start * along + offset * across, length * along}, hit))
                << length << " m, " << offset << " m off";
        }
    }
}

TEST(ShapeRayPrecisionTest, LongRaysHitASphereWhereTheyMeetItAndMissItBeside)
{
    const ShapeRef sphere = SphereShape::Create(cRadius).Value();
    ExpectRaysMeetTheCircle(*sphere, "sphere", 0.0f, cRadius);
}

TEST(ShapeRayPrecisionTest, LongRaysHitACapsuleWhereTheyMeetItAndMissItBeside)
{
    constexpr float cHalfHeight = 1.0f;
    const ShapeRef capsule = CapsuleShape::Create(cHalfHeight, cRadius).Value();
    // Through the side band, then through the top cap 0.2 m above its centre, where its circle is smaller
    ExpectRaysMeetTheCircle(*capsule, "capsule side", 0.0f, cRadius);
    ExpectRaysMeetTheCircle(*capsule, "capsule cap", cHalfHeight + 0.2f,
                            std::sqrt(cRadius * cRadius - 0.04f));
}

} // namespace
} // namespace cairn::test
