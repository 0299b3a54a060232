// Changing a live body through the BodyInterface (issue 31): motion type, object layer, shape, and kinematic
// moves to a target. Each call's effect on the simulation, on queries and on the published pose, and its
// errors (which change nothing). The same calls racing queries and the step: tests/concurrency/.

#include "SimulationFixture.h"
#include "cairn/physics/body/BodyLock.h"
#include "cairn/physics/body/PublishedPose.h"
#include "cairn/physics/shapes/CompoundShape.h"
#include "cairn/physics/shapes/TriangleMeshShape.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <vector>

namespace cairn::test
{
using namespace cairn::physics;

class LiveBodyChangeTest : public SimulationFixture
{
protected:
    /// The mass of a dynamic body, from the velocity an impulse gives it (its velocity is put back).
    float MassOf(const BodyID& inID)
    {
        const Vec3 before = Velocity(inID);
        EXPECT_TRUE(Bodies().AddImpulse(inID, Vec3(1000, 0, 0)).IsOk());
        const float mass = 1000.0f / (Velocity(inID).x() - before.x());
        EXPECT_TRUE(Bodies().SetLinearVelocity(inID, before).IsOk());
        return mass;
    }
    /// The body's published pose (false when it is not in the world).
    bool Published(const BodyID& inID, PublishedPose& outPose)
    {
        const PoseReader reader(System().GetBodyManager());
        return reader.Read(inID, outPose);
    }
    /// The bodies the broad phase finds in inBox for the object layers inMask.
    std::vector<BodyID> Found(const AABB& inBox, ObjectLayerMask inMask = cAllObjectLayers)
    {
        std::vector<BodyID> found;
        System().GetBroadPhase().CollideAABox(inBox, {inMask}, [&](BodyID inID) { found.push_back(inID); });
        std::sort(found.begin(), found.end());
        return found;
    }
    /// A body created and destroyed again: its id is stale.
    BodyID StaleID()
    {
        const BodyID id =
            Bodies().CreateBody(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(30, 5, 30))).Value();
        EXPECT_TRUE(Bodies().DestroyBody(id).IsOk());
        return id;
    }
    BodyID AddKinematic(const ShapeRef& inShape, const Vec3& inPosition)
    {
        BodyCreationSettings settings = DynamicSettings(inShape, inPosition);
        settings.mMotionType = MotionType::Kinematic;
        return AddDynamic(settings);
    }
    /// A flat two-triangle mesh: a shape without volume.
    static ShapeRef FlatMesh()
    {
        const std::vector<Vec3> vertices{{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}};
        const std::vector<std::array<uint32_t, 3>> triangles{{0, 2, 1}, {0, 3, 2}};
        return TriangleMeshShape::Create(vertices, triangles).Value();
    }
    static ErrorCode Code(const Status& inStatus) { return inStatus.GetError().mCode; }
};

// ---- SetMotionType

TEST_F(LiveBodyChangeTest, DynamicToStaticToDynamicKeepsTheSimulationSane)
{
    AddFloor();
    const BodyID box = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 4, 0)));
    Step(10);
    ASSERT_LT(Velocity(box).y(), -1.0f);

    // Static in mid-air: it stops, leaves the active list and stays put; a box dropped on it lands on it
    ASSERT_TRUE(Bodies().SetMotionType(box, MotionType::Static, Activation::Activate).IsOk());
    EXPECT_FALSE(IsActive(box));
    EXPECT_EQ(Velocity(box), Vec3::Zero());
    PublishedPose pose;
    ASSERT_TRUE(Published(box, pose));
    EXPECT_EQ(pose.mMotionType, MotionType::Static);
    const Vec3 heldAt = Position(box);
    const BodyID dropped = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), heldAt + Vec3(0, 2, 0)));
    Step(90);
    EXPECT_EQ(Position(box), heldAt);
    EXPECT_FALSE(IsActive(box));
    EXPECT_TRUE(Bodies().ActivateBody(box).IsOk()); // A static body never enters the active list
    EXPECT_FALSE(IsActive(box));
    EXPECT_NEAR(Position(dropped).y(), heldAt.y() + 1.0f, 0.05f) << "the dropped box rests on the static one";

    // Dynamic again: it falls (and the box on it with it) and both come to rest on the floor, stacked
    ASSERT_TRUE(Bodies().SetMotionType(box, MotionType::Dynamic, Activation::Activate).IsOk());
    EXPECT_TRUE(IsActive(box));
    ASSERT_TRUE(Published(box, pose));
    EXPECT_EQ(pose.mMotionType, MotionType::Dynamic);
    Step(5);
    EXPECT_LT(Velocity(box).y(), -0.5f);
    Step(180);
    EXPECT_NEAR(Position(box).y(), 0.5f, 0.05f);
    EXPECT_NEAR(Position(dropped).y(), 1.5f, 0.05f);
    EXPECT_NEAR(Position(box).x(), 0.0f, 0.05f);
}

