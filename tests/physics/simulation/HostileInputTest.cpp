// Hostile input to the physics API, beyond what BadInputTest, SetupValidationTest, WorldQueryTest and the
// shape tests already try. It proves that every BodyInterface call refuses garbage and stale ids (a reused
// slot included) without touching the body now in that slot; that add batches naming a body twice, empty,
// finished, moved from, handed to another world or aborted from the wrong thread neither corrupt the world
// nor strand their bodies; that values the validation lets through (a density whose mass or contact impulses
// overflow, a ray whose squared length overflows a sphere's test, a huge query separation, time steps that
// underflow, extreme shape sizes, bodies placed on top of each other) get a clear error or leave a sane,
// finite world; that a query the narrow phase cannot answer (mesh against mesh) or whose probe shape was
// built around its checked Create is an error, not "nothing there"; that the broad phase ignores NaN queries
// as documented; and that object layers past the layer tables are not read out of bounds. Where the engine
// accepts bad input, the test steps the world and checks that every body stays finite.

#include "SimulationFixture.h"
#include "cairn/physics/body/BodyLock.h"
#include "cairn/physics/shapes/CapsuleShape.h"
#include "cairn/physics/shapes/ConvexHullShape.h"
#include "cairn/physics/shapes/TriangleMeshShape.h"
#include "common/MakePhysicsSystem.h"

#include <array>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <new>
#include <string>
#include <vector>

namespace cairn::test
{
using namespace cairn::physics;
namespace
{

constexpr float cNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float cInf = std::numeric_limits<float>::infinity();

/// A flat square of two triangles at height inY, inHalfSize on each side of the origin, facing +Y.
std::shared_ptr<const TriangleMeshShape> FlatMesh(float inHalfSize, float inY)
{
    const std::vector<Vec3> vertices = {Vec3(-inHalfSize, inY, -inHalfSize),
                                        Vec3(inHalfSize, inY, -inHalfSize), Vec3(inHalfSize, inY, inHalfSize),
                                        Vec3(-inHalfSize, inY, inHalfSize)};
    const std::vector<std::array<uint32_t, 3>> triangles = {{0, 2, 1}, {0, 3, 2}};
    return TriangleMeshShape::Create(vertices, triangles).Value();
}

} // namespace

class HostileInputTest : public SimulationFixture
{
protected:
    void SetUp() override { mFloor = AddFloor(); }

    const WorldQuery& Query() { return System().GetWorldQuery(); }

    /// A dynamic box of half extent 0.5 resting on the floor at inX.
    BodyID AddRestingBox(float inX)
    {
        return AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(inX, 0.5f, 0)));
    }

    /// Position, rotation and both velocities of inID are finite numbers.
    void ExpectBodyFinite(const BodyID& inID, const char* inWhat)
    {
        const Vec3 position = Bodies().GetPosition(inID).Value();
        const Quat rotation = Bodies().GetRotation(inID).Value();
        EXPECT_TRUE(IsFinite(position)) << inWhat << ": position " << position.transpose();
        EXPECT_TRUE(rotation.coeffs().allFinite())
            << inWhat << ": rotation " << rotation.coeffs().transpose();
        EXPECT_TRUE(IsFinite(Bodies().GetLinearVelocity(inID).Value())) << inWhat << ": linear velocity";
        EXPECT_TRUE(IsFinite(Bodies().GetAngularVelocity(inID).Value())) << inWhat << ": angular velocity";
        EXPECT_TRUE(Bodies().GetWorldBounds(inID).Value().IsFinite()) << inWhat << ": bounds";
    }

    /// Every BodyInterface call with inID fails with inExpected; none of them may change a body.
    void ExpectEveryCallRefuses(const BodyID& inID, ErrorCode inExpected, const std::string& inWhat)
    {
        SCOPED_TRACE(inWhat);
        auto code = [](const auto& inResult)
        { return inResult.IsOk() ? std::string("Ok") : ToString(inResult.GetError().mCode); };
        const std::string expected = ToString(inExpected);
        EXPECT_EQ(code(Bodies().AddBody(inID, Activation::Activate)), expected) << "AddBody";
        EXPECT_EQ(code(Bodies().RemoveBody(inID)), expected) << "RemoveBody";
        EXPECT_EQ(code(Bodies().DestroyBody(inID)), expected) << "DestroyBody";
        EXPECT_EQ(code(Bodies().SetPosition(inID, Vec3(1, 2, 3), Activation::Activate)), expected)
            << "SetPosition";
        EXPECT_EQ(code(Bodies().SetRotation(inID, Quat::Identity(), Activation::Activate)), expected)
            << "SetRotation";
        EXPECT_EQ(code(Bodies().SetPositionAndRotation(inID, Vec3(1, 2, 3), Quat::Identity(),
                                                       Activation::Activate)),
                  expected)
            << "SetPositionAndRotation";
        EXPECT_EQ(code(Bodies().SetLinearVelocity(inID, Vec3(1, 0, 0))), expected) << "SetLinearVelocity";
        EXPECT_EQ(code(Bodies().SetAngularVelocity(inID, Vec3(1, 0, 0))), expected) << "SetAngularVelocity";
        EXPECT_EQ(code(Bodies().AddForce(inID, Vec3(1, 0, 0))), expected) << "AddForce";
        EXPECT_EQ(code(Bodies().AddTorque(inID, Vec3(1, 0, 0))), expected) << "AddTorque";
        EXPECT_EQ(code(Bodies().AddImpulse(inID, Vec3(1, 0, 0))), expected) << "AddImpulse";
        EXPECT_EQ(code(Bodies().AddImpulse(inID, Vec3(1, 0, 0), Vec3(0, 1, 0))), expected)
            << "AddImpulse at a point";
        EXPECT_EQ(code(Bodies().AddAngularImpulse(inID, Vec3(1, 0, 0))), expected) << "AddAngularImpulse";
        EXPECT_EQ(code(Bodies().ActivateBody(inID)), expected) << "ActivateBody";
        EXPECT_EQ(code(Bodies().DeactivateBody(inID)), expected) << "DeactivateBody";
        EXPECT_EQ(code(Bodies().GetPosition(inID)), expected) << "GetPosition";
        EXPECT_EQ(code(Bodies().GetRotation(inID)), expected) << "GetRotation";
        EXPECT_EQ(code(Bodies().GetLinearVelocity(inID)), expected) << "GetLinearVelocity";
        EXPECT_EQ(code(Bodies().GetAngularVelocity(inID)), expected) << "GetAngularVelocity";
        EXPECT_EQ(code(Bodies().GetWorldBounds(inID)), expected) << "GetWorldBounds";
        EXPECT_EQ(code(Bodies().IsActive(inID)), expected) << "IsActive";
        EXPECT_EQ(code(Bodies().IsAdded(inID)), expected) << "IsAdded";
        EXPECT_EQ(code(Bodies().AddBodiesPrepare({&inID, 1})), expected) << "AddBodiesPrepare";
        BodyLockRead read(System().GetBodyManager(), inID);
        EXPECT_FALSE(read.Succeeded()) << "BodyLockRead";
    }

    BodyID mFloor;
};

