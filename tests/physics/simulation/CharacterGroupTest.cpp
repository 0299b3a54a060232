// CharacterGroup: the members of a group block each other (walking into each other, around each other, one on
// another's head), each sees the others as last published, and membership follows the controller (a copy is
// no member, a moved one keeps its place, a destroyed one leaves). Characters in no group pass through each
// other. The threaded use is tests/concurrency/CharacterConcurrencyTest.cpp.

#include "cairn/physics/character/CharacterGroup.h"

#include "SimulationFixture.h"
#include "cairn/physics/character/CharacterController.h"
#include "cairn/physics/shapes/CapsuleShape.h"

#include <algorithm>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

namespace cairn::test
{
using namespace cairn::physics;

namespace
{
constexpr float cHalfHeight = 0.6f, cRadius = 0.3f;
constexpr float cStandHeight = cHalfHeight + cRadius;
const Vec3 cGravity(0.0f, -9.81f, 0.0f);

class CharacterGroupTest : public SimulationFixture
{
protected:
    CharacterController MakeCharacter(const Vec3& inPosition)
    {
        CharacterSettings settings;
        settings.mShape = CapsuleShape::Create(cHalfHeight, cRadius).Value();
        return CharacterController::Create(System(), settings, inPosition).Value();
    }

    /// One frame: each character walks at its velocity (the fall kept), then the group publishes.
    static void Frame(std::vector<CharacterController*> ioCharacters, const std::vector<Vec3>& inWalks,
                      CharacterGroup* ioGroup)
    {
        for (size_t i = 0; i < ioCharacters.size(); ++i)
        {
            Vec3 velocity = inWalks[i];
            velocity.y() = ioCharacters[i]->GetLinearVelocity().y();
            ASSERT_TRUE(ioCharacters[i]->SetLinearVelocity(velocity).IsOk());
            ASSERT_TRUE(ioCharacters[i]->Update(cDeltaTime, cGravity).IsOk());
        }
        if (ioGroup != nullptr) ioGroup->Publish();
    }

    /// Adds ioBelow and ioAbove (over it) to ioGroup, and lets ioAbove come to rest on ioBelow's head.
    static void SettleOnHead(CharacterGroup& ioGroup, CharacterController& ioBelow,
                             CharacterController& ioAbove)
    {
        ASSERT_TRUE(ioGroup.Add(ioBelow));
        ASSERT_TRUE(ioGroup.Add(ioAbove));
        for (int frame = 0; frame < 30; ++frame)
            Frame({&ioBelow, &ioAbove}, {Vec3::Zero(), Vec3::Zero()}, &ioGroup);
        ASSERT_EQ(ioAbove.GetGroundMember(), ioBelow.GetGroupMember());
    }

    static bool Touches(const CharacterController& inCharacter, CharacterGroup::MemberID inMember)
    {
        const auto contacts = inCharacter.GetCharacterContacts();
        return std::find(contacts.begin(), contacts.end(), inMember) != contacts.end();
    }