TEST_F(LiveBodyChangeTest, MadeDynamicABodyGetsItsShapesMassAtItsCreationDensity)
{
    BodyCreationSettings settings = DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 5, 0));
    settings.mMotionType = MotionType::Static;
    settings.mDensity = 500.0f; // 1 m^3
    const BodyID body = Bodies().CreateAndAddBody(settings, Activation::DontActivate).Value();
    ASSERT_TRUE(Bodies().SetMotionType(body, MotionType::Dynamic, Activation::DontActivate).IsOk());
    EXPECT_FALSE(IsActive(body)) << "DontActivate leaves it asleep";
    EXPECT_NEAR(MassOf(body), 500.0f, 0.5f);
    EXPECT_TRUE(IsActive(body)); // The impulse woke it
}

TEST_F(LiveBodyChangeTest, KinematicMadeDynamicKeepsItsVelocityAndTheSameTypeOnlyActivates)
{
    const BodyID door = AddKinematic(Box(Vec3(0.5f, 1, 0.1f)), Vec3(0, 10, 0));
    ASSERT_TRUE(Bodies().SetLinearVelocity(door, Vec3(2, 0, 0)).IsOk());
    Step(6);
    ASSERT_TRUE(Bodies().SetMotionType(door, MotionType::Dynamic, Activation::Activate).IsOk());
    EXPECT_NEAR(Velocity(door).x(), 2.0f, 1e-5f);
    Step(1);
    EXPECT_NEAR(Velocity(door).x(), 2.0f, 0.01f);
    EXPECT_LT(Velocity(door).y(), 0.0f) << "a dynamic body falls";

    // The same motion type changes nothing but activation
    ASSERT_TRUE(Bodies().DeactivateBody(door).IsOk());
    ASSERT_TRUE(Bodies().SetMotionType(door, MotionType::Dynamic, Activation::DontActivate).IsOk());
    EXPECT_FALSE(IsActive(door));
    ASSERT_TRUE(Bodies().SetMotionType(door, MotionType::Dynamic, Activation::Activate).IsOk());
    EXPECT_TRUE(IsActive(door));

    // Made kinematic it keeps its velocity and no longer falls
    ASSERT_TRUE(Bodies().SetLinearVelocity(door, Vec3(0, 0, 1)).IsOk());
    ASSERT_TRUE(Bodies().SetMotionType(door, MotionType::Kinematic, Activation::Activate).IsOk());
    Step(10);
    EXPECT_NEAR(Velocity(door).y(), 0.0f, 1e-6f);
    EXPECT_NEAR(Velocity(door).z(), 1.0f, 1e-5f);
}

