#pragma once

// Axis-aligned bounding box. Plain value type: safe to use from any thread.

#include "cairn/physics/math/Transform.h"

#include <algorithm>

namespace cairn::physics
{

struct AABB
{
    Vec3 mMin = Vec3::Constant(cLargeFloat); ///< Empty by default: min > max
    Vec3 mMax = Vec3::Constant(-cLargeFloat);

    AABB() = default;
    AABB(const Vec3& inMin, const Vec3& inMax) : mMin(inMin), mMax(inMax) {}

    static AABB Empty() { return {}; }
    static AABB FromCenterExtent(const Vec3& inCenter, const Vec3& inHalfExtent)
    {
        return {inCenter - inHalfExtent, inCenter + inHalfExtent};
    }

    /// An empty box has min > max on some axis; it overlaps nothing.
    bool IsEmpty() const { return (mMin.array() > mMax.array()).any(); }
    bool IsFinite() const { return physics::IsFinite(mMin) && physics::IsFinite(mMax); }

    Vec3 Center() const { return 0.5f * (mMin + mMax); }
    Vec3 HalfExtent() const { return 0.5f * (mMax - mMin); }
    Vec3 Size() const { return mMax - mMin; }

    void Encapsulate(const Vec3& inPoint)
    {
        mMin = mMin.cwiseMin(inPoint);
        mMax = mMax.cwiseMax(inPoint);
    }
    void Encapsulate(const AABB& inBox)
    {
        mMin = mMin.cwiseMin(inBox.mMin);
        mMax = mMax.cwiseMax(inBox.mMax);
    }
    AABB Expanded(float inMargin) const { return {mMin.array() - inMargin, mMax.array() + inMargin}; }

    /// Closed-interval overlap: boxes that only touch count as overlapping.
    bool Overlaps(const AABB& inOther) const
    {
        return (mMin.array() <= inOther.mMax.array()).all() && (inOther.mMin.array() <= mMax.array()).all();
    }
    /// Closed: a box contains itself.
    bool Contains(const AABB& inOther) const
    {
        return (mMin.array() <= inOther.mMin.array()).all() && (inOther.mMax.array() <= mMax.array()).all();
    }
    bool Contains(const Vec3& inPoint) const
    {
        return (mMin.array() <= inPoint.array()).all() && (inPoint.array() <= mMax.array()).all();
    }

    /// Bounds of this box after a rigid transform (exact bounds of the rotated box).
    AABB Transformed(const Transform& inTransform) const
    {
        if (IsEmpty()) return *this;
        const Mat3 r = inTransform.mRotation.toRotationMatrix();
        const Vec3 c = inTransform * Center();
        const Vec3 e = r.cwiseAbs() * HalfExtent();
        return {c - e, c + e};
    }

    /// Slab test of the segment inOrigin + t * inDirection, t in [0, inMaxFraction].
    /// inInvDirection is 1 / inDirection per component (infinities allowed). Returns the entry fraction,
    /// or a value > inMaxFraction when missed.
    float RayEntryFraction(const Vec3& inOrigin, const Vec3& inInvDirection, float inMaxFraction) const
    {
        float tMin = 0.0f;
        float tMax = inMaxFraction;
        for (int axis = 0; axis < 3; ++axis)
        {
            float t1 = (mMin[axis] - inOrigin[axis]) * inInvDirection[axis];
            float t2 = (mMax[axis] - inOrigin[axis]) * inInvDirection[axis];
            // 0 * inf gives NaN when the origin lies on a slab plane of a parallel ray; treat it as inside
            if (std::isnan(t1)) t1 = -cLargeFloat;
            if (std::isnan(t2)) t2 = cLargeFloat;
            tMin = std::max(tMin, std::min(t1, t2));
            tMax = std::min(tMax, std::max(t1, t2));
        }
        return tMin <= tMax ? tMin : cLargeFloat;
    }
};

/// Component-wise reciprocal that maps 0 (of either sign) to +infinity, for slab tests. Always +infinity: the
/// NaN patch of RayEntryFraction (origin on a slab plane of a parallel ray counts as inside) assumes it; with
/// -infinity from a -0 component a ray would touch a box but miss a larger box containing it, and a tree
/// would skip bodies that brute force reports (found by the quad tree's property test).
inline Vec3 SafeReciprocal(const Vec3& inV)
{
    Vec3 r;
    for (int i = 0; i < 3; ++i)
        r[i] = inV[i] != 0.0f ? 1.0f / inV[i] : std::numeric_limits<float>::infinity();
    return r;
}

} // namespace cairn::physics
