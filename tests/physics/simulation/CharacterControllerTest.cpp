// CharacterController: standing and landing, walls and creases, slopes it may and may not walk, stairs up and
// down (also with up along z), moving platforms, bodies that move into it, its contacts and pushes, and bad
// input.

#include "cairn/physics/character/CharacterController.h"

#include "SimulationFixture.h"
#include "cairn/physics/shapes/CapsuleShape.h"
#include "cairn/physics/shapes/HeightFieldShape.h"
#include "cairn/physics/shapes/TriangleMeshShape.h"
#include "character/CharacterMoves.h"
#include "common/StaticFloor.h"
#include "narrowphase/FaceClipping.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <vector>

namespace cairn::test
{
using namespace cairn::physics;

namespace
{
constexpr float cCharacterHalfHeight = 0.6f;
constexpr float cCharacterRadius = 0.3f;
/// The capsule's centre above the ground it stands on
constexpr float cCharacterStandHeight = cCharacterHalfHeight + cCharacterRadius;
const Vec3 cCharacterGravity(0.0f, -9.81f, 0.0f);
} // namespace

class CharacterControllerTest : public SimulationFixture
{
protected:
    static CharacterSettings Settings()
    {
        CharacterSettings settings;
        settings.mShape = CapsuleShape::Create(cCharacterHalfHeight, cCharacterRadius).Value();
        return settings;
    }
    CharacterController MakeCharacter(const Vec3& inPosition,
                                      const CharacterSettings& inSettings = Settings())
    {
        return CharacterController::Create(System(), inSettings, inPosition).Value();
    }

    /// Walks the character at inVelocity (kept each frame, the fall added) for inFrames frames at 60 Hz.
    static void Walk(CharacterController& ioCharacter, const Vec3& inVelocity, int inFrames)
    {
        for (int frame = 0; frame < inFrames; ++frame)
        {
            Vec3 velocity = inVelocity;
            velocity.y() = ioCharacter.GetLinearVelocity().y();
            ASSERT_TRUE(ioCharacter.SetLinearVelocity(velocity).IsOk());
            ASSERT_TRUE(ioCharacter.Update(cDeltaTime, cCharacterGravity).IsOk());
        }
    }

    /// On the floor (top at y = 0), clear of it by no more than its padding and a millimetre: a fall shorter
    /// than the padding in its last frame ends that little higher.
    static void ExpectStandingOnFloor(const CharacterController& inCharacter)
    {
        EXPECT_GE(inCharacter.GetPosition().y(), cCharacterStandHeight);
        EXPECT_LE(inCharacter.GetPosition().y(),
                  cCharacterStandHeight + inCharacter.GetSettings().mPadding + 1.0e-3f);
        EXPECT_EQ(inCharacter.GetGroundState(), GroundState::OnGround);
    }

    /// A kinematic platform inHalfWidth metres across each way from the origin, its top at y = 1.25 above the
    /// floor, and a character that stood on it at x = inRiderX for 10 frames (its ground the platform).
    struct Ride
    {
        BodyID mPlatform;
        CharacterController mRider;
    };
    Ride AddPlatformWithRider(float inHalfWidth, float inRiderX)
    {
        AddFloor();
        const BodyID platform =
            Bodies()
                .CreateAndAddBody(BoxBodySettings(Vec3(0, 1, 0), Vec3(inHalfWidth, 0.25f, inHalfWidth),
                                                  MotionType::Kinematic),
                                  Activation::Activate)
                .Value();
        CharacterController rider = MakeCharacter(Vec3(inRiderX, 1.25f + cCharacterStandHeight + 0.02f, 0));
        Walk(rider, Vec3::Zero(), 10);
        return {platform, std::move(rider)};
    }

    /// Whether inBody is among the contacts of inCharacter's last Update.
    static bool Touches(const CharacterController& inCharacter, const BodyID& inBody)
    {
        const std::span<const CharacterContact> contacts = inCharacter.GetContacts();
        return std::any_of(contacts.begin(), contacts.end(),
                           [&](const CharacterContact& inContact) { return inContact.mBody == inBody; });
    }

    /// How deep the character's shape is in any body where it stands (0 when clear).
    float DeepestOverlap(const CharacterController& inCharacter)
    {
        std::vector<ShapeQueryHit> hits;
        EXPECT_TRUE(System()
                        .GetWorldQuery()
                        .CollideShape(*inCharacter.GetSettings().mShape,
                                      {inCharacter.GetPosition(), Quat::Identity()}, hits)
                        .IsOk());
        float deepest = 0.0f;
        for (const ShapeQueryHit& hit : hits)
            deepest = std::max(deepest, MaxPenetration(hit.mManifold));
        return deepest;
    }

    /// A static ramp rising along +x at inAngle, its top surface through the origin's ground line at x = 0.
    BodyID AddRamp(float inAngle)
    {
        const Quat tilt(Eigen::AngleAxisf(inAngle, Vec3::UnitZ()));
        // A slab 20 m long and 1 m thick, its top face's centre line through (0, 0, 0) at its low end's side
        const Vec3 halfExtent(10.0f, 0.5f, 5.0f);
        const Vec3 center = tilt * Vec3(10.0f, -0.5f, 0.0f);
        return AddStatic(Box(halfExtent), center, tilt);
    }

