#include "SimulationFixture.h"
#include "cairn/physics/body/BodyLock.h"
#include "cairn/physics/shapes/CapsuleShape.h"
#include "cairn/physics/shapes/ConvexHullShape.h"
#include "cairn/physics/shapes/TriangleMeshShape.h"

#include <limits>

namespace cairn::test
{
using namespace cairn::physics;

class BadInputTest : public SimulationFixture
{
protected:
    void SetUp() override
    {
        mFloor = AddFloor();
        mBox = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 0.5f, 0)));
        mBoxPosition = Position(mBox);
    }

    /// The world is as SetUp left it.
    void ExpectWorldUnchanged()
    {
        EXPECT_EQ(System().GetBodyManager().GetNumBodies(), 2u);
        EXPECT_EQ(System().GetBroadPhase().GetBodyCount(), 2u);
        EXPECT_EQ(Position(mBox), mBoxPosition);
    }

    BodyID mFloor;
    BodyID mBox;
    Vec3 mBoxPosition;
};

TEST_F(BadInputTest, UnknownAndStaleIDsAreRejected)
{
    const BodyID unknown(12345, 0);
    EXPECT_EQ(Bodies().SetPosition(unknown, Vec3::Zero(), Activation::Activate).GetError().mCode,
              ErrorCode::InvalidBodyID);
    EXPECT_EQ(Bodies().GetPosition(BodyID()).GetError().mCode, ErrorCode::InvalidBodyID);

    // A destroyed body's id stays stale even after its slot is reused
    const BodyID temporary = Bodies().CreateBody(DynamicSettings(Sphere(1), Vec3(5, 5, 5))).Value();
    ASSERT_TRUE(Bodies().DestroyBody(temporary).IsOk());
    const BodyID reused = Bodies().CreateBody(DynamicSettings(Sphere(1), Vec3(9, 9, 9))).Value();
    EXPECT_EQ(reused.GetIndex(), temporary.GetIndex());
    EXPECT_NE(reused, temporary);
    EXPECT_EQ(Bodies().AddBody(temporary, Activation::Activate).GetError().mCode, ErrorCode::InvalidBodyID);
    EXPECT_EQ(Bodies().AddImpulse(temporary, Vec3(1, 0, 0)).GetError().mCode, ErrorCode::InvalidBodyID);
    EXPECT_EQ(Position(reused), Vec3(9, 9, 9));
    ASSERT_TRUE(Bodies().DestroyBody(reused).IsOk());
    ExpectWorldUnchanged();
}

TEST_F(BadInputTest, NaNAndInfinitePositionsAreRejected)
{
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    EXPECT_EQ(Bodies().SetPosition(mBox, Vec3(nan, 0, 0), Activation::Activate).GetError().mCode,
              ErrorCode::InvalidArgument);
    EXPECT_EQ(Bodies().SetPosition(mBox, Vec3(0, inf, 0), Activation::Activate).GetError().mCode,
              ErrorCode::InvalidArgument);
    EXPECT_EQ(Bodies().SetPosition(mBox, Vec3(0, 0, 1.0e9f), Activation::Activate).GetError().mCode,
              ErrorCode::InvalidArgument);
    EXPECT_FALSE(Bodies().SetLinearVelocity(mBox, Vec3(nan, 0, 0)).IsOk());
    EXPECT_FALSE(Bodies().AddForce(mBox, Vec3(0, inf, 0)).IsOk());
    EXPECT_FALSE(Bodies().SetRotation(mBox, Quat(nan, 0, 0, 0), Activation::Activate).IsOk());
    EXPECT_FALSE(Bodies().SetRotation(mBox, Quat(2, 0, 0, 0), Activation::Activate).IsOk());

    BodyCreationSettings settings = DynamicSettings(Sphere(1), Vec3(nan, 0, 0));
    Result<BodyID> created = Bodies().CreateBody(settings);
    ASSERT_FALSE(created.IsOk());
    EXPECT_EQ(created.GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_NE(created.GetError().mMessage.find("position"), std::string::npos);
    ExpectWorldUnchanged();
}

TEST_F(BadInputTest, DegenerateShapesAreRejected)
{
    EXPECT_EQ(BoxShape::Create(Vec3(0, 1, 1)).GetError().mCode, ErrorCode::DegenerateShape);
    EXPECT_FALSE(BoxShape::Create(Vec3(-1, 1, 1)).IsOk());
    EXPECT_FALSE(SphereShape::Create(0.0f).IsOk());
    EXPECT_FALSE(SphereShape::Create(std::numeric_limits<float>::quiet_NaN()).IsOk());
    EXPECT_FALSE(CapsuleShape::Create(1.0f, -0.5f).IsOk());
    const Vec3 coplanar[] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(0.5f, 0, 0.5f)};
    Result<std::shared_ptr<const ConvexHullShape>> hull = ConvexHullShape::Create(coplanar);
    ASSERT_FALSE(hull.IsOk());
    EXPECT_EQ(hull.GetError().mCode, ErrorCode::DegenerateShape);

    // A shape without volume cannot be dynamic
    const Vec3 vertices[] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1)};
    const std::array<uint32_t, 3> triangles[] = {{0, 1, 2}};
    BodyCreationSettings meshBody =
        DynamicSettings(TriangleMeshShape::Create(vertices, triangles).Value(), Vec3::Zero());
    EXPECT_FALSE(Bodies().CreateBody(meshBody).IsOk());
    BodyCreationSettings noShape = DynamicSettings(nullptr, Vec3::Zero());
    EXPECT_FALSE(Bodies().CreateBody(noShape).IsOk());
    ExpectWorldUnchanged();
}

