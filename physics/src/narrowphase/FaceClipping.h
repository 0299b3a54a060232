#pragma once

// Manifold building from two touching faces: the face more aligned with the contact normal is the reference,
// the other (the incident face) is clipped against the reference face's side planes (Sutherland-Hodgman),
// and each surviving point is projected along the normal onto the reference plane, which gives the point on
// the other shape and the penetration. More than 4 points are reduced to 4 that keep the deepest point and
// span the largest area. Fixed-size buffers: no allocation.

#include "cairn/physics/narrowphase/ContactManifold.h"

#include <algorithm>

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

/// The penetration of a manifold's deepest point (-cLargeFloat when it has none).
inline float MaxPenetration(const ContactManifold& inManifold)
{
    float deepest = -cLargeFloat;
    for (int i = 0; i < inManifold.mNumPoints; ++i)
        deepest = std::max(deepest, inManifold.mPoints[i].mPenetration);
    return deepest;
}

/// A manifold that claims more clearance than its contact by more than this (metres) takes the contact in:
/// well below the shape casts' tolerance, well above the float noise between the two figures where the
/// contact's point was kept.
inline constexpr float cClippedGapSlack = 1.0e-5f;

/// Clipping keeps the part of the incident face over the reference face, and can lose the point where the
/// contact was found (it lay beside the other face); the manifold then claims more clearance than the shapes
/// have: a speculative contact that lets the solver close them further than they are apart in one step, and a
/// shape cast advance past the touch. Where ioManifold claims clearance (its least gap > 0) wider than
/// inContact's (its point pair along ioManifold's normal) by more than cClippedGapSlack, inContact takes the
/// place of the farthest point, or joins them when there is room. Penetrating manifolds are left as they are.
/// The two halves apart, for a caller whose contact point costs something to make (box-box: the boxes'
/// support points, whose depth is the axis's).
bool ClaimsMoreClearance(const ContactManifold& inManifold, float inContactPenetration);
void PutContactIn(const ContactPoint& inContact, ContactManifold& ioManifold);
inline void KeepTheContactGap(const ContactPoint& inContact, ContactManifold& ioManifold)
{
    if (ClaimsMoreClearance(ioManifold, inContact.mPenetration)) PutContactIn(inContact, ioManifold);
}

/// Copies at most ContactManifold::cMaxPoints of inPoints into outManifold: the deepest, the one furthest
/// from it, then the two that add the most area on either side. Returns the number copied.
int ReduceContactPoints(const ContactPoint* inPoints, int inCount, const Vec3& inNormal,
                        ContactManifold& outManifold);

} // namespace cairn::physics
