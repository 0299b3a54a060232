#include "narrowphase/ManifoldMerger.h"

#include "narrowphase/FaceClipping.h"

namespace cairn::physics
{

bool ManifoldMerger::Add(const ContactManifold& inManifold)
{
    for (int g = 0; g < mNumGroups; ++g)
    {
        Group& group = mGroups[g];
        if (group.mFirstNormal.dot(inManifold.mNormal) < cMergeNormalCos) continue;
        group.mNormalSum += inManifold.mNormal;
        ++group.mNumMerged;
        AddPoints(group, inManifold);
        return true;
    }
    if (mNumGroups == cMaxGroups) return false;
    Group& group = mGroups[mNumGroups++];
    group.mFirstNormal = inManifold.mNormal;
    group.mNormalSum = inManifold.mNormal;
    group.mSubShapeA = inManifold.mSubShapeA;
    group.mSubShapeB = inManifold.mSubShapeB;
    group.mNumMerged = 1;
    group.mNumPoints = 0;
    AddPoints(group, inManifold);
    return true;
}

void ManifoldMerger::AddPoints(Group& ioGroup, const ContactManifold& inManifold)
{
    constexpr float cSameSq = cSamePointDistance * cSamePointDistance;
    for (int i = 0; i < inManifold.mNumPoints; ++i)
    {
        const ContactPoint& point = inManifold.mPoints[i];
        bool known = false;
        for (int k = 0; k < ioGroup.mNumPoints && !known; ++k)
        {
            ContactPoint& other = ioGroup.mPoints[k];
            if ((other.mPositionOnA - point.mPositionOnA).squaredNorm() > cSameSq ||
                (other.mPositionOnB - point.mPositionOnB).squaredNorm() > cSameSq)
                continue;
            known = true;
            if (point.mPenetration > other.mPenetration) other = point; // The deeper report of the two
        }
        if (known) continue;
        if (ioGroup.mNumPoints == cMaxGroupPoints) Compact(ioGroup);
        ioGroup.mPoints[ioGroup.mNumPoints++] = point;
    }
}

void ManifoldMerger::Compact(Group& ioGroup)
{
    ContactManifold reduced;
    const Vec3 normal = ioGroup.mNormalSum.normalized();
    ReduceContactPoints(ioGroup.mPoints, ioGroup.mNumPoints, normal, reduced);
    ioGroup.mNumPoints = reduced.mNumPoints;
    for (int i = 0; i < reduced.mNumPoints; ++i)
        ioGroup.mPoints[i] = reduced.mPoints[i];
}

void ManifoldMerger::Finish(const Group& inGroup, ContactManifold& outManifold)
{
    outManifold.mSubShapeA = inGroup.mSubShapeA;
    outManifold.mSubShapeB = inGroup.mSubShapeB;
    if (inGroup.mNumMerged == 1)
    {
        // Alone: as the shapes reported it
        outManifold.mNormal = inGroup.mFirstNormal;
        outManifold.mNumPoints = inGroup.mNumPoints;
        for (int i = 0; i < inGroup.mNumPoints; ++i)
            outManifold.mPoints[i] = inGroup.mPoints[i];
        return;
    }
    // The members' normals are within a few degrees of each other: their sum is far from zero
    outManifold.mNormal = inGroup.mNormalSum.normalized();
    // Each point's depth along the shared normal (its gap was measured along its own triangle's)
    ContactPoint points[cMaxGroupPoints];
    for (int i = 0; i < inGroup.mNumPoints; ++i)
    {
        points[i] = inGroup.mPoints[i];
        points[i].mPenetration = (points[i].mPositionOnA - points[i].mPositionOnB).dot(outManifold.mNormal);
    }
    ReduceContactPoints(points, inGroup.mNumPoints, outManifold.mNormal, outManifold);
}

} // namespace cairn::physics