TEST_F(BadInputTest, AddingTwiceAndRemovingTwiceAreRejected)
{
    EXPECT_EQ(Bodies().AddBody(mBox, Activation::Activate).GetError().mCode, ErrorCode::AlreadyAdded);
    const BodyID extra = Bodies().CreateBody(DynamicSettings(Sphere(1), Vec3(5, 5, 5))).Value();
    ASSERT_TRUE(Bodies().AddBody(extra, Activation::Activate).IsOk());
    ASSERT_TRUE(Bodies().RemoveBody(extra).IsOk());
    EXPECT_EQ(Bodies().RemoveBody(extra).GetError().mCode, ErrorCode::NotAdded);
    EXPECT_EQ(Bodies().DestroyBody(mBox).GetError().mCode, ErrorCode::AlreadyAdded)
        << "destroying a body in the world";
    ASSERT_TRUE(Bodies().DestroyBody(extra).IsOk());
    EXPECT_EQ(Bodies().DestroyBody(extra).GetError().mCode, ErrorCode::InvalidBodyID);
    ExpectWorldUnchanged();
}

TEST_F(BadInputTest, BatchWithABadIDMarksNothing)
{
    const BodyID a = Bodies().CreateBody(DynamicSettings(Sphere(1), Vec3(5, 5, 5))).Value();
    const BodyID ids[] = {a, mBox};
    Result<BodyInterface::AddBatch> batch = Bodies().AddBodiesPrepare(ids);
    ASSERT_FALSE(batch.IsOk());
    EXPECT_EQ(batch.GetError().mCode, ErrorCode::AlreadyAdded);
    // a was not left pending: it can still be added
    EXPECT_TRUE(Bodies().AddBody(a, Activation::Activate).IsOk());
    ASSERT_TRUE(Bodies().RemoveBody(a).IsOk());
    ASSERT_TRUE(Bodies().DestroyBody(a).IsOk());
    ExpectWorldUnchanged();
}

TEST_F(BadInputTest, BodyInAPreparedBatchCannotBeDestroyed)
{
    const BodyID pending = Bodies().CreateBody(DynamicSettings(Sphere(1), Vec3(5, 5, 5))).Value();
    Result<BodyInterface::AddBatch> batch = Bodies().AddBodiesPrepare({&pending, 1});
    ASSERT_TRUE(batch.IsOk());
    EXPECT_EQ(Bodies().DestroyBody(pending).GetError().mCode, ErrorCode::AlreadyAdded);
    EXPECT_TRUE(Bodies().AddBodiesAbort(batch.Value()).IsOk());
    EXPECT_TRUE(Bodies().DestroyBody(pending).IsOk()) << "after the abort it is free to go";
    ExpectWorldUnchanged();
}