TEST_F(LiveBodyChangeTest, SetMotionTypeErrorsChangeNothing)
{
    const BodyID mesh = AddStatic(FlatMesh(), Vec3(0, 0, 0));
    const BodyID box = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 3, 0)));
    // A shape without volume can not carry a dynamic body
    const Status noVolume = Bodies().SetMotionType(mesh, MotionType::Dynamic, Activation::Activate);
    EXPECT_EQ(Code(noVolume), ErrorCode::InvalidArgument);
    EXPECT_NE(noVolume.GetError().mMessage.find("volume"), std::string::npos) << noVolume.GetError().mMessage;
    PublishedPose pose;
    ASSERT_TRUE(Published(mesh, pose));
    EXPECT_EQ(pose.mMotionType, MotionType::Static);
    EXPECT_EQ(Code(Bodies().SetMotionType(StaleID(), MotionType::Static, Activation::Activate)),
              ErrorCode::InvalidBodyID);
    EXPECT_EQ(Code(Bodies().SetMotionType(box, MotionType(7), Activation::Activate)),
              ErrorCode::InvalidArgument);
    {
        BodyLockRead lock(System().GetBodyManager(), mesh);
        EXPECT_EQ(Code(Bodies().SetMotionType(box, MotionType::Static, Activation::Activate)),
                  ErrorCode::WrongThread);
    }
    EXPECT_TRUE(IsActive(box));
    Step(1);
    EXPECT_LT(Velocity(box).y(), 0.0f);
}

/// Calls inCall from inside the step (a body falling asleep there tells it), and keeps what it returned.
class InsideStepCaller final : public BodyChangeListener
{
public:
    explicit InsideStepCaller(std::function<Status()> inCall) : mCall(std::move(inCall)) {}
    void OnBodyChanged(const BodyChange& inChange) override
    {
        // Seq_cst: a test's handshake, not a hot path
        if (inChange.mKind != BodyChangeKind::FellAsleep || !BodyManager::IsInsideStep() ||
            mCalled.exchange(true))
            return;
        const Status status = mCall();
        mCode = status.IsOk() ? -1 : int(status.GetError().mCode);
    }
    std::function<Status()> mCall;
    std::atomic<bool> mCalled{false};
    std::atomic<int> mCode{-2}; ///< -2: not called, -1: Ok, else the ErrorCode
};

TEST_F(LiveBodyChangeTest, EveryChangeIsRefusedFromInsideTheStep)
{
    AddFloor();
    const BodyID box = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 0.5f, 0)));
    const std::vector<std::function<Status()>> calls{
        [&] { return Bodies().SetMotionType(box, MotionType::Static, Activation::Activate); },
        [&] { return Bodies().SetObjectLayer(box, Layers::cDebris); },
        [&] { return Bodies().SetShape(box, Box(Vec3(1, 1, 1)), true, Activation::Activate); },
        [&] { return Bodies().MoveKinematic(box, Vec3(0, 1, 0), Quat::Identity(), cDeltaTime); }};
    for (const std::function<Status()>& call : calls)
    {
        InsideStepCaller caller(call);
        ASSERT_TRUE(System().AddBodyChangeListener(&caller));
        ASSERT_TRUE(Bodies().ActivateBody(box).IsOk());
        for (int i = 0; i < 120 && !caller.mCalled; ++i)
            Step(1);
        System().RemoveBodyChangeListener(&caller);
        EXPECT_EQ(caller.mCode, int(ErrorCode::WrongThread));
    }
    PublishedPose pose;
    ASSERT_TRUE(Published(box, pose));
    EXPECT_EQ(pose.mMotionType, MotionType::Dynamic);
    EXPECT_EQ(pose.mLayer, Layers::cMoving);
}

// ---- SetObjectLayer

