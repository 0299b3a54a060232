#pragma once

// The moves a CharacterController is made of, each a few shape casts or overlap queries through WorldQuery:
// like the queries, any thread, no lock, never a wait for the step. A move stops the shape mPadding short of
// what it meets (along the surface's normal), so that the next move slides along that surface without
// touching it; a cast that leaves or slides along a body it touches is not stopped by it (WorldQuery.h).

#include "cairn/physics/character/CharacterController.h"

#include <optional>
#include <span>
#include <vector>

namespace cairn::physics
{

struct CharacterMoveContext
{
    const WorldQuery& mQuery;
    const Shape& mShape;
    Quat mRotation; ///< The shape's, turning its local y axis to mUp
    const QueryFilter& mFilter;
    Vec3 mUp;
    float mCosMaxSlope;
    float mPadding;
    float mBottom; ///< From the shape's origin down to its lowest point, along -mUp
    std::vector<CharacterContact>& mContacts; ///< Every body a move met, each once
    /// The character's group (null: none) and its number there; every member a move met, each once
    const CharacterGroup* mGroup;
    CharacterGroup::MemberID mSelf;
    std::vector<CharacterGroup::MemberID>& mCharacterContacts;

    bool IsWalkable(const Vec3& inNormal) const { return inNormal.dot(mUp) >= mCosMaxSlope; }
    Transform At(const Vec3& inPosition) const { return {inPosition, mRotation}; }
};

/// inVector without its part along inAxis (a unit vector): what of it lies across the axis.
inline Vec3 AcrossAxis(const Vec3& inVector, const Vec3& inAxis)
{
    return inVector - inVector.dot(inAxis) * inAxis;
}

/// The part of inRotation that turns about inAxis (a unit vector), the twist of its swing-twist split: how
/// far a rotating platform turns a character standing on it. Identity for a rotation with none (a half turn
/// about a level axis).
inline Quat TwistAbout(const Quat& inRotation, const Vec3& inAxis)
{
    const Vec3 along = inAxis * inRotation.vec().dot(inAxis);
    const Quat twist(inRotation.w(), along.x(), along.y(), along.z());
    const float norm = twist.norm();
    return norm > 1.0e-6f ? Quat(twist.coeffs() / norm) : Quat::Identity();
}

/// Adds a contact with inBody to the context's, unless it holds one with that body already or inBody is none
/// (another character).
void RecordContact(const CharacterMoveContext& inContext, const BodyID& inBody, const Vec3& inPoint,
                   const Vec3& inNormal);
/// Adds inMember to the context's members met, unless it is there already or is none.
void RecordCharacterContact(const CharacterMoveContext& inContext, CharacterGroup::MemberID inMember);

/// Moves shorter than this (metres) are not cast: nothing can stop them that a query would see.
inline constexpr float cMinCharacterMove = 1.0e-6f;

struct CharacterSweep
{
    Vec3 mEnd;                           ///< Where the move ends
    std::optional<ShapeCastResult> mHit; ///< What stopped it, if anything (no body: a member of the group)
    CharacterGroup::MemberID mHitMember = CharacterGroup::cNoMember; ///< The member that stopped it
};

/// From inStart along inDisplacement, to its end or mPadding short of the first body or other member of the
/// group in the way (a contact, unless inRecordContact is false).
Result<CharacterSweep> SweepCharacter(const CharacterMoveContext& inContext, const Vec3& inStart,
                                      const Vec3& inDisplacement, bool inRecordContact = true);

/// What holds a character up: the body, and the ground's normal there.
struct CharacterSupport
{
    BodyID mBody;
    Vec3 mPoint; ///< On its surface, world space
    Vec3 mNormal;
};

/// Whether inGround, under the character at inPosition, holds it up: where its normal is walkable, inGround;
/// where it is not, walkable ground straight under the character no more than inReach below its bottom (a
/// round bottom meets a stair's edge at a slant: the tread under it is the ground); else nullopt.
Result<std::optional<CharacterSupport>> FindSupport(const CharacterMoveContext& inContext,
                                                    const Vec3& inPosition, const CharacterContact& inGround,
                                                    float inReach);

/// The vector nearest inVector that points into none of the planes whose normals are inNormals: inVector
/// itself, its projection on one plane, on the crease of two, or zero in a corner.
Vec3 ClipToPlanes(const Vec3& inVector, std::span<const Vec3> inNormals);

/// inStart moved out of the bodies and other members of the group that overlap the shape there (a body or a
/// character that moved into the character, or a body added on it), deepest first, each to mPadding clear, in
/// a few rounds: a corner may push it back in.
Result<Vec3> PushOutOfBodies(const CharacterMoveContext& inContext, const Vec3& inStart);

/// A step up a stair: up by at most inStepHeight, along inHorizontal, then down onto walkable ground no lower
/// than inStart. Where the stair's edge is too steep to stand on, ground a little farther on must be
/// walkable. The end, or nullopt where there is no such step.
Result<std::optional<Vec3>> StepUp(const CharacterMoveContext& inContext, const Vec3& inStart,
                                   const Vec3& inHorizontal, float inStepHeight);

} // namespace cairn::physics
