#pragma once

// CharacterController: a character that is not a body (a convex shape, usually an upright capsule) walked
// through the world by collide-and-slide over WorldQuery's shape casts. It stands on slopes up to a maximum
// angle and slides down steeper ones, slides along walls and into creases, steps up stairs, follows the floor
// walking down, rides moving platforms and is pushed out of bodies that moved into it. What Jolt's
// CharacterVirtual, PhysX's character controllers and Unreal's character movement give a game.
//
// Threads: a controller belongs to one thread at a time (it has no lock of its own); many controllers update
// at once on any threads, also while the physics step runs. It reads the world only through WorldQuery and
// PoseReader, so an Update never waits for the step and never makes it wait. It sees the bodies as last
// published (the last collision step, or the last move by hand). Update moves no body: the bodies it touched
// are in GetContacts, and PushBodies, called after it, pushes the dynamic ones through BodyInterface (its one
// write, which takes body locks as BodyInterface does).
// Characters do not see each other unless they are members of one CharacterGroup, whose Publish is then
// their sync point (CharacterGroup.h).
// The world (PhysicsSystem) must outlive the controller.
// Errors: bad input (a NaN or out-of-world position, a velocity or gravity that is not finite, a time step
// that is not positive and finite, a move past the queries' reach, settings out of range, a shape that is
// neither convex nor a compound of convex shapes) is InvalidArgument and leaves the controller as it was.

#include "cairn/physics/body/BodyInterface.h"
#include "cairn/physics/body/Layers.h"
#include "cairn/physics/character/CharacterGroup.h"
#include "cairn/physics/math/Result.h"
#include "cairn/physics/queries/WorldQuery.h"
#include "cairn/physics/shapes/Shape.h"

#include <span>
#include <vector>

namespace cairn::physics
{

class PhysicsSystem;

struct CharacterSettings
{
    /// Convex, or a compound of convex shapes. It does not turn; its local y axis points along mUp (a
    /// CapsuleShape stands upright)
    ShapeRef mShape;
    Vec3 mUp = Vec3::UnitY(); ///< Unit vector; gravity is the caller's and may point anywhere
    /// Ground steeper than this (radians, in (0, 89 degrees]) is not walkable: the character slides down it
    /// and can not walk up it
    float mMaxSlopeAngle = 50.0f * cPi / 180.0f;
    /// Steps (a stair, a kerb) up to this high are walked up; 0 walks up none
    float mStepHeight = 0.3f;
    /// Walking on, ground up to this far below is followed down (stairs and slopes down); with 0, only the
    /// ground within five paddings is (as a character landing within them is put down on it)
    float mStickToFloorDistance = 0.4f;
    /// The gap kept from every surface, so that sliding along one is not a touch; in (0, 0.1] metres
    float mPadding = 0.02f;
    /// What PushBodies pushes with: the character's mass (kg, > 0), and the most force it pushes a body
    /// with (N, >= 0; 0 pushes nothing)
    float mMass = 70.0f;
    float mMaxPushForce = 500.0f;
    /// What blocks the character: by default every layer but Layers::cTrigger (sensors, which queries find
    /// and nothing collides with). Its own body, if it has one, goes in mIgnoreBody
    QueryFilter mFilter{cAllObjectLayers & ~(ObjectLayerMask(1) << Layers::cTrigger), BodyID()};
};

enum class GroundState : uint8_t
{
    OnGround,      ///< On walkable ground: no gravity, follows the floor down
    OnSteepGround, ///< Touching ground too steep to stand on: slides down it
    InAir,
};

/// A body the character touched in the last Update.
struct CharacterContact
{
    BodyID mBody;
    Vec3 mPoint = Vec3::Zero();  ///< World space, on the body's surface
    Vec3 mNormal = Vec3::Zero(); ///< The body's surface normal there, towards the character
    /// How fast the character walked into it, along -mNormal (m/s): 0 for a body it only touched
    float mApproachSpeed = 0.0f;
};

class CharacterController
{
public:
    /// A character standing (or hanging) at inPosition (where the shape's origin is). It does not look at
    /// the world until the first Update.
    static Result<CharacterController> Create(const PhysicsSystem& inWorld,
                                              const CharacterSettings& inSettings, const Vec3& inPosition);

    /// Moves the character by its velocity over inDeltaTime seconds. Off walkable ground the velocity first
    /// gains inGravity * inDeltaTime; on it, the velocity's part into the ground is dropped, unless the
    /// velocity leaves the ground upwards (a jump: the character is InAir after it). Then the character is
    /// carried by a moving ground body, pushed out of bodies that moved into it, slid, stepped up, stuck to
    /// the floor, and its ground found. The velocity loses what the surfaces it slid along took; on the
    /// ground it loses its part along up too (the ground takes the character up and down its slopes), and a
    /// character leaving a moving ground body gains that body's velocity.
    Status Update(float inDeltaTime, const Vec3& inGravity);