TEST_F(LiveBodyChangeTest, TheNewObjectLayerDecidesCollisionsQueriesAndThePublishedPose)
{
    AddFloor();
    const BodyID box = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 0.5f, 0)));
    const BodyID debris = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(3, 0.5f, 0)));
    Step(30);
    // Debris still collides with the static floor
    ASSERT_TRUE(Bodies().SetObjectLayer(debris, Layers::cDebris).IsOk());
    // A trigger collides with nothing: the box falls through the floor
    ASSERT_TRUE(Bodies().SetObjectLayer(box, Layers::cTrigger).IsOk());
    const AABB around(Vec3(-0.4f, 0.1f, -0.4f), Vec3(0.4f, 0.9f, 0.4f));
    EXPECT_EQ(Found(around, ObjectLayerMask(1) << Layers::cTrigger), std::vector<BodyID>{box});
    EXPECT_TRUE(Found(around, ObjectLayerMask(1) << Layers::cMoving).empty());
    PublishedPose pose;
    ASSERT_TRUE(Published(box, pose));
    EXPECT_EQ(pose.mLayer, Layers::cTrigger);
    ASSERT_TRUE(Bodies().ActivateBody(box).IsOk());
    Step(60);
    EXPECT_LT(Position(box).y(), -1.0f);
    EXPECT_NEAR(Position(debris).y(), 0.5f, 0.05f);
}

TEST_F(LiveBodyChangeTest, AStaticBodyMovesBetweenBroadPhaseLayersAndBack)
{
    const BodyID wall = AddStatic(Box(Vec3(1, 1, 1)), Vec3(0, 1, 0));
    const AABB inside(Vec3(-0.5f, 0.5f, -0.5f), Vec3(0.5f, 1.5f, 0.5f));
    for (ObjectLayer layer :
         {Layers::cMoving, Layers::cDebris, Layers::cStatic, Layers::cTrigger, Layers::cStatic})
    {
        ASSERT_TRUE(Bodies().SetObjectLayer(wall, layer).IsOk());
        EXPECT_EQ(Found(inside), std::vector<BodyID>{wall}) << "found once, layer " << int(layer);
        EXPECT_EQ(Found(inside, ObjectLayerMask(1) << layer), std::vector<BodyID>{wall});
        EXPECT_TRUE(Found(inside, cAllObjectLayers & ~(ObjectLayerMask(1) << layer)).empty());
        PublishedPose pose;
        ASSERT_TRUE(Published(wall, pose));
        EXPECT_EQ(pose.mLayer, layer);
        Step(1); // The broad phase's update between changes
    }
    // A body outside the world takes its new layer into the world
    ASSERT_TRUE(Bodies().RemoveBody(wall).IsOk());
    ASSERT_TRUE(Bodies().SetObjectLayer(wall, Layers::cMoving).IsOk());
    ASSERT_TRUE(Bodies().AddBody(wall, Activation::DontActivate).IsOk());
    EXPECT_EQ(Found(inside, ObjectLayerMask(1) << Layers::cMoving), std::vector<BodyID>{wall});
}

TEST_F(LiveBodyChangeTest, SetObjectLayerErrorsChangeNothing)
{
    const BodyID box = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 3, 0)));
    EXPECT_EQ(Code(Bodies().SetObjectLayer(box, 40)), ErrorCode::InvalidArgument); // Not in the setup
    EXPECT_EQ(Code(Bodies().SetObjectLayer(StaleID(), Layers::cDebris)), ErrorCode::InvalidBodyID);
    {
        BodyLockRead lock(System().GetBodyManager(), box);
        EXPECT_EQ(Code(Bodies().SetObjectLayer(box, Layers::cDebris)), ErrorCode::WrongThread);
    }
    // A body waiting in an add batch: the batch holds its layer
    const BodyID pending =
        Bodies().CreateBody(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(5, 3, 0))).Value();
    Result<BodyInterface::AddBatch> batch = Bodies().AddBodiesPrepare({&pending, 1});
    ASSERT_TRUE(batch.IsOk());
    EXPECT_EQ(Code(Bodies().SetObjectLayer(pending, Layers::cDebris)), ErrorCode::InvalidArgument);
    ASSERT_TRUE(Bodies().AddBodiesFinalize(batch.Value(), Activation::Activate).IsOk());
    EXPECT_TRUE(Bodies().SetObjectLayer(pending, Layers::cDebris).IsOk());
    PublishedPose pose;
    ASSERT_TRUE(Published(box, pose));
    EXPECT_EQ(pose.mLayer, Layers::cMoving);
    EXPECT_EQ(Found(Bodies().GetWorldBounds(box).Value(), ObjectLayerMask(1) << Layers::cMoving),
              std::vector<BodyID>{box});
}