// --- Ids --------------------------------------------------------------------------------------------------

TEST_F(HostileInputTest, EveryBodyCallRefusesGarbageIDs)
{
    const BodyID box = AddRestingBox(0.0f);
    const Vec3 boxPosition = Position(box);
    const uint32_t maxBodies = System().GetBodyManager().GetMaxBodies();
    ExpectEveryCallRefuses(BodyID(), ErrorCode::InvalidBodyID, "the default (invalid) id");
    ExpectEveryCallRefuses(BodyID(BodyID::cInvalidIndex, 12345), ErrorCode::InvalidBodyID,
                           "the invalid index with a sequence");
    ExpectEveryCallRefuses(BodyID(maxBodies, 0), ErrorCode::InvalidBodyID, "one past the last slot");
    ExpectEveryCallRefuses(BodyID(maxBodies - 1, 0), ErrorCode::InvalidBodyID, "the last slot, never used");
    ExpectEveryCallRefuses(BodyID(0xfffffffeu, 0xffffffffu), ErrorCode::InvalidBodyID, "all bits but one");
    ExpectEveryCallRefuses(BodyID(box.GetIndex(), box.GetSequence() + 1), ErrorCode::InvalidBodyID,
                           "a live slot with a sequence from the future");
    ExpectEveryCallRefuses(BodyID(box.GetIndex(), 0xffffffffu), ErrorCode::InvalidBodyID,
                           "a live slot with a garbage sequence");

    // Nothing happened to the real bodies
    EXPECT_EQ(System().GetBodyManager().GetNumBodies(), 2u);
    EXPECT_EQ(System().GetBroadPhase().GetBodyCount(), 2u);
    EXPECT_EQ(Position(box), boxPosition);
    EXPECT_EQ(Velocity(box), Vec3::Zero());
    Step(10);
    ExpectBodyFinite(box, "box");
}

TEST_F(HostileInputTest, AStaleIDWhoseSlotWasReusedLeavesTheNewBodyAlone)
{
    const BodyID old = AddRestingBox(5.0f);
    ASSERT_TRUE(Bodies().RemoveBody(old).IsOk());
    ASSERT_TRUE(Bodies().DestroyBody(old).IsOk());
    const BodyID reused = AddRestingBox(-5.0f);
    ASSERT_EQ(reused.GetIndex(), old.GetIndex()) << "the test needs the slot to be reused";
    Step(1);
    const Vec3 position = Position(reused);
    const Vec3 velocity = Velocity(reused);

    // Removing or destroying through the stale id must not take the new body out of the world
    ExpectEveryCallRefuses(old, ErrorCode::InvalidBodyID, "the removed body's id");
    EXPECT_TRUE(Bodies().IsAdded(reused).Value());
    EXPECT_EQ(Position(reused), position);
    EXPECT_EQ(Velocity(reused), velocity);
    std::vector<BodyID> found;
    ASSERT_TRUE(Query().CollidePoint(position, found).IsOk());
    ASSERT_EQ(found.size(), 1u);
    EXPECT_EQ(found[0], reused);
    EXPECT_EQ(System().GetBroadPhase().GetBodyCount(), 2u);
}