    Vec3 GetPosition() const { return mPosition; }
    /// Teleports the character (no sweep); it forgets its ground and contacts until the next Update.
    Status SetPosition(const Vec3& inPosition);
    Vec3 GetLinearVelocity() const { return mVelocity; }
    Status SetLinearVelocity(const Vec3& inVelocity);

    GroundState GetGroundState() const { return mGroundState; }
    /// The body under the character, invalid InAir and on another character
    BodyID GetGroundBody() const { return mGroundBody; }
    /// The member of its group it stands on (CharacterGroup::cNoMember when none): as a moving ground body,
    /// it carries the character where the group's Publishes put it
    CharacterGroup::MemberID GetGroundMember() const { return mGroundMember; }
    /// The ground's surface normal under the character (towards it); mUp InAir
    Vec3 GetGroundNormal() const { return mGroundNormal; }
    /// The ground body's velocity where the character stands, as its moves since the last Updates measured
    /// it (zero for static ground, a ground body at rest for 0.1 s, and InAir): what the character keeps when
    /// it steps off.
    Vec3 GetGroundVelocity() const { return mGroundVelocity; }
    /// How far its ground body turned it about mUp in the last Update (identity when it did not turn, on
    /// static ground and InAir): the character's facing is the game's, which turns it by this to ride a
    /// rotating platform as Unreal's characters follow their base's rotation.
    Quat GetGroundTurn() const { return mGroundTurn; }
    /// The bodies the last Update touched (the ground among them), each once.
    std::span<const CharacterContact> GetContacts() const { return mContacts; }
    /// The members of its CharacterGroup the last Update touched (one it stands on among them), each once.
    std::span<const CharacterGroup::MemberID> GetCharacterContacts() const { return mCharacterContacts; }
    /// Its group (null when it is in none) and its number there.
    const CharacterGroup* GetGroup() const { return mSeat.GetGroup(); }
    CharacterGroup::MemberID GetGroupMember() const { return mSeat.GetMember(); }

    /// Pushes the dynamic bodies the last Update walked into, each with an impulse at its contact, along
    /// -mNormal: as much as would stop the character's walk into it (mMass times mApproachSpeed), at most
    /// mMaxPushForce over the Update's time step; and presses on a dynamic ground body with the character's
    /// weight over that time step. Update only reads the world: this is its one write, through ioBodies, so
    /// it takes body locks and waits for a running step (BodyInterface's threads, not a step callback's). A
    /// body gone since the Update is skipped; other errors are ioBodies's, returned at the first.
    Status PushBodies(BodyInterface& ioBodies) const;
    const CharacterSettings& GetSettings() const { return mSettings; }

private:
    friend class CharacterGroup;

    CharacterController(const PhysicsSystem& inWorld, const CharacterSettings& inSettings,
                        const Vec3& inPosition);

    const PhysicsSystem* mWorld;
    CharacterSettings mSettings;
    float mCosMaxSlope;
    /// The shape's rotation (its local y axis to mUp) and the distance from its origin down to its lowest
    /// point: the settings' own, worked out once
    Quat mShapeRotation;
    float mShapeBottom;
    Vec3 mPosition;
    Vec3 mVelocity = Vec3::Zero();
    GroundState mGroundState = GroundState::InAir;
    BodyID mGroundBody;
    Vec3 mGroundNormal;
    /// Where the character stood in its ground body's frame, and the version of that body's pose then: a
    /// ground body that moved since carries the character along
    Vec3 mPositionOnGround = Vec3::Zero();
    Quat mGroundRotationAtAnchor = Quat::Identity(); ///< That pose's rotation
    uint32_t mGroundPoseVersion = 0;
    Quat mGroundTurn = Quat::Identity();
    bool mGroundMoves = false;
    /// Seconds since the ground body's pose last changed, and its velocity as its carries measured it: what a
    /// character leaving a moving platform keeps
    float mTimeSinceGroundMoved = 0.0f;
    Vec3 mGroundVelocity = Vec3::Zero();
    std::vector<CharacterContact> mContacts;
    std::vector<CharacterContact> mNextContacts; ///< An Update's, kept only if it succeeds
    std::vector<CharacterGroup::MemberID> mCharacterContacts,
        mNextCharacterContacts; ///< The same, of members
    CharacterGroup::Seat mSeat; ///< Its place in a group, if any
    /// The member it stands on, that member's serial, and the member's published place it was carried to
    CharacterGroup::MemberID mGroundMember = CharacterGroup::cNoMember;
    uint32_t mGroundMemberSerial = 0;
    Vec3 mGroundMemberAt = Vec3::Zero();
    /// The last Update's: where the character stood on its ground, its time step and gravity (PushBodies)
    Vec3 mGroundPoint = Vec3::Zero();
    float mLastDeltaTime = 0.0f;
    Vec3 mLastGravity = Vec3::Zero();
};

} // namespace cairn::physics
