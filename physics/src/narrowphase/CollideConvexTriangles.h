#pragma once

// A convex shape against the triangles of a mesh or height field (or any shape through
// Shape::VisitTriangles). The convex shape's bounds, moved into the mesh's local space and grown by the max
// separation, select the triangles; each triangle gives at most one manifold, with mSubShapeB =
// Triangle::mSubShape. Work happens in the mesh's local space (one transform for the convex shape instead of
// one per triangle vertex).
//
// One-sided: a triangle only collides when the convex shape's centre is on its front side (the side its
// normal (v1 - v0) x (v2 - v0) points to), and never pushes the shape towards its back.
//
// Internal edges: a triangle seen alone has sharp edges and vertices, and a shape sliding across the seam
// between two coplanar triangles would hit the seam's edge with a tilted normal and catch on it. The mesh
// marks every edge shared with a neighbour that continues the surface (flat or concave) as inactive
// (Triangle::mActiveEdges). Rule: when the contact normal is not within cFaceNormalCos of the triangle's face
// normal and the triangle feature that supports the contact is an inactive edge, or a vertex whose two edges
// are both inactive, the normal is replaced by the face normal and the penetration is recomputed along it
// (deepest point of the convex shape below the triangle's plane). The neighbouring triangle that continues
// the surface reports the real contact there, so nothing is lost; a sphere rolling across a flat mesh of many
// triangles sees only face normals. Active edges (mesh borders, convex ridges) keep their true normal.

#include "cairn/physics/narrowphase/CollideShapes.h"

namespace cairn::physics
{

/// A contact normal whose dot product with the triangle's face normal is above this counts as the face
/// normal (about 0.1 degrees). It must be tight: the solver pushes along the normal against the approach
/// speed, so a tilt of 1 degree on a sphere rolling at 6 m/s kicked it up at 0.09 m/s.
inline constexpr float cFaceNormalCos = 0.999998f;

/// Convex A (transform inTransformA in the triangle's space) against one triangle (B), with the one-sided and
/// internal-edge rules above. Returns false when there is no contact within inSettings.mMaxSeparation.
bool CollideConvexTriangle(const ConvexShape& inA, const Transform& inTransformA, const Triangle& inTriangle,
                           const CollideSettings& inSettings, ContactManifold& outManifold);

/// Convex A against every triangle of inB; reports one manifold per touching triangle (world space). Returns
/// the number of manifolds reported.
int CollideConvexTriangles(const ConvexShape& inA, const Transform& inTransformA, const Shape& inB,
                           const Transform& inTransformB, const CollideSettings& inSettings,
                           ManifoldVisitor inVisitor);

} // namespace cairn::physics