// --- Batches ----------------------------------------------------------------------------------------------

TEST_F(HostileInputTest, ABatchNamingOneBodyTwiceMarksNothing)
{
    const BodyID body = Bodies().CreateBody(DynamicSettings(Sphere(0.5f), Vec3(0, 3, 0))).Value();
    const BodyID twice[] = {body, body};
    Result<BodyInterface::AddBatch> batch = Bodies().AddBodiesPrepare(twice);
    ASSERT_FALSE(batch.IsOk()) << "a body added twice by one batch";
    EXPECT_EQ(batch.GetError().mCode, ErrorCode::AlreadyAdded);
    // Not left pending: it can still be added, once
    ASSERT_TRUE(Bodies().AddBody(body, Activation::Activate).IsOk());
    EXPECT_EQ(System().GetBroadPhase().GetBodyCount(), 2u);
    Step(30);
    ExpectBodyFinite(body, "sphere");
}

TEST_F(HostileInputTest, EmptyAndFinishedBatchesAreHandledCleanly)
{
    Result<BodyInterface::AddBatch> empty = Bodies().AddBodiesPrepare({});
    ASSERT_TRUE(empty.IsOk()) << "an empty batch is no error: " << empty.GetError().mMessage;
    EXPECT_TRUE(Bodies().AddBodiesFinalize(empty.Value(), Activation::Activate).IsOk());

    const BodyID body = Bodies().CreateBody(DynamicSettings(Sphere(0.5f), Vec3(0, 3, 0))).Value();
    Result<BodyInterface::AddBatch> batch = Bodies().AddBodiesPrepare({&body, 1});
    ASSERT_TRUE(batch.IsOk());
    ASSERT_TRUE(Bodies().AddBodiesFinalize(batch.Value(), Activation::Activate).IsOk());
    EXPECT_EQ(Bodies().AddBodiesFinalize(batch.Value(), Activation::Activate).GetError().mCode,
              ErrorCode::InvalidArgument)
        << "finalized twice";
    EXPECT_TRUE(Bodies().AddBodiesAbort(batch.Value()).IsOk()); // Aborting a finalized batch does nothing
    EXPECT_TRUE(Bodies().IsAdded(body).Value());
    EXPECT_EQ(System().GetBroadPhase().GetBodyCount(), 2u);

    // A moved-from batch is empty too
    const BodyID second = Bodies().CreateBody(DynamicSettings(Sphere(0.5f), Vec3(3, 3, 0))).Value();
    Result<BodyInterface::AddBatch> prepared = Bodies().AddBodiesPrepare({&second, 1});
    ASSERT_TRUE(prepared.IsOk());
    BodyInterface::AddBatch taken(std::move(prepared.Value()));
    EXPECT_EQ(Bodies().AddBodiesFinalize(prepared.Value(), Activation::Activate).GetError().mCode,
              ErrorCode::InvalidArgument);
    ASSERT_TRUE(Bodies().AddBodiesFinalize(taken, Activation::Activate).IsOk());
    EXPECT_EQ(System().GetBroadPhase().GetBodyCount(), 3u);
    Step(10);
}

TEST_F(HostileInputTest, AnAbortFromTheWrongThreadDoesNotStrandTheBatchsBodies)
{
    const BodyID pending = Bodies().CreateBody(DynamicSettings(Sphere(0.5f), Vec3(0, 3, 0))).Value();
    Result<BodyInterface::AddBatch> batch = Bodies().AddBodiesPrepare({&pending, 1});
    ASSERT_TRUE(batch.IsOk());
    {
        // As from a body change listener: this thread holds a body lock, so it may not take another
        BodyLockRead lock(System().GetBodyManager(), mFloor);
        ASSERT_TRUE(lock.Succeeded());
        EXPECT_EQ(Bodies().AddBodiesAbort(batch.Value()).GetError().mCode, ErrorCode::WrongThread);
    }
    // Refused whole: the batch can still be aborted, which leaves a body that can be added or destroyed
    EXPECT_TRUE(Bodies().AddBodiesAbort(batch.Value()).IsOk());
    EXPECT_TRUE(Bodies().DestroyBody(pending).IsOk())
        << "the body is stuck as pending: it can never be added nor destroyed";
    EXPECT_EQ(System().GetBroadPhase().GetBodyCount(), 1u);
}

TEST_F(HostileInputTest, AFullWorldSaysSo)
{
    PhysicsSettings settings;
    settings.mMaxBodies = 3;
    ResetWorld(settings);
    AddFloor();
    AddRestingBox(0.0f);
    AddRestingBox(3.0f);
    const Result<BodyID> overflow =
        Bodies().CreateAndAddBody(DynamicSettings(Sphere(1), Vec3(0, 5, 0)), Activation::Activate);
    ASSERT_FALSE(overflow.IsOk());
    EXPECT_EQ(overflow.GetError().mCode, ErrorCode::OutOfCapacity);
    EXPECT_EQ(System().GetBodyManager().GetNumBodies(), 3u);
    Step(5);
}