    /// The gap between two upright capsules side by side (negative: overlapping), across x and z.
    static float SideGap(const CharacterController& inA, const CharacterController& inB)
    {
        const Vec3 between = inA.GetPosition() - inB.GetPosition();
        return Vec3(between.x(), 0, between.z()).norm() - 2.0f * cRadius;
    }
};

TEST_F(CharacterGroupTest, MembersWalkingIntoEachOtherStopThereAndOthersPassThrough)
{
    AddFloor();
    const auto walkTowards = [&](bool inGrouped)
    {
        CharacterGroup group;
        CharacterController a = MakeCharacter(Vec3(-2, cStandHeight + 0.02f, 0));
        CharacterController b = MakeCharacter(Vec3(2, cStandHeight + 0.02f, 0));
        if (inGrouped)
        {
            EXPECT_TRUE(group.Add(a));
            EXPECT_TRUE(group.Add(b));
        }
        float deepest = 0.0f;
        for (int frame = 0; frame < 120; ++frame)
        {
            Frame({&a, &b}, {Vec3(2, 0, 0), Vec3(-2, 0, 0)}, inGrouped ? &group : nullptr);
            deepest = std::min(deepest, SideGap(a, b));
        }
        // Each moved towards where the other stood a frame before: they meet within two frames' walk
        if (inGrouped)
        {
            EXPECT_GT(deepest, -2.0f * 2.0f * cDeltaTime);
            EXPECT_GE(SideGap(a, b), 0.0f) << "pushed apart again";
            EXPECT_LT(a.GetPosition().x(), b.GetPosition().x());
            EXPECT_TRUE(Touches(a, b.GetGroupMember()));
            EXPECT_TRUE(Touches(b, a.GetGroupMember()));
            EXPECT_EQ(a.GetGroundState(), GroundState::OnGround);
        }
        return a.GetPosition().x() - b.GetPosition().x();
    };
    EXPECT_LT(walkTowards(true), 0.0f) << "stopped at each other";
    EXPECT_GT(walkTowards(false), 2.0f) << "in no group they pass through each other";
}

TEST_F(CharacterGroupTest, AMemberAnotherWasPutIntoIsPushedOut)
{
    AddFloor();
    CharacterGroup group;
    CharacterController a = MakeCharacter(Vec3(0, cStandHeight + 0.02f, 0));
    CharacterController b = MakeCharacter(Vec3(3, cStandHeight + 0.02f, 0));
    ASSERT_TRUE(group.Add(a));
    ASSERT_TRUE(group.Add(b));
    ASSERT_TRUE(b.SetPosition(Vec3(0.4f, cStandHeight + 0.02f, 0)).IsOk()); // 0.2 m into a
    group.Publish();
    Frame({&a}, {Vec3::Zero()}, &group);
    EXPECT_GE(SideGap(a, b), 0.0f);
    EXPECT_LT(a.GetPosition().x(), -0.15f) << "a went, away from b";
    EXPECT_TRUE(Touches(a, b.GetGroupMember()));
}

TEST_F(CharacterGroupTest, AMemberSlidesAroundAnotherInItsWay)
{
    AddFloor();
    CharacterGroup group;
    CharacterController walker = MakeCharacter(Vec3(-2, cStandHeight + 0.02f, 0.15f));
    CharacterController stander = MakeCharacter(Vec3(0, cStandHeight + 0.02f, 0));
    ASSERT_TRUE(group.Add(walker));
    ASSERT_TRUE(group.Add(stander));
    bool touched = false;
    for (int frame = 0; frame < 150; ++frame)
    {
        Frame({&walker, &stander}, {Vec3(2, 0, 0), Vec3::Zero()}, &group);
        touched = touched || Touches(walker, stander.GetGroupMember());
        EXPECT_GT(SideGap(walker, stander), -0.01f) << "frame " << frame;
    }
    EXPECT_TRUE(touched);
    EXPECT_GT(walker.GetPosition().x(), 1.0f) << "round it, not stuck behind it";
    EXPECT_NEAR(stander.GetPosition().x(), 0.0f, 1.0e-4f) << "Update moves only its own character";
}

TEST_F(CharacterGroupTest, InALargeGroupAMemberMeetsEachNeighbourItsGridHolds)
{
    // 400 members standing 1 m apart (0.4 m between them), more than the cells a move looks at: a large group
    // finds its members in its grid. They stand still, so only the walkers update
    AddFloor();
    CharacterGroup group;
    constexpr int cSide = 20;
    std::vector<CharacterController> standers;
    standers.reserve(cSide * cSide);
    for (int i = 0; i < cSide * cSide; ++i)
    {
        standers.push_back(MakeCharacter(Vec3(float(i % cSide), cStandHeight + 0.02f, float(i / cSide))));
        ASSERT_TRUE(group.Add(standers.back()));
    }
    // Walkers into the lattice from two sides, one between two rows, one along a row
    CharacterController west = MakeCharacter(Vec3(-2, cStandHeight + 0.02f, 3.5f));
    CharacterController south = MakeCharacter(Vec3(5, cStandHeight + 0.02f, -2));
    ASSERT_TRUE(group.Add(west));
    ASSERT_TRUE(group.Add(south));
    const std::vector<CharacterController*> everyone{&west, &south};
    const std::vector<Vec3> walks{Vec3(2, 0, 0), Vec3(0, 0, 2)};
    float deepest = 0.0f;
    for (int frame = 0; frame < 120; ++frame)
    {
        Frame(everyone, walks, &group);
        for (const CharacterController& stander : standers)
            deepest = std::min({deepest, SideGap(west, stander), SideGap(south, stander)});
    }
    EXPECT_GT(deepest, -1.0e-3f) << "no walker in a stander";
    EXPECT_LT(west.GetPosition().x(), 0.0f) << "held at the lattice's edge";
    EXPECT_LT(south.GetPosition().z(), 0.0f);
    EXPECT_FALSE(west.GetCharacterContacts().empty());
    EXPECT_FALSE(south.GetCharacterContacts().empty());

    // Two walkers meeting beside the lattice: each finds the other where the last Publish put it
    CharacterController a = MakeCharacter(Vec3(-6, cStandHeight + 0.02f, 25));
    CharacterController b = MakeCharacter(Vec3(6, cStandHeight + 0.02f, 25));
    ASSERT_TRUE(group.Add(a));
    ASSERT_TRUE(group.Add(b));
    for (int frame = 0; frame < 150; ++frame)
        Frame({&a, &b}, {Vec3(3, 0, 0), Vec3(-3, 0, 0)}, &group);
    EXPECT_LT(a.GetPosition().x(), b.GetPosition().x()) << "they did not pass through each other";
    EXPECT_GE(SideGap(a, b), -0.2f);

    // A wide member stops a walker at its side. The grid's cells are as wide as the wide member: this one
    // stands near its cell's upper edge, so the cells the walker's own reach covers when it meets it do not
    // hold it
    CharacterSettings wideSettings;
    wideSettings.mShape = CapsuleShape::Create(0.3f, 1.2f).Value();
    constexpr float cWideX = 13.3f;
    CharacterController wide =
        CharacterController::Create(System(), wideSettings, Vec3(cWideX, 1.52f, 35)).Value();
    CharacterController walker = MakeCharacter(Vec3(18, cStandHeight + 0.02f, 35));
    ASSERT_TRUE(group.Add(walker));
    ASSERT_TRUE(group.Add(wide));
    group.Publish();
    float closest = 10.0f;
    for (int frame = 0; frame < 90; ++frame)
    {
        Frame({&walker}, {Vec3(-3, 0, 0)}, nullptr);
        closest = std::min(closest, walker.GetPosition().x() - cWideX - 1.2f - cRadius);
    }
    EXPECT_GT(closest, -1.0e-3f) << "never in the wide member";
    EXPECT_LT(closest, 0.1f) << "but at its side";
    EXPECT_TRUE(Touches(walker, wide.GetGroupMember()));

    // A member added in a walker's way is there for its next Update, before any Publish puts it in the grid
    CharacterController blocker = MakeCharacter(Vec3(-10, cStandHeight + 0.02f, 25));
    ASSERT_TRUE(group.Add(blocker));
    for (int frame = 0; frame < 240; ++frame)
        Frame({&a}, {Vec3(-3, 0, 0)}, nullptr);
    EXPECT_GT(a.GetPosition().x(), -10.0f + 2.0f * cRadius - 1.0e-3f) << "stopped at the new member";
    EXPECT_LT(a.GetPosition().x(), -10.0f + 2.0f * cRadius + 0.1f) << "and there";
    EXPECT_TRUE(Touches(a, blocker.GetGroupMember()));
}

TEST_F(CharacterGroupTest, AMemberStandsOnAnothersHead)
{
    AddFloor();
    CharacterGroup group;
    CharacterController below = MakeCharacter(Vec3(0, cStandHeight + 0.02f, 0));
    CharacterController above = MakeCharacter(Vec3(0, 4, 0));
    ASSERT_TRUE(group.Add(below));
    ASSERT_TRUE(group.Add(above));
    for (int frame = 0; frame < 120; ++frame)
        Frame({&below, &above}, {Vec3::Zero(), Vec3::Zero()}, &group);
    EXPECT_EQ(above.GetGroundState(), GroundState::OnGround);
    EXPECT_TRUE(above.GetGroundBody().IsInvalid()) << "its ground is a character, not a body";
    EXPECT_TRUE(Touches(above, below.GetGroupMember()));
    // Its bottom on the other's top, within the padding
    const float top = below.GetPosition().y() + cStandHeight;
    EXPECT_GE(above.GetPosition().y(), top + cStandHeight - 1.0e-3f);
    EXPECT_LE(above.GetPosition().y(), top + cStandHeight + above.GetSettings().mPadding + 1.0e-3f);
}

TEST_F(CharacterGroupTest, AMemberOnAnothersHeadIsCarriedWhereItWalks)
{
    AddFloor();
    CharacterGroup group;
    CharacterController below = MakeCharacter(Vec3(0, cStandHeight + 0.02f, 0));
    CharacterController above = MakeCharacter(Vec3(0, 3.0f * cStandHeight + 0.1f, 0));
    SettleOnHead(group, below, above);
    ASSERT_EQ(above.GetGroundState(), GroundState::OnGround);
    // The one below walks 2 m; the one above stands still on it
    for (int frame = 0; frame < 60; ++frame)
    {
        Frame({&below, &above}, {Vec3(2, 0, 0), Vec3::Zero()}, &group);
        ASSERT_EQ(above.GetGroundMember(), below.GetGroupMember()) << "frame " << frame;
    }
    EXPECT_NEAR(above.GetPosition().x(), below.GetPosition().x(), 2.0f * 2.0f * cDeltaTime)
        << "a frame behind at most";
    EXPECT_GT(above.GetPosition().y(), below.GetPosition().y() + 2.0f * cStandHeight - 1.0e-3f)
        << "still on its head";
    EXPECT_NEAR(above.GetGroundVelocity().x(), 2.0f, 0.05f);
    // Stepping off sideways it leaves with the speed it was carried at
    int frame = 0;
    for (; frame < 30 && above.GetGroundMember() != CharacterGroup::cNoMember; ++frame)
        Frame({&below, &above}, {Vec3(2, 0, 0), Vec3(0, 0, 3)}, &group);
    ASSERT_LT(frame, 30) << "it stepped off";
    EXPECT_EQ(above.GetGroundState(), GroundState::InAir);
    EXPECT_NEAR(above.GetLinearVelocity().x(), 2.0f, 0.05f);
}

TEST_F(CharacterGroupTest, AMemberIsNotCarriedByAnotherThatTookTheSlotOfTheOneItStoodOn)
{
    AddFloor();
    CharacterGroup group;
    CharacterController below = MakeCharacter(Vec3(0, cStandHeight + 0.02f, 0));
    CharacterController above = MakeCharacter(Vec3(0, 3.0f * cStandHeight + 0.1f, 0));
    SettleOnHead(group, below, above);
    const CharacterGroup::MemberID slot = below.GetGroupMember();
    ASSERT_TRUE(group.Remove(below).IsOk());
    CharacterController elsewhere = MakeCharacter(Vec3(10, cStandHeight + 0.02f, 0));
    ASSERT_EQ(group.Add(elsewhere).Value(), slot);
    group.Publish();
    Frame({&above}, {Vec3::Zero()}, &group);
    EXPECT_NEAR(above.GetPosition().x(), 0.0f, 1.0e-3f) << "not carried 10 m to the slot's new member";
}

TEST_F(CharacterGroupTest, MembersSeeEachOtherAsLastPublished)
{
    AddFloor();
    CharacterGroup group;
    CharacterController mover = MakeCharacter(Vec3(0, cStandHeight + 0.02f, 0));
    CharacterController walker = MakeCharacter(Vec3(-2, cStandHeight + 0.02f, 3));
    ASSERT_TRUE(group.Add(mover));
    ASSERT_TRUE(group.Add(walker));
    // The mover steps into the walker's way, unpublished: the walker walks where it was seen
    ASSERT_TRUE(mover.SetPosition(Vec3(0, cStandHeight + 0.02f, 3)).IsOk());
    for (int frame = 0; frame < 30; ++frame)
        Frame({&walker}, {Vec3(4, 0, 0)}, nullptr);
    EXPECT_GT(walker.GetPosition().x(), 0.0f) << "through the place it has not been published at";
    // Published, it is in the way
    group.Publish();
    ASSERT_TRUE(walker.SetPosition(Vec3(-2, cStandHeight + 0.02f, 3)).IsOk());
    for (int frame = 0; frame < 30; ++frame)
        Frame({&walker}, {Vec3(4, 0, 0)}, nullptr);
    EXPECT_LT(walker.GetPosition().x(), -2.0f * cRadius + 1.0e-3f);
    int seen = 0;
    group.ForEachMember(
        [&](CharacterGroup::MemberID inMember, const Shape&, const Transform& inAt, float inRadius)
        {
            ++seen;
            EXPECT_GE(inRadius, cStandHeight - 1.0e-4f) << "it holds the capsule";
            EXPECT_LE(inRadius, 1.0f) << "its bounding box's corner at most";
            if (inMember == mover.GetGroupMember())
            {
                EXPECT_TRUE(inAt.mPosition.isApprox(mover.GetPosition()));
            }
        });
    EXPECT_EQ(seen, 2);
}

TEST_F(CharacterGroupTest, MembershipFollowsTheController)
{
    AddFloor();
    CharacterGroup group, other;
    CharacterController a = MakeCharacter(Vec3(0, cStandHeight + 0.02f, 0));
    const Result<CharacterGroup::MemberID> added = group.Add(a);
    ASSERT_TRUE(added);
    EXPECT_EQ(a.GetGroup(), &group);
    EXPECT_EQ(group.Add(a).GetError().mCode, ErrorCode::AlreadyAdded);
    EXPECT_EQ(other.Add(a).GetError().mCode, ErrorCode::AlreadyAdded);
    EXPECT_EQ(other.Remove(a).GetError().mCode, ErrorCode::NotAdded);

    const CharacterController copy(a);
    EXPECT_EQ(copy.GetGroup(), nullptr) << "a copy is in no group";
    CharacterController assigned = MakeCharacter(Vec3(5, cStandHeight + 0.02f, 0));
    ASSERT_TRUE(other.Add(assigned));
    assigned = a;
    EXPECT_EQ(assigned.GetGroup(), nullptr) << "a copy assigned is in no group, and the member it was left";
    EXPECT_EQ(other.GetNumMembers(), 0u);
    EXPECT_EQ(group.GetNumMembers(), 1u);

    CharacterController moved = std::move(a);
    EXPECT_EQ(moved.GetGroup(), &group);
    EXPECT_EQ(moved.GetGroupMember(), added.Value());
    EXPECT_EQ(group.GetNumMembers(), 1u);
    {
        CharacterController scoped = MakeCharacter(Vec3(3, cStandHeight + 0.02f, 0));
        ASSERT_TRUE(group.Add(scoped));
        EXPECT_EQ(group.GetNumMembers(), 2u);
    }
    EXPECT_EQ(group.GetNumMembers(), 1u) << "a destroyed member leaves";

    // A group destroyed first lets its members go, wherever their controllers moved
    {
        auto shortLived = std::make_unique<CharacterGroup>();
        CharacterController first = MakeCharacter(Vec3(6, cStandHeight + 0.02f, 0));
        ASSERT_TRUE(shortLived->Add(first));
        CharacterController second = std::move(first);
        shortLived.reset();
        EXPECT_EQ(second.GetGroup(), nullptr);
        EXPECT_EQ(second.GetGroupMember(), CharacterGroup::cNoMember);
    }

    CharacterController walker = MakeCharacter(Vec3(-2, cStandHeight + 0.02f, 0));
    ASSERT_TRUE(group.Add(walker));
    group.Publish();
    ASSERT_TRUE(group.Remove(moved).IsOk());
    EXPECT_EQ(moved.GetGroup(), nullptr);
    EXPECT_EQ(group.GetNumMembers(), 1u);
    EXPECT_EQ(group.Remove(moved).GetError().mCode, ErrorCode::NotAdded);
    // Gone from the group, though its place was published: a member walking through it is not stopped
    for (int frame = 0; frame < 60; ++frame)
        Frame({&walker}, {Vec3(4, 0, 0)}, &group);
    EXPECT_GT(walker.GetPosition().x(), 1.0f);
    EXPECT_TRUE(walker.GetCharacterContacts().empty());
}

TEST_F(CharacterGroupTest, ALookUpNearBoundsThatAreNotNumbersOrPastTheWorldSeesEveryoneItShould)
{
    CharacterGroup group;
    std::vector<CharacterController> members;
    members.reserve(40);
    for (int i = 0; i < 40; ++i)
    {
        members.push_back(MakeCharacter(Vec3(float(i) * 3.0f, cStandHeight, 0)));
        ASSERT_TRUE(group.Add(members.back()));
    }
    group.Publish();
    const auto count = [&](const AABB& inBounds)
    {
        int seen = 0;
        group.ForEachMemberNear(inBounds, [&](CharacterGroup::MemberID, const Shape&, const Transform&, float)
                                { ++seen; });
        return seen;
    };
    EXPECT_EQ(count(AABB(Vec3(-0.5f, 0, -0.5f), Vec3(0.5f, 2, 0.5f))), 1) << "the one there";
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    EXPECT_EQ(count(AABB(Vec3(nan, 0, 0), Vec3(1, 1, 1))), 40) << "not a number: everyone";
    EXPECT_EQ(count(AABB(Vec3(-inf, -inf, -inf), Vec3(inf, inf, inf))), 40);
    EXPECT_EQ(count(AABB(Vec3(-1.0e30f, -1.0e30f, -1.0e30f), Vec3(1.0e30f, 1.0e30f, 1.0e30f))), 40)
        << "past the world's edge, every cell: everyone";
    EXPECT_EQ(count(AABB(Vec3(1.0e30f, 0, 0), Vec3(2.0e30f, 1, 1))), 0) << "far past it: no one";
}

TEST_F(CharacterGroupTest, AGroupRefusesMembersPastItsCapacity)
{
    CharacterGroup group;
    CharacterSettings settings;
    settings.mShape = CapsuleShape::Create(cHalfHeight, cRadius).Value();
    std::vector<CharacterController> crowd;
    crowd.reserve(CharacterGroup::cMaxMembers + 1);
    for (uint32_t i = 0; i <= CharacterGroup::cMaxMembers; ++i)
        crowd.push_back(CharacterController::Create(System(), settings,
                                                    Vec3(float(i % 256), cStandHeight, float(i / 256)))
                            .Value());
    for (uint32_t i = 0; i < CharacterGroup::cMaxMembers; ++i)
        ASSERT_TRUE(group.Add(crowd[i])) << i;
    const Result<CharacterGroup::MemberID> over = group.Add(crowd.back());
    ASSERT_FALSE(over);
    EXPECT_EQ(over.GetError().mCode, ErrorCode::OutOfCapacity);
    EXPECT_EQ(crowd.back().GetGroup(), nullptr);
    EXPECT_EQ(group.GetNumMembers(), CharacterGroup::cMaxMembers);
    group.Publish(); // Its grid of them all
    // One leaves, and the one left out takes its place
    ASSERT_TRUE(group.Remove(crowd[7]).IsOk());
    ASSERT_TRUE(group.Add(crowd.back()));
    EXPECT_EQ(crowd.back().GetGroupMember(), CharacterGroup::MemberID(7)) << "the free slot, taken again";
}

} // namespace
} // namespace cairn::test
