#pragma once

// CharacterGroup: characters that block each other. CharacterControllers are not bodies, so the world's
// queries do not see them; the members of a group see each other: a member's moves stop at the others'
// shapes as at a wall, it stands on another's head (carried where that one walks, as by a moving body), and
// one that moved into it pushes it out. What Jolt's CharacterVsCharacterCollision gives, without a lock and
// without a wait: a member's Update sees the others where they stood at the group's last Publish, so the
// members of a group update at once on any threads, as characters do (two characters walking into each other
// meet within a frame's move, and the next Update's push-out parts them; a member is carried a frame behind
// the one it stands on).
//
// Threads: Add, Remove, Publish, and a member's controller's move or destruction, on one thread while no
// member's Update runs (the game's thread, between frames: Publish is the group's sync point). Between two of
// them, the members' Updates and SetPositions may run at once, each member on one thread at a time: each
// reads every member's published place (which only Publish writes) and writes its own member's next place
// (which only Publish reads). No lock. A move looks only at the members near it, in a grid of their published
// places. A member leaves the group when it is removed or its controller destroyed; a group destroyed first
// lets its members go (they are then in no group).

#include "cairn/physics/math/AABB.h"
#include "cairn/physics/math/FunctionRef.h"
#include "cairn/physics/math/Result.h"
#include "cairn/physics/math/Transform.h"
#include "cairn/physics/shapes/Shape.h"

#include <cstdint>
#include <utility>
#include <vector>

namespace cairn::physics
{

class CharacterController;

class CharacterGroup
{
public:
    /// A member's number in its group, kept while it is a member.
    using MemberID = uint32_t;
    static constexpr MemberID cNoMember = ~MemberID(0);
    /// The most members a group holds at once.
    static constexpr uint32_t cMaxMembers = 1u << 16;

    /// A character's place in a group, which its CharacterController holds: a copy of it is in no group, a
    /// moved-to one takes the place of the moved-from one, a destroyed one leaves the group.
    class Seat
    {
    public:
        Seat() = default;
        Seat(const Seat&) noexcept {}
        Seat(Seat&& ioOther) noexcept;
        Seat& operator=(const Seat& inOther);
        Seat& operator=(Seat&& ioOther) noexcept;
        ~Seat() { Leave(); }

        CharacterGroup* GetGroup() const { return mGroup; }
        MemberID GetMember() const { return mMember; }

    private:
        friend class CharacterGroup;
        void Leave();
        void TakeOver(Seat& ioOther);

        CharacterGroup* mGroup = nullptr;
        MemberID mMember = cNoMember;
    };

    CharacterGroup() = default;
    CharacterGroup(const CharacterGroup&) = delete;
    CharacterGroup& operator=(const CharacterGroup&) = delete;
    /// Its members leave it (they are then in no group).
    ~CharacterGroup();

    /// Makes ioCharacter a member, where it stands now (the others see it there from this call on). Errors:
    /// it is a member of a group already, or the group holds cMaxMembers.
    Result<MemberID> Add(CharacterController& ioCharacter);
    /// ioCharacter leaves the group. Error: it is not a member of this group.
    Status Remove(CharacterController& ioCharacter);
    /// The sync point: every member's place after its last Update or SetPosition is what the others see in
    /// their next Updates.
    void Publish();

    uint32_t GetNumMembers() const { return mNumMembers; }
    /// Sees a member: its number, its shape where the members' Updates see it (at the last Publish, or where
    /// Add put it), and the radius round its origin that holds the shape.
    using MemberVisitor = FunctionRef<void(MemberID, const Shape&, const Transform&, float inRadius)>;
    /// Calls inVisit with each member: to draw them.
    void ForEachMember(MemberVisitor inVisit) const;
    /// The same for the members whose shapes may reach into inBounds (and perhaps a few more), found in a
    /// grid of their places that Publish builds (members added since are each looked at): what a character's
    /// moves look at, so a move's cost grows with the members near it, not with the group's size. Bounds
    /// that are not finite visit every member.
    void ForEachMemberNear(const AABB& inBounds, MemberVisitor inVisit) const;

private:
    friend class CharacterController;

    struct Member
    {
        ShapeRef mShape; ///< Null when the slot is free
        Quat mRotation = Quat::Identity();
        float mRadius = 0.0f;
        Vec3 mPublished = Vec3::Zero(); ///< Written by Add and Publish, read by every member's Update
        Vec3 mNext = Vec3::Zero(); ///< Written by the member's own Update and SetPosition, read by Publish
        Seat* mSeat = nullptr;     ///< The member's, wherever its controller has moved
        uint32_t mSerial = 0;      ///< Tells apart the members a slot has held
    };

    /// A member's published place, or null when inSerial is not its serial (it left, its slot perhaps taken
    /// again): what a member standing on it is carried by.
    const Vec3* PublishedPlace(MemberID inMember, uint32_t inSerial) const
    {
        return inMember < mMembers.size() && mMembers[inMember].mShape != nullptr &&
                       mMembers[inMember].mSerial == inSerial
                   ? &mMembers[inMember].mPublished
                   : nullptr;
    }
    uint32_t SerialOf(MemberID inMember) const { return mMembers[inMember].mSerial; }
    /// The member's place after its Update or SetPosition: on its own thread.
    void SetNext(MemberID inMember, const Vec3& inPosition) { mMembers[inMember].mNext = inPosition; }
    /// A member gone (removed, or destroyed without being removed).
    void Leave(MemberID inMember);

    /// The grid of the members' published places: each member's cell, by a key packing its coordinates
    void BuildGrid();
    /// inVisit with the member, unless its slot is free
    void Visit(MemberID inMember, MemberVisitor inVisit) const;

    /// The least cell size (metres): the keys' 21 bits a coordinate then reach past the world's edge
    static constexpr float cMinCellSize = 1.0f;

    std::vector<Member> mMembers;
    std::vector<MemberID> mFree;
    uint32_t mNumMembers = 0;
    /// The grid: (cell key, member) sorted by key, cells as wide as the largest member (every member overlaps
    /// only the cells next to its own), and that largest radius
    std::vector<std::pair<uint64_t, MemberID>> mGrid;
    float mCellSize = cMinCellSize;
    float mMaxRadius = 0.0f;
    /// Members added since the grid was built: every look-up visits them
    std::vector<MemberID> mUnplaced;
    uint32_t mNextSerial = 1;
};

} // namespace cairn::physics