// A body removed keeps its broad-phase nodes until an update frees them: a world that adds and removes bodies
// without stepping found its node pool full with no body in it. The error says what frees them, and
// OptimizeBroadPhase does, between Updates
TEST_F(HostileInputTest, AddsAndRemovesWithoutStepsFillTheBroadPhaseUntilItIsOptimized)
{
    PhysicsSettings settings;
    settings.mMaxBodies = 16;
    ResetWorld(settings);
    BodyCreationSettings box = DynamicSettings(Sphere(1), Vec3(0, 5, 0));
    box.mMotionType = MotionType::Static;
    box.mObjectLayer = Layers::cStatic;
    auto cycle = [&]() -> Status
    {
        const Result<BodyID> added = Bodies().CreateAndAddBody(box, Activation::DontActivate);
        if (!added) return added.GetError();
        EXPECT_TRUE(Bodies().RemoveBody(added.Value()));
        EXPECT_TRUE(Bodies().DestroyBody(added.Value()));
        return Status::Ok();
    };
    int cycles = 0;
    Status last = Status::Ok();
    while (cycles < 1'000'000 && (last = cycle()))
        ++cycles;
    ASSERT_FALSE(last) << "a million adds and removes and the pool never filled: the test tests nothing";
    EXPECT_EQ(last.GetError().mCode, ErrorCode::OutOfCapacity);
    EXPECT_NE(last.GetError().mMessage.find("OptimizeBroadPhase"), std::string::npos)
        << last.GetError().mMessage;
    EXPECT_EQ(System().GetBroadPhase().GetBodyCount(), 0u);

    ASSERT_TRUE(System().OptimizeBroadPhase());
    for (int i = 0; i < cycles; ++i)
        ASSERT_TRUE(cycle()) << "cycle " << i << " of the " << cycles << " that fitted before";
    ASSERT_TRUE(System().OptimizeBroadPhase());
    Step(1);
}

// --- Values the validation lets through --------------------------------------------------------------------

TEST_F(HostileInputTest, PushesAndMovesWithNaNInfOrHugeValuesAreRefusedWhole)
{
    const BodyID box = AddRestingBox(0.0f);
    Step(1);
    const Vec3 position = Position(box);
    const Quat rotation = Bodies().GetRotation(box).Value();
    auto refused = [](const Status& inStatus)
    { return !inStatus.IsOk() && inStatus.GetError().mCode == ErrorCode::InvalidArgument; };
    EXPECT_TRUE(refused(Bodies().SetAngularVelocity(box, Vec3(cNaN, 0, 0))));
    EXPECT_TRUE(refused(Bodies().SetAngularVelocity(box, Vec3(0, 0, 1e20f))));
    EXPECT_TRUE(refused(Bodies().AddTorque(box, Vec3(0, cInf, 0))));
    EXPECT_TRUE(refused(Bodies().AddAngularImpulse(box, Vec3(0, 0, cNaN))));
    EXPECT_TRUE(refused(Bodies().AddImpulse(box, Vec3(cNaN, 0, 0))));
    EXPECT_TRUE(refused(Bodies().AddImpulse(box, Vec3(1, 0, 0), Vec3(cNaN, 0, 0))));
    EXPECT_TRUE(refused(Bodies().AddImpulse(box, Vec3(1, 0, 0), Vec3(1e30f, 0, 0))));
    // Finite impulse and lever, but an angular velocity too large to square: refused, not half applied
    EXPECT_TRUE(refused(Bodies().AddImpulse(box, Vec3(0, 1e19f, 0), Vec3(1e6f, 0, 0))));
    EXPECT_TRUE(refused(Bodies().SetPosition(box, Vec3(1e30f, 0, 0), Activation::Activate)));
    EXPECT_TRUE(refused(
        Bodies().SetPositionAndRotation(box, Vec3(0, cNaN, 0), Quat::Identity(), Activation::Activate)));
    EXPECT_TRUE(
        refused(Bodies().SetPositionAndRotation(box, Vec3::Zero(), Quat(0, 0, 0, 0), Activation::Activate)));
    EXPECT_TRUE(refused(Bodies().SetRotation(box, Quat(cInf, 0, 0, 0), Activation::Activate)));
    EXPECT_EQ(Position(box), position);
    EXPECT_TRUE(Bodies().GetRotation(box).Value().coeffs() == rotation.coeffs());
    EXPECT_LT(Velocity(box).norm(), 1.0f);
    EXPECT_LT(Bodies().GetAngularVelocity(box).Value().norm(), 1.0f);
    // Accepted (its square is finite) though far beyond the body's limit: the step clamps it
    ASSERT_TRUE(Bodies().AddAngularImpulse(box, Vec3(1e19f, 0, 0)).IsOk());
    Step(30);
    ExpectBodyFinite(box, "box");
}

