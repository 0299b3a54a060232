#pragma once

// Manifold building from two touching faces: the face more aligned with the contact normal is the reference,
// the other (the incident face) is clipped against the reference face's side planes (Sutherland-Hodgman),
// and each surviving point is projected along the normal onto the reference plane, which gives the point on
// the other shape and the penetration. More than 4 points are reduced to 4 that keep the deepest point and
// span the largest area. Fixed-size buffers: no allocation.

#include "cairn/physics/narrowphase/ContactManifold.h"

namespace cairn::physics
{

/// Most points a clipped polygon can have (two faces of SupportingFace::cMaxVertices each).
inline constexpr int cMaxClipPoints = 2 * SupportingFace::cMaxVertices + 2;

/// Fills outManifold's points (not its normal or sub-shapes) from face A and face B (world space, convex,
/// either winding; 1 vertex = point, 2 = edge) touching along inNormal (unit, from A towards B). Keeps points
/// with penetration >= -inMaxSeparation. Returns the number of points, 0 when the faces give no manifold
/// (the caller then uses its single deepest point).
int ManifoldFromFaces(const Vec3* inFaceA, int inCountA, const Vec3* inFaceB, int inCountB,
                      const Vec3& inNormal, float inMaxSeparation, ContactManifold& outManifold);

/// Copies at most ContactManifold::cMaxPoints of inPoints into outManifold: the deepest, the one furthest
/// from it, then the two that add the most area on either side. Returns the number copied.
int ReduceContactPoints(const ContactPoint* inPoints, int inCount, const Vec3& inNormal,
                        ContactManifold& outManifold);

} // namespace cairn::physics