// ---- SetShape

TEST_F(LiveBodyChangeTest, SetShapeChangesTheMassWhenAsked)
{
    const BodyID body = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 10, 0)));
    EXPECT_NEAR(MassOf(body), 1000.0f, 0.5f);
    ASSERT_TRUE(Bodies().SetShape(body, Box(Vec3(1, 1, 1)), true, Activation::Activate).IsOk());
    EXPECT_NEAR(MassOf(body), 8000.0f, 4.0f);
    // Not asked: the mass stays, the shape changes
    ASSERT_TRUE(Bodies().SetShape(body, Sphere(0.25f), false, Activation::Activate).IsOk());
    EXPECT_NEAR(MassOf(body), 8000.0f, 4.0f);
    const AABB bounds = Bodies().GetWorldBounds(body).Value();
    EXPECT_NEAR(bounds.mMax.x() - bounds.mMin.x(), 0.5f, 1e-4f);
}

TEST_F(LiveBodyChangeTest, SetShapeMovesTheBoundsThePublishedShapeAndRetiresTheOldOne)
{
    std::weak_ptr<const Shape> oldShape;
    BodyID pillar;
    {
        const ShapeRef first = Box(Vec3(0.5f, 0.5f, 0.5f));
        oldShape = first;
        pillar = AddStatic(first, Vec3(0, 0.5f, 0));
    }
    const ShapeRef tall = Box(Vec3(0.5f, 3, 0.5f));
    ASSERT_TRUE(Bodies().SetShape(pillar, tall, false, Activation::Activate).IsOk());
    EXPECT_NEAR(Bodies().GetWorldBounds(pillar).Value().mMax.y(), 3.5f, 1e-5f);
    EXPECT_EQ(Found(AABB(Vec3(-0.1f, 3.0f, -0.1f), Vec3(0.1f, 3.4f, 0.1f))), std::vector<BodyID>{pillar});
    PublishedPose pose;
    ASSERT_TRUE(Published(pillar, pose));
    EXPECT_EQ(pose.mShape, tall.get());
    EXPECT_EQ(Position(pillar), Vec3(0, 0.5f, 0)) << "the shape's origin stays";
    // Retired, not freed at once (a query may hold it), and freed once the updates have collected it
    EXPECT_FALSE(oldShape.expired());
    Step(3);
    EXPECT_TRUE(oldShape.expired());
}

// The narrow phase's body-pair cache takes last step's manifolds over for a pair whose relative pose did not
// change (ContactsStage::ReuseManifolds): it must tell a new shape from the old (a shape generation per body,
// kept with each cached pair), or a resting body given a larger shape keeps the old contacts and stays sunk
// in the floor (y 0.5 here, before the generation)
TEST_F(LiveBodyChangeTest, ABodyGivenALargerShapeRestsOnItsNewSurface)
{
    AddFloor();
    const BodyID ball = AddDynamic(DynamicSettings(Sphere(0.5f), Vec3(0, 0.5f, 0)));
    Step(20);
    ASSERT_NEAR(Position(ball).y(), 0.5f, 0.02f);
    ASSERT_TRUE(Bodies().SetShape(ball, Sphere(1.0f), true, Activation::Activate).IsOk());
    Step(90);
    EXPECT_NEAR(Position(ball).y(), 1.0f, 0.03f) << "the larger ball rests on the floor, not in it";
}