TEST_F(HostileInputTest, AVeryDenseBodyIsRefusedAndTheHeaviestAllowedLandsFinitely)
{
    // Finite density, finite mass (3.2e38 kg), finite inverse, but its contact impulses (mass times speed)
    // are beyond a float: refused
    BodyCreationSettings settings = DynamicSettings(Box(Vec3(1, 1, 1)), Vec3(0, 10, 0));
    settings.mDensity = 4.0e37f;
    const Result<BodyID> refused = Bodies().CreateAndAddBody(settings, Activation::Activate);
    ASSERT_FALSE(refused.IsOk());
    EXPECT_EQ(refused.GetError().mCode, ErrorCode::InvalidArgument);

    // The heaviest body taken (8 m^3 at cMaxBodyMass) lands on the floor, and on an ordinary box
    settings.mDensity = cMaxBodyMass / 8.0f;
    const Result<BodyID> heaviest = Bodies().CreateAndAddBody(settings, Activation::Activate);
    ASSERT_TRUE(heaviest.IsOk()) << heaviest.GetError().mMessage;
    const BodyID ordinary = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(5, 0.5f, 0)));
    settings.mPosition = Vec3(5, 10, 0);
    const BodyID crusher = AddDynamic(settings);
    for (int i = 0; i < 120; ++i)
        ASSERT_TRUE(UpdateWorld(cDeltaTime).IsOk());
    ExpectBodyFinite(heaviest.Value(), "heaviest box");
    EXPECT_NEAR(Position(heaviest.Value()).y(), 1.0f, 0.1f) << "it rests on the floor";
    ExpectBodyFinite(ordinary, "ordinary box");
    ExpectBodyFinite(crusher, "heaviest box on the ordinary one");
}

TEST_F(HostileInputTest, AMassThatOverflowsIsNamedAsSuch)
{
    // Density times volume is beyond a float: refused, but with a reason the caller can act on
    BodyCreationSettings settings = DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 10, 0));
    settings.mDensity = 3.0e38f;
    const Result<BodyID> created = Bodies().CreateBody(settings);
    ASSERT_FALSE(created.IsOk());
    EXPECT_EQ(created.GetError().mCode, ErrorCode::InvalidArgument);
    const std::string& message = created.GetError().mMessage;
    EXPECT_TRUE(message.find("mass") != std::string::npos || message.find("density") != std::string::npos)
        << "a box of 1 m^3 refused with: '" << message << "'";
}

TEST_F(HostileInputTest, TimeStepsThatUnderflowKeepTheWorldFinite)
{
    const BodyID resting = AddRestingBox(0.0f);
    const BodyID falling = AddDynamic(DynamicSettings(Sphere(0.5f), Vec3(3, 0.52f, 0)));
    Step(1);
    // Valid per Update's range (0, 1], but 1e-45 / 16 collision steps is a step of exactly 0 s, and 1e-40
    // and FLT_MIN divide the speculative gaps into infinities
    for (const float dt : {1e-45f, 1e-40f, std::numeric_limits<float>::min()})
        for (const int collisionSteps : {1, 16})
        {
            // Refusing is fine; taking it must leave the world sane
            const Status status = UpdateWorld(dt, collisionSteps);
            if (!status.IsOk())
            {
                EXPECT_EQ(status.GetError().mCode, ErrorCode::InvalidArgument) << dt;
            }
        }
    ExpectBodyFinite(resting, "resting box");
    ExpectBodyFinite(falling, "falling sphere");
    Step(30);
    ExpectBodyFinite(resting, "resting box");
    ExpectBodyFinite(falling, "falling sphere");
    EXPECT_NEAR(Position(resting).y(), 0.5f, 0.05f);
}

TEST_F(HostileInputTest, ExtremeButAcceptedShapesSimulateFinitely)
{
    std::vector<BodyID> bodies;
    // A kilometre-thin sliver of a capsule as a static beam, a tiny hull dropped on it
    const ShapeRef beam = CapsuleShape::Create(1.0e5f, 0.01f).Value();
    bodies.push_back(AddStatic(beam, Vec3(0, 3, 0), Quat(Eigen::AngleAxisf(0.5f * cPi, Vec3::UnitZ()))));
    const Vec3 corners[] = {Vec3(0, 0, 0), Vec3(0.01f, 0, 0), Vec3(0, 0.01f, 0), Vec3(0, 0, 0.01f)};
    bodies.push_back(
        AddDynamic(DynamicSettings(ConvexHullShape::Create(corners).Value(), Vec3(0.001f, 3.1f, 0.001f))));
    // A planet of a static sphere, far off, with a small box dropped on it
    bodies.push_back(AddStatic(Sphere(1.0e5f), Vec3(3.0e5f, 0, 0)));
    bodies.push_back(
        AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(3.0e5f, 1.0e5f + 1.0f, 0))));
    // A dynamic box 800 km across landing on a static one, far off the other way, as light as it must be to
    // stay within cMaxBodyMass
    bodies.push_back(AddStatic(Box(Vec3(5.0e5f, 1.0f, 5.0e5f)), Vec3(-5.0e5f, -1.0f, -5.0e5f)));
    BodyCreationSettings giant =
        DynamicSettings(Box(Vec3(4.0e5f, 4.0e5f, 4.0e5f)), Vec3(-5.0e5f, 4.0e5f + 1.0f, -5.0e5f));
    giant.mDensity = 0.99f * cMaxBodyMass / 5.12e17f; // 5.12e17 m^3
    bodies.push_back(AddDynamic(giant));
    // A millimetre box on the floor
    bodies.push_back(AddDynamic(DynamicSettings(Box(Vec3(1e-3f, 1e-3f, 1e-3f)), Vec3(7, 1e-3f, 0))));
    // Spinning as fast as the limit allows
    BodyCreationSettings spinner = DynamicSettings(Box(Vec3(0.5f, 0.1f, 2.0f)), Vec3(-7, 0.2f, 0));
    spinner.mMaxAngularVelocity = 1e5f;
    spinner.mMaxLinearVelocity = 1e5f;
    spinner.mAngularVelocity = Vec3(1e5f, 3e4f, -2e4f);
    spinner.mLinearVelocity = Vec3(0, -1e5f, 0);
    bodies.push_back(AddDynamic(spinner));
    for (int i = 0; i < 60; ++i)
        ASSERT_TRUE(UpdateWorld(cDeltaTime).IsOk());
    for (size_t i = 0; i < bodies.size(); ++i)
        ExpectBodyFinite(bodies[i], ("body " + std::to_string(i)).c_str());
}

