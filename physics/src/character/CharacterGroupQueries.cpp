#include "character/CharacterGroupQueries.h"

#include "cairn/physics/narrowphase/CollideShapes.h"
#include "narrowphase/FaceClipping.h"
#include "narrowphase/ShapeCast.h"

namespace cairn::physics
{
float BoundingRadius(const Shape& inShape)
{
    const AABB bounds = inShape.GetLocalBounds();
    return std::max(bounds.mMin.norm(), bounds.mMax.norm());
}

namespace
{
/// The distance from inPoint to the segment from inStart along inDisplacement.
float DistanceToSegment(const Vec3& inPoint, const Vec3& inStart, const Vec3& inDisplacement)
{
    const float lengthSq = inDisplacement.squaredNorm();
    const float along =
        lengthSq > 0.0f ? std::clamp((inPoint - inStart).dot(inDisplacement) / lengthSq, 0.0f, 1.0f) : 0.0f;
    return (inStart + along * inDisplacement - inPoint).norm();
}
} // namespace

std::optional<MemberCastHit> CastAgainstMembers(const CharacterGroup& inGroup,
                                                CharacterGroup::MemberID inSelf, const Shape& inShape,
                                                const Transform& inStart, const Vec3& inDisplacement,
                                                float inMaxFraction)
{
    ShapeCastSettings settings;
    settings.mTolerance = QueryCastTolerance(inStart.mPosition);
    settings.mMaxFraction = inMaxFraction;
    const float reach = BoundingRadius(inShape) + settings.mTolerance;
    std::optional<MemberCastHit> best;
    AABB swept(inStart.mPosition, inStart.mPosition);
    swept.Encapsulate(inStart.mPosition + inDisplacement);
    inGroup.ForEachMemberNear(
        swept.Expanded(reach),
        [&](CharacterGroup::MemberID inMember, const Shape& inOther, const Transform& inAt, float inRadius)
        {
            if (inMember == inSelf ||
                DistanceToSegment(inAt.mPosition, inStart.mPosition, inDisplacement) > reach + inRadius)
                return;
            // A later member wins only by touching first
            if (best) settings.mMaxFraction = best->mCast.mFraction;
            const std::optional<ShapeCastHit> hit =
                CastShapeAgainst(inShape, inStart, inDisplacement, inOther, inAt, settings);
            if (!hit || (best && hit->mFraction >= best->mCast.mFraction)) return;
            const ContactPoint& point = hit->mManifold.mPoints[hit->mDeepestPoint];
            best = MemberCastHit{inMember, ShapeCastResult{BodyID(), hit->mFraction, point.mPositionOnB,
                                                           -hit->mManifold.mNormal, point.mPenetration,
                                                           hit->mManifold.mSubShapeB}};
        });
    return best;
}

std::optional<MemberOverlap> DeepestMemberOverlap(const CharacterGroup& inGroup,
                                                  CharacterGroup::MemberID inSelf, const Shape& inShape,
                                                  const Transform& inTransform, float inMinPenetration)
{
    const float reach = BoundingRadius(inShape);
    std::optional<MemberOverlap> deepest;
    float deepestPenetration = inMinPenetration;
    CollideSettings settings;
    settings.mMaxSeparation = 0.0f;
    inGroup.ForEachMemberNear(
        AABB(inTransform.mPosition, inTransform.mPosition).Expanded(reach),
        [&](CharacterGroup::MemberID inMember, const Shape& inOther, const Transform& inAt, float inRadius)
        {
            if (inMember == inSelf || (inAt.mPosition - inTransform.mPosition).norm() > reach + inRadius)
                return;
            CollideShapes(inShape, inTransform, inOther, inAt, settings,
                          [&](const ContactManifold& inManifold)
                          {
                              const float penetration = MaxPenetration(inManifold);
                              if (penetration <= deepestPenetration) return;
                              deepestPenetration = penetration;
                              deepest = MemberOverlap{inMember, inManifold};
                          });
        });
    return deepest;
}

} // namespace cairn::physics
