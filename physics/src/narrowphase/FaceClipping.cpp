#include "narrowphase/FaceClipping.h"

#include <algorithm>

namespace cairn::physics
{

namespace
{

/// A face must be within about 60 degrees of the contact normal to serve as reference: projecting along the
/// normal onto a steeper face would move points far away.
constexpr float cMinReferenceCos = 0.5f;

/// Edges more parallel than this (about 5 degrees) give a two-point edge-edge manifold.
constexpr float cParallelEdgeCos = 0.996f;

// Newell's method: robust normal of a planar polygon, zero when it has no area
Vec3 PolygonNormal(const Vec3* inFace, int inCount)
{
    Vec3 n = Vec3::Zero();
    for (int i = 0; i < inCount; ++i)
        n += inFace[i].cross(inFace[(i + 1) % inCount]);
    const float len = n.norm();
    return len > 1.0e-12f ? Vec3(n / len) : Vec3::Zero();
}

// Keeps the part of the polygon (or, for 2 vertices, the segment) on the inner side of the plane
// dot(inPlaneNormal, p) >= inPlaneD. Returns the new count.
int ClipByPlane(const Vec3* inPoly, int inCount, const Vec3& inPlaneNormal, float inPlaneD, Vec3* outPoly)
{
    if (inCount == 0) return 0;
    if (inCount == 1)
    {
        if (inPlaneNormal.dot(inPoly[0]) < inPlaneD) return 0;
        outPoly[0] = inPoly[0];
        return 1;
    }
    if (inCount == 2)
    {
        const float d0 = inPlaneNormal.dot(inPoly[0]) - inPlaneD;
        const float d1 = inPlaneNormal.dot(inPoly[1]) - inPlaneD;
        if (d0 < 0.0f && d1 < 0.0f) return 0;
        outPoly[0] = inPoly[0];
        outPoly[1] = inPoly[1];
        if (d0 < 0.0f)
            outPoly[0] = inPoly[0] + (inPoly[1] - inPoly[0]) * (d0 / (d0 - d1));
        else if (d1 < 0.0f)
            outPoly[1] = inPoly[0] + (inPoly[1] - inPoly[0]) * (d0 / (d0 - d1));
        return 2;
    }
    int count = 0;
    Vec3 prev = inPoly[inCount - 1];
    float prevD = inPlaneNormal.dot(prev) - inPlaneD;
    for (int i = 0; i < inCount && count < cMaxClipPoints - 1; ++i)
    {
        const Vec3& cur = inPoly[i];
        const float curD = inPlaneNormal.dot(cur) - inPlaneD;
        if ((prevD < 0.0f) != (curD < 0.0f))
            outPoly[count++] = prev + (cur - prev) * (prevD / (prevD - curD));
        if (curD >= 0.0f) outPoly[count++] = cur;
        prev = cur;
        prevD = curD;
    }
    return count;
}

// Clips the incident polygon to the prism swept by the reference polygon along inNormal, then projects each
// point along inNormal onto the reference plane. inSign is +1 when the reference belongs to A, -1 for B.
int ClipAgainstReference(const Vec3* inRef, int inRefCount, const Vec3& inRefNormal, const Vec3* inInc,
                         int inIncCount, const Vec3& inNormal, float inSign, float inMaxSeparation,
                         ContactPoint* outPoints)
{
    Vec3 bufA[cMaxClipPoints];
    Vec3 bufB[cMaxClipPoints];
    int count = std::min(inIncCount, cMaxClipPoints);
    std::copy(inInc, inInc + count, bufA);
    Vec3* cur = bufA;
    Vec3* next = bufB;

    Vec3 centroid = Vec3::Zero();
    for (int i = 0; i < inRefCount; ++i)
        centroid += inRef[i];
    centroid /= static_cast<float>(inRefCount);

    for (int i = 0; i < inRefCount && count > 0; ++i)
    {
        const Vec3& a = inRef[i];
        const Vec3 edge = inRef[(i + 1) % inRefCount] - a;
        // Side plane through the edge, containing the normal; inward facing whatever the winding is
        Vec3 m = edge.cross(inNormal);
        if (m.dot(centroid - a) < 0.0f) m = -m;
        if (m.squaredNorm() < 1.0e-20f) continue;
        count = ClipByPlane(cur, count, m, m.dot(a), next);
        std::swap(cur, next);
    }

    const float nDotRef = inNormal.dot(inRefNormal);
    int numPoints = 0;
    for (int i = 0; i < count; ++i)
    {
        // Move along the normal until on the reference plane
        const float t = (inRef[0] - cur[i]).dot(inRefNormal) / nDotRef;
        const Vec3 onRef = cur[i] + t * inNormal;
        ContactPoint& cp = outPoints[numPoints];
        cp.mPositionOnA = inSign > 0.0f ? onRef : cur[i];
        cp.mPositionOnB = inSign > 0.0f ? cur[i] : onRef;
        cp.mPenetration = (cp.mPositionOnA - cp.mPositionOnB).dot(inNormal);
        if (cp.mPenetration >= -inMaxSeparation) ++numPoints;
    }
    return numPoints;
}

} // namespace

bool ClaimsMoreClearance(const ContactManifold& inManifold, float inContactPenetration)
{
    const float leastGap = -MaxPenetration(inManifold);
    return inManifold.mNumPoints > 0 && leastGap > 0.0f &&
           leastGap > -inContactPenetration + cClippedGapSlack;
}

void PutContactIn(const ContactPoint& inContact, ContactManifold& ioManifold)
{
    int farthest = 0;
    for (int i = 1; i < ioManifold.mNumPoints; ++i)
        if (ioManifold.mPoints[i].mPenetration < ioManifold.mPoints[farthest].mPenetration) farthest = i;
    const int slot = ioManifold.mNumPoints < ContactManifold::cMaxPoints ? ioManifold.mNumPoints++ : farthest;
    ioManifold.mPoints[slot] = inContact;
}

int ReduceContactPoints(const ContactPoint* inPoints, int inCount, const Vec3& inNormal,
                        ContactManifold& outManifold)
{
    if (inCount <= ContactManifold::cMaxPoints)
    {
        for (int i = 0; i < inCount; ++i)
            outManifold.mPoints[i] = inPoints[i];
        outManifold.mNumPoints = inCount;
        return inCount;
    }
    // The deepest point must stay: it is what the solver pushes on hardest
    int i0 = 0;
    for (int i = 1; i < inCount; ++i)
        if (inPoints[i].mPenetration > inPoints[i0].mPenetration) i0 = i;
    const Vec3& p0 = inPoints[i0].mPositionOnB;
    int i1 = -1;
    float bestSq = -1.0f;
    for (int i = 0; i < inCount; ++i)
    {
        const float d = (inPoints[i].mPositionOnB - p0).squaredNorm();
        if (i != i0 && d > bestSq)
        {
            bestSq = d;
            i1 = i;
        }
    }
    // Signed areas of the triangles (p0, p1, p) around the normal: the largest on each side
    const Vec3 e = inPoints[i1].mPositionOnB - p0;
    int i2 = -1;
    int i3 = -1;
    float maxArea = 0.0f;
    float minArea = 0.0f;
    for (int i = 0; i < inCount; ++i)
    {
        if (i == i0 || i == i1) continue;
        const float area = e.cross(inPoints[i].mPositionOnB - p0).dot(inNormal);
        if (i2 < 0 || area > maxArea)
        {
            maxArea = area;
            i2 = i;
        }
        if (i3 < 0 || area < minArea)
        {
            minArea = area;
            i3 = i;
        }
    }
    int n = 0;
    outManifold.mPoints[n++] = inPoints[i0];
    outManifold.mPoints[n++] = inPoints[i1];
    if (i2 >= 0) outManifold.mPoints[n++] = inPoints[i2];
    if (i3 >= 0 && i3 != i2) outManifold.mPoints[n++] = inPoints[i3];
    outManifold.mNumPoints = n;
    return n;
}

int ManifoldFromFaces(const Vec3* inFaceA, int inCountA, const Vec3* inFaceB, int inCountB,
                      const Vec3& inNormal, float inMaxSeparation, ContactManifold& outManifold)
{
    outManifold.mNumPoints = 0;
    if (inCountA <= 0 || inCountB <= 0) return 0;

    const Vec3 normalA = inCountA >= 3 ? PolygonNormal(inFaceA, inCountA) : Vec3::Zero();
    const Vec3 normalB = inCountB >= 3 ? PolygonNormal(inFaceB, inCountB) : Vec3::Zero();
    const float cosA = std::abs(normalA.dot(inNormal));
    const float cosB = std::abs(normalB.dot(inNormal));

    ContactPoint points[cMaxClipPoints];
    int count = 0;
    // Ties go to A so that the result does not flicker between two parallel faces
    if (cosA >= cMinReferenceCos && cosA >= cosB)
        count = ClipAgainstReference(inFaceA, inCountA, normalA, inFaceB, inCountB, inNormal, 1.0f,
                                     inMaxSeparation, points);
    else if (cosB >= cMinReferenceCos)
        count = ClipAgainstReference(inFaceB, inCountB, normalB, inFaceA, inCountA, inNormal, -1.0f,
                                     inMaxSeparation, points);
    else if (inCountA == 2 && inCountB == 2)
    {
        // Two edges: only parallel ones give more than the single deepest point
        Vec3 dirA = inFaceA[1] - inFaceA[0];
        const float lenA = dirA.norm();
        const Vec3 dirB = inFaceB[1] - inFaceB[0];
        if (lenA < 1.0e-6f || dirB.norm() < 1.0e-6f ||
            std::abs(dirA.dot(dirB)) < cParallelEdgeCos * lenA * dirB.norm())
            return 0;
        dirA /= lenA;
        // Clip B's edge to the slab spanned by A's edge along A's direction
        Vec3 seg[2] = {inFaceB[0], inFaceB[1]};
        Vec3 tmp[2];
        int n = ClipByPlane(seg, 2, dirA, dirA.dot(inFaceA[0]), tmp);
        n = n == 2 ? ClipByPlane(tmp, 2, -dirA, -dirA.dot(inFaceA[1]), seg) : 0;
        for (int i = 0; i < n; ++i)
        {
            // Closest point on A's line, moved so that the pair is aligned with the normal
            const Vec3 onLine = inFaceA[0] + dirA * dirA.dot(seg[i] - inFaceA[0]);
            ContactPoint& cp = points[count];
            cp.mPositionOnB = seg[i];
            cp.mPenetration = (onLine - seg[i]).dot(inNormal);
            cp.mPositionOnA = seg[i] + inNormal * cp.mPenetration;
            if (cp.mPenetration >= -inMaxSeparation) ++count;
        }
        if (count == 2 && (points[0].mPositionOnB - points[1].mPositionOnB).squaredNorm() < 1.0e-10f)
            count = 1;
    }
    return ReduceContactPoints(points, count, inNormal, outManifold);
}

} // namespace cairn::physics