TEST_F(HostileInputTest, BodiesPlacedExactlyOnTopOfEachOtherSeparateFinitely)
{
    // SetPosition can put a body anywhere: here each pair shares its centre (and axis), where a contact
    // normal has no preferred direction
    const Vec3 corners[] = {Vec3(-0.5f, -0.5f, -0.5f), Vec3(0.5f, -0.5f, -0.5f), Vec3(0, 0.5f, -0.5f),
                            Vec3(0, 0, 0.5f)};
    const ShapeRef hull = ConvexHullShape::Create(corners).Value();
    const ShapeRef capsule = CapsuleShape::Create(0.5f, 0.3f).Value();
    const std::pair<ShapeRef, ShapeRef> pairs[] = {{Sphere(0.5f), Sphere(0.5f)},
                                                   {Box(Vec3(0.5f, 0.5f, 0.5f)), Box(Vec3(0.5f, 0.5f, 0.5f))},
                                                   {capsule, capsule},
                                                   {hull, hull},
                                                   {Sphere(0.5f), Box(Vec3(0.5f, 0.5f, 0.5f))},
                                                   {Sphere(0.3f), capsule},
                                                   {capsule, Box(Vec3(0.5f, 0.5f, 0.5f))},
                                                   {hull, Sphere(0.4f)}};
    std::vector<BodyID> bodies;
    float x = -40.0f;
    for (const auto& [a, b] : pairs)
    {
        bodies.push_back(AddDynamic(DynamicSettings(a, Vec3(x, 3, 0))));
        bodies.push_back(AddDynamic(DynamicSettings(b, Vec3(x + 5, 3, 0))));
        ASSERT_TRUE(Bodies().SetPosition(bodies.back(), Vec3(x, 3, 0), Activation::Activate).IsOk());
        x += 10.0f;
    }
    // And one teleported into the middle of the static floor
    bodies.push_back(AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(45, 3, 0))));
    ASSERT_TRUE(Bodies().SetPosition(bodies.back(), Vec3(0, -1, 0), Activation::Activate).IsOk());
    for (int i = 0; i < 120; ++i)
        ASSERT_TRUE(UpdateWorld(cDeltaTime).IsOk());
    for (size_t i = 0; i < bodies.size(); ++i)
        ExpectBodyFinite(bodies[i], ("body " + std::to_string(i)).c_str());
}

// --- World queries ----------------------------------------------------------------------------------------

TEST_F(HostileInputTest, ARayPastTheLongestIsRefusedAndTheLongestStillHitsTheNearestBody)
{
    const BodyID sphere = AddStatic(Sphere(1.0f), Vec3(0, 1, 0));
    // Its squared length (2.25e38) is finite, but a sphere's test overflows on it and misses: refused
    const Result<std::optional<RayCastResult>> refused =
        Query().CastRayClosest({Vec3(0, 10, 0), Vec3(0, -1.5e19f, 0)});
    ASSERT_FALSE(refused.IsOk());
    EXPECT_EQ(refused.GetError().mCode, ErrorCode::InvalidArgument);

    // The longest ray taken hits the sphere first, and the floor behind it
    const RayCast ray{Vec3(0, 10, 0), Vec3(0, -cMaxRayLength, 0)};
    const Result<std::optional<RayCastResult>> hit = Query().CastRayClosest(ray);
    ASSERT_TRUE(hit.IsOk()) << hit.GetError().mMessage;
    ASSERT_TRUE(hit.Value().has_value());
    EXPECT_EQ(hit.Value()->mBody, sphere) << "the ray passed through the sphere and hit the floor behind it";
    EXPECT_TRUE(IsFinite(hit.Value()->mNormal));
    std::vector<RayCastResult> all;
    ASSERT_TRUE(Query().CastRayAll(ray, all).IsOk());
    EXPECT_EQ(all.size(), 2u) << "sphere and floor";
}