    /// Stairs along +x from x = inStartX: inSteps steps of inRise each, inRun deep, the top one 3 m deep.
    void AddStairs(float inStartX, int inSteps, float inRise, float inRun)
    {
        for (int step = 0; step < inSteps; ++step)
        {
            const float height = inRise * float(step + 1);
            const float run = step + 1 == inSteps ? 3.0f : inRun;
            AddStatic(Box(Vec3(run / 2.0f, height / 2.0f, 3.0f)),
                      Vec3(inStartX + inRun * float(step) + run / 2.0f, height / 2.0f, 0.0f));
        }
    }
};

TEST_F(CharacterControllerTest, FallsLandsAndStandsStillOnTheFloor)
{
    const BodyID floor = AddFloor();
    CharacterController character = MakeCharacter(Vec3(0, cCharacterStandHeight + 3.0f, 0));
    EXPECT_EQ(character.GetGroundState(), GroundState::InAir);
    float lowest = std::numeric_limits<float>::max();
    for (int frame = 0; frame < 120; ++frame)
    {
        ASSERT_TRUE(character.Update(cDeltaTime, cCharacterGravity).IsOk());
        lowest = std::min(lowest, character.GetPosition().y());
    }
    EXPECT_EQ(character.GetGroundState(), GroundState::OnGround);
    EXPECT_EQ(character.GetGroundBody(), floor);
    EXPECT_NEAR(character.GetGroundNormal().y(), 1.0f, 1.0e-4f);
    EXPECT_GE(lowest, cCharacterStandHeight) << "it never sinks into the floor, landing at about 6 m/s";
    ExpectStandingOnFloor(character);
    EXPECT_NEAR(character.GetLinearVelocity().norm(), 0.0f, 1.0e-5f) << "the fall ended on landing";

    const Vec3 rested = character.GetPosition();
    for (int frame = 0; frame < 300; ++frame)
        ASSERT_TRUE(character.Update(cDeltaTime, cCharacterGravity).IsOk());
    EXPECT_LT((character.GetPosition() - rested).norm(), 1.0e-5f) << "standing still, it stays put";
    EXPECT_EQ(character.GetGroundState(), GroundState::OnGround);
}

TEST_F(CharacterControllerTest, AJumpLeavesTheGroundAndComesBackDown)
{
    AddFloor();
    CharacterController character = MakeCharacter(Vec3(0, cCharacterStandHeight + 0.02f, 0));
    Walk(character, Vec3::Zero(), 5);
    ASSERT_EQ(character.GetGroundState(), GroundState::OnGround);
    ASSERT_TRUE(character.SetLinearVelocity(Vec3(0, 5, 0)).IsOk());
    float highest = 0.0f;
    int framesInAir = 0;
    for (int frame = 0; frame < 90; ++frame)
    {
        ASSERT_TRUE(character.Update(cDeltaTime, cCharacterGravity).IsOk());
        highest = std::max(highest, character.GetPosition().y());
        framesInAir += character.GetGroundState() == GroundState::InAir ? 1 : 0;
    }
    // 5 m/s up rises 5^2 / (2 g) = 1.27 m, and is up about 2 * 5 / g = 1.02 s
    EXPECT_NEAR(highest - (cCharacterStandHeight + 0.02f), 25.0f / (2.0f * 9.81f), 0.05f);
    EXPECT_NEAR(framesInAir, 61, 2);
    ExpectStandingOnFloor(character);

    // A hop at 1 m/s, whose first frame stays within the ground's gap, still leaves it: 1 / (2 g) = 5.1 cm
    ASSERT_TRUE(character.SetLinearVelocity(Vec3(0, 1, 0)).IsOk());
    highest = 0.0f;
    for (int frame = 0; frame < 30; ++frame)
    {
        ASSERT_TRUE(character.Update(cDeltaTime, cCharacterGravity).IsOk());
        highest = std::max(highest, character.GetPosition().y());
    }
    EXPECT_GT(highest - (cCharacterStandHeight + 0.02f), 0.04f);
}

TEST_F(CharacterControllerTest, AWallStopsItAndItSlidesAlongTheWall)
{
    AddFloor();
    const BodyID wall = AddStatic(Box(Vec3(0.5f, 2, 10)), Vec3(3.5f, 2, 0)); // Its -x face at x = 3
    CharacterController character = MakeCharacter(Vec3(0, cCharacterStandHeight + 0.02f, 0));
    Walk(character, Vec3(4, 0, 0), 90);
    EXPECT_LE(character.GetPosition().x(), 3.0f - cCharacterRadius) << "never into the wall";
    EXPECT_GT(character.GetPosition().x(), 3.0f - cCharacterRadius - 0.05f)
        << "stopped at it, a padding short";
    EXPECT_NEAR(character.GetLinearVelocity().x(), 0.0f, 1.0e-4f) << "the wall took the velocity into it";
    EXPECT_EQ(character.GetGroundState(), GroundState::OnGround);

    // Along the wall at 45 degrees: the part along it goes on, at full speed
    const float zBefore = character.GetPosition().z();
    Walk(character, Vec3(2, 0, 2), 60);
    EXPECT_NEAR(character.GetPosition().z() - zBefore, 2.0f, 0.02f);
    EXPECT_LE(character.GetPosition().x(), 3.0f - cCharacterRadius);
    bool touchesWall = false;
    for (const CharacterContact& contact : character.GetContacts())
        touchesWall = touchesWall || (contact.mBody == wall && contact.mNormal.x() < -0.99f);
    EXPECT_TRUE(touchesWall) << "the wall is among the contacts, its normal towards the character";
    EXPECT_LT(DeepestOverlap(character), 1.0e-3f);
}

TEST_F(CharacterControllerTest, NeitherAFastFallNorAFastRunPassesThroughAThinSlab)
{
    AddFloor();
    const BodyID roof = AddStatic(Box(Vec3(3, 0.025f, 3)), Vec3(0, 5, 0)); // 5 cm thick, its top at 5.025
    const BodyID wall =
        AddStatic(Box(Vec3(0.025f, 3, 3)), Vec3(10, 3, 0)); // 5 cm thick, its -x face at 9.975
    // Dropped from 200 m: over 60 m/s, a metre a frame, when it meets the slab
    CharacterController faller = MakeCharacter(Vec3(0, 200, 0));
    for (int frame = 0; frame < 400; ++frame)
        ASSERT_TRUE(faller.Update(cDeltaTime, cCharacterGravity).IsOk());
    EXPECT_EQ(faller.GetGroundBody(), roof);
    EXPECT_GE(faller.GetPosition().y(), 5.025f + cCharacterStandHeight);
    // Running at 60 m/s into the wall
    CharacterController runner = MakeCharacter(Vec3(0, cCharacterStandHeight + 0.02f, 0));
    Walk(runner, Vec3(60, 0, 0), 30);
    EXPECT_LE(runner.GetPosition().x(), 9.975f - cCharacterRadius);
    EXPECT_TRUE(Touches(runner, wall));
}

TEST_F(CharacterControllerTest, ASensorInItsWayDoesNotStopIt)
{
    AddFloor();
    BodyCreationSettings trigger = BoxBodySettings(Vec3(3.5f, 2, 0), Vec3(0.5f, 2, 5), MotionType::Static);
    trigger.mObjectLayer = Layers::cTrigger;
    trigger.mIsSensor = true;
    ASSERT_TRUE(Bodies().CreateAndAddBody(trigger, Activation::DontActivate));
    CharacterController character = MakeCharacter(Vec3(0, cCharacterStandHeight + 0.02f, 0));
    Walk(character, Vec3(4, 0, 0), 90);
    EXPECT_GT(character.GetPosition().x(), 5.0f) << "through the trigger volume";
}

TEST_F(CharacterControllerTest, AnAcuteCornerHoldsItStillWithoutJitter)
{
    AddFloor();
    // Two walls meeting at x = 4 in a V 60 degrees wide, open towards -x
    for (const float side : {-1.0f, 1.0f})
    {
        const Quat turn(Eigen::AngleAxisf(side * cPi / 6.0f, Vec3::UnitY()));
        AddStatic(Box(Vec3(3, 2, 0.25f)), Vec3(4, 2, 0) + turn * Vec3(-3, 0, side * 0.25f), turn);
    }
    CharacterController character = MakeCharacter(Vec3(0, cCharacterStandHeight + 0.02f, 0.1f));
    Walk(character, Vec3(3, 0, 0), 120);
    const Vec3 settled = character.GetPosition();
    float wander = 0.0f;
    for (int frame = 0; frame < 60; ++frame)
    {
        Walk(character, Vec3(3, 0, 0), 1);
        wander = std::max(wander, (character.GetPosition() - settled).norm());
        EXPECT_LT(DeepestOverlap(character), 1.0e-3f) << "frame " << frame;
    }
    EXPECT_LT(wander, 2.0e-3f) << "pushed into the corner, it stays in it";
    EXPECT_GT(settled.x(), 1.5f) << "it went into the corner";
}

TEST_F(CharacterControllerTest, ItWalksUpAWalkableSlopeAndNotUpASteepOne)
{
    AddFloor();
    AddRamp(30.0f * cPi / 180.0f);
    CharacterController walker = MakeCharacter(Vec3(-2, cCharacterStandHeight + 0.02f, 0));
    Walk(walker, Vec3(3, 0, 0), 120);
    EXPECT_GT(walker.GetPosition().y(), cCharacterStandHeight + 2.0f) << "up the 30 degree ramp";
    EXPECT_EQ(walker.GetGroundState(), GroundState::OnGround);
    EXPECT_LT(DeepestOverlap(walker), 1.0e-3f);
}

TEST_F(CharacterControllerTest, ItCanNotClimbASteepSlopeAndSlidesDownIt)
{
    AddFloor();
    AddRamp(60.0f * cPi / 180.0f);
    CharacterController walker = MakeCharacter(Vec3(-2, cCharacterStandHeight + 0.02f, 0));
    float highest = 0.0f;
    for (int frame = 0; frame < 180; ++frame)
    {
        Walk(walker, Vec3(3, 0, 0), 1);
        highest = std::max(highest, walker.GetPosition().y());
    }
    // The capsule's round bottom rests against the slope's foot a little up it, no higher
    EXPECT_LT(highest, cCharacterStandHeight + 0.2f) << "the 60 degree ramp is a wall to it";
    EXPECT_EQ(walker.GetGroundState(), GroundState::OnGround) << "on the floor at the ramp's foot";

    // Put on the steep ramp, it slides down to its foot
    const Vec3 onRamp =
        Quat(Eigen::AngleAxisf(cPi / 3.0f, Vec3::UnitZ())) * Vec3(2, cCharacterRadius + 0.05f, 0) +
        Vec3(0, cCharacterHalfHeight, 0);
    CharacterController slider = MakeCharacter(onRamp);
    int onSteepGround = 0;
    for (int frame = 0; frame < 120; ++frame)
    {
        ASSERT_TRUE(slider.Update(cDeltaTime, cCharacterGravity).IsOk());
        onSteepGround += slider.GetGroundState() == GroundState::OnSteepGround ? 1 : 0;
        EXPECT_TRUE(frame >= 10 || slider.GetGroundState() != GroundState::OnGround) << frame;
    }
    EXPECT_GE(onSteepGround, 10) << "it touches the ramp as it slides down it, not falls";
    EXPECT_LT(slider.GetPosition().y(), onRamp.y() - 1.0f);
    EXPECT_LT(DeepestOverlap(slider), 1.0e-3f);
}

TEST_F(CharacterControllerTest, ItWalksOverRollingTerrainWithoutSnaggingOrSinking)
{
    // 40 m of height field, 1 m cells, hills 2.4 m from trough to top, nowhere steeper than 32 degrees
    constexpr uint32_t cSamples = 41;
    std::vector<float> heights(cSamples * cSamples);
    for (uint32_t z = 0; z < cSamples; ++z)
        for (uint32_t x = 0; x < cSamples; ++x)
            heights[x + z * cSamples] = 1.2f * std::sin(0.4f * float(x)) * std::cos(0.3f * float(z));
    AddStatic(HeightFieldShape::Create(cSamples, cSamples, 1.0f, heights).Value(), Vec3(-20, 0, -20));
    CharacterController character = MakeCharacter(Vec3(-15, cCharacterStandHeight + 1.5f, 0.5f));
    Walk(character, Vec3::Zero(), 60); // Lands
    const float startX = character.GetPosition().x();
    int offGround = 0;
    float deepest = 0.0f;
    for (int frame = 0; frame < 360; ++frame)
    {
        Walk(character, Vec3(4, 0, 0), 1);
        offGround += character.GetGroundState() != GroundState::OnGround ? 1 : 0;
        deepest = std::max(deepest, DeepestOverlap(character));
    }
    EXPECT_EQ(offGround, 0) << "over the hills and down them, on its feet";
    EXPECT_LT(deepest, 1.0e-3f) << "never into the ground";
    EXPECT_GT(character.GetPosition().x() - startX, 0.99f * 24.0f) << "at its pace across up, never caught";
}

TEST_F(CharacterControllerTest, ItWalksAcrossAFlatMeshAtFullPaceWithoutBumpingOnItsSeams)
{
    // 20 x 20 quads of 1 m, two triangles each, at y = 0
    std::vector<Vec3> vertices;
    std::vector<std::array<uint32_t, 3>> triangles;
    constexpr uint32_t cQuads = 20;
    for (uint32_t z = 0; z <= cQuads; ++z)
        for (uint32_t x = 0; x <= cQuads; ++x)
            vertices.emplace_back(float(x) - 10.0f, 0.0f, float(z) - 10.0f);
    for (uint32_t z = 0; z < cQuads; ++z)
        for (uint32_t x = 0; x < cQuads; ++x)
        {
            const uint32_t corner = x + z * (cQuads + 1);
            triangles.push_back({corner, corner + cQuads + 1, corner + 1});
            triangles.push_back({corner + 1, corner + cQuads + 1, corner + cQuads + 2});
        }
    AddStatic(TriangleMeshShape::Create(vertices, triangles).Value(), Vec3::Zero());
    CharacterController character = MakeCharacter(Vec3(-7, cCharacterStandHeight + 0.02f, -7.3f));
    Walk(character, Vec3::Zero(), 5);
    const Vec3 start = character.GetPosition();
    float lowest = start.y(), highest = start.y();
    int offGround = 0;
    for (int frame = 0; frame < 180; ++frame)
    {
        Walk(character, Vec3(3, 0, 3), 1);
        lowest = std::min(lowest, character.GetPosition().y());
        highest = std::max(highest, character.GetPosition().y());
        offGround += character.GetGroundState() != GroundState::OnGround ? 1 : 0;
    }
    EXPECT_EQ(offGround, 0);
    EXPECT_LT(highest - lowest, 1.0e-3f) << "no bump where triangles meet";
    EXPECT_NEAR((character.GetPosition() - start).norm(), 9.0f * std::sqrt(2.0f), 0.01f);
}

TEST_F(CharacterControllerTest, ItStepsUpStairsNoHigherThanItsStepHeight)
{
    AddFloor();
    AddStairs(1.0f, 5, 0.2f, 0.4f); // Top at 1 m, from x = 2.6 to 5.6
    CharacterController climber = MakeCharacter(Vec3(0, cCharacterStandHeight + 0.02f, 0));
    int offGround = 0;
    for (int frame = 0; frame < 100; ++frame)
    {
        Walk(climber, Vec3(2, 0, 0), 1);
        offGround += climber.GetGroundState() != GroundState::OnGround ? 1 : 0;
    }
    EXPECT_EQ(offGround, 0) << "on its feet all the way up";
    EXPECT_NEAR(climber.GetPosition().y(), cCharacterStandHeight + 1.0f, 0.05f) << "on the top step";
    EXPECT_GT(climber.GetPosition().x(), 3.0f) << "and on along it";
    EXPECT_EQ(climber.GetGroundState(), GroundState::OnGround);

    CharacterSettings noSteps = Settings();
    noSteps.mStepHeight = 0.0f;
    CharacterController blocked = MakeCharacter(Vec3(0, cCharacterStandHeight + 0.02f, 1), noSteps);
    Walk(blocked, Vec3(2, 0, 0), 150);
    EXPECT_LT(blocked.GetPosition().y(), cCharacterStandHeight + 0.1f)
        << "with no step height the first step stops it";
    EXPECT_LT(blocked.GetPosition().x(), 1.0f);
}

TEST_F(CharacterControllerTest, WithUpAlongZItLandsWalksAndClimbsAsWithUpAlongY)
{
    // The stairs scene turned so that y goes to z: the floor's top and the treads face +z, gravity pulls -z
    const Quat turn(Eigen::AngleAxisf(cPi / 2.0f, Vec3::UnitX()));
    const Vec3 up = turn * Vec3::UnitY();
    ASSERT_TRUE(up.isApprox(Vec3::UnitZ()));
    AddStatic(Box(Vec3(50, 1, 50)), turn * Vec3(0, -1, 0), turn);
    for (int step = 0; step < 5; ++step)
    {
        const float height = 0.2f * float(step + 1), run = step == 4 ? 3.0f : 0.4f;
        AddStatic(Box(Vec3(run / 2.0f, height / 2.0f, 3.0f)),
                  turn * Vec3(1.0f + 0.4f * float(step) + run / 2.0f, height / 2.0f, 0.0f), turn);
    }
    CharacterSettings settings = Settings();
    settings.mUp = up;
    CharacterController character = MakeCharacter(turn * Vec3(0, cCharacterStandHeight + 0.5f, 0), settings);
    const Vec3 gravity = turn * cCharacterGravity;
    const auto walk = [&](const Vec3& inVelocity, int inFrames)
    {
        for (int frame = 0; frame < inFrames; ++frame)
        {
            const Vec3 fall = character.GetLinearVelocity().dot(up) * up;
            ASSERT_TRUE(character.SetLinearVelocity(turn * inVelocity + fall).IsOk());
            ASSERT_TRUE(character.Update(cDeltaTime, gravity).IsOk());
        }
    };
    walk(Vec3::Zero(), 60); // Lands
    EXPECT_EQ(character.GetGroundState(), GroundState::OnGround);
    EXPECT_TRUE(character.GetGroundNormal().isApprox(up, 1.0e-4f));
    EXPECT_NEAR(character.GetPosition().dot(up), cCharacterStandHeight,
                character.GetSettings().mPadding + 1.0e-3f);
    EXPECT_GE(character.GetPosition().dot(up), cCharacterStandHeight);
    int offGround = 0;
    for (int frame = 0; frame < 100; ++frame)
    {
        walk(Vec3(2, 0, 0), 1);
        offGround += character.GetGroundState() != GroundState::OnGround ? 1 : 0;
    }
    EXPECT_EQ(offGround, 0) << "on its feet all the way up";
    EXPECT_NEAR(character.GetPosition().dot(up), cCharacterStandHeight + 1.0f, 0.05f) << "on the top step";
    EXPECT_GT(character.GetPosition().x(), 3.0f) << "and on along it";
    EXPECT_NEAR(character.GetPosition().y(), 0.0f, 1.0e-3f) << "straight, not sideways";
}

TEST_F(CharacterControllerTest, AStepHigherThanItsStepHeightStopsIt)
{
    AddFloor();
    AddStatic(Box(Vec3(1, 0.25f, 3)), Vec3(3, 0.25f, 0)); // 0.5 m high, from x = 2
    CharacterController character = MakeCharacter(Vec3(0, cCharacterStandHeight + 0.02f, 0));
    Walk(character, Vec3(2, 0, 0), 120);
    EXPECT_LT(character.GetPosition().y(), cCharacterStandHeight + 0.1f);
    EXPECT_LT(character.GetPosition().x(), 2.0f);
    EXPECT_EQ(character.GetGroundState(), GroundState::OnGround);
}

TEST_F(CharacterControllerTest, WalkingDownStairsItKeepsToTheFloor)
{
    AddFloor();
    AddStairs(1.0f, 5, 0.2f, 0.4f);
    const Vec3 top(3.4f, cCharacterStandHeight + 1.0f + 0.02f, 0);
    const auto framesOffGround = [&](const CharacterSettings& inSettings)
    {
        CharacterController character = MakeCharacter(top, inSettings);
        Walk(character, Vec3(0, 0, 0), 10);
        EXPECT_EQ(character.GetGroundState(), GroundState::OnGround);
        int offGround = 0;
        for (int frame = 0; frame < 90; ++frame)
        {
            Walk(character, Vec3(-2, 0, 0), 1);
            offGround += character.GetGroundState() != GroundState::OnGround ? 1 : 0;
        }
        EXPECT_LT(character.GetPosition().x(), 0.5f) << "it walked down to the floor";
        ExpectStandingOnFloor(character);
        return offGround;
    };
    EXPECT_EQ(framesOffGround(Settings()), 0) << "it follows each step down";
    CharacterSettings loose = Settings();
    loose.mStickToFloorDistance = 0.0f;
    EXPECT_GE(framesOffGround(loose), 5) << "without it, it drops off each step";
}

TEST_F(CharacterControllerTest, AMovingPlatformCarriesItAndAnElevatorLiftsIt)
{
    Ride ride = AddPlatformWithRider(2.0f, 0.0f);
    const BodyID id = ride.mPlatform;
    CharacterController& rider = ride.mRider;
    ASSERT_EQ(rider.GetGroundBody(), id);

    // Sideways at 1 m/s, then up at 1 m/s, a second each
    for (int frame = 0; frame < 120; ++frame)
    {
        const Vec3 velocity = frame < 60 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
        const Vec3 target = Position(id) + velocity * cDeltaTime;
        ASSERT_TRUE(Bodies().MoveKinematic(id, target, Quat::Identity(), cDeltaTime).IsOk());
        ASSERT_TRUE(UpdateWorld(cDeltaTime).IsOk());
        Walk(rider, Vec3::Zero(), 1);
        EXPECT_EQ(rider.GetGroundState(), GroundState::OnGround) << "frame " << frame;
        EXPECT_GE(rider.GetPosition().y() - Position(id).y(), 0.25f + cCharacterStandHeight - 1.0e-3f)
            << "never sunk into the platform, frame " << frame;
    }
    EXPECT_NEAR(rider.GetPosition().x(), 1.0f, 0.03f);
    EXPECT_LT((rider.GetGroundVelocity() - Vec3(0, 1, 0)).norm(), 0.05f) << "rising at 1 m/s";
    EXPECT_NEAR(rider.GetPosition().y() - Position(id).y(), 0.25f + cCharacterStandHeight + 0.02f, 0.03f);

    // Stepping off while the platform rises, it keeps the platform's velocity
    ASSERT_TRUE(rider.SetLinearVelocity(Vec3(0, 3, 0)).IsOk());
    ASSERT_TRUE(rider.Update(cDeltaTime, cCharacterGravity).IsOk());
    EXPECT_EQ(rider.GetGroundState(), GroundState::InAir);
    EXPECT_NEAR(rider.GetLinearVelocity().y(), 3.0f + 1.0f - 9.81f * cDeltaTime, 0.05f);
}

// A turntable at 1 rad/s about +y carries a rider round and turns it by as much (GetGroundTurn, the game's
// to apply to the rider's facing); a platform tilting about a level axis turns it by nothing about +y; on
// static ground the turn is none
TEST_F(CharacterControllerTest, ATurntableTurnsItsRiderAndATiltingPlatformDoesNot)
{
    Ride ride = AddPlatformWithRider(3.0f, 1.0f);
    const BodyID id = ride.mPlatform;
    CharacterController& rider = ride.mRider;
    ASSERT_EQ(rider.GetGroundBody(), id);
    EXPECT_TRUE(rider.GetGroundTurn().isApprox(Quat::Identity())) << "the table has not turned yet";
    const auto yawOf = [](const Quat& inTurn) { return 2.0f * std::atan2(inTurn.y(), inTurn.w()); };

    Quat facing = Quat::Identity(), table = Quat::Identity();
    for (int frame = 0; frame < 90; ++frame)
    {
        table = Quat(Eigen::AngleAxisf(cDeltaTime, Vec3::UnitY())) * table;
        ASSERT_TRUE(Bodies().MoveKinematic(id, Vec3(0, 1, 0), table, cDeltaTime).IsOk());
        ASSERT_TRUE(UpdateWorld(cDeltaTime).IsOk());
        Walk(rider, Vec3::Zero(), 1);
        facing = rider.GetGroundTurn() * facing;
    }
    EXPECT_NEAR(yawOf(facing), 1.5f, 0.03f) << "turned as far as the table";
    EXPECT_NEAR(yawOf(rider.GetGroundTurn()), cDeltaTime, 0.002f) << "a frame's turn";
    // Carried round with it: 1 m out, 1.5 rad on (counter-clockwise seen from above, from +x towards -z)
    EXPECT_NEAR(rider.GetPosition().x(), std::cos(1.5f), 0.05f);
    EXPECT_NEAR(rider.GetPosition().z(), -std::sin(1.5f), 0.05f);
    CharacterController moved = rider;
    ASSERT_TRUE(moved.SetPosition(Vec3(8, cCharacterStandHeight + 0.02f, 8)).IsOk());
    EXPECT_TRUE(moved.GetGroundTurn().isApprox(Quat::Identity())) << "put elsewhere";
    Walk(moved, Vec3::Zero(), 5);
    EXPECT_TRUE(moved.GetGroundTurn().isApprox(Quat::Identity())) << "on the static floor";

    // Tilting about x by 0.1 rad over a second: the rider rides it, turned by nothing about +y
    Quat tilt = table;
    float mostTurn = 0.0f;
    for (int frame = 0; frame < 60; ++frame)
    {
        tilt = tilt * Quat(Eigen::AngleAxisf(0.1f * cDeltaTime, Vec3::UnitX()));
        ASSERT_TRUE(Bodies().MoveKinematic(id, Vec3(0, 1, 0), tilt, cDeltaTime).IsOk());
        ASSERT_TRUE(UpdateWorld(cDeltaTime).IsOk());
        Walk(rider, Vec3::Zero(), 1);
        ASSERT_EQ(rider.GetGroundBody(), id) << "frame " << frame;
        mostTurn = std::max(mostTurn, rider.GetGroundTurn().angularDistance(Quat::Identity()));
    }
    EXPECT_LT(mostTurn, 1.0e-4f);
}

TEST_F(CharacterControllerTest, ItPushesADynamicBoxItWalksIntoWhenAskedTo)
{
    AddFloor();
    const auto walkIntoCrate = [&](bool inPush)
    {
        BodyCreationSettings crate =
            DynamicSettings(Box(Vec3::Constant(0.3f)), Vec3(2.0f + (inPush ? 0 : 10), 0.3f, 0));
        crate.mDensity =
            100.0f; // 21.6 kg: its friction on the floor, about 106 N, is less than the push's 500 N
        const BodyID id = AddDynamic(crate);
        CharacterController character =
            MakeCharacter(Vec3(inPush ? 0 : 10, cCharacterStandHeight + 0.02f, 0));
        const float start = Position(id).x();
        for (int frame = 0; frame < 120; ++frame)
        {
            Walk(character, Vec3(2, 0, 0), 1);
            if (inPush)
            {
                EXPECT_TRUE(character.PushBodies(Bodies()).IsOk());
            }
            EXPECT_TRUE(UpdateWorld(cDeltaTime).IsOk());
        }
        return Position(id).x() - start;
    };
    EXPECT_GT(walkIntoCrate(true), 1.0f) << "pushed ahead of it";
    EXPECT_LT(walkIntoCrate(false), 0.05f) << "Update alone moves no body";
}

TEST_F(CharacterControllerTest, ItPressesOnADynamicBodyItStandsOnAndLeavesStaticOnesBe)
{
    PhysicsSettings weightless;
    weightless.mGravity = Vec3::Zero();
    ResetWorld(weightless);
    const BodyID wall = AddStatic(Box(Vec3(0.5f, 2, 5)), Vec3(1.5f, 2, 0)); // Its -x face at x = 1
    BodyCreationSettings raft = DynamicSettings(Box(Vec3(2, 0.25f, 2)), Vec3(0, -0.25f, 0));
    const BodyID id = AddDynamic(raft);
    CharacterController character = MakeCharacter(Vec3(0, cCharacterStandHeight + 0.02f, 0));
    Walk(character, Vec3(3, 0, 0), 30); // On the raft and against the wall
    ASSERT_EQ(character.GetGroundBody(), id);
    ASSERT_TRUE(Touches(character, wall));
    ASSERT_TRUE(character.PushBodies(Bodies()).IsOk())
        << "the static wall is not pushed, and that is no error";
    // Its 70 kg's weight over one frame, on the raft's 2,000 kg (it has no gravity of its own here)
    const float raftMass = 1000.0f * 4 * 0.5f * 4;
    EXPECT_NEAR(Velocity(id).y(), -70.0f * 9.81f * cDeltaTime / raftMass, 1.0e-4f);
}

TEST_F(CharacterControllerTest, AfterSetPositionPushBodiesPushesNothingUntilTheNextUpdate)
{
    PhysicsSettings weightless;
    weightless.mGravity = Vec3::Zero();
    ResetWorld(weightless);
    const BodyID raft = AddDynamic(DynamicSettings(Box(Vec3(3, 0.25f, 3)), Vec3(0, -0.25f, 0)));
    const BodyID crate = AddDynamic(DynamicSettings(Box(Vec3::Constant(0.3f)), Vec3(1.5f, 0.6f, 0)));
    CharacterController character = MakeCharacter(Vec3(0, cCharacterStandHeight + 0.02f, 0));
    for (int frame = 0; frame < 20; ++frame)
    {
        ASSERT_TRUE(character.SetLinearVelocity(Vec3(3, 0, 0)).IsOk());
        ASSERT_TRUE(character.Update(cDeltaTime, cCharacterGravity).IsOk());
    }
    ASSERT_EQ(character.GetGroundBody(), raft);
    ASSERT_TRUE(Touches(character, crate));
    CharacterController control = character; // Where it stands, pushing and pressing

    ASSERT_TRUE(character.SetPosition(Vec3(0, cCharacterStandHeight + 0.02f, -20)).IsOk());
    ASSERT_TRUE(character.PushBodies(Bodies()).IsOk());
    EXPECT_EQ(Velocity(raft), Vec3::Zero()) << "no weight on the raft it no longer stands on";
    EXPECT_EQ(Velocity(crate), Vec3::Zero()) << "no push on the crate it is no longer at";

    ASSERT_TRUE(control.PushBodies(Bodies()).IsOk());
    EXPECT_LT(Velocity(raft).y(), 0.0f);
    EXPECT_GT(Velocity(crate).x(), 0.0f);
}

TEST_F(CharacterControllerTest, ABodyMovedIntoItPushesItOut)
{
    AddFloor();
    CharacterController character = MakeCharacter(Vec3(0, cCharacterStandHeight + 0.02f, 0));
    Walk(character, Vec3::Zero(), 5);
    // A crate dropped half into it from the side
    const BodyID crate = AddStatic(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0.6f, 0.5f, 0));
    ASSERT_GT(DeepestOverlap(character), 0.1f);
    ASSERT_TRUE(character.Update(cDeltaTime, cCharacterGravity).IsOk());
    EXPECT_LT(DeepestOverlap(character), 1.0e-3f);
    EXPECT_LT(character.GetPosition().x(), 0.1f - cCharacterRadius + 1.0e-3f);
    EXPECT_NEAR(character.GetPosition().y(), cCharacterStandHeight + 0.02f, 0.01f)
        << "pushed sideways, not up or down";
    EXPECT_TRUE(Touches(character, crate));
}

