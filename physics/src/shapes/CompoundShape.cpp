#include "cairn/physics/shapes/CompoundShape.h"

#include <algorithm>
#include <bit>
#include <string>

namespace cairn::physics
{

Result<std::shared_ptr<const CompoundShape>> CompoundShape::Create(std::vector<SubShape> inSubShapes)
{
    if (inSubShapes.empty())
        return MakeError(ErrorCode::DegenerateShape, "CompoundShape: needs at least one sub-shape");
    if (inSubShapes.size() > size_t(std::numeric_limits<SubShapeID>::max()))
        return MakeError(ErrorCode::InvalidArgument, "CompoundShape: too many sub-shapes");
    for (size_t i = 0; i < inSubShapes.size(); ++i)
    {
        const SubShape& sub = inSubShapes[i];
        if (sub.mShape == nullptr)
            return MakeError(ErrorCode::InvalidArgument,
                             "CompoundShape: sub-shape " + std::to_string(i) + " is null");
        if (!IsValidWorldPosition(sub.mLocalTransform.mPosition) ||
            !IsValidRotation(sub.mLocalTransform.mRotation))
            return MakeError(ErrorCode::InvalidArgument,
                             "CompoundShape: sub-shape " + std::to_string(i) +
                                 " has a non-finite position or a non-unit rotation");
        if (sub.mShape->GetType() == ShapeType::Compound &&
            static_cast<const CompoundShape&>(*sub.mShape).GetDepth() >= cMaxDepth)
            return MakeError(ErrorCode::InvalidArgument, "CompoundShape: sub-shape " + std::to_string(i) +
                                                             " nests compounds " + std::to_string(cMaxDepth) +
                                                             " deep, the most allowed");
    }
    return std::shared_ptr<const CompoundShape>(std::make_shared<CompoundShape>(std::move(inSubShapes)));
}

CompoundShape::CompoundShape(std::vector<SubShape> inSubShapes)
    : Shape(ShapeType::Compound), mSubShapes(std::move(inSubShapes))
{
    for (SubShape& sub : mSubShapes)
    {
        // Create() accepts rotations within a small tolerance of unit length; store them exactly unit
        sub.mLocalTransform.mRotation.normalize();
        mBounds.Encapsulate(sub.mShape->GetWorldBounds(sub.mLocalTransform));
        if (sub.mShape->GetType() == ShapeType::Compound)
            mDepth = std::max(mDepth, static_cast<const CompoundShape&>(*sub.mShape).GetDepth() + 1);
    }
}

AABB CompoundShape::GetLocalBounds() const
{
    return mBounds;
}

AABB CompoundShape::GetWorldBounds(const Transform& inTransform) const
{
    // Each child bounds itself at its world transform, which is tighter than rotating the compound's box
    AABB bounds;
    for (const SubShape& sub : mSubShapes)
        bounds.Encapsulate(sub.mShape->GetWorldBounds(inTransform * sub.mLocalTransform));
    return bounds;
}

MassProperties CompoundShape::GetMassProperties(float inDensity) const
{
    MassProperties total;
    Vec3 weightedCenter = Vec3::Zero();
    std::vector<MassProperties> children;
    children.reserve(mSubShapes.size());
    for (const SubShape& sub : mSubShapes)
    {
        MassProperties child = sub.mShape->GetMassProperties(inDensity);
        // Into compound space: move the centre, rotate the inertia tensor (R I R^T)
        const Mat3 rotation = sub.mLocalTransform.mRotation.toRotationMatrix();
        child.mCenterOfMass = sub.mLocalTransform * child.mCenterOfMass;
        child.mInertia = rotation * child.mInertia * rotation.transpose();
        total.mMass += child.mMass;
        weightedCenter += child.mMass * child.mCenterOfMass;
        children.push_back(child);
    }
    if (!(total.mMass > 0.0f)) return {};
    total.mCenterOfMass = weightedCenter / total.mMass;

    // Parallel axis theorem: I + m (|r|^2 E - r r^T), r = child centre relative to the compound's centre
    for (const MassProperties& child : children)
    {
        const Vec3 r = child.mCenterOfMass - total.mCenterOfMass;
        total.mInertia +=
            child.mInertia + child.mMass * (r.squaredNorm() * Mat3::Identity() - r * r.transpose());
    }
    return total;
}

namespace
{
int ChildBits(size_t inNumChildren)
{
    return inNumChildren <= 1 ? 0 : int(std::bit_width(uint64_t(inNumChildren - 1)));
}
} // namespace

SubShapeID CompoundShape::MakeManifoldSubShapeID(uint32_t inChild, size_t inNumChildren,
                                                 SubShapeID inChildSubShape)
{
    const int bits = ChildBits(inNumChildren);
    if (bits >= 32) return inChild; // Cannot happen with a vector's worth of children; be safe
    if ((uint64_t(inChildSubShape) << bits) <= 0xffffffffull) return inChildSubShape << bits | inChild;
    // Too many triangles for the bits left: a mix of both, with the child index kept in the low bits
    uint64_t mixed = (uint64_t(inChildSubShape) * 0x9e3779b97f4a7c15ull) >> 32;
    return SubShapeID(mixed << bits) | inChild;
}

uint32_t CompoundShape::GetManifoldChild(SubShapeID inID, size_t inNumChildren)
{
    const int bits = ChildBits(inNumChildren);
    return bits == 0 ? 0u : inID & ((1u << bits) - 1u);
}

bool CompoundShape::CastCheckedRay(const RayCast& inLocalRay, RayHit& ioHit) const
{
    bool hit = false;
    for (size_t i = 0; i < mSubShapes.size(); ++i)
    {
        const Transform& transform = mSubShapes[i].mLocalTransform;
        const RayCast childRay{transform.InverseTransformPoint(inLocalRay.mOrigin),
                               transform.InverseRotateVector(inLocalRay.mDirection)};
        RayHit childHit;
        childHit.mFraction = ioHit.mFraction;
        if (!mSubShapes[i].mShape->CastRay(childRay, childHit)) continue;
        ioHit.mFraction = childHit.mFraction;
        ioHit.mNormal = transform.RotateVector(childHit.mNormal);
        ioHit.mSubShape = SubShapeID(i);
        hit = true;
    }
    return hit;
}

void CompoundShape::VisitTriangles(const AABB& inLocalBox, TriangleVisitor inVisitor) const
{
    if (!inLocalBox.Overlaps(mBounds)) return;
    for (size_t i = 0; i < mSubShapes.size(); ++i)
    {
        const Transform& transform = mSubShapes[i].mLocalTransform;
        // The box in child space is the compound box rotated back and boxed again: conservative
        const AABB childBox = inLocalBox.Transformed(transform.Inverse());
        mSubShapes[i].mShape->VisitTriangles(childBox,
                                             [&](const Triangle& inTriangle)
                                             {
                                                 Triangle triangle = inTriangle;
                                                 for (Vec3& v : triangle.mV)
                                                     v = transform * v;
                                                 // As for ray hits, the sub-shape of a compound is the
                                                 // child's index
                                                 triangle.mSubShape = SubShapeID(i);
                                                 inVisitor(triangle);
                                             });
    }
}

} // namespace cairn::physics
