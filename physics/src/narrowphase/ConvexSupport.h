#pragma once

// ConvexSupport: the support mapping that GJK and EPA run on. A convex shape (or a mesh triangle) placed in
// world space and split into a "core" plus a radius: a sphere is its centre point plus its radius, a capsule
// its inner segment plus its radius, a box, a hull or a triangle is itself with radius 0. GJK on the cores is
// exact and finite (every core is a polytope), and the radius is added afterwards, which makes round shapes
// exact and fast. Plain value type, no allocation: build one per query on the stack.

#include "cairn/physics/shapes/Shape.h"

namespace cairn::physics
{

class ConvexSupport
{
public:
    /// The core of inShape at inTransform (sphere -> point, capsule -> segment, others -> the shape itself).
    static ConvexSupport FromShape(const ConvexShape& inShape, const Transform& inTransform);

    /// A triangle given by its three vertices (same space as the other support of the query), radius 0.
    static ConvexSupport FromTriangle(const Vec3& inV0, const Vec3& inV1, const Vec3& inV2);

    /// Furthest point of the core along inDirection (non-zero, need not be normalised).
    Vec3 GetCoreSupport(const Vec3& inDirection) const;

    /// Furthest point of the core inflated by inInflation along inDirection: with inInflation = GetRadius()
    /// this is the support of the full shape.
    Vec3 GetSupport(const Vec3& inDirection, float inInflation) const
    {
        const float len = inDirection.norm();
        const Vec3 core = GetCoreSupport(inDirection);
        return len > 0.0f ? Vec3(core + inDirection * (inInflation / len)) : core;
    }

    /// The radius the core lacks to be the full shape (0 for boxes, hulls and triangles).
    float GetRadius() const { return mRadius; }

    /// A point inside the core: a good first search direction for GJK.
    const Vec3& GetCenter() const { return mCenter; }

private:
    enum class Kind : uint8_t
    {
        Points, ///< Point, segment or triangle stored in mPoints
        Box,    ///< Oriented box: mCenter, mRotation, mHalfExtent
        Shape,  ///< Any other convex shape through its virtual GetSupport
    };

    Kind mKind = Kind::Points;
    int mNumPoints = 0;
    Vec3 mPoints[3];
    Vec3 mCenter = Vec3::Zero();      ///< Inside the core
    Vec3 mTranslation = Vec3::Zero(); ///< Shape kind: world position of the shape's local origin
    Mat3 mRotation = Mat3::Identity();
    Vec3 mHalfExtent = Vec3::Zero();
    const ConvexShape* mShape = nullptr;
    float mRadius = 0.0f;
};

} // namespace cairn::physics
