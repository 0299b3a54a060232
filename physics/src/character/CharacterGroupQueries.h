#pragma once

// The queries of a character's moves against the other members of its CharacterGroup, as WorldQuery's against
// the bodies: a shape cast and the deepest overlap, each against the members as last published. Any thread,
// no lock (CharacterGroup.h says who writes what).

#include "cairn/physics/character/CharacterGroup.h"
#include "cairn/physics/narrowphase/ContactManifold.h"
#include "cairn/physics/queries/WorldQuery.h"

#include <optional>

namespace cairn::physics
{

/// The radius round a shape's origin that holds it: a member's reach, wherever it turns.
float BoundingRadius(const Shape& inShape);

struct MemberCastHit
{
    CharacterGroup::MemberID mMember;
    ShapeCastResult mCast; ///< As WorldQuery's, with no body
};

/// The first member other than inSelf that inShape, turned by inRotation, meets moving from inStart along
/// inDisplacement before inMaxFraction of it, as WorldQuery::CastShapeClosest meets a body.
std::optional<MemberCastHit> CastAgainstMembers(const CharacterGroup& inGroup,
                                                CharacterGroup::MemberID inSelf, const Shape& inShape,
                                                const Transform& inStart, const Vec3& inDisplacement,
                                                float inMaxFraction);

struct MemberOverlap
{
    CharacterGroup::MemberID mMember;
    ContactManifold mManifold; ///< Its normal from inShape towards the member
};

/// The member other than inSelf that inShape at inTransform overlaps deepest, if it overlaps one deeper than
/// inMinPenetration.
std::optional<MemberOverlap> DeepestMemberOverlap(const CharacterGroup& inGroup,
                                                  CharacterGroup::MemberID inSelf, const Shape& inShape,
                                                  const Transform& inTransform, float inMinPenetration);

} // namespace cairn::physics
