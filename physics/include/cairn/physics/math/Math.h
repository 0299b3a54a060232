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

/// Rotation inQ turned by the small rotation vector inAngle (axis * angle, world space), renormalised:
/// the first-order quaternion update q' = q + 0.5 * (0, angle) * q used by symplectic Euler.
inline Quat IntegrateRotation(const Quat& inQ, const Vec3& inAngle)
{
    const Quat spin(0.0f, 0.5f * inAngle.x(), 0.5f * inAngle.y(), 0.5f * inAngle.z());
    Quat result;
    result.coeffs() = inQ.coeffs() + (spin * inQ).coeffs();
    return result.normalized();
}

} // namespace cairn::physics
