#pragma once

// Closest points between simple primitives (point, segment, triangle), shared by GJK's simplex solver and
// the dedicated sphere/capsule/triangle routines. Pure functions.

#include "cairn/physics/math/Math.h"

#include <cstdint>

namespace cairn::physics
{

/// Closest point to inP on the segment [inA, inB]; outT in [0, 1] is its parameter from inA.
Vec3 ClosestPointOnSegment(const Vec3& inP, const Vec3& inA, const Vec3& inB, float& outT);

/// Closest points between segments [inP1, inQ1] and [inP2, inQ2]: outC1 = inP1 + outS (inQ1 - inP1),
/// outC2 = inP2 + outT (inQ2 - inP2). Handles zero-length segments. Returns the squared distance.
float ClosestPointsSegmentSegment(const Vec3& inP1, const Vec3& inQ1, const Vec3& inP2, const Vec3& inQ2,
                                  float& outS, float& outT, Vec3& outC1, Vec3& outC2);

/// Closest point to inP on the triangle (inA, inB, inC) as barycentric weights (outBary sums to 1).
/// outFeature has bit i set for every vertex i that carries weight: one bit = vertex, two = edge, three =
/// interior. Degenerate (collinear) triangles fall back to the closest edge.
Vec3 ClosestPointOnTriangle(const Vec3& inP, const Vec3& inA, const Vec3& inB, const Vec3& inC, Vec3& outBary,
                            uint32_t& outFeature);

} // namespace cairn::physics
