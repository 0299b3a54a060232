#include "narrowphase/CollideBoxBox.h"

#include "narrowphase/ClosestPoints.h"
#include "narrowphase/FaceClipping.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace cairn::physics
{

namespace
{

/// Edge axes from nearly parallel edges are numerically meaningless; the face axes cover those cases.
constexpr float cMinEdgeAxisLength = 1.0e-3f;

// The 4 corners of the face of a box (centre inCenter, unit axes = columns of inAxes) with outward normal
// inSign * axis inAxis, in order around the face
void BoxFace(const Vec3& inCenter, const Mat3& inAxes, const Vec3& inExtent, int inAxis, float inSign,
             Vec3* outFace)
{
    const int u = (inAxis + 1) % 3;
    const int v = (inAxis + 2) % 3;
    const Vec3 c = inCenter + inAxes.col(inAxis) * (inSign * inExtent[inAxis]);
    const Vec3 du = inAxes.col(u) * inExtent[u];
    const Vec3 dv = inAxes.col(v) * inExtent[v];
    outFace[0] = c + du + dv;
    outFace[1] = c - du + dv;
    outFace[2] = c - du - dv;
    outFace[3] = c + du - dv;
}

// The face of a box whose outward normal is most aligned with inDirection
void BoxSupportingFace(const Vec3& inCenter, const Mat3& inAxes, const Vec3& inExtent,
                       const Vec3& inDirection, Vec3* outFace)
{
    const Vec3 local = inAxes.transpose() * inDirection;
    int axis = 0;
    local.cwiseAbs().maxCoeff(&axis);
    BoxFace(inCenter, inAxes, inExtent, axis, local[axis] < 0.0f ? -1.0f : 1.0f, outFace);
}

// The corner of a box (local space) furthest along inLocalDirection
Vec3 BoxCorner(const Vec3& inLocalDirection, const Vec3& inExtent)
{
    return {inLocalDirection.x() >= 0.0f ? inExtent.x() : -inExtent.x(),
            inLocalDirection.y() >= 0.0f ? inExtent.y() : -inExtent.y(),
            inLocalDirection.z() >= 0.0f ? inExtent.z() : -inExtent.z()};
}

// Reference face of a box: a rectangle with centre mCenter, outward normal mNormal and half sizes mHalfU,
// mHalfV along the unit axes mU, mV
struct ReferenceFace
{
    Vec3 mCenter;
    Vec3 mNormal;
    Vec3 mU;
    Vec3 mV;
    float mHalfU;
    float mHalfV;
};

ReferenceFace MakeReferenceFace(const Vec3& inCenter, const Mat3& inAxes, const Vec3& inExtent, int inAxis,
                                float inSign)
{
    const int u = (inAxis + 1) % 3;
    const int v = (inAxis + 2) % 3;
    return {inCenter + inAxes.col(inAxis) * (inSign * inExtent[inAxis]),
            inAxes.col(inAxis) * inSign,
            inAxes.col(u),
            inAxes.col(v),
            inExtent[u],
            inExtent[v]};
}

// Sutherland-Hodgman of the incident quad against the reference rectangle, done in the rectangle's 2D frame
// (the generic polygon clipper works for any faces but is twice as slow, and box-box is the hot pair).
// inRefIsA tells which box the reference face belongs to. Returns the number of points written.
int ClipIncidentAgainstReference(const ReferenceFace& inRef, const Vec3* inIncident, bool inRefIsA,
                                 float inMaxSep, ContactManifold& outManifold)
{
    // x, y in the reference frame, d = depth below the reference face (> 0 penetrating)
    struct Point2
    {
        float mX[2];
        float mD;
    };
    Point2 bufA[8];
    Point2 bufB[8];
    for (int i = 0; i < 4; ++i)
    {
        const Vec3 rel = inIncident[i] - inRef.mCenter;
        bufA[i] = {{rel.dot(inRef.mU), rel.dot(inRef.mV)}, -rel.dot(inRef.mNormal)};
    }
    Point2* cur = bufA;
    Point2* next = bufB;
    int count = 4;
    const float limits[2] = {inRef.mHalfU, inRef.mHalfV};
    for (int plane = 0; plane < 4 && count > 0; ++plane)
    {
        // Keep inSign * x[axis] <= limit; a convex quad gains at most one vertex per plane
        const int axis = plane >> 1;
        const float sign = (plane & 1) ? -1.0f : 1.0f;
        const float limit = limits[axis];
        int out = 0;
        Point2 prev = cur[count - 1];
        float prevF = limit - sign * prev.mX[axis];
        for (int i = 0; i < count; ++i)
        {
            const Point2& p = cur[i];
            const float f = limit - sign * p.mX[axis];
            if ((prevF < 0.0f) != (f < 0.0f))
            {
                const float t = prevF / (prevF - f);
                next[out++] = {
                    {prev.mX[0] + t * (p.mX[0] - prev.mX[0]), prev.mX[1] + t * (p.mX[1] - prev.mX[1])},
                    prev.mD + t * (p.mD - prev.mD)};
            }
            if (f >= 0.0f) next[out++] = p;
            prev = p;
            prevF = f;
        }
        count = out;
        std::swap(cur, next);
    }

    ContactPoint points[8];
    int numPoints = 0;
    for (int i = 0; i < count; ++i)
    {
        if (cur[i].mD < -inMaxSep) continue;
        const Vec3 onRef = inRef.mCenter + inRef.mU * cur[i].mX[0] + inRef.mV * cur[i].mX[1];
        const Vec3 onIncident = onRef - inRef.mNormal * cur[i].mD;
        points[numPoints++] = inRefIsA ? ContactPoint{onRef, onIncident, cur[i].mD}
                                       : ContactPoint{onIncident, onRef, cur[i].mD};
    }
    const Vec3 normal = inRefIsA ? inRef.mNormal : Vec3(-inRef.mNormal);
    return ReduceContactPoints(points, numPoints, normal, outManifold);
}

} // namespace

bool CollideBoxBox(const BoxShape& inA, const Transform& inTransformA, const BoxShape& inB,
                   const Transform& inTransformB, const CollideSettings& inSettings,
                   ContactManifold& outManifold, BoxBoxAxis* outAxis)
{
    const Vec3& eA = inA.GetHalfExtent();
    const Vec3& eB = inB.GetHalfExtent();
    const Mat3 rotA = inTransformA.mRotation.toRotationMatrix();
    const Mat3 rotB = inTransformB.mRotation.toRotationMatrix();
    const Vec3 d = inTransformB.mPosition - inTransformA.mPosition;

    // Everything in A's frame: c.col(j) is B's axis j, t is B's centre
    const Mat3 c = rotA.transpose() * rotB;
    const Mat3 absC = c.cwiseAbs();
    const Vec3 t = rotA.transpose() * d;
    const float maxSep = inSettings.mMaxSeparation;

    // Separation along each axis (> 0 separated); keep the largest
    float bestFaceA = -cLargeFloat;
    int faceA = 0;
    for (int i = 0; i < 3; ++i)
    {
        const float s = std::abs(t[i]) - (eA[i] + absC.row(i).dot(eB));
        if (s > maxSep) return false;
        if (s > bestFaceA)
        {
            bestFaceA = s;
            faceA = i;
        }
    }
    float bestFaceB = -cLargeFloat;
    int faceB = 0;
    const Vec3 tInB = c.transpose() * t;
    for (int j = 0; j < 3; ++j)
    {
        const float s = std::abs(tInB[j]) - (absC.col(j).dot(eA) + eB[j]);
        if (s > maxSep) return false;
        if (s > bestFaceB)
        {
            bestFaceB = s;
            faceB = j;
        }
    }
    float bestEdge = -cLargeFloat;
    Vec3 edgeAxis = Vec3::Zero();
    int edgeA = 0;
    int edgeB = 0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
        {
            const Vec3 axis = Vec3::Unit(i).cross(c.col(j));
            const float len = axis.norm();
            if (len < cMinEdgeAxisLength) continue;
            const float rA = axis.cwiseAbs().dot(eA);
            const float rB = (c.transpose() * axis).cwiseAbs().dot(eB);
            const float s = (std::abs(axis.dot(t)) - rA - rB) / len;
            if (s > maxSep) return false;
            if (s > bestEdge)
            {
                bestEdge = s;
                edgeAxis = axis / len;
                edgeA = i;
                edgeB = j;
            }
        }

    BoxBoxAxis kind = BoxBoxAxis::FaceA;
    float best = bestFaceA;
    if (bestFaceB > best + cBoxFaceBBias)
    {
        kind = BoxBoxAxis::FaceB;
        best = bestFaceB;
    }
    // The best face axis, in A's frame: an edge axis close to it is read through the faces (below)
    const Vec3 faceAxis = kind == BoxBoxAxis::FaceA ? Vec3(Vec3::Unit(faceA)) : Vec3(c.col(faceB));
    if (bestEdge > best + cBoxEdgeBias) kind = BoxBoxAxis::Edge;
    if (outAxis != nullptr) *outAxis = kind;

    Vec3 n;
    if (kind == BoxBoxAxis::Edge)
    {
        n = rotA * edgeAxis;
        if (n.dot(d) < 0.0f) n = -n;
        // The supporting edge of each box: all coordinates fixed by the support direction except the edge's
        // own
        Vec3 cornerA = BoxCorner(rotA.transpose() * n, eA);
        Vec3 cornerB = BoxCorner(rotB.transpose() * -n, eB);
        cornerA[edgeA] = eA[edgeA];
        cornerB[edgeB] = eB[edgeB];
        Vec3 endA = cornerA;
        Vec3 endB = cornerB;
        endA[edgeA] = -eA[edgeA];
        endB[edgeB] = -eB[edgeB];
        float s;
        float u;
        Vec3 pA;
        Vec3 pB;
        ClosestPointsSegmentSegment(inTransformA * cornerA, inTransformA * endA, inTransformB * cornerB,
                                    inTransformB * endB, s, u, pA, pB);
        const ContactPoint edges{pA, pB, (pA - pB).dot(n)};
        outManifold.mNormal = n;
        // Near a face axis the edges cross where a face lies nearly flat on the other box (a landing box
        // tilted by a fraction of a degree gets here by more than the bias). Their single point would carry
        // that face on one corner, and the box would spin deep into the other: the faces' clipped points
        // hold it, with the edges' pair among them so that the manifold is as deep as the axis
        if (std::abs(edgeAxis.dot(faceAxis)) >= cBoxEdgeAxisNearFaceCos)
        {
            Vec3 faceOfA[4];
            Vec3 faceOfB[4];
            BoxSupportingFace(inTransformA.mPosition, rotA, eA, n, faceOfA);
            BoxSupportingFace(inTransformB.mPosition, rotB, eB, -n, faceOfB);
            if (ManifoldFromFaces(faceOfA, 4, faceOfB, 4, n, maxSep, outManifold) > 0)
            {
                if (MaxPenetration(outManifold) < edges.mPenetration - cClippedGapSlack)
                    PutContactIn(edges, outManifold);
                return true;
            }
        }
        outManifold.mNumPoints = 1;
        outManifold.mPoints[0] = edges;
        return true;
    }

    Vec3 incident[4];
    ReferenceFace ref;
    const bool refIsA = kind == BoxBoxAxis::FaceA;
    if (refIsA)
    {
        const float sign = t[faceA] < 0.0f ? -1.0f : 1.0f;
        ref = MakeReferenceFace(inTransformA.mPosition, rotA, eA, faceA, sign);
        n = ref.mNormal;
        BoxSupportingFace(inTransformB.mPosition, rotB, eB, -n, incident);
    }
    else
    {
        const float sign = tInB[faceB] < 0.0f ? -1.0f : 1.0f;
        ref = MakeReferenceFace(inTransformB.mPosition, rotB, eB, faceB, -sign);
        n = -ref.mNormal;
        BoxSupportingFace(inTransformA.mPosition, rotA, eA, n, incident);
    }
    outManifold.mNormal = n;
    // The two boxes' support points along the normal: the axis's own gap apart along it
    const auto supportPair = [&]() -> ContactPoint
    {
        const Vec3 pA = inTransformA * BoxCorner(rotA.transpose() * n, eA);
        const Vec3 pB = inTransformB * BoxCorner(rotB.transpose() * -n, eB);
        return {pA, pB, (pA - pB).dot(n)};
    };
    if (ClipIncidentAgainstReference(ref, incident, refIsA, maxSep, outManifold) > 0)
    {
        // KeepTheContactGap, the support pair made only when it goes in
        if (ClaimsMoreClearance(outManifold, -best)) PutContactIn(supportPair(), outManifold);
        return true;
    }

    // Clipping lost everything (only possible through float noise at a corner): use the two support points
    const ContactPoint support = supportPair();
    if (support.mPenetration < -maxSep) return false;
    outManifold.mNumPoints = 1;
    outManifold.mPoints[0] = support;
    return true;
}

} // namespace cairn::physics
