#pragma once

// The swing-twist joint's angles (issue 33, ragdolls): B's constraint frame in A's, split into a twist about
// the frame's x axis (the limb's) and a swing that tilts x (about an axis in the y-z plane), as Jolt and
// PhysX split it. The swing is limited to an elliptic cone: its rotation vector's part about y (towards the
// normal axis z) within the normal half angle, about z (within the x-y plane) within the plane half angle.
//
// Threads: any; pure functions.

#include "cairn/physics/math/Math.h"

#include <algorithm>
#include <cmath>

namespace cairn::physics
{

/// inRelative = swing * twist: the twist about x, the swing about an axis in the y-z plane.
inline void SplitSwingTwist(const Quat& inRelative, Quat& outSwing, Quat& outTwist)
{
    // Unit quaternion parts: no overflow for std::hypot to guard against, and its care costs
    const float length = std::sqrt(inRelative.w() * inRelative.w() + inRelative.x() * inRelative.x());
    // A half turn of swing leaves no twist to speak of: none
    outTwist = length > 1.0e-6f ? Quat(inRelative.w() / length, inRelative.x() / length, 0.0f, 0.0f)
                                : Quat::Identity();
    outSwing = inRelative * outTwist.conjugate();
}

/// A rotation's angle about its axis times the axis, the short way round (within [-pi, pi] rad).
inline Vec3 RotationVector(const Quat& inRotation)
{
    const float sign = inRotation.w() < 0.0f ? -1.0f : 1.0f; // q and -q are one rotation
    const Vec3 v = sign * inRotation.vec();
    const float sine = v.norm();
    if (sine < 1.0e-7f) return 2.0f * v; // Small: the first-order angle
    return (2.0f * std::atan2(sine, sign * inRotation.w()) / sine) * v;
}

/// The twist's angle about x (rad, within [-pi, pi]).
inline float TwistAngle(const Quat& inTwist)
{
    return RotationVector(inTwist).x();
}

/// Whether the swing (its rotation vector, in the frame) is past the elliptic cone of half angles
/// inNormalHalfAngle (about y) and inPlaneHalfAngle (about z), or within inBand (rad) of its edge; if so, the
/// frame direction (unit, in the y-z plane) whose spin takes it further out, and how far past the edge it is
/// (rad, along the swing's own direction: below zero while inside).
inline bool SwingPastCone(const Vec3& inSwing, float inNormalHalfAngle, float inPlaneHalfAngle, float inBand,
                          Vec3& outDirection, float& outError)
{
    // A zero half angle is a thin ellipse, not a division by zero: the swing about that axis is held near 0
    const float a = std::max(inNormalHalfAngle, 1.0e-4f), b = std::max(inPlaneHalfAngle, 1.0e-4f);
    const float y = inSwing.y(), z = inSwing.z();
    // Angles and their ratios to half angles of at least 1e-4 rad: squares far from float's range
    const float scaled = std::sqrt((y / a) * (y / a) + (z / b) * (z / b)); // 1 on the cone's edge
    const float length = std::sqrt(y * y + z * z);
    // Past the edge along its own ray by this much (its edge point is the swing over scaled)
    if (!(scaled > 1.0e-6f)) return false; // No swing: no direction, and far inside
    const float past = length * (1.0f - 1.0f / scaled);
    if (past <= -inBand) return false;
    // Outwards across the edge: the ellipse's gradient there
    outDirection = Vec3(0.0f, y / (a * a), z / (b * b)).normalized();
    outError = past * (Vec3(0.0f, y, z) / length).dot(outDirection);
    return true;
}

} // namespace cairn::physics