TEST_F(LiveBodyChangeTest, SetShapeErrorsChangeNothing)
{
    const ShapeRef box = Box(Vec3(0.5f, 0.5f, 0.5f));
    const BodyID body = AddDynamic(DynamicSettings(box, Vec3(0, 3, 0)));
    EXPECT_EQ(Code(Bodies().SetShape(body, nullptr, true, Activation::Activate)), ErrorCode::InvalidArgument);
    // A dynamic body needs a shape with volume, mass updated or not
    EXPECT_EQ(Code(Bodies().SetShape(body, FlatMesh(), true, Activation::Activate)),
              ErrorCode::InvalidArgument);
    EXPECT_EQ(Code(Bodies().SetShape(body, FlatMesh(), false, Activation::Activate)),
              ErrorCode::InvalidArgument);
    EXPECT_EQ(Code(Bodies().SetShape(StaleID(), Sphere(1), true, Activation::Activate)),
              ErrorCode::InvalidBodyID);
    {
        BodyLockRead lock(System().GetBodyManager(), body);
        EXPECT_EQ(Code(Bodies().SetShape(body, Sphere(1), true, Activation::Activate)),
                  ErrorCode::WrongThread);
    }
    PublishedPose pose;
    ASSERT_TRUE(Published(body, pose));
    EXPECT_EQ(pose.mShape, box.get());
    EXPECT_NEAR(MassOf(body), 1000.0f, 0.5f);
    // A static body may take a shape without volume
    const BodyID ground = AddStatic(box, Vec3(10, 0, 0));
    EXPECT_TRUE(Bodies().SetShape(ground, FlatMesh(), true, Activation::Activate).IsOk());
}

// ---- MoveKinematic

TEST_F(LiveBodyChangeTest, MoveKinematicReachesTheTargetPoseAfterOneUpdate)
{
    // Off its centre of mass: the target names the shape's origin, the body turns about its centre of mass
    const ShapeRef offCentre =
        CompoundShape::Create({{Box(Vec3(0.5f, 0.25f, 0.25f)), Transform{Vec3(1, 0, 0), Quat::Identity()}}})
            .Value();
    const BodyID platform = AddKinematic(offCentre, Vec3(0, 5, 0));
    struct Target
    {
        Vec3 mPosition;
        Quat mRotation;
        int mCollisionSteps;
    };
    const Target targets[] = {
        {Vec3(0.5f, 5.25f, -0.25f), Quat(Eigen::AngleAxisf(0.4f, Vec3(1, 1, 0).normalized())), 1},
        {Vec3(0.6f, 5.0f, 0.0f), Quat(Eigen::AngleAxisf(-0.3f, Vec3::UnitY())), 2},
        {Vec3(0.6f, 5.0f, 0.0f), Quat(Eigen::AngleAxisf(-0.3f, Vec3::UnitY())), 1}, // Stays: zero velocity
    };
    for (const Target& target : targets)
    {
        ASSERT_TRUE(Bodies().MoveKinematic(platform, target.mPosition, target.mRotation, cDeltaTime).IsOk());
        EXPECT_TRUE(IsActive(platform));
        ASSERT_TRUE(UpdateWorld(cDeltaTime, target.mCollisionSteps).IsOk());
        EXPECT_LT((Position(platform) - target.mPosition).norm(), 1e-4f);
        EXPECT_LT(Bodies().GetRotation(platform).Value().angularDistance(target.mRotation), 1e-3f);
    }
    // The velocities stay after the target: the body moves on at them
    ASSERT_TRUE(
        Bodies().MoveKinematic(platform, Vec3(0.6f, 5.1f, 0.0f), targets[2].mRotation, cDeltaTime).IsOk());
    Step(2);
    EXPECT_NEAR(Position(platform).y(), 5.2f, 1e-4f);
}

TEST_F(LiveBodyChangeTest, MoveKinematicTakesTheShortWayRound)
{
    const BodyID spinner = AddKinematic(Box(Vec3(1, 0.1f, 0.1f)), Vec3(0, 5, 0));
    // 350 degrees about y is -10 degrees: a small turn, not nearly a full one
    const Quat target(Eigen::AngleAxisf(350.0f * 3.14159265f / 180.0f, Vec3::UnitY()));
    ASSERT_TRUE(Bodies().MoveKinematic(spinner, Vec3(0, 5, 0), target, cDeltaTime).IsOk());
    EXPECT_NEAR(Bodies().GetAngularVelocity(spinner).Value().norm(),
                10.0f * 3.14159265f / 180.0f / cDeltaTime, 1e-2f);
    Step(1);
    EXPECT_LT(Bodies().GetRotation(spinner).Value().angularDistance(target), 1e-3f);
}