TEST_F(BadInputTest, ABodyMovedBetweenPrepareAndFinalizeIsFoundWhereItIs)
{
    BodyCreationSettings settings = DynamicSettings(Box(Vec3(1, 1, 1)), Vec3(20, 1, 0));
    settings.mMotionType = MotionType::Static;
    settings.mObjectLayer = Layers::cStatic;
    const BodyID pending = Bodies().CreateBody(settings).Value();
    Result<BodyInterface::AddBatch> batch = Bodies().AddBodiesPrepare({&pending, 1});
    ASSERT_TRUE(batch.IsOk());
    ASSERT_TRUE(Bodies().SetPosition(pending, Vec3(-20, 1, 0), Activation::DontActivate).IsOk());
    ASSERT_TRUE(Bodies().AddBodiesFinalize(batch.Value(), Activation::DontActivate).IsOk());
    bool found = false;
    System().GetBroadPhase().CollidePoint(Vec3(-20, 1, 0), {},
                                          [&](BodyID inID) { found |= inID == pending; });
    EXPECT_TRUE(found) << "the broad phase kept the bounds of the prepare";
}

static_assert(!std::is_copy_constructible_v<BodyInterface::AddBatch>,
              "a copy of a prepared batch could be finalized and aborted: its state freed twice");

TEST_F(BadInputTest, ChangesThatWouldOverflowABodysStateAreRefused)
{
    BodyCreationSettings light = DynamicSettings(Sphere(0.1f), Vec3(5, 1, 5));
    light.mDensity = 1.0f; // About 4 g
    const BodyID body = AddDynamic(light);
    EXPECT_EQ(Bodies().AddForce(body, Vec3(2e38f, 0, 0)).GetError().mCode, ErrorCode::InvalidArgument)
        << "finite, but its length cannot be squared";
    ASSERT_TRUE(Bodies().AddForce(body, Vec3(1e19f, 0, 0)).IsOk());
    EXPECT_EQ(Bodies().AddForce(body, Vec3(1e19f, 0, 0)).GetError().mCode, ErrorCode::InvalidArgument)
        << "two forces of 1e19 N square to more than a float holds";
    // A finite impulse that makes the velocity too large to square
    EXPECT_EQ(Bodies().AddImpulse(body, Vec3(0, 1e18f, 0)).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_EQ(Bodies().SetLinearVelocity(body, Vec3(1e20f, 0, 0)).GetError().mCode,
              ErrorCode::InvalidArgument);
    // The first force stays: a = 1e19 N / 4 g; the step clamps the speed to the body's limit without NaN
    Step(1);
    EXPECT_TRUE(IsFinite(Position(body)));
    EXPECT_NEAR(Velocity(body).norm(), light.mMaxLinearVelocity, 1.0f);
}

TEST_F(BadInputTest, BodySettingsThatWouldOverflowAreRejected)
{
    BodyCreationSettings settings = DynamicSettings(Sphere(1), Vec3(5, 5, 5));
    settings.mGravityFactor = 1e38f;
    EXPECT_EQ(Bodies().CreateBody(settings).GetError().mCode, ErrorCode::InvalidArgument);
    settings = DynamicSettings(Sphere(1), Vec3(5, 5, 5));
    settings.mMaxLinearVelocity = std::numeric_limits<float>::infinity();
    EXPECT_EQ(Bodies().CreateBody(settings).GetError().mCode, ErrorCode::InvalidArgument);
    settings = DynamicSettings(Sphere(1), Vec3(5, 5, 5));
    settings.mDensity = 1e-40f; // A denormal mass: its inverse is infinite
    EXPECT_EQ(Bodies().CreateBody(settings).GetError().mCode, ErrorCode::InvalidArgument);
    settings = DynamicSettings(Sphere(1), Vec3(5, 5, 5));
    settings.mLinearVelocity = Vec3(1e20f, 0, 0);
    EXPECT_EQ(Bodies().CreateBody(settings).GetError().mCode, ErrorCode::InvalidArgument);
    ExpectWorldUnchanged();
}

// A motion type outside the enum made a body that was added and active but never moved, and whose published
// pose carried the stray bits into its layer
TEST_F(BadInputTest, AMotionTypeOutsideTheEnumIsRejected)
{
    for (const uint8_t value : {3, 4, 0x41, 0xff})
    {
        BodyCreationSettings settings = DynamicSettings(Sphere(1), Vec3(5, 5, 5));
        settings.mMotionType = MotionType(value);
        const Result<BodyID> created = Bodies().CreateAndAddBody(settings, Activation::Activate);
        ASSERT_FALSE(created) << "motion type " << int(value);
        EXPECT_EQ(created.GetError().mCode, ErrorCode::InvalidArgument);
        EXPECT_NE(created.GetError().mMessage.find("motion type"), std::string::npos);
    }
    ExpectWorldUnchanged();
}

TEST_F(BadInputTest, AShapeWithNoExtentIsRejected)
{
    // Built around CapsuleShape::Create, which would refuse it: its bounds are inverted
    BodyCreationSettings settings =
        DynamicSettings(std::make_shared<CapsuleShape>(-5.0f, 1.0f), Vec3(5, 5, 5));
    settings.mMotionType = MotionType::Kinematic;
    EXPECT_EQ(Bodies().CreateBody(settings).GetError().mCode, ErrorCode::InvalidArgument);
    ExpectWorldUnchanged();
}

TEST_F(BadInputTest, KinematicBodiesKeepToTheirVelocityLimit)
{
    BodyCreationSettings settings = DynamicSettings(Box(Vec3(1, 1, 1)), Vec3(0, 20, 0));
    settings.mMotionType = MotionType::Kinematic;
    const BodyID kinematic = AddDynamic(settings);
    ASSERT_TRUE(Bodies().SetLinearVelocity(kinematic, Vec3(1e9f, 0, 0)).IsOk());
    Step(1);
    EXPECT_NEAR(Velocity(kinematic).norm(), settings.mMaxLinearVelocity, 1e-3f);
    EXPECT_NEAR(Position(kinematic).x(), settings.mMaxLinearVelocity * cDeltaTime, 1e-2f);
}

TEST_F(BadInputTest, CallsThatWouldDeadlockWhileHoldingABodyLockAreRefused)
{
    {
        BodyLockRead lock(System().GetBodyManager(), mBox);
        ASSERT_TRUE(lock.Succeeded());
        // Each of these would wait for a lock this thread holds, or take a second one: refused, not hung
        EXPECT_EQ(UpdateWorld(cDeltaTime).GetError().mCode, ErrorCode::WrongThread);
        EXPECT_EQ(Bodies().GetPosition(mFloor).GetError().mCode, ErrorCode::WrongThread);
        EXPECT_EQ(Bodies().SetLinearVelocity(mBox, Vec3(1, 0, 0)).GetError().mCode, ErrorCode::WrongThread);
        BodyLockWrite second(System().GetBodyManager(), mFloor);
        EXPECT_FALSE(second.Succeeded());
        EXPECT_TRUE(second.WasWrongThread());
    }
    // Released: everything works again
    EXPECT_TRUE(UpdateWorld(cDeltaTime).IsOk());
    EXPECT_TRUE(Bodies().GetPosition(mFloor).IsOk());
    EXPECT_EQ(System().GetBodyManager().GetNumBodies(), 2u);
}

TEST_F(BadInputTest, BadTimeStepsAreRejected)
{
    EXPECT_FALSE(UpdateWorld(0.0f).IsOk());
    EXPECT_FALSE(UpdateWorld(-1.0f).IsOk());
    EXPECT_FALSE(UpdateWorld(std::numeric_limits<float>::quiet_NaN()).IsOk());
    EXPECT_FALSE(UpdateWorld(cDeltaTime, 0).IsOk());
    ExpectWorldUnchanged();
}

TEST_F(BadInputTest, ObjectLayerOutsideTheSetupIsRejected)
{
    BodyCreationSettings settings = DynamicSettings(Sphere(1), Vec3(5, 5, 5));
    settings.mObjectLayer = 40;
    EXPECT_EQ(Bodies().CreateBody(settings).GetError().mCode, ErrorCode::InvalidArgument);
    ExpectWorldUnchanged();
}

} // namespace cairn::test