TEST_F(CharacterControllerTest, BadInputIsRefusedAndChangesNothing)
{
    AddFloor();
    const auto refused = [&](const CharacterSettings& inSettings, const Vec3& inPosition)
    {
        Result<CharacterController> created = CharacterController::Create(System(), inSettings, inPosition);
        return !created && created.GetError().mCode == ErrorCode::InvalidArgument;
    };
    const Vec3 start(0, cCharacterStandHeight + 0.02f, 0);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    CharacterSettings settings = Settings();
    EXPECT_TRUE(refused(settings, Vec3(nan, 0, 0)));
    EXPECT_TRUE(refused(settings, Vec3(0, 2.0e6f, 0)));
    settings.mShape = nullptr;
    EXPECT_TRUE(refused(settings, start));
    const std::array<Vec3, 3> vertices{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1)};
    const std::array<std::array<uint32_t, 3>, 1> triangle{{{0, 1, 2}}};
    settings.mShape = TriangleMeshShape::Create(vertices, triangle).Value();
    EXPECT_TRUE(refused(settings, start)) << "a mesh can not be swept";
    // Each out-of-range value of a setting, the others valid
    const auto refusesEach = [&](float CharacterSettings::*inField, std::initializer_list<float> inValues)
    {
        for (const float value : inValues)
        {
            CharacterSettings bad = Settings();
            bad.*inField = value;
            EXPECT_TRUE(refused(bad, start)) << value;
        }
    };
    refusesEach(&CharacterSettings::mMaxSlopeAngle, {0.0f, cPi / 2.0f, nan});
    refusesEach(&CharacterSettings::mStepHeight, {-1.0f, nan, 1.0e9f});
    refusesEach(&CharacterSettings::mStickToFloorDistance, {-1.0f, nan, 1.0e9f});
    refusesEach(&CharacterSettings::mPadding, {0.0f, 0.5f, nan});
    refusesEach(&CharacterSettings::mMass, {0.0f, -70.0f, nan, 1.0e7f});
    refusesEach(&CharacterSettings::mMaxPushForce, {-1.0f, nan, 1.0e10f});
    settings = Settings();
    settings.mUp = Vec3(0, 2, 0);
    EXPECT_TRUE(refused(settings, start));

    CharacterController character = MakeCharacter(start);
    Walk(character, Vec3(1, 0, 0), 5);
    const Vec3 position = character.GetPosition();
    const Vec3 velocity = character.GetLinearVelocity();
    for (const float deltaTime : {0.0f, -1.0f, nan, std::numeric_limits<float>::infinity()})
        EXPECT_EQ(character.Update(deltaTime, cCharacterGravity).GetError().mCode,
                  ErrorCode::InvalidArgument);
    EXPECT_EQ(character.Update(cDeltaTime, Vec3(0, nan, 0)).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_EQ(character.SetLinearVelocity(Vec3(nan, 0, 0)).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_EQ(character.SetPosition(Vec3(0, 0, 1.0e7f)).GetError().mCode, ErrorCode::InvalidArgument);
    // A move past the queries' reach: refused as a whole, not half made
    const BodyID groundBody = character.GetGroundBody();
    const size_t contacts = character.GetContacts().size();
    ASSERT_TRUE(character.SetLinearVelocity(Vec3(1.0e12f, 0, 0)).IsOk());
    EXPECT_EQ(character.Update(cDeltaTime, cCharacterGravity).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_EQ(character.GetPosition(), position);
    EXPECT_EQ(character.GetLinearVelocity(), Vec3(1.0e12f, 0, 0))
        << "as set, not as a half-made Update left it";
    EXPECT_EQ(character.GetGroundState(), GroundState::OnGround);
    EXPECT_EQ(character.GetGroundBody(), groundBody);
    EXPECT_EQ(character.GetContacts().size(), contacts);
    ASSERT_TRUE(character.SetLinearVelocity(velocity).IsOk());
    EXPECT_TRUE(character.Update(cDeltaTime, cCharacterGravity).IsOk());

    // A move the queries allow (17 m, rising: no sweep down follows it) that would end beyond the world's
    // edge: refused, where it was
    CharacterController atTheEdge = MakeCharacter(Vec3(cMaxWorldCoordinate - 10.0f, 10, 0));
    ASSERT_TRUE(atTheEdge.SetLinearVelocity(Vec3(1000, 5, 0)).IsOk());
    EXPECT_EQ(atTheEdge.Update(cDeltaTime, cCharacterGravity).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_EQ(atTheEdge.GetPosition(), Vec3(cMaxWorldCoordinate - 10.0f, 10, 0));
}

TEST_F(CharacterControllerTest, ABoxShapedCharacterStepsUpAStairsSheerRiser)
{
    AddFloor();
    AddStairs(1.0f, 3, 0.2f, 0.5f);
    CharacterSettings boxy = Settings();
    boxy.mShape = Box(Vec3(0.3f, 0.9f, 0.3f)); // Its side meets a riser face to face: a level normal
    CharacterController character = MakeCharacter(Vec3(0, 0.92f, 0), boxy);
    Walk(character, Vec3(2, 0, 0), 120);
    EXPECT_NEAR(character.GetPosition().y(), 0.9f + 0.6f, 0.05f) << "on the top step";
    EXPECT_GT(character.GetPosition().x(), 2.0f);
    EXPECT_EQ(character.GetGroundState(), GroundState::OnGround);
}

TEST(CharacterClipToPlanesTest, ItKeepsWhatPointsIntoNoPlaneAlongOnePlaneACreaseOrNothing)
{
    const Vec3 floor = Vec3::UnitY();
    const Vec3 wall = -Vec3::UnitX();
    const std::array<Vec3, 1> justFloor{floor};
    EXPECT_EQ(ClipToPlanes(Vec3(1, 2, 0), justFloor), Vec3(1, 2, 0)) << "away from the plane: kept";
    EXPECT_TRUE(ClipToPlanes(Vec3(1, -2, 3), justFloor).isApprox(Vec3(1, 0, 3)));
    const std::array<Vec3, 2> floorAndWall{floor, wall};
    EXPECT_TRUE(ClipToPlanes(Vec3(1, -1, 2), floorAndWall).isApprox(Vec3(0, 0, 2))) << "along the crease";
    // Along the crease whichever way it points: the planes' cross product points +z, the vector -z
    EXPECT_TRUE(floor.cross(wall).z() > 0.0f);
    EXPECT_TRUE(ClipToPlanes(Vec3(1, -1, -2), floorAndWall).isApprox(Vec3(0, 0, -2)))
        << "along the crease, back";
    const std::array<Vec3, 2> wallAndFloor{wall, floor};
    EXPECT_TRUE(ClipToPlanes(Vec3(1, -1, -2), wallAndFloor).isApprox(Vec3(0, 0, -2)))
        << "the planes in any order";
    // Two walls in a V: into it the nearest allowed is nothing; along one, the other does not matter
    const Vec3 left = Vec3(-1, 0, 1).normalized(), right = Vec3(-1, 0, -1).normalized();
    const std::array<Vec3, 3> corner{floor, left, right};
    EXPECT_LT(ClipToPlanes(Vec3(1, -1, 0), corner).norm(), 1.0e-6f);
    // Into the left wall and away from the right one: along the left wall
    EXPECT_TRUE(ClipToPlanes(Vec3(1, 0, -2), corner).isApprox(Vec3(-0.5f, 0, -0.5f)));
}

} // namespace cairn::test