TEST_F(HostileInputTest, ZeroLengthRaysHitOnlyWhatTheyStartIn)
{
    const BodyID sphere = AddStatic(Sphere(1.0f), Vec3(0, 1, 0));
    const Result<std::optional<RayCastResult>> inside =
        Query().CastRayClosest({Vec3(0, 1.2f, 0), Vec3::Zero()});
    ASSERT_TRUE(inside.IsOk());
    ASSERT_TRUE(inside.Value().has_value());
    EXPECT_EQ(inside.Value()->mBody, sphere);
    EXPECT_EQ(inside.Value()->mFraction, 0.0f);
    EXPECT_NEAR(inside.Value()->mNormal.norm(), 1.0f, 1e-5f) << "a unit normal, not the zero direction";
    const Result<bool> outside = Query().CastRayAny({Vec3(5, 5, 5), Vec3::Zero()});
    ASSERT_TRUE(outside.IsOk());
    EXPECT_FALSE(outside.Value());
    // Denormal directions: as good as zero
    const Result<bool> denormal = Query().CastRayAny({Vec3(5, 5, 5), Vec3(1e-45f, -1e-45f, 1e-45f)});
    ASSERT_TRUE(denormal.IsOk());
    EXPECT_FALSE(denormal.Value());
}

TEST_F(HostileInputTest, AMeshQueryAgainstAMeshBodyIsNotReportedAsClear)
{
    // Terrain as a static mesh at y = 3 (above the box floor), and a mesh probe that cuts right through it
    const BodyID terrain = AddStatic(FlatMesh(10.0f, 0.0f), Vec3(0, 3, 0));
    const std::vector<Vec3> vertices = {Vec3(-1, -1, 0), Vec3(1, -1, 0), Vec3(0, 1, 0)};
    const std::vector<std::array<uint32_t, 3>> triangles = {{0, 1, 2}};
    const ShapeRef probe = TriangleMeshShape::Create(vertices, triangles).Value();
    std::vector<ShapeQueryHit> hits;
    QueryFilter onlyTerrain;
    onlyTerrain.mIgnoreBody = mFloor;
    const Status status = Query().CollideShape(*probe, {Vec3(0, 3, 0), Quat::Identity()}, hits, onlyTerrain);
    if (!status.IsOk())
    {
        EXPECT_EQ(status.GetError().mCode, ErrorCode::InvalidArgument) << "a clear refusal is fine";
        return;
    }
    ASSERT_EQ(hits.size(), 1u) << "the probe crosses the terrain, yet the query said the space is clear";
    EXPECT_EQ(hits[0].mBody, terrain);
}

TEST_F(HostileInputTest, AProbeShapeBuiltAroundItsCreateIsRefused)
{
    // Each of these overlaps the floor where it is put; a query with it must not answer "nothing there"
    const SphereShape nanSphere(cNaN);
    const BoxShape invertedBox(Vec3(-1, -1, -1));
    const CapsuleShape invertedCapsule(-5.0f, 1.0f);
    const SphereShape infiniteSphere(cInf);
    const std::pair<const Shape*, const char*> probes[] = {{&nanSphere, "NaN sphere"},
                                                           {&invertedBox, "inverted box"},
                                                           {&invertedCapsule, "inverted capsule"},
                                                           {&infiniteSphere, "infinite sphere"}};
    for (const auto& [probe, name] : probes)
    {
        std::vector<ShapeQueryHit> hits;
        const Status status = Query().CollideShape(*probe, {Vec3(0, 0, 0), Quat::Identity()}, hits);
        EXPECT_FALSE(status.IsOk()) << name << ": got Ok with " << hits.size() << " hits";
        if (!status.IsOk())
        {
            EXPECT_EQ(status.GetError().mCode, ErrorCode::InvalidArgument) << name;
        }
        for (const ShapeQueryHit& hit : hits)
            EXPECT_TRUE(IsFinite(hit.mManifold.mNormal)) << name << ": a NaN contact normal";
    }
}

TEST_F(HostileInputTest, AHugeButFiniteQuerySeparationFindsEverythingOrIsRefused)
{
    AddStatic(Sphere(1.0f), Vec3(0, 1, 0));
    const SphereShape probe(0.5f);
    for (const float separation : {1.0e30f, 3.0e38f})
    {
        std::vector<ShapeQueryHit> hits;
        const Status status =
            Query().CollideShape(probe, {Vec3(0, 100, 0), Quat::Identity()}, hits, {}, separation);
        if (!status.IsOk())
        {
            EXPECT_EQ(status.GetError().mCode, ErrorCode::InvalidArgument) << separation;
            continue;
        }
        EXPECT_EQ(hits.size(), 2u) << "max separation " << separation
                                   << ": both bodies are within it, but the query found " << hits.size();
        for (const ShapeQueryHit& hit : hits)
            EXPECT_TRUE(IsFinite(hit.mManifold.mNormal));
    }
}

