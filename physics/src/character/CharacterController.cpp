#include "cairn/physics/character/CharacterController.h"

#include "cairn/physics/PhysicsSystem.h"
#include "character/CharacterMoves.h"
#include "queries/QueryShape.h"

#include <array>
#include <cmath>
#include <string>

namespace cairn::physics
{

namespace
{
/// A character on the ground whose velocity leaves it faster than this (m/s), up and off the ground's plane,
/// jumps: no floor holds it, gravity pulls it
constexpr float cLeaveSpeed = 1.0e-2f;
/// A normal this close to level (the cosine with up) is a vertical face's (a stair's riser, a box's side),
/// rounded: a wall to a character on its feet, and a step up to try
constexpr float cLevelCos = 1.0e-3f;
/// A ground body's velocity is measured over at least this long (seconds): its move over a shorter time,
/// right after it changed, would read as a huge speed
constexpr float cMinGroundMoveTime = 1.0e-3f;
/// Surfaces met in one Update's slide; more is a corner it can not get out of this frame
constexpr int cMaxSlidePlanes = 6;
constexpr int cMaxSlideIterations = 8;
/// Ground is what the character touches within this many paddings along its normal: the moves stop it one
/// padding short
constexpr float cGroundGapPaddings = 2.0f;
/// The ground is looked for at least this many paddings down: a move that met a slant stopped up to
/// 1 / cMinApproachCos (4) paddings short of it along the move (CharacterMoves.cpp)
constexpr float cGroundProbePaddings = 5.0f;
/// A ground body whose pose has not changed for this long (seconds) is at rest (asleep, or stopped): a
/// character leaving it keeps no velocity of its
constexpr float cGroundAtRestAfter = 0.1f;
/// The steepest walkable ground a character may have: walking keeps its pace across up by dividing by the
/// cosine of the ground's slope, which nearer 90 degrees would be a division by almost nothing
constexpr float cMaxSlopeAngleLimit = 89.0f * cPi / 180.0f;
/// Lengths past this (metres) are refused, as a world query refuses them
constexpr float cMaxCharacterLength = 100.0f;
/// A mass and a push past these are no character's: refused, so that an impulse stays far from overflowing
constexpr float cMaxCharacterMass = 1.0e6f, cMaxCharacterPushForce = 1.0e9f;

Error InvalidCharacter(const std::string& inWhat)
{
    return MakeError(ErrorCode::InvalidArgument, "character: " + inWhat);
}

bool IsLength(float inValue)
{
    return std::isfinite(inValue) && inValue >= 0.0f && inValue <= cMaxCharacterLength;
}

Status CheckSettings(const CharacterSettings& inSettings)
{
    if (inSettings.mShape == nullptr) return InvalidCharacter("no shape");
    if (!CanBeQueryShape(*inSettings.mShape))
        return InvalidCharacter("the shape must be convex or a compound of convex shapes");
    if (!IsFinite(inSettings.mUp) || std::abs(inSettings.mUp.norm() - 1.0f) > 1.0e-3f)
        return InvalidCharacter("up must be a unit vector");
    if (!(inSettings.mMaxSlopeAngle > 0.0f && inSettings.mMaxSlopeAngle <= cMaxSlopeAngleLimit))
        return InvalidCharacter("the maximum slope angle must be in (0, 89] degrees");
    if (!IsLength(inSettings.mStepHeight)) return InvalidCharacter("step height must be in [0, 100] m");
    if (!IsLength(inSettings.mStickToFloorDistance))
        return InvalidCharacter("stick-to-floor distance must be in [0, 100] m");
    if (!(inSettings.mPadding > 0.0f && inSettings.mPadding <= 0.1f))
        return InvalidCharacter("padding must be in (0, 0.1] m");
    if (!(std::isfinite(inSettings.mMass) && inSettings.mMass > 0.0f &&
          inSettings.mMass <= cMaxCharacterMass))
        return InvalidCharacter("mass must be in (0, 1e6] kg");
    if (!(std::isfinite(inSettings.mMaxPushForce) && inSettings.mMaxPushForce >= 0.0f &&
          inSettings.mMaxPushForce <= cMaxCharacterPushForce))
        return InvalidCharacter("maximum push force must be in [0, 1e9] N");
    return Status::Ok();
}

/// The walk inVelocity along walkable ground whose normal is inNormal: its part across up kept, and as much
/// along up as follows the ground's slope (as Unreal's characters keep their horizontal speed on ramps).
Vec3 AlongGround(const Vec3& inVelocity, const Vec3& inNormal, const Vec3& inUp)
{
    const Vec3 across = AcrossAxis(inVelocity, inUp);
    return across - inUp * (across.dot(inNormal) / inNormal.dot(inUp));
}

/// Keeps on inBody's contact how fast the character walked into it, the fastest of this Update's meetings.
void RecordApproach(const CharacterMoveContext& inContext, const BodyID& inBody, float inSpeed)
{
    for (CharacterContact& contact : inContext.mContacts)
        if (contact.mBody == inBody) contact.mApproachSpeed = std::max(contact.mApproachSpeed, inSpeed);
}

/// How the slide ended.
struct Slide
{
    Vec3 mEnd;
    Vec3 mVelocity;
    bool mStepped = false;
};

/// Collide-and-slide: along the velocity's displacement, each surface met taking the part of the move (and
/// of the velocity) that goes into it. A character on its feet takes ground too steep to stand on as a wall
/// (it can not climb it), and tries to step up onto what it walked into.
Result<Slide> SlideAlong(const CharacterMoveContext& inContext, const Vec3& inStart, const Vec3& inVelocity,
                         float inDeltaTime, bool inOnFeet, float inStepHeight)
{
    Slide slide{inStart, inVelocity};
    const Vec3 wanted = inVelocity * inDeltaTime;
    Vec3 remaining = wanted;
    std::array<Vec3, cMaxSlidePlanes> planes;
    size_t numPlanes = 0;
    bool onFeet = inOnFeet;
    for (int iteration = 0; iteration < cMaxSlideIterations; ++iteration)
    {
        if (remaining.norm() < cMinCharacterMove) break;
        Result<CharacterSweep> sweep = SweepCharacter(inContext, slide.mEnd, remaining);
        if (!sweep) return sweep.GetError();
        const Vec3 rest = remaining - (sweep.Value().mEnd - slide.mEnd);
        slide.mEnd = sweep.Value().mEnd;
        if (!sweep.Value().mHit) break;

        Vec3 normal = sweep.Value().mHit->mNormal;
        RecordApproach(inContext, sweep.Value().mHit->mBody, -slide.mVelocity.dot(normal));
        Vec3 next = rest;
        if (inContext.IsWalkable(normal))
        {
            // Onto a ramp or over an edge it can walk: on its feet, it keeps its pace across up
            if (onFeet)
            {
                next = AlongGround(rest, normal, inContext.mUp);
                slide.mVelocity = AlongGround(slide.mVelocity, normal, inContext.mUp);
            }
            onFeet = true;
        }
        else if (onFeet && normal.dot(inContext.mUp) > -cLevelCos)
        {
            const Vec3 across = AcrossAxis(normal, inContext.mUp);
            if (across.norm() > 1.0e-3f) normal = across.normalized();
            const Vec3 horizontal = AcrossAxis(rest, inContext.mUp);
            if (!slide.mStepped && inStepHeight > 0.0f && horizontal.dot(normal) < 0.0f)
            {
                Result<std::optional<Vec3>> step = StepUp(inContext, slide.mEnd, horizontal, inStepHeight);
                if (!step) return step.GetError();
                if (step.Value())
                {
                    // The step took the rest of this frame's walk
                    slide.mEnd = *step.Value();
                    slide.mStepped = true;
                    break;
                }
            }
        }
        if (numPlanes == planes.size()) break;
        planes[numPlanes++] = normal;
        const std::span<const Vec3> met(planes.data(), numPlanes);
        remaining = ClipToPlanes(next, met);
        slide.mVelocity = ClipToPlanes(slide.mVelocity, met);
        // Turned back against the walk (an acute corner): stopping here is still, bouncing between is jitter
        if (remaining.dot(wanted) <= 0.0f) break;
    }
    return slide;
}

} // namespace

Result<CharacterController> CharacterController::Create(const PhysicsSystem& inWorld,
                                                        const CharacterSettings& inSettings,
                                                        const Vec3& inPosition)
{
    if (Status settings = CheckSettings(inSettings); !settings) return settings.GetError();
    if (!IsValidWorldPosition(inPosition))
        return InvalidCharacter("position is NaN, infinite or beyond the world");
    return CharacterController(inWorld, inSettings, inPosition);
}

CharacterController::CharacterController(const PhysicsSystem& inWorld, const CharacterSettings& inSettings,
                                         const Vec3& inPosition)
    : mWorld(&inWorld), mSettings(inSettings), mCosMaxSlope(std::cos(inSettings.mMaxSlopeAngle)),
      mShapeRotation(Quat::FromTwoVectors(Vec3::UnitY(), inSettings.mUp.normalized())),
      mShapeBottom(-inSettings.mShape->GetLocalBounds().mMin.y()), mPosition(inPosition),
      mGroundNormal(inSettings.mUp.normalized())
{
    mSettings.mUp.normalize();
}

Status CharacterController::SetPosition(const Vec3& inPosition)
{
    if (!IsValidWorldPosition(inPosition))
        return InvalidCharacter("position is NaN, infinite or beyond the world");
    mPosition = inPosition;
    mGroundState = GroundState::InAir;
    mGroundBody = BodyID();
    mGroundNormal = mSettings.mUp;
    mGroundMoves = false;
    mGroundVelocity = Vec3::Zero();
    mGroundTurn = Quat::Identity();
    mGroundMember = CharacterGroup::cNoMember;
    mContacts.clear(); // Not where it is now: nothing for PushBodies
    mCharacterContacts.clear();
    if (mSeat.GetGroup() != nullptr) mSeat.GetGroup()->SetNext(mSeat.GetMember(), mPosition);
    return Status::Ok();
}

Status CharacterController::SetLinearVelocity(const Vec3& inVelocity)
{
    if (!IsFinite(inVelocity)) return InvalidCharacter("velocity is NaN or infinite");
    mVelocity = inVelocity;
    return Status::Ok();
}

Status CharacterController::Update(float inDeltaTime, const Vec3& inGravity)
{
    if (!(std::isfinite(inDeltaTime) && inDeltaTime > 0.0f))
        return InvalidCharacter("time step must be positive and finite");
    if (!IsFinite(inGravity)) return InvalidCharacter("gravity is NaN or infinite");

    const Vec3& up = mSettings.mUp;
    mNextContacts.clear();
    mNextCharacterContacts.clear();
    const CharacterMoveContext context{mWorld->GetWorldQuery(),
                                       *mSettings.mShape,
                                       mShapeRotation,
                                       mSettings.mFilter,
                                       up,
                                       mCosMaxSlope,
                                       mSettings.mPadding,
                                       mShapeBottom,
                                       mNextContacts,
                                       mSeat.GetGroup(),
                                       mSeat.GetMember(),
                                       mNextCharacterContacts};

    // On its feet unless it jumps: then the floor holds it (no gravity, nothing of the velocity into it)
    Vec3 velocity = mVelocity;
    const bool wasOnGround = mGroundState == GroundState::OnGround;
    const bool jumps = velocity.dot(up) > cLeaveSpeed && velocity.dot(mGroundNormal) > cLeaveSpeed;
    const bool onFeet = wasOnGround && !jumps;
    if (onFeet)
        velocity = AlongGround(velocity, mGroundNormal, up);
    else
        velocity += inGravity * inDeltaTime;

    // Carried by its ground, where that moved since the last Update
    Vec3 position = mPosition;
    Vec3 groundVelocity = mGroundVelocity;
    const float sinceGroundMoved = mTimeSinceGroundMoved + inDeltaTime;
    bool groundMovedNow = false;
    Quat groundTurn = Quat::Identity();
    // Swept along by inMove, the ground's since the last Update; its velocity is measured from it
    const auto carry = [&](const Vec3& inMove) -> Status
    {
        Result<CharacterSweep> carried = SweepCharacter(context, position, inMove);
        if (!carried) return carried.GetError();
        groundVelocity = (carried.Value().mEnd - position) / std::max(sinceGroundMoved, cMinGroundMoveTime);
        position = carried.Value().mEnd;
        groundMovedNow = true;
        return Status::Ok();
    };
    // The ground's pose the character is carried to: kept as its anchor when it still stands on that body,
    // since a pose read after the moves could be a step newer than the one they were made against
    std::optional<PublishedPose> carriedBy;
    if (mGroundState != GroundState::InAir && mGroundMoves)
    {
        PoseReader poses(mWorld->GetBodyManager());
        PublishedPose pose;
        if (poses.Read(mGroundBody, pose)) carriedBy = pose;
        if (carriedBy && pose.mVersion != mGroundPoseVersion)
        {
            if (Status carried = carry(pose.mTransform * mPositionOnGround - position); !carried)
                return carried;
            groundTurn = TwistAbout(pose.mTransform.mRotation * mGroundRotationAtAnchor.conjugate(), up);
        }
    }
    // Or by the member of its group it stands on, where a Publish has moved it since
    CharacterGroup* const group = mSeat.GetGroup();
    if (mGroundState != GroundState::InAir && mGroundMember != CharacterGroup::cNoMember && group != nullptr)
    {
        const Vec3* below = group->PublishedPlace(mGroundMember, mGroundMemberSerial);
        if (below != nullptr && *below != mGroundMemberAt)
        {
            if (Status carried = carry(*below - mGroundMemberAt); !carried) return carried;
        }
    }

    Result<Vec3> pushedOut = PushOutOfBodies(context, position);
    if (!pushedOut) return pushedOut.GetError();
    position = pushedOut.Value();

    const float groundGap = cGroundGapPaddings * mSettings.mPadding;
    Result<Slide> slide = SlideAlong(context, position, velocity, inDeltaTime, onFeet, mSettings.mStepHeight);
    if (!slide) return slide.GetError();
    position = slide.Value().mEnd;
    velocity = slide.Value().mVelocity;

    // Walking on, down a slope or a stair: the floor a little below is followed, not fallen to. Landing (or
    // walking) within the ground's gap, it is put down to its padding. The same sweep finds the ground: what
    // holds the character up, it stands on; what it meets within the gap and can not stand on, it touches
    const float stickDistance =
        std::max(onFeet && !slide.Value().mStepped ? mSettings.mStickToFloorDistance : 0.0f,
                 cGroundProbePaddings * mSettings.mPadding);
    std::optional<CharacterContact> ground;
    std::optional<CharacterSupport> support;
    CharacterGroup::MemberID groundMember = CharacterGroup::cNoMember; // Another character under it
    if (!jumps)
    {
        Result<CharacterSweep> stick = SweepCharacter(context, position, -up * stickDistance, false);
        if (!stick) return stick.GetError();
        if (stick.Value().mHit)
        {
            const ShapeCastResult& hit = *stick.Value().mHit;
            const CharacterContact met{hit.mBody, hit.mContactPoint, hit.mNormal};
            Result<std::optional<CharacterSupport>> found = FindSupport(
                context, stick.Value().mEnd, met, std::max(mSettings.mStickToFloorDistance, groundGap));
            if (!found) return found.GetError();
            if (found.Value())
            {
                position = stick.Value().mEnd;
                support = found.Value();
                ground = met;
                groundMember = stick.Value().mHitMember;
            }
            else if (hit.mFraction * stickDistance * std::max(hit.mNormal.dot(up), 0.1f) <= groundGap)
            {
                ground = met; // Within the gap along the slope's normal
                groundMember = stick.Value().mHitMember;
            }
        }
    }

    // Every query has answered: what follows can not fail, so the controller changes all at once or not at
    // all
    GroundState state = GroundState::InAir;
    BodyID groundBody;
    Vec3 groundNormal = up;
    if (support)
    {
        state = GroundState::OnGround;
        groundBody = support->mBody;
        groundNormal = support->mNormal;
    }
    else if (ground)
    {
        state = GroundState::OnSteepGround;
        groundBody = ground->mBody;
        groundNormal = ground->mNormal;
    }
    // What it touched below, and what holds it up where that is another body (a tread under a stair's edge)
    if (ground) RecordContact(context, ground->mBody, ground->mPoint, ground->mNormal);
    if (support) RecordContact(context, support->mBody, support->mPoint, support->mNormal);
    RecordCharacterContact(context, groundMember);
    // On the ground the velocity is the walk: the ground takes it up and down its slopes, so no speed along
    // up is left to read as a jump (or a fall) in the next Update
    if (state == GroundState::OnGround) velocity = AcrossAxis(velocity, up);
    // At rest, or another body's: this one's is measured from its next move
    if ((!groundMovedNow && sinceGroundMoved > cGroundAtRestAfter) ||
        (state != GroundState::InAir && (groundBody != mGroundBody || groundMember != mGroundMember)))
        groundVelocity = Vec3::Zero();
    // Off a moving platform (or a moving member of its group), from its top or down its steep side
    if (mGroundState != GroundState::InAir && state == GroundState::InAir) velocity += groundVelocity;

    // A move the queries allowed can still end past the world's edge (they reach farther), and a step of a
    // nanosecond can measure an enormous speed: such an Update is refused whole, as bad input is
    if (!IsValidWorldPosition(position)) return InvalidCharacter("the move would end beyond the world");
    if (!IsFiniteLength(velocity) || !IsFiniteLength(groundVelocity))
        return InvalidCharacter("the velocity would overflow");

    const BodyID previousGround = mGroundBody;
    mGroundMoves = false;
    if (state != GroundState::InAir)
    {
        PoseReader poses(mWorld->GetBodyManager());
        PublishedPose pose;
        const bool sameGround = carriedBy && groundBody == previousGround;
        if (sameGround) pose = *carriedBy;
        if ((sameGround || poses.Read(groundBody, pose)) && pose.mMotionType != MotionType::Static)
        {
            mGroundMoves = true;
            mPositionOnGround = pose.mTransform.InverseTransformPoint(position);
            mGroundRotationAtAnchor = pose.mTransform.mRotation;
            mGroundPoseVersion = pose.mVersion;
        }
    }
    const CharacterGroup::MemberID previousGroundMember = mGroundMember;
    mGroundMember = CharacterGroup::cNoMember;
    if (state != GroundState::InAir && groundMember != CharacterGroup::cNoMember && group != nullptr)
    {
        // Its anchor is the place it was carried to: a Publish can not come between the moves and here
        const uint32_t serial = group->SerialOf(groundMember);
        if (const Vec3* below = group->PublishedPlace(groundMember, serial))
        {
            mGroundMoves = true;
            mGroundMember = groundMember;
            mGroundMemberSerial = serial;
            mGroundMemberAt = *below;
        }
    }
    mTimeSinceGroundMoved =
        groundMovedNow || groundBody != previousGround || mGroundMember != previousGroundMember
            ? 0.0f
            : sinceGroundMoved;
    mGroundVelocity = mGroundMoves ? groundVelocity : Vec3::Zero();
    mGroundTurn = groundTurn;
    mPosition = position;
    mVelocity = velocity;
    mGroundState = state;
    mGroundBody = groundBody;
    mGroundNormal = groundNormal;
    mGroundPoint = support ? support->mPoint : ground ? ground->mPoint : position;
    mLastDeltaTime = inDeltaTime;
    mLastGravity = inGravity;
    mContacts.swap(mNextContacts);
    mCharacterContacts.swap(mNextCharacterContacts);
    if (mSeat.GetGroup() != nullptr) mSeat.GetGroup()->SetNext(mSeat.GetMember(), mPosition);
    return Status::Ok();
}

Status CharacterController::PushBodies(BodyInterface& ioBodies) const
{
    const float maxImpulse = mSettings.mMaxPushForce * mLastDeltaTime;
    PoseReader poses(mWorld->GetBodyManager());
    const auto isDynamic = [&](const BodyID& inBody)
    {
        PublishedPose pose;
        return poses.Read(inBody, pose) && pose.mMotionType == MotionType::Dynamic;
    };
    // A body removed, destroyed or turned static since the Update is no longer there to push
    const auto skipGone = [](const Status& inStatus)
    {
        return inStatus || inStatus.GetError().mCode == ErrorCode::InvalidBodyID ||
               inStatus.GetError().mCode == ErrorCode::NotAdded;
    };
    for (const CharacterContact& contact : mContacts)
    {
        const float impulse = std::min(mSettings.mMass * contact.mApproachSpeed, maxImpulse);
        if (impulse <= 0.0f || !isDynamic(contact.mBody)) continue;
        const Status pushed = ioBodies.AddImpulse(contact.mBody, -contact.mNormal * impulse, contact.mPoint);
        if (!skipGone(pushed) && isDynamic(contact.mBody)) return pushed; // Else it turned static meanwhile
    }
    if (mGroundState != GroundState::InAir && isDynamic(mGroundBody))
    {
        const Status pressed =
            ioBodies.AddImpulse(mGroundBody, mLastGravity * (mSettings.mMass * mLastDeltaTime), mGroundPoint);
        if (!skipGone(pressed) && isDynamic(mGroundBody)) return pressed;
    }
    return Status::Ok();
}

} // namespace cairn::physics