TEST_F(LiveBodyChangeTest, MoveKinematicErrorsChangeNothing)
{
    const BodyID kinematic = AddKinematic(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 5, 0));
    const BodyID dynamic = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(5, 5, 0)));
    const BodyID fixed = AddStatic(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(-5, 5, 0));
    BodyCreationSettings outside = DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 5, 5));
    outside.mMotionType = MotionType::Kinematic;
    const BodyID notAdded = Bodies().CreateBody(outside).Value();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    const Vec3 to(0, 6, 0);
    const Quat turn = Quat::Identity();
    EXPECT_EQ(Code(Bodies().MoveKinematic(dynamic, to, turn, cDeltaTime)), ErrorCode::InvalidArgument);
    EXPECT_EQ(Code(Bodies().MoveKinematic(fixed, to, turn, cDeltaTime)), ErrorCode::InvalidArgument);
    EXPECT_EQ(Code(Bodies().MoveKinematic(notAdded, to, turn, cDeltaTime)), ErrorCode::NotAdded);
    EXPECT_EQ(Code(Bodies().MoveKinematic(StaleID(), to, turn, cDeltaTime)), ErrorCode::InvalidBodyID);
    EXPECT_EQ(Code(Bodies().MoveKinematic(kinematic, Vec3(nan, 6, 0), turn, cDeltaTime)),
              ErrorCode::InvalidArgument);
    EXPECT_EQ(Code(Bodies().MoveKinematic(kinematic, Vec3(2e6f, 6, 0), turn, cDeltaTime)),
              ErrorCode::InvalidArgument);
    EXPECT_EQ(Code(Bodies().MoveKinematic(kinematic, to, Quat(2, 0, 0, 0), cDeltaTime)),
              ErrorCode::InvalidArgument);
    EXPECT_EQ(Code(Bodies().MoveKinematic(kinematic, to, Quat(nan, 0, 0, 1), cDeltaTime)),
              ErrorCode::InvalidArgument);
    for (float deltaTime : {0.0f, -cDeltaTime, nan, inf})
        EXPECT_EQ(Code(Bodies().MoveKinematic(kinematic, to, turn, deltaTime)), ErrorCode::InvalidArgument)
            << deltaTime;
    // Faster than the body's limits (500 m/s, a quarter turn a 1/60 s step): the step would stop it short
    EXPECT_EQ(Code(Bodies().MoveKinematic(kinematic, Vec3(1000, 5, 0), turn, cDeltaTime)),
              ErrorCode::InvalidArgument);
    EXPECT_EQ(Code(Bodies().MoveKinematic(kinematic, Vec3(0, 5, 0),
                                          Quat(Eigen::AngleAxisf(3.0f, Vec3::UnitZ())), cDeltaTime)),
              ErrorCode::InvalidArgument);
    EXPECT_EQ(Code(Bodies().MoveKinematic(kinematic, to, turn, 1e-38f)), ErrorCode::InvalidArgument);
    {
        BodyLockRead lock(System().GetBodyManager(), dynamic);
        EXPECT_EQ(Code(Bodies().MoveKinematic(kinematic, to, turn, cDeltaTime)), ErrorCode::WrongThread);
    }
    EXPECT_EQ(Bodies().GetLinearVelocity(kinematic).Value(), Vec3::Zero());
    EXPECT_EQ(Bodies().GetAngularVelocity(kinematic).Value(), Vec3::Zero());
    Step(1);
    EXPECT_EQ(Position(kinematic), Vec3(0, 5, 0));
}

} // namespace cairn::test