TEST_F(HostileInputTest, BroadPhaseQueriesIgnoreNaNAndSurviveHugeInput)
{
    AddRestingBox(0.0f);
    const BroadPhase& broadPhase = System().GetBroadPhase();
    int reported = 0;
    auto count = [&](BodyID) { ++reported; };
    float lastFraction = 0.0f;
    auto countRay = [&](BodyID, float inFraction) -> float
    {
        ++reported;
        lastFraction = inFraction;
        return 1.0f;
    };
    // Documented as ignored: nothing reported, no crash, no hang
    reported = 0;
    broadPhase.CollideAABox(AABB(Vec3(cNaN, 0, 0), Vec3(1, 1, 1)), {}, count);
    EXPECT_EQ(reported, 0) << "a box with a NaN corner";
    reported = 0;
    broadPhase.CollideAABox(AABB(Vec3(1, 1, 1), Vec3(-1, -1, -1)), {}, count);
    EXPECT_EQ(reported, 0) << "an inverted box";
    reported = 0;
    broadPhase.CollideSphere(Vec3(0, 0, 0), cNaN, {}, count);
    EXPECT_EQ(reported, 0) << "a sphere of NaN radius";
    reported = 0;
    broadPhase.CollideSphere(Vec3(cNaN, 0, 0), 1.0f, {}, count);
    EXPECT_EQ(reported, 0) << "a sphere at a NaN centre";
    reported = 0;
    broadPhase.CollidePoint(Vec3(0, cNaN, 0), {}, count);
    EXPECT_EQ(reported, 0) << "a NaN point";
    reported = 0;
    broadPhase.CastRay({Vec3(cNaN, 1, 0), Vec3(0, -5, 0)}, {}, countRay);
    EXPECT_EQ(reported, 0) << "a ray from a NaN origin, the last at fraction " << lastFraction;
    reported = 0;
    broadPhase.CastRay({Vec3(0, 1, 0), Vec3(cNaN, -5, 0)}, {}, countRay);
    EXPECT_EQ(reported, 0) << "a ray along a NaN direction, the last at fraction " << lastFraction;
    reported = 0;
    broadPhase.CastAABox(AABB(Vec3(-1, 5, -1), Vec3(1, 6, 1)), Vec3(0, cNaN, 0), {}, countRay);
    EXPECT_EQ(reported, 0) << "a box swept by a NaN displacement, the last at fraction " << lastFraction;

    // Huge but finite: everything is found
    reported = 0;
    broadPhase.CollideAABox(AABB(Vec3::Constant(-1e30f), Vec3::Constant(1e30f)), {}, count);
    EXPECT_EQ(reported, 2);
    reported = 0;
    broadPhase.CastRay({Vec3(0, 1e30f, 0), Vec3(0, -2e30f, 0)}, {}, countRay);
    EXPECT_EQ(reported, 2);
    reported = 0;
    broadPhase.CollideSphere(Vec3(0, 0, 0), 1e30f, {}, count);
    EXPECT_EQ(reported, 2);
    Step(5);
}

// --- Layers -----------------------------------------------------------------------------------------------

TEST_F(HostileInputTest, ObjectLayersPastTheTablesAreNotReadOutOfBounds)
{
    // The setup sits at the start of a buffer of 0xff bytes: a read past its 64-entry tables finds ones
    alignas(std::max_align_t) unsigned char buffer[8192];
    std::memset(buffer, 0xff, sizeof(buffer));
    static_assert(sizeof(LayerSetup) < sizeof(buffer));
    LayerSetup* layers = new (buffer) LayerSetup(LayerSetup::CreateDefault());
    const ObjectLayer outside = 200; // An ObjectLayer is a uint8_t: 64..255 are past the tables
    EXPECT_FALSE(layers->IsValid(outside));
    EXPECT_FALSE(layers->ShouldCollide(outside, Layers::cMoving)) << "read past mCollidesWith";
    EXPECT_EQ(layers->GetCollisionMask(outside), 0u) << "read past mCollidesWith";
    EXPECT_FALSE(layers->ShouldCollide(Layers::cMoving, outside)) << "a shift by 200 bits";
    layers->~LayerSetup();
}

TEST(HostileInputBatchTest, ABatchFinalizedOrAbortedInAnotherWorldIsRefused)
{
    const std::unique_ptr<PhysicsSystem> first = MakePhysicsSystem(), second = MakePhysicsSystem();
    BodyCreationSettings settings;
    settings.mShape = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
    settings.mPosition = Vec3(0, 3, 0);
    // Two bodies in the first world, so the id's slot is empty in the second
    (void)first->GetBodyInterface().CreateBody(settings);
    const BodyID body = first->GetBodyInterface().CreateBody(settings).Value();
    Result<BodyInterface::AddBatch> batch = first->GetBodyInterface().AddBodiesPrepare({&body, 1});
    ASSERT_TRUE(batch.IsOk());
    EXPECT_EQ(
        second->GetBodyInterface().AddBodiesFinalize(batch.Value(), Activation::Activate).GetError().mCode,
        ErrorCode::InvalidArgument);
    EXPECT_EQ(second->GetBodyInterface().AddBodiesAbort(batch.Value()).GetError().mCode,
              ErrorCode::InvalidArgument);
    EXPECT_EQ(second->GetBroadPhase().GetBodyCount(), 0u);
    // The batch is still whole: its own world takes it
    ASSERT_TRUE(first->GetBodyInterface().AddBodiesFinalize(batch.Value(), Activation::Activate).IsOk());
    EXPECT_TRUE(first->GetBodyInterface().IsAdded(body).Value());
    EXPECT_EQ(first->GetBroadPhase().GetBodyCount(), 1u);
}

} // namespace cairn::test
