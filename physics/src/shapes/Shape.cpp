#include "cairn/physics/shapes/Shape.h"

namespace cairn::physics
{

const char* ToString(ShapeType inType)
{
    switch (inType)
    {
    case ShapeType::Sphere:
        return "Sphere";
    case ShapeType::Box:
        return "Box";
    case ShapeType::Capsule:
        return "Capsule";
    case ShapeType::ConvexHull:
        return "ConvexHull";
    case ShapeType::TriangleMesh:
        return "TriangleMesh";
    case ShapeType::HeightField:
        return "HeightField";
    case ShapeType::Compound:
        return "Compound";
    }
    return "Unknown";
}

void Shape::CollectTriangles(const AABB& inWorldBox, const Transform& inTransform,
                             std::vector<Vec3>& outVertices) const
{
    if (inWorldBox.IsEmpty()) return;

    // The rotated world box, boxed again in local space, contains every local point that can land in the
    // world box; the exact per-triangle test below removes the extra triangles this lets through
    const AABB localBox = inWorldBox.Transformed(inTransform.Inverse());
    VisitTriangles(localBox,
                   [&](const Triangle& inTriangle)
                   {
                       const Vec3 v0 = inTransform * inTriangle.mV[0];
                       const Vec3 v1 = inTransform * inTriangle.mV[1];
                       const Vec3 v2 = inTransform * inTriangle.mV[2];
                       if (!ShapeHelpers::TriangleBounds(v0, v1, v2).Overlaps(inWorldBox)) return;
                       outVertices.push_back(v0);
                       outVertices.push_back(v1);
                       outVertices.push_back(v2);
                   });
}

namespace ShapeHelpers
{

Vec3 SafeNormalized(const Vec3& inV, const Vec3& inFallback)
{
    if (!IsFinite(inV)) return inFallback;
    // Scaling by the largest component first keeps tiny vectors (whose squared norm underflows) usable
    const float scale = inV.cwiseAbs().maxCoeff();
    if (scale == 0.0f) return inFallback;
    return (inV / scale).normalized();
}

bool ReportStartInside(const RayCast& inRay, RayHit& ioHit)
{
    if (!(0.0f < ioHit.mFraction)) return false;
    ioHit.mFraction = 0.0f;
    // A zero-length ray has no direction to oppose; any unit vector keeps the hit free of NaN
    ioHit.mNormal = -SafeNormalized(inRay.mDirection, -Vec3::UnitY());
    ioHit.mSubShape = 0;
    return true;
}

float RayTriangleFraction(const RayCast& inRay, const Vec3& inV0, const Vec3& inV1, const Vec3& inV2)
{
    // Moller-Trumbore, without culling so that both sides are hit
    const Vec3 e1 = inV1 - inV0;
    const Vec3 e2 = inV2 - inV0;
    const Vec3 p = inRay.mDirection.cross(e2);
    const float det = e1.dot(p);
    if (!(std::abs(det) > 0.0f)) return cLargeFloat;
    const float invDet = 1.0f / det;
    const Vec3 s = inRay.mOrigin - inV0;
    const float u = s.dot(p) * invDet;
    if (!(u >= 0.0f && u <= 1.0f)) return cLargeFloat;
    const Vec3 q = s.cross(e1);
    const float v = inRay.mDirection.dot(q) * invDet;
    if (!(v >= 0.0f && u + v <= 1.0f)) return cLargeFloat;
    const float t = e2.dot(q) * invDet;
    return t >= 0.0f && t <= 1.0f ? t : cLargeFloat;
}

Vec3 TriangleNormalFacing(const Vec3& inV0, const Vec3& inV1, const Vec3& inV2, const Vec3& inRayDirection)
{
    const Vec3 n = SafeNormalized((inV1 - inV0).cross(inV2 - inV0), Vec3::UnitY());
    return n.dot(inRayDirection) > 0.0f ? Vec3(-n) : n;
}

bool IsEdgeActive(const Vec3& inNormal, const Vec3& inEdgePoint, const Vec3& inNeighbourNormal,
                  const Vec3& inNeighbourApex, float inCosThreshold)
{
    // The cosine from normals of any length: the height field works out a flag per cell edge at creation,
    // from raw cross products, and normalising them would be most of that work. In double: the squared
    // lengths of a large triangle's normal (its doubled area) overflow a float
    const Eigen::Vector3d normal = inNormal.cast<double>(), neighbour = inNeighbourNormal.cast<double>();
    if (normal.dot(neighbour) >
        double(inCosThreshold) * std::sqrt(normal.squaredNorm() * neighbour.squaredNorm()))
        return false;
    // A neighbour rising in front of this triangle's plane makes a concave joint: nothing can touch its
    // edge from outside without touching one of the two faces first
    const bool concave = inNormal.dot(inNeighbourApex - inEdgePoint) > 0.0f;
    return !concave;
}

AABB TriangleBounds(const Vec3& inV0, const Vec3& inV1, const Vec3& inV2)
{
    return {inV0.cwiseMin(inV1).cwiseMin(inV2), inV0.cwiseMax(inV1).cwiseMax(inV2)};
}

} // namespace ShapeHelpers

} // namespace cairn::physics
