#include "character/CharacterMoves.h"

#include "character/CharacterGroupQueries.h"
#include "narrowphase/FaceClipping.h"

#include <algorithm>

namespace cairn::physics
{

namespace
{
/// A move that meets a surface at a slant backs off along its direction by padding / cos(angle to the normal)
/// to keep the gap along the normal; at a grazing angle that would be metres, so the cosine counts as at
/// least this (the gap kept is then smaller, and the slide that follows keeps off the surface anyway).
constexpr float cMinApproachCos = 0.25f;

/// Overlaps shallower than this (metres) are left: the moves keep mPadding clear of every surface, so only a
/// body that moved into the character or appeared on it is this deep, and a cast slides along a touch.
constexpr float cPushOutSlack = 1.0e-3f;
/// Rounds of pushing out: each takes the deepest body; a character wedged between bodies stops after these.
constexpr int cPushOutRounds = 4;

/// A step up moves at least this far forward (metres), so that a slow walk still gets onto the stair.
constexpr float cMinStepForward = 0.02f;
/// A step up that gets no farther forward than this at the raised height is a wall, not a stair.
constexpr float cMinStepAdvance = 1.0e-3f;
/// Where the stair's edge is too steep to stand on, the ground this far farther on must be walkable.
constexpr float cStepForwardTest = 0.15f;
} // namespace

void RecordContact(const CharacterMoveContext& inContext, const BodyID& inBody, const Vec3& inPoint,
                   const Vec3& inNormal)
{
    if (inBody.IsInvalid()) return;
    for (const CharacterContact& contact : inContext.mContacts)
        if (contact.mBody == inBody) return;
    inContext.mContacts.push_back({inBody, inPoint, inNormal});
}

void RecordCharacterContact(const CharacterMoveContext& inContext, CharacterGroup::MemberID inMember)
{
    if (inMember == CharacterGroup::cNoMember ||
        std::find(inContext.mCharacterContacts.begin(), inContext.mCharacterContacts.end(), inMember) !=
            inContext.mCharacterContacts.end())
        return;
    inContext.mCharacterContacts.push_back(inMember);
}

Result<CharacterSweep> SweepCharacter(const CharacterMoveContext& inContext, const Vec3& inStart,
                                      const Vec3& inDisplacement, bool inRecordContact)
{
    CharacterSweep sweep{inStart, std::nullopt};
    const float length = inDisplacement.norm();
    if (length < cMinCharacterMove) return sweep;
    Result<std::optional<ShapeCastResult>> cast = inContext.mQuery.CastShapeClosest(
        inContext.mShape, inContext.At(inStart), inDisplacement, inContext.mFilter);
    if (!cast) return cast.GetError();
    std::optional<ShapeCastResult> first = cast.Value();
    if (inContext.mGroup != nullptr)
    {
        // Another member in the way before the body (which holds none of them)
        const std::optional<MemberCastHit> member =
            CastAgainstMembers(*inContext.mGroup, inContext.mSelf, inContext.mShape, inContext.At(inStart),
                               inDisplacement, first ? first->mFraction : 1.0f);
        if (member && (!first || member->mCast.mFraction < first->mFraction))
        {
            first = member->mCast;
            sweep.mHitMember = member->mMember;
        }
    }
    if (!first)
    {
        sweep.mEnd = inStart + inDisplacement;
        return sweep;
    }
    const ShapeCastResult& hit = *first;
    const Vec3 direction = inDisplacement / length;
    const float approach = std::max(-direction.dot(hit.mNormal), cMinApproachCos);
    const float travel = std::max(hit.mFraction * length - inContext.mPadding / approach, 0.0f);
    sweep.mEnd = inStart + direction * travel;
    sweep.mHit = hit;
    if (inRecordContact)
    {
        RecordContact(inContext, hit.mBody, hit.mContactPoint, hit.mNormal);
        RecordCharacterContact(inContext, sweep.mHitMember);
    }
    return sweep;
}

Result<std::optional<CharacterSupport>> FindSupport(const CharacterMoveContext& inContext,
                                                    const Vec3& inPosition, const CharacterContact& inGround,
                                                    float inReach)
{
    if (inContext.IsWalkable(inGround.mNormal))
        return std::optional<CharacterSupport>({inGround.mBody, inGround.mPoint, inGround.mNormal});
    // (at least a padding long: a shape whose origin lies below it has no length of its own to reach down)
    const RayCast underfoot{inPosition,
                            -inContext.mUp * std::max(inContext.mBottom + inReach, inContext.mPadding)};
    Result<std::optional<RayCastResult>> ray = inContext.mQuery.CastRayClosest(underfoot, inContext.mFilter);
    if (!ray) return ray.GetError();
    if (!ray.Value() || !inContext.IsWalkable(ray.Value()->mNormal)) return std::optional<CharacterSupport>();
    return std::optional<CharacterSupport>({ray.Value()->mBody,
                                            underfoot.mOrigin + ray.Value()->mFraction * underfoot.mDirection,
                                            ray.Value()->mNormal});
}

Vec3 ClipToPlanes(const Vec3& inVector, std::span<const Vec3> inNormals)
{
    // A projection's rounding leaves it a hair into its own plane: that is not pointing into it
    const float slack = 1.0e-5f * inVector.norm();
    const auto pointsIntoNone = [&](const Vec3& inCandidate)
    {
        return std::all_of(inNormals.begin(), inNormals.end(),
                           [&](const Vec3& inNormal) { return inCandidate.dot(inNormal) >= -slack; });
    };
    if (pointsIntoNone(inVector)) return inVector;
    // Each candidate is inVector's projection on a subspace, so the longest allowed one is the nearest
    Vec3 best = Vec3::Zero();
    float bestLengthSq = 0.0f;
    const auto consider = [&](const Vec3& inCandidate)
    {
        const float lengthSq = inCandidate.squaredNorm();
        if (lengthSq > bestLengthSq && pointsIntoNone(inCandidate))
        {
            best = inCandidate;
            bestLengthSq = lengthSq;
        }
    };
    for (size_t i = 0; i < inNormals.size(); ++i)
    {
        const float into = inVector.dot(inNormals[i]);
        if (into < 0.0f) consider(inVector - into * inNormals[i]);
    }
    for (size_t i = 0; i < inNormals.size(); ++i)
        for (size_t j = i + 1; j < inNormals.size(); ++j)
        {
            const Vec3 crease = inNormals[i].cross(inNormals[j]);
            const float creaseLength = crease.norm();
            if (creaseLength < 1.0e-4f) continue; // Parallel planes: the one-plane projections cover them
            const Vec3 along = crease / creaseLength;
            consider(along * inVector.dot(along));
        }
    return best;
}

Result<Vec3> PushOutOfBodies(const CharacterMoveContext& inContext, const Vec3& inStart)
{
    // Per-thread scratch, as the queries' own: a controller's Update never re-enters itself on one thread
    thread_local std::vector<ShapeQueryHit> tHits;
    Vec3 position = inStart;
    for (int round = 0; round < cPushOutRounds; ++round)
    {
        const Status collided =
            inContext.mQuery.CollideShape(inContext.mShape, inContext.At(position), tHits, inContext.mFilter);
        if (!collided) return collided.GetError();
        const ShapeQueryHit* deepest = nullptr;
        float deepestPenetration = cPushOutSlack;
        for (const ShapeQueryHit& hit : tHits)
        {
            const float penetration = MaxPenetration(hit.mManifold);
            if (penetration > deepestPenetration)
            {
                deepest = &hit;
                deepestPenetration = penetration;
            }
        }
        // Another member deeper still
        const std::optional<MemberOverlap> member =
            inContext.mGroup == nullptr
                ? std::nullopt
                : DeepestMemberOverlap(*inContext.mGroup, inContext.mSelf, inContext.mShape,
                                       inContext.At(position), deepestPenetration);
        if (deepest == nullptr && !member) break;
        // The manifold's normal points from the character towards the body. The push is swept: a body behind
        // the character stops it, rather than taking it in (it leaves the body it is pushed out of, which
        // so does not stop it)
        const ContactManifold& manifold = member ? member->mManifold : deepest->mManifold;
        if (member) deepestPenetration = MaxPenetration(manifold);
        int deepestPoint = 0;
        for (int i = 1; i < manifold.mNumPoints; ++i)
            if (manifold.mPoints[i].mPenetration > manifold.mPoints[deepestPoint].mPenetration)
                deepestPoint = i;
        if (member)
            RecordCharacterContact(inContext, member->mMember);
        else
            RecordContact(inContext, deepest->mBody, manifold.mPoints[deepestPoint].mPositionOnB,
                          -manifold.mNormal);
        Result<CharacterSweep> push = SweepCharacter(
            inContext, position, -manifold.mNormal * (deepestPenetration + inContext.mPadding), false);
        if (!push) return push.GetError();
        if ((push.Value().mEnd - position).norm() < cMinCharacterMove) break; // Wedged: it stays as it is
        position = push.Value().mEnd;
    }
    return position;
}

namespace
{
Result<std::optional<Vec3>> TryStepUp(const CharacterMoveContext& inContext, const Vec3& inStart,
                                      const Vec3& inHorizontal, float inStepHeight)
{
    const float length = inHorizontal.norm();
    if (length < cMinCharacterMove) return std::optional<Vec3>();
    const Vec3 forward = inHorizontal / length;

    Result<CharacterSweep> up = SweepCharacter(inContext, inStart, inContext.mUp * inStepHeight);
    if (!up) return up.GetError();
    const Vec3 raised = up.Value().mEnd;
    const float rise = (raised - inStart).dot(inContext.mUp);
    if (rise <= inContext.mPadding) return std::optional<Vec3>(); // No headroom to step up into

    Result<CharacterSweep> along =
        SweepCharacter(inContext, raised, forward * std::max(length, cMinStepForward));
    if (!along) return along.GetError();
    const Vec3 ahead = along.Value().mEnd;
    if ((ahead - raised).dot(forward) < cMinStepAdvance) return std::optional<Vec3>();

    // Down no lower than the start: ground at the start's height or below is no stair (a ledge, or a fence
    // to climb over)
    Result<CharacterSweep> down = SweepCharacter(inContext, ahead, -inContext.mUp * rise);
    if (!down) return down.GetError();
    if (!down.Value().mHit) return std::optional<Vec3>();
    if (!inContext.IsWalkable(down.Value().mHit->mNormal))
    {
        // On the stair's edge a round bottom meets it at a slant: look at the tread a little farther on
        // (a look, not a move: what it meets is no contact)
        Result<CharacterSweep> further = SweepCharacter(inContext, ahead, forward * cStepForwardTest, false);
        if (!further) return further.GetError();
        Result<CharacterSweep> tread =
            SweepCharacter(inContext, further.Value().mEnd, -inContext.mUp * rise, false);
        if (!tread) return tread.GetError();
        if (!tread.Value().mHit || !inContext.IsWalkable(tread.Value().mHit->mNormal))
            return std::optional<Vec3>();
    }
    return std::optional<Vec3>(down.Value().mEnd);
}
} // namespace

Result<std::optional<Vec3>> StepUp(const CharacterMoveContext& inContext, const Vec3& inStart,
                                   const Vec3& inHorizontal, float inStepHeight)
{
    // A step not taken touched nothing: its casts' contacts go
    const size_t contactsBefore = inContext.mContacts.size();
    Result<std::optional<Vec3>> step = TryStepUp(inContext, inStart, inHorizontal, inStepHeight);
    if (!step || !step.Value()) inContext.mContacts.resize(contactsBefore);
    return step;
}

} // namespace cairn::physics
