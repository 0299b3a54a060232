#pragma once

// A rigid transform (rotation then translation). Plain value type: safe to use from any thread.

#include "cairn/physics/math/Math.h"

namespace cairn::physics
{

struct Transform
{
    Vec3 mPosition = Vec3::Zero();     ///< Translation in world (or parent) space
    Quat mRotation = Quat::Identity(); ///< Unit quaternion

    static Transform Identity() { return {}; }

    /// Maps a point from local to parent space.
    Vec3 operator*(const Vec3& inLocalPoint) const { return mRotation * inLocalPoint + mPosition; }

    /// Maps a direction (no translation) from local to parent space.
    Vec3 RotateVector(const Vec3& inLocalDir) const { return mRotation * inLocalDir; }

    /// Composition: (A * B) applied to p equals A applied to (B applied to p).
    Transform operator*(const Transform& inRhs) const
    {
        return {mRotation * inRhs.mPosition + mPosition, (mRotation * inRhs.mRotation).normalized()};
    }

    Transform Inverse() const
    {
        const Quat inv = mRotation.conjugate();
        return {inv * -mPosition, inv};
    }

    /// Maps a point from parent to local space.
    Vec3 InverseTransformPoint(const Vec3& inPoint) const
    {
        return mRotation.conjugate() * (inPoint - mPosition);
    }

    /// Maps a direction from parent to local space.
    Vec3 InverseRotateVector(const Vec3& inDir) const { return mRotation.conjugate() * inDir; }
};

} // namespace cairn::physics
