#include "cairn/physics/shapes/BoxShape.h"

#include <string>

namespace cairn::physics
{

namespace
{

/// The 4 corners of the face of a box with outward normal inSign * axis inAxis, counter-clockwise from
/// outside.
void GetBoxFace(const Vec3& inHalfExtent, int inAxis, float inSign, Vec3 outVertices[4])
{
    // Axes j and k complete a right-handed frame with i (e_j x e_k = e_i), so this (j, k) order turns
    // counter-clockwise around +e_i; the negative face walks it backwards
    const int j = (inAxis + 1) % 3;
    const int k = (inAxis + 2) % 3;
    static constexpr float cCornerJ[4] = {-1.0f, 1.0f, 1.0f, -1.0f};
    static constexpr float cCornerK[4] = {-1.0f, -1.0f, 1.0f, 1.0f};
    for (int v = 0; v < 4; ++v)
    {
        const int corner = inSign > 0.0f ? v : 3 - v;
        Vec3 p;
        p[inAxis] = inSign * inHalfExtent[inAxis];
        p[j] = cCornerJ[corner] * inHalfExtent[j];
        p[k] = cCornerK[corner] * inHalfExtent[k];
        outVertices[v] = p;
    }
}

} // namespace

Result<std::shared_ptr<const BoxShape>> BoxShape::Create(const Vec3& inHalfExtent)
{
    if (!IsFinite(inHalfExtent) || inHalfExtent.maxCoeff() > cMaxWorldCoordinate)
        return MakeError(ErrorCode::InvalidArgument,
                         "BoxShape: half extents must be finite and <= cMaxWorldCoordinate");
    if (!(inHalfExtent.minCoeff() > 0.0f))
        return MakeError(ErrorCode::DegenerateShape, "BoxShape: every half extent must be > 0");
    return std::shared_ptr<const BoxShape>(std::make_shared<BoxShape>(inHalfExtent));
}

BoxShape::BoxShape(const Vec3& inHalfExtent) : ConvexShape(ShapeType::Box), mHalfExtent(inHalfExtent) {}

AABB BoxShape::GetLocalBounds() const
{
    return AABB::FromCenterExtent(Vec3::Zero(), mHalfExtent);
}

MassProperties BoxShape::GetMassProperties(float inDensity) const
{
    MassProperties props;
    const Vec3 sq = mHalfExtent.cwiseProduct(mHalfExtent);
    props.mMass = inDensity * 8.0f * mHalfExtent.prod();
    // m/12 (b^2 + c^2) with full sizes b = 2 hb, c = 2 hc
    const float k = props.mMass / 3.0f;
    props.mInertia = Vec3(k * (sq.y() + sq.z()), k * (sq.x() + sq.z()), k * (sq.x() + sq.y())).asDiagonal();
    return props;
}

bool BoxShape::CastCheckedRay(const RayCast& inLocalRay, RayHit& ioHit) const
{
    const Vec3& o = inLocalRay.mOrigin;
    const Vec3& d = inLocalRay.mDirection;
    if ((o.cwiseAbs().array() <= mHalfExtent.array()).all())
        return ShapeHelpers::ReportStartInside(inLocalRay, ioHit);

    float tEnter = 0.0f;
    float tExit = 1.0f;
    int enterAxis = -1;
    for (int axis = 0; axis < 3; ++axis)
    {
        if (d[axis] == 0.0f)
        {
            if (std::abs(o[axis]) > mHalfExtent[axis]) return false;
            continue;
        }
        const float inv = 1.0f / d[axis];
        float t1 = (-mHalfExtent[axis] - o[axis]) * inv;
        float t2 = (mHalfExtent[axis] - o[axis]) * inv;
        if (t1 > t2) std::swap(t1, t2);
        if (t1 > tEnter)
        {
            tEnter = t1;
            enterAxis = axis;
        }
        tExit = std::min(tExit, t2);
        if (tEnter > tExit) return false;
    }
    // enterAxis stays -1 only when the origin is inside, which was handled above (kept for float edge cases)
    if (enterAxis < 0 || !(tEnter < ioHit.mFraction)) return false;
    ioHit.mFraction = tEnter;
    ioHit.mNormal = Vec3::Zero();
    ioHit.mNormal[enterAxis] = d[enterAxis] > 0.0f ? -1.0f : 1.0f;
    ioHit.mSubShape = 0;
    return true;
}

void BoxShape::VisitTriangles(const AABB& inLocalBox, TriangleVisitor inVisitor) const
{
    if (!inLocalBox.Overlaps(GetLocalBounds())) return;
    for (int face = 0; face < 6; ++face)
    {
        Vec3 v[4];
        GetBoxFace(mHalfExtent, face / 2, face % 2 == 0 ? 1.0f : -1.0f, v);
        const Triangle triangles[2] = {{{v[0], v[1], v[2]}}, {{v[0], v[2], v[3]}}};
        for (const Triangle& triangle : triangles)
            if (ShapeHelpers::TriangleBounds(triangle.mV[0], triangle.mV[1], triangle.mV[2])
                    .Overlaps(inLocalBox))
                inVisitor(triangle);
    }
}

Vec3 BoxShape::GetSupport(const Vec3& inDirection) const
{
    Vec3 p;
    for (int axis = 0; axis < 3; ++axis)
        p[axis] = inDirection[axis] < 0.0f ? -mHalfExtent[axis] : mHalfExtent[axis];
    return p;
}

void BoxShape::GetSupportingFace(const Vec3& inDirection, SupportingFace& outFace) const
{
    // The outward face normals are the unit axes, so the best aligned one has the largest |component|
    int axis = 0;
    inDirection.cwiseAbs().maxCoeff(&axis);
    outFace.mCount = 4;
    GetBoxFace(mHalfExtent, axis, inDirection[axis] < 0.0f ? -1.0f : 1.0f, outFace.mVertices);
}

} // namespace cairn::physics
