#pragma once

// Math types for the whole engine: Eigen in single precision, with the few helpers every module needs.
// Everything here is a plain value type: safe to use from any thread.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>

namespace cairn::physics
{

using Vec3 = Eigen::Vector3f;
using Vec4 = Eigen::Vector4f;
using Mat3 = Eigen::Matrix3f;
using Quat = Eigen::Quaternionf;

/// A value larger than any coordinate the engine accepts; empty bounds are [+cLargeFloat, -cLargeFloat].
inline constexpr float cLargeFloat = 1.0e30f;

/// Coordinates beyond this (in metres) are rejected as input: float precision is gone at that distance
/// (1 ulp at 1e6 m is 6 cm), and it keeps every sum of two coordinates finite.
inline constexpr float cMaxWorldCoordinate = 1.0e6f;

inline constexpr float cPi = 3.14159265358979323846f;

/// True when every component is a finite number (no NaN, no infinity).
inline bool IsFinite(const Vec3& inV)
{
    return std::isfinite(inV.x()) && std::isfinite(inV.y()) && std::isfinite(inV.z());
}

/// Finite, and so is its squared length (components up to about 1e19): lengths and normalisations of it stay
/// finite.
inline bool IsFiniteLength(const Vec3& inV)
{
    return std::isfinite(inV.squaredNorm());
}

/// True when every component is finite and within the accepted world range.
inline bool IsValidWorldPosition(const Vec3& inV)
{
    return IsFinite(inV) && inV.cwiseAbs().maxCoeff() <= cMaxWorldCoordinate;
}

/// True when the quaternion is finite and of unit length (within a tolerance that allows float drift).
inline bool IsValidRotation(const Quat& inQ)
{
    const float n = inQ.squaredNorm();
    return std::isfinite(n) && std::abs(n - 1.0f) < 1.0e-3f;
}

/// A vector perpendicular to inV (inV must be non-zero); used to build tangent frames.
inline Vec3 AnyPerpendicular(const Vec3& inV)
{
    // Cross with the axis least aligned with inV, which keeps the result well conditioned
    const Vec3 a = inV.cwiseAbs();
    const Vec3 axis =
        a.x() <= a.y() && a.x() <= a.z() ? Vec3::UnitX() : (a.y() <= a.z() ? Vec3::UnitY() : Vec3::UnitZ());
    return inV.cross(axis).normalized();
}

/// Skew-symmetric matrix so that Skew(a) * b == a.cross(b).
inline Mat3 Skew(const Vec3& inA)
{
    Mat3 m;
    m << 0.0f, -inA.z(), inA.y(), inA.z(), 0.0f, -inA.x(), -inA.y(), inA.x(), 0.0f;
    return m;
}

/// Rotation inQ turned by the rotation vector inAngle (axis * angle, world space): the exact rotation,
/// exp(angle / 2) * q. The first-order update q + 0.5 * (0, angle) * q, renormalised, turns by 2 atan(angle /
/// 2) instead, short by angle^3 / 12 a step: a constant spin drifts behind by that much every step. Small
/// angles, a step's usual turn, take the series of cos and sin (exact to float rounding below 0.5 rad),
/// larger ones the functions.
inline Quat IntegrateRotation(const Quat& inQ, const Vec3& inAngle)
{
    const float angleSq = inAngle.squaredNorm();
    const float halfSq = 0.25f * angleSq; // (angle / 2)^2
    float cosHalf, sinHalfOverAngle;      // cos(angle / 2), sin(angle / 2) / angle
    if (halfSq < 0.0625f)
    {
        cosHalf = 1.0f - halfSq * (0.5f - halfSq * (1.0f / 24.0f - halfSq * (1.0f / 720.0f)));
        sinHalfOverAngle = 0.5f * (1.0f - halfSq * (1.0f / 6.0f - halfSq * (1.0f / 120.0f)));
    }
    else
    {
        const float angle = std::sqrt(angleSq);
        cosHalf = std::cos(0.5f * angle);
        sinHalfOverAngle = std::sin(0.5f * angle) / angle;
    }
    const Quat turn(cosHalf, sinHalfOverAngle * inAngle.x(), sinHalfOverAngle * inAngle.y(),
                    sinHalfOverAngle * inAngle.z());
    // Normalised all the same: rounding would otherwise add up over thousands of steps
    return (turn * inQ).normalized();
}

} // namespace cairn::physics
