#include "narrowphase/CollideConvexTriangles.h"

#include "cairn/physics/shapes/SphereShape.h"
#include "narrowphase/ClosestPoints.h"
#include "narrowphase/ConvexContact.h"
#include "narrowphase/FaceClipping.h"

#include <algorithm>

namespace cairn::physics
{

namespace
{

/// Below this cosine between the contact normal and the face normal, the triangle's face no longer serves
/// as its supporting face for clipping (its edge or vertex does).
constexpr float cTriangleFaceCos = 0.7f;

// Bit mask of the vertices of the triangle that support inDirection (within a tolerance): 1 bit = vertex,
// 2 bits = edge, 3 = the whole face
uint32_t SupportingFeature(const Triangle& inTriangle, const Vec3& inDirection, float inTolerance)
{
    float d[3];
    for (int i = 0; i < 3; ++i)
        d[i] = inTriangle.mV[i].dot(inDirection);
    const float maxD = std::max(d[0], std::max(d[1], d[2]));
    uint32_t feature = 0;
    for (int i = 0; i < 3; ++i)
        if (d[i] >= maxD - inTolerance) feature |= 1u << i;
    return feature;
}

// True when the feature (vertex bit mask) is an inactive edge or a vertex whose two edges are inactive
bool IsInactiveFeature(uint32_t inFeature, uint8_t inActiveEdges)
{
    // Edge bit of the edge between vertices i and j: 01 -> cEdge01, 12 -> cEdge12, 20 -> cEdge20
    switch (inFeature)
    {
    case 0b011:
        return (inActiveEdges & cEdge01) == 0;
    case 0b110:
        return (inActiveEdges & cEdge12) == 0;
    case 0b101:
        return (inActiveEdges & cEdge20) == 0;
    case 0b001:
        return (inActiveEdges & (cEdge01 | cEdge20)) == 0;
    case 0b010:
        return (inActiveEdges & (cEdge01 | cEdge12)) == 0;
    case 0b100:
        return (inActiveEdges & (cEdge12 | cEdge20)) == 0;
    default:
        return false;
    }
}

} // namespace

bool CollideConvexTriangle(const ConvexShape& inA, const Transform& inTransformA, const Triangle& inTriangle,
                           const CollideSettings& inSettings, ContactManifold& outManifold)
{
    const Vec3& v0 = inTriangle.mV[0];
    const Vec3& v1 = inTriangle.mV[1];
    const Vec3& v2 = inTriangle.mV[2];
    Vec3 faceNormal = (v1 - v0).cross(v2 - v0);
    const float area2 = faceNormal.norm();
    if (!(area2 > 1.0e-12f)) return false;
    faceNormal /= area2;

    const float maxSep = inSettings.mMaxSeparation;
    const ConvexSupport support = ConvexSupport::FromShape(inA, inTransformA);
    if ((support.GetCenter() - v0).dot(faceNormal) < 0.0f) return false;

    ConvexContact contact;
    uint32_t feature = 0;
    if (inA.GetType() == ShapeType::Sphere)
    {
        // Spheres are common on meshes (characters, debris): the closest point on the triangle is enough
        const float radius = support.GetRadius();
        const Vec3& center = support.GetCenter();
        Vec3 bary;
        const Vec3 onTriangle = ClosestPointOnTriangle(center, v0, v1, v2, bary, feature);
        const Vec3 delta = onTriangle - center;
        const float distSq = delta.squaredNorm();
        if (distSq > (radius + maxSep) * (radius + maxSep)) return false;
        const float dist = std::sqrt(distSq);
        contact.mNormal = dist > 1.0e-6f ? Vec3(delta / dist) : Vec3(-faceNormal);
        contact.mPointA = center + contact.mNormal * radius;
        contact.mPointB = onTriangle;
        contact.mPenetration = radius - dist;
    }
    else
    {
        const ConvexSupport triangle = ConvexSupport::FromTriangle(v0, v1, v2);
        if (!FindConvexContact(support, triangle, maxSep, contact)) return false;
        const float size = std::max((v1 - v0).norm(), std::max((v2 - v1).norm(), (v0 - v2).norm()));
        feature = SupportingFeature(inTriangle, -contact.mNormal, 1.0e-4f * size);
    }

    // The triangle pushes A along -normal; it must push A out of its front
    float cosFace = -contact.mNormal.dot(faceNormal);
    if (inSettings.mFaceNormalsAtInternalEdges && cosFace < cFaceNormalCos &&
        IsInactiveFeature(feature, inTriangle.mActiveEdges))
    {
        // Internal edge or vertex: use the face normal, and the deepest point of A below the plane
        const Vec3 n = -faceNormal;
        const Vec3 deepest = support.GetSupport(n, support.GetRadius());
        contact.mNormal = n;
        contact.mPenetration = (v0 - deepest).dot(faceNormal);
        contact.mPointA = deepest;
        contact.mPointB = deepest + faceNormal * contact.mPenetration;
        cosFace = 1.0f;
        if (contact.mPenetration < -maxSep) return false;
    }
    if (cosFace < 0.0f) return false;

    outManifold.mNormal = contact.mNormal;
    if (inA.GetType() != ShapeType::Sphere)
    {
        SupportingFace faceA;
        inA.GetSupportingFace(inTransformA.InverseRotateVector(contact.mNormal), faceA);
        for (int i = 0; i < faceA.mCount; ++i)
            faceA.mVertices[i] = inTransformA * faceA.mVertices[i];
        // The triangle's own supporting face along the normal: itself, or its supporting edge or vertex
        Vec3 faceB[3];
        int countB = 0;
        const uint32_t triFeature = cosFace >= cTriangleFaceCos ? 0b111u : feature;
        for (int i = 0; i < 3; ++i)
            if (triFeature & (1u << i)) faceB[countB++] = inTriangle.mV[i];
        if (countB == 0) faceB[countB++] = contact.mPointB;
        if (ManifoldFromFaces(faceA.mVertices, faceA.mCount, faceB, countB, contact.mNormal, maxSep,
                              outManifold) > 0)
        {
            KeepTheContactGap({contact.mPointA, contact.mPointB, contact.mPenetration}, outManifold);
            return true;
        }
    }
    outManifold.mNumPoints = 1;
    outManifold.mPoints[0] = {contact.mPointA, contact.mPointB, contact.mPenetration};
    return true;
}

int CollideConvexTriangles(const ConvexShape& inA, const Transform& inTransformA, const Shape& inB,
                           const Transform& inTransformB, const CollideSettings& inSettings,
                           ManifoldVisitor inVisitor)
{
    // Work in B's local space: the convex shape is moved once instead of every triangle
    const Transform relative = inTransformB.Inverse() * inTransformA;
    AABB localBox = inA.GetWorldBounds(relative);
    if (inSettings.mSweep == Vec3::Zero())
        localBox = localBox.Expanded(inSettings.mMaxSeparation);
    else
    {
        // A cast: the triangles its remaining path can reach
        const Vec3 sweep = inTransformB.InverseRotateVector(inSettings.mSweep);
        localBox =
            AABB(localBox.mMin.cwiseMin(localBox.mMin + sweep), localBox.mMax.cwiseMax(localBox.mMax + sweep))
                .Expanded(cSweptTriangleMargin);
    }
    const Mat3 rotB = inTransformB.mRotation.toRotationMatrix();
    int count = 0;
    inB.VisitTriangles(localBox,
                       [&](const Triangle& inTriangle)
                       {
                           ContactManifold m;
                           if (!CollideConvexTriangle(inA, relative, inTriangle, inSettings, m)) return;
                           m.mNormal = rotB * m.mNormal;
                           for (int i = 0; i < m.mNumPoints; ++i)
                           {
                               m.mPoints[i].mPositionOnA =
                                   rotB * m.mPoints[i].mPositionOnA + inTransformB.mPosition;
                               m.mPoints[i].mPositionOnB =
                                   rotB * m.mPoints[i].mPositionOnB + inTransformB.mPosition;
                           }
                           m.mSubShapeA = 0;
                           m.mSubShapeB = inTriangle.mSubShape;
                           inVisitor(m);
                           ++count;
                       });
    return count;
}

} // namespace cairn::physics
