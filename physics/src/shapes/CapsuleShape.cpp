#include "cairn/physics/shapes/CapsuleShape.h"

#include "shapes/RayQuadratic.h"

#include <array>
#include <string>

namespace cairn::physics
{

namespace
{

/// Tessellation resolution: rings per hemisphere (pole to equator) and segments around the axis.
constexpr int cHemisphereStacks = 4;
constexpr int cSlices = 16;
constexpr int cMaxRings = 2 * (cHemisphereStacks + 1);

/// Below this |cos| between the direction and the axis, the capsule's side is the supporting feature.
constexpr float cSideFaceCos = 0.05f;

/// A horizontal circle of the tessellation.
struct Ring
{
    float mY;
    float mRadius;
};

/// Rings from the bottom pole to the top pole; returns how many were written.
int BuildRings(float inHalfHeight, float inRadius, std::array<Ring, cMaxRings>& outRings)
{
    int count = 0;
    for (int hemisphere = 0; hemisphere < 2; ++hemisphere)
    {
        const float centerY = hemisphere == 0 ? -inHalfHeight : inHalfHeight;
        for (int stack = 0; stack <= cHemisphereStacks; ++stack)
        {
            // Without an inner segment both equators coincide: keep one so no zero-height band is made
            if (hemisphere == 1 && stack == 0 && inHalfHeight == 0.0f) continue;
            const int step = hemisphere == 0 ? stack - cHemisphereStacks : stack;
            const float angle = 0.5f * cPi * float(step) / float(cHemisphereStacks);
            const bool pole = step == -cHemisphereStacks || step == cHemisphereStacks;
            outRings[count++] = {centerY + inRadius * std::sin(angle),
                                 pole ? 0.0f : inRadius * std::cos(angle)};
        }
    }
    return count;
}

Vec3 RingPoint(const Ring& inRing, int inSlice)
{
    const float angle = 2.0f * cPi * float(inSlice % cSlices) / float(cSlices);
    return {inRing.mRadius * std::cos(angle), inRing.mY, inRing.mRadius * std::sin(angle)};
}

/// Entry fraction (>= 0) of a ray whose origin is outside the sphere, or cLargeFloat when it misses.
float RaySphereEntry(const Vec3& inOrigin, const Vec3& inDirection, const Vec3& inCenter, float inRadius)
{
    const Vec3 o = inOrigin - inCenter;
    const float a = inDirection.squaredNorm();
    const float b = o.dot(inDirection);
    const float c = o.squaredNorm() - inRadius * inRadius;
    if (!(a > 0.0f) || b >= 0.0f) return cLargeFloat;
    const float disc = RayQuadratic::Discriminant(o, inDirection, a, b, inRadius);
    if (disc < 0.0f) return cLargeFloat;
    return std::max(0.0f, RayQuadratic::Entry(b, c, disc));
}

/// Entry fraction of a ray (origin outside) into the side of the infinite cylinder around Y, restricted to
/// |y| <= inHalfHeight; cLargeFloat when it misses.
float RayCylinderSideEntry(const Vec3& inOrigin, const Vec3& inDirection, float inHalfHeight, float inRadius)
{
    const float a = inDirection.x() * inDirection.x() + inDirection.z() * inDirection.z();
    const float b = inOrigin.x() * inDirection.x() + inOrigin.z() * inDirection.z();
    const float c = inOrigin.x() * inOrigin.x() + inOrigin.z() * inOrigin.z() - inRadius * inRadius;
    if (!(a > 0.0f) || b >= 0.0f || c < 0.0f) return cLargeFloat;
    // The quadratic in the XZ plane: the direction's and origin's Y play no part
    const Vec3 flatOrigin(inOrigin.x(), 0.0f, inOrigin.z());
    const Vec3 flatDirection(inDirection.x(), 0.0f, inDirection.z());
    const float disc = RayQuadratic::Discriminant(flatOrigin, flatDirection, a, b, inRadius);
    if (disc < 0.0f) return cLargeFloat;
    const float t = RayQuadratic::Entry(b, c, disc);
    const float y = inOrigin.y() + t * inDirection.y();
    return std::abs(y) <= inHalfHeight ? t : cLargeFloat;
}

} // namespace

Result<std::shared_ptr<const CapsuleShape>> CapsuleShape::Create(float inHalfHeight, float inRadius)
{
    if (!std::isfinite(inHalfHeight) || !std::isfinite(inRadius) ||
        inHalfHeight + inRadius > cMaxWorldCoordinate)
        return MakeError(
            ErrorCode::InvalidArgument,
            "CapsuleShape: half height and radius must be finite and within cMaxWorldCoordinate");
    if (!(inRadius > 0.0f))
        return MakeError(ErrorCode::DegenerateShape,
                         "CapsuleShape: radius must be > 0, got " + std::to_string(inRadius));
    if (!(inHalfHeight >= 0.0f))
        return MakeError(ErrorCode::DegenerateShape,
                         "CapsuleShape: half height must be >= 0, got " + std::to_string(inHalfHeight));
    return std::shared_ptr<const CapsuleShape>(std::make_shared<CapsuleShape>(inHalfHeight, inRadius));
}

CapsuleShape::CapsuleShape(float inHalfHeight, float inRadius)
    : ConvexShape(ShapeType::Capsule), mHalfHeight(inHalfHeight), mRadius(inRadius)
{
}

AABB CapsuleShape::GetLocalBounds() const
{
    return AABB::FromCenterExtent(Vec3::Zero(), Vec3(mRadius, mHalfHeight + mRadius, mRadius));
}

AABB CapsuleShape::GetWorldBounds(const Transform& inTransform) const
{
    // A capsule made around Create (a negative or NaN size) keeps the generic box, inverted or NaN, which
    // bodies and queries refuse
    if (!(mHalfHeight >= 0.0f && mRadius > 0.0f)) return Shape::GetWorldBounds(inTransform);
    // A capsule is its segment swept by a sphere, so its box is the segment's grown by the radius: the turned
    // local box is up to 1.7 times as wide on two axes, and every pair search around a limb would find bodies
    // it cannot touch
    const Vec3 halfSegment = inTransform.mRotation * Vec3(0.0f, mHalfHeight, 0.0f);
    return AABB::FromCenterExtent(inTransform.mPosition, halfSegment.cwiseAbs() + Vec3::Constant(mRadius));
}

MassProperties CapsuleShape::GetMassProperties(float inDensity) const
{
    const float r2 = mRadius * mRadius;
    const float h = mHalfHeight;
    const float cylinderMass = inDensity * cPi * r2 * 2.0f * h;
    const float spheresMass = inDensity * (4.0f / 3.0f) * cPi * r2 * mRadius;

    // Each hemisphere: 2/5 m r^2 about its flat face centre, minus m (3r/8)^2 to move to its own centre of
    // mass, plus m (h + 3r/8)^2 to move to the capsule centre; the 3r/8 squares cancel to this closed form
    const float spheresAxial = 0.4f * spheresMass * r2;
    const float spheresTransverse = spheresMass * (0.4f * r2 + h * h + 0.75f * h * mRadius);
    const float cylinderAxial = 0.5f * cylinderMass * r2;
    const float cylinderTransverse = cylinderMass * (0.25f * r2 + (4.0f * h * h) / 12.0f);

    MassProperties props;
    props.mMass = cylinderMass + spheresMass;
    const float transverse = cylinderTransverse + spheresTransverse;
    props.mInertia = Vec3(transverse, cylinderAxial + spheresAxial, transverse).asDiagonal();
    return props;
}

bool CapsuleShape::CastCheckedRay(const RayCast& inLocalRay, RayHit& ioHit) const
{
    const Vec3& o = inLocalRay.mOrigin;
    const Vec3& d = inLocalRay.mDirection;
    const Vec3 closestOnAxis(0.0f, std::clamp(o.y(), -mHalfHeight, mHalfHeight), 0.0f);
    if ((o - closestOnAxis).squaredNorm() <= mRadius * mRadius)
        return ShapeHelpers::ReportStartInside(inLocalRay, ioHit);

    // From outside, the first point of the union (side band + two end spheres) is the earliest entry into
    // any one of them
    const Vec3 top(0.0f, mHalfHeight, 0.0f);
    const float tSide = RayCylinderSideEntry(o, d, mHalfHeight, mRadius);
    const float tTop = RaySphereEntry(o, d, top, mRadius);
    const float tBottom = RaySphereEntry(o, d, -top, mRadius);
    const float t = std::min({tSide, tTop, tBottom});
    if (!(t <= 1.0f && t < ioHit.mFraction)) return false;

    const Vec3 p = o + t * d;
    const Vec3 axisPoint(0.0f, std::clamp(p.y(), -mHalfHeight, mHalfHeight), 0.0f);
    ioHit.mFraction = t;
    ioHit.mNormal = ShapeHelpers::SafeNormalized(p - axisPoint, -d.normalized());
    ioHit.mSubShape = 0;
    return true;
}

void CapsuleShape::VisitTriangles(const AABB& inLocalBox, TriangleVisitor inVisitor) const
{
    if (!inLocalBox.Overlaps(GetLocalBounds())) return;
    std::array<Ring, cMaxRings> rings;
    const int ringCount = BuildRings(mHalfHeight, mRadius, rings);
    for (int ring = 0; ring + 1 < ringCount; ++ring)
    {
        const Ring& lower = rings[ring];
        const Ring& upper = rings[ring + 1];
        for (int slice = 0; slice < cSlices; ++slice)
        {
            const Vec3 a = RingPoint(lower, slice);
            const Vec3 b = RingPoint(lower, slice + 1);
            const Vec3 c = RingPoint(upper, slice + 1);
            const Vec3 d = RingPoint(upper, slice);
            // (a, d, c) and (a, c, b) face outwards; a pole ring collapses one of them to a line
            Triangle triangles[2] = {{{a, d, c}}, {{a, c, b}}};
            const bool keep[2] = {upper.mRadius > 0.0f, lower.mRadius > 0.0f};
            for (int i = 0; i < 2; ++i)
                if (keep[i] &&
                    ShapeHelpers::TriangleBounds(triangles[i].mV[0], triangles[i].mV[1], triangles[i].mV[2])
                        .Overlaps(inLocalBox))
                    inVisitor(triangles[i]);
        }
    }
}

Vec3 CapsuleShape::GetSupport(const Vec3& inDirection) const
{
    const Vec3 n = ShapeHelpers::SafeNormalized(inDirection, Vec3::UnitY());
    return Vec3(0.0f, n.y() < 0.0f ? -mHalfHeight : mHalfHeight, 0.0f) + mRadius * n;
}

void CapsuleShape::GetSupportingFace(const Vec3& inDirection, SupportingFace& outFace) const
{
    const Vec3 n = ShapeHelpers::SafeNormalized(inDirection, Vec3::UnitY());
    if (mHalfHeight == 0.0f || std::abs(n.y()) >= cSideFaceCos)
    {
        outFace.mCount = 1;
        outFace.mVertices[0] = GetSupport(inDirection);
        return;
    }
    // The side line furthest along the direction: push the segment out perpendicular to the axis
    const Vec3 side = mRadius * ShapeHelpers::SafeNormalized(Vec3(n.x(), 0.0f, n.z()), Vec3::UnitX());
    outFace.mCount = 2;
    outFace.mVertices[0] = Vec3(0.0f, mHalfHeight, 0.0f) + side;
    outFace.mVertices[1] = Vec3(0.0f, -mHalfHeight, 0.0f) + side;
}

} // namespace cairn::physics
