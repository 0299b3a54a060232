// Joints (issue 33): a welded cantilever and a welded pair, a pendulum against its analytic period, a spring
// against the implicit spring step, a rope and a rod, a hinge's motor, limit and friction, a slider's limit
// against the slide under gravity, its motor and friction against their forces, a swing-twist's cone and
// twist range, its pendulum period within them and its friction, a joint that joins two
// islands into one that sleeps and wakes whole, the same bodies for any thread count, and bad input.

#include "SimulationFixture.h"
#include "cairn/physics/body/BodyLock.h"
#include "common/StaticFloor.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace cairn::test
{
namespace
{

class JointTest : public SimulationFixture
{
protected:
    ConstraintInterface& Joints() { return System().GetConstraintInterface(); }
    /// A 200 kg box wheel (1 x 1 x 0.2 m) at (0, 3, 0) spinning about z at inSpin, kept awake, its spin
    /// undamped
    BodyID AddWheel(float inSpin)
    {
        BodyCreationSettings settings = DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.1f)), Vec3(0.0f, 3.0f, 0.0f));
        settings.mAngularDamping = 0.0f;
        settings.mAngularVelocity = Vec3(0.0f, 0.0f, inSpin);
        settings.mAllowSleeping = false;
        return AddDynamic(settings);
    }
};

TEST_F(JointTest, APendulumSwingsWithThePeriodOfItsLengthAndKeepsIt)
{
    // A sphere of radius r on a massless rod of length L from a fixed point (the joint's point, on the
    // world): a physical pendulum, I = 2/5 m r^2 + m L^2 about the pivot, T0 = 2 pi sqrt(I / (m g L)), and at
    // an amplitude of theta0 T = T0 (1 + theta0^2 / 16 + ...)
    const float length = 1.0f, radius = 0.05f, theta0 = 0.1f;
    const Vec3 pivot(0.0f, 5.0f, 0.0f);
    BodyCreationSettings settings =
        DynamicSettings(Sphere(radius), pivot + length * Vec3(std::sin(theta0), -std::cos(theta0), 0.0f));
    settings.mLinearDamping = 0.0f;
    settings.mAngularDamping = 0.0f;
    settings.mAllowSleeping = false;
    const BodyID bob = AddDynamic(settings);
    PointConstraintSettings joint;
    joint.mBodyB = bob; // A: the world
    joint.mPoint = pivot;
    ASSERT_TRUE(Joints().AddPoint(joint).IsOk());

    // Downward zero crossings of x over 6 s (about 3 periods), interpolated within the step
    std::vector<double> crossings;
    float previousX = Position(bob).x();
    float longest = 0.0f, shortest = 1.0e9f, radialSpeed = 0.0f;
    for (int step = 1; step <= 360; ++step)
    {
        ASSERT_TRUE(UpdateWorld(cDeltaTime).IsOk());
        const Vec3 position = Position(bob);
        longest = std::max(longest, (position - pivot).norm());
        shortest = std::min(shortest, (position - pivot).norm());
        radialSpeed = std::max(radialSpeed, std::abs(Velocity(bob).dot((position - pivot).normalized())));
        if (previousX > 0.0f && position.x() <= 0.0f)
            crossings.push_back((step - 1 + previousX / (previousX - position.x())) * double(cDeltaTime));
        previousX = position.x();
    }
    ASSERT_GE(crossings.size(), 3u);
    const double measured = (crossings.back() - crossings.front()) / double(crossings.size() - 1);
    const double inertia = 0.4 * radius * radius + length * length; // Per unit mass
    const double expected =
        2.0 * std::numbers::pi * std::sqrt(inertia / (9.81 * length)) * (1.0 + theta0 * theta0 / 16.0);
    // Symplectic Euler at 60 Hz shortens a 2 s period by about (omega dt)^2 / 24 (0.04 %); the position rows
    // pull the bob back onto its circle a little late each step. 1 % tells a wrong inertia or a joint that
    // gives (a 1 % longer rod is 0.5 % on the period) from these
    EXPECT_NEAR(measured, expected, 0.01 * expected);
    // The rod keeps its length: the velocity rows leave a drift (a quarter of a percent over these 6 s) that
    // the position rows take out
    EXPECT_LT(longest, length * 1.001f);
    EXPECT_GT(shortest, length * 0.999f);
    // The bob moves round the pivot, never along the rod (the velocity rows; the position rows alone would
    // leave it the radial speed gravity gives it, g dt a step)
    EXPECT_LT(radialSpeed, 0.02f);
}

TEST_F(JointTest, ADisabledJointHoldsNothingAndARemovedOneLetsGo)
{
    const Vec3 pivot(0.0f, 5.0f, 0.0f);
    const BodyID bob = AddDynamic(DynamicSettings(Sphere(0.1f), pivot - Vec3(0.0f, 1.0f, 0.0f)));
    PointConstraintSettings settings;
    settings.mBodyA = bob; // B: the world, this time
    settings.mPoint = pivot;
    const ConstraintID joint = Joints().AddPoint(settings).Value();
    Step(30);
    EXPECT_NEAR(Position(bob).y(), 4.0f, 0.01f); // Hanging
    ASSERT_TRUE(Joints().SetEnabled(joint, false).IsOk());
    EXPECT_FALSE(Joints().IsEnabled(joint).Value());
    Step(30); // Half a second of free fall: 1.2 m
    EXPECT_LT(Position(bob).y(), 3.0f);
    ASSERT_TRUE(Joints().Remove(joint).IsOk());
    EXPECT_EQ(Joints().GetNumConstraints().Value(), 0u);
    // The removed joint's id is stale, also once its slot is reused
    const ConstraintID next = Joints().AddPoint(settings).Value();
    EXPECT_EQ(next.GetIndex(), joint.GetIndex());
    EXPECT_EQ(Joints().IsEnabled(joint).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_EQ(Joints().Remove(joint).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_TRUE(Joints().IsEnabled(next).Value());
}

TEST_F(JointTest, AJointMakesOneIslandThatSleepsAndWakesWhole)
{
    AddFloor();
    // Two boxes far apart on the floor: two islands. Jointed (at the point between them, a metre up), one
    auto scene = [&](bool inJoined)
    {
        ResetWorld(PhysicsSettings{});
        AddFloor();
        const BodyID a = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(-5.0f, 0.5f, 0.0f)));
        const BodyID b = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(5.0f, 0.5f, 0.0f)));
        if (inJoined)
        {
            PointConstraintSettings joint;
            joint.mBodyA = a;
            joint.mBodyB = b;
            joint.mPoint = Vec3(0.0f, 1.0f, 0.0f);
            EXPECT_TRUE(Joints().AddPoint(joint).IsOk());
        }
        return std::pair(a, b);
    };
    for (bool joined : {false, true})
    {
        const auto [a, b] = scene(joined);
        Step(1);
        EXPECT_EQ(System().GetLastStepStatistics().mNumIslands, joined ? 1u : 2u) << "joined " << joined;
        // At rest, both asleep
        for (int i = 0; i < 600 && (IsActive(a) || IsActive(b)); ++i)
            Step(1);
        ASSERT_FALSE(IsActive(a));
        ASSERT_FALSE(IsActive(b));
        // Waking one wakes the other through the joint (alone, it stays asleep)
        ASSERT_TRUE(Bodies().ActivateBody(a).IsOk());
        Step(1);
        EXPECT_TRUE(IsActive(a));
        EXPECT_EQ(IsActive(b), joined) << "joined " << joined;
    }
}

TEST_F(JointTest, AChainOfJointedBodiesIsTheSameForAnyThreadCount)
{
    // Five spheres in a chain from a fixed point, swinging into a box on the floor: joints, contacts and both
    // in one island
    auto run = [](jobs::JobSystem* ioJobs)
    {
        std::unique_ptr<PhysicsSystem> system = MakePhysicsSystem();
        BodyInterface& bodies = system->GetBodyInterface();
        (void)bodies.CreateAndAddBody(StaticFloorSettings(20.0f), Activation::DontActivate);
        BodyCreationSettings box;
        box.mShape = BoxShape::Create(Vec3(0.3f, 0.3f, 0.3f)).Value();
        box.mPosition = Vec3(-1.0f, 0.3f, 0.0f);
        box.mMotionType = MotionType::Dynamic;
        box.mObjectLayer = Layers::cMoving;
        (void)bodies.CreateAndAddBody(box, Activation::Activate);
        BodyID previous;
        std::vector<BodyID> links;
        for (int i = 0; i < 5; ++i)
        {
            BodyCreationSettings link;
            link.mShape = SphereShape::Create(0.2f).Value();
            link.mPosition = Vec3(0.5f * float(i + 1), 3.0f, 0.0f);
            link.mMotionType = MotionType::Dynamic;
            link.mObjectLayer = Layers::cMoving;
            const BodyID id = bodies.CreateAndAddBody(link, Activation::Activate).Value();
            PointConstraintSettings joint;
            joint.mBodyA = previous; // The world for the first
            joint.mBodyB = id;
            joint.mPoint = Vec3(0.5f * float(i) + 0.25f * float(i > 0), 3.0f, 0.0f);
            EXPECT_TRUE(system->GetConstraintInterface().AddPoint(joint).IsOk());
            links.push_back(id);
            previous = id;
        }
        for (int step = 0; step < 240; ++step)
            EXPECT_TRUE(
                (ioJobs != nullptr ? system->Update(1.0f / 60.0f, 1, *ioJobs) : system->Update(1.0f / 60.0f))
                    .IsOk());
        std::vector<Vec3> positions;
        for (const BodyID& id : links)
            positions.push_back(bodies.GetPosition(id).Value());
        return positions;
    };
    const std::vector<Vec3> alone = run(nullptr);
    for (uint32_t threads : {1u, 2u, 4u})
    {
        jobs::JobSystem::Settings settings;
        settings.mNumThreads = threads;
        jobs::JobSystem jobSystem(settings);
        const std::vector<Vec3> withJobs = run(&jobSystem);
        for (size_t i = 0; i < alone.size(); ++i)
            EXPECT_EQ(withJobs[i], alone[i]) << threads << " threads, link " << i;
    }
    // And the chain hangs together: each link within its rest length of the next
    EXPECT_LT(alone.front().y(), 3.0f); // It swung down
}

TEST_F(JointTest, ADistanceSpringFollowsTheImplicitSpringStep)
{
    // A sphere on a spring of rest length 1 m to a point of the world, pulled 0.2 m along it and let go, no
    // gravity, no damping of its own. The soft row is the implicit Euler step of the spring and damper on the
    // row's effective mass (here the body's mass: the anchor is its centre): for the stretch e and its rate
    // v,
    //   v' = (v - h w^2 e) / (1 + 2 z h w + h^2 w^2),  e' = e + h v'
    // whatever the mass, and the position iterations leave a soft row alone
    const float frequency = 1.0f, damping = 0.1f, rest = 1.0f;
    const Vec3 pivot(0.0f, 5.0f, 0.0f);
    BodyCreationSettings settings = DynamicSettings(Sphere(0.1f), pivot + Vec3(rest + 0.2f, 0.0f, 0.0f));
    settings.mGravityFactor = 0.0f;
    settings.mLinearDamping = 0.0f;
    settings.mAngularDamping = 0.0f;
    settings.mAllowSleeping = false;
    settings.mDensity = 7800.0f; // Heavy: the frequency does not depend on the mass
    const BodyID bob = AddDynamic(settings);
    DistanceConstraintSettings spring;
    spring.mBodyB = bob;
    spring.mPointA = pivot;
    spring.mPointB = Position(bob);
    spring.mMinDistance = spring.mMaxDistance = rest;
    spring.mLimitsSpring = {frequency, damping};
    ASSERT_TRUE(Joints().AddDistance(spring).IsOk());

    const double h = cDeltaTime, omega = 2.0 * std::numbers::pi * frequency;
    double e = 0.2, v = 0.0, largestDifference = 0.0;
    for (int step = 0; step < 180; ++step)
    {
        ASSERT_TRUE(UpdateWorld(cDeltaTime).IsOk());
        v = (v - h * omega * omega * e) / (1.0 + 2.0 * damping * h * omega + h * h * omega * omega);
        e += h * v;
        largestDifference =
            std::max(largestDifference, std::abs(double((Position(bob) - pivot).norm()) - rest - e));
    }
    // Float rounding over 180 steps of a 0.2 m swing
    EXPECT_LT(largestDifference, 2.0e-4);
    // And it did swing: three periods later the stretch is what the formula says, not 0.2 m or 0
    EXPECT_GT(std::abs(e), 0.01);
}

TEST_F(JointTest, ARopeIsSlackWithinItsLengthAndHoldsAtIt)
{
    const Vec3 pivot(0.0f, 5.0f, 0.0f);
    BodyCreationSettings settings = DynamicSettings(Sphere(0.1f), pivot - Vec3(0.0f, 0.5f, 0.0f));
    settings.mLinearDamping = 0.0f;
    const BodyID bob = AddDynamic(settings);
    DistanceConstraintSettings rope;
    rope.mBodyB = bob;
    rope.mPointA = pivot;
    rope.mPointB = Position(bob);
    rope.mMinDistance = 0.0f;
    rope.mMaxDistance = 1.5f;
    ASSERT_TRUE(Joints().AddDistance(rope).IsOk());
    Step(6); // 0.1 s of free fall: slack, the rope does nothing
    EXPECT_NEAR(Position(bob).y(), 4.5f - 0.5f * 9.81f * 0.1f * 0.1f, 0.01f);
    float longest = 0.0f;
    for (int step = 0; step < 120; ++step)
    {
        Step(1);
        longest = std::max(longest, (Position(bob) - pivot).norm());
    }
    EXPECT_NEAR((Position(bob) - pivot).norm(), 1.5f, 0.015f); // Taut, hanging
    EXPECT_LT(longest, 1.5f * 1.02f); // The jerk when it went taut stretched it 2 % at most
    // A rod (equal limits) pushes too: a body on a 1 m rod above its pivot stays 1 m up while it topples
    ResetWorld(PhysicsSettings{});
    const BodyID top = AddDynamic(DynamicSettings(Sphere(0.1f), pivot + Vec3(0.01f, 1.0f, 0.0f)));
    DistanceConstraintSettings rod;
    rod.mBodyB = top;
    rod.mPointA = pivot;
    rod.mPointB = Position(top);
    ASSERT_TRUE(Joints().AddDistance(rod).IsOk()); // Limits: the distance now
    for (int step = 0; step < 120; ++step)
    {
        Step(1);
        ASSERT_NEAR((Position(top) - pivot).norm(), (rod.mPointB - pivot).norm(), 0.01f) << "step " << step;
    }
}

TEST_F(JointTest, AFixedJointHoldsACantileverAndTwoBodiesTumblingAsOne)
{
    // A box welded to the world at a point half a metre beside its centre: gravity's torque turns it about
    // that point unless the rotation rows hold it (a point joint alone lets it swing down)
    const BodyID beam = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.1f, 0.1f)), Vec3(0.0f, 3.0f, 0.0f)));
    FixedConstraintSettings weld;
    weld.mBodyB = beam;
    weld.mPoint = Vec3(-0.5f, 3.0f, 0.0f);
    ASSERT_TRUE(Joints().AddFixed(weld).IsOk());
    Step(120);
    EXPECT_LT((Position(beam) - Vec3(0.0f, 3.0f, 0.0f)).norm(), 0.01f);
    EXPECT_LT(Bodies().GetRotation(beam).Value().angularDistance(Quat::Identity()),
              1.0f * std::numbers::pi_v<float> / 180.0f);

    // Two bodies welded at a point between them, thrown spinning with no gravity: they keep their pose
    // relative to each other while the pair tumbles (each started with its own spin: the joint makes it one)
    ResetWorld(PhysicsSettings{});
    BodyCreationSettings boxSettings = DynamicSettings(Box(Vec3(0.4f, 0.2f, 0.3f)), Vec3(0.0f, 5.0f, 0.0f));
    boxSettings.mGravityFactor = 0.0f;
    boxSettings.mAngularVelocity = Vec3(0.0f, 2.0f, 1.0f);
    boxSettings.mAllowSleeping = false;
    BodyCreationSettings ballSettings = DynamicSettings(Sphere(0.3f), Vec3(0.8f, 5.0f, 0.0f));
    ballSettings.mGravityFactor = 0.0f;
    ballSettings.mAngularVelocity = Vec3(3.0f, 0.0f, 0.0f);
    ballSettings.mAllowSleeping = false;
    const BodyID box = AddDynamic(boxSettings), ball = AddDynamic(ballSettings);
    FixedConstraintSettings pair;
    pair.mBodyA = box;
    pair.mBodyB = ball;
    pair.mPoint = Vec3(0.4f, 5.0f, 0.0f);
    ASSERT_TRUE(Joints().AddFixed(pair).IsOk());
    const Quat relative0 = Bodies().GetRotation(box).Value().conjugate() * Bodies().GetRotation(ball).Value();
    const Vec3 offset0 = Vec3(0.8f, 0.0f, 0.0f); // The ball's centre in the box's frame
    float worstAngle = 0.0f, worstOffset = 0.0f;
    for (int step = 0; step < 120; ++step)
    {
        Step(1);
        const Quat boxRotation = Bodies().GetRotation(box).Value();
        const Quat relative = boxRotation.conjugate() * Bodies().GetRotation(ball).Value();
        worstAngle = std::max(worstAngle, relative.angularDistance(relative0));
        const Vec3 offset = boxRotation.conjugate() * (Position(ball) - Position(box));
        worstOffset = std::max(worstOffset, (offset - offset0).norm());
    }
    EXPECT_LT(worstAngle, 0.5f * std::numbers::pi_v<float> / 180.0f);
    EXPECT_LT(worstOffset, 0.005f);
    EXPECT_GT(Bodies().GetAngularVelocity(box).Value().norm(), 0.5f); // Tumbling, not stopped
}

TEST_F(JointTest, AHingeMotorReachesItsSpeedAndALimitStopsTheDoor)
{
    // A wheel (a box turning about its own centre, so gravity gives no torque) on a hinge to the world with
    // a velocity motor: it spins up to the target within the motor's torque
    const float target = 2.0f;
    const BodyID wheel = AddWheel(0.0f);
    HingeConstraintSettings motor;
    motor.mBodyB = wheel;
    motor.mPoint = Vec3(0.0f, 3.0f, 0.0f);
    motor.mHingeAxis = Vec3(0.0f, 0.0f, 1.0f);
    motor.mMotor.mMode = MotorMode::Velocity;
    motor.mMotor.mTargetVelocity = target;
    motor.mMotor.mMaxForce = 500.0f;
    ASSERT_TRUE(Joints().AddHinge(motor).IsOk());
    Step(60);
    const Vec3 spin = Bodies().GetAngularVelocity(wheel).Value();
    EXPECT_NEAR(spin.z(), target, 0.05f * target);    // The 5 %
    EXPECT_LT(std::hypot(spin.x(), spin.y()), 0.01f); // About its axis only
    EXPECT_LT((Position(wheel) - Vec3(0.0f, 3.0f, 0.0f)).norm(), 0.005f);

    // A door hinged at its edge on a vertical axis, pushed open fast: the limit at 0.5 rad stops it there,
    // and the door keeps to its axis under gravity
    ResetWorld(PhysicsSettings{});
    BodyCreationSettings doorSettings = DynamicSettings(Box(Vec3(0.5f, 1.0f, 0.05f)), Vec3(0.5f, 1.2f, 0.0f));
    doorSettings.mAngularVelocity = Vec3(0.0f, 3.0f, 0.0f);
    doorSettings.mLinearVelocity = Vec3(0.0f, 0.0f, -1.5f); // The hinge edge at rest
    doorSettings.mAllowSleeping = false;
    const BodyID door = AddDynamic(doorSettings);
    HingeConstraintSettings hinge;
    hinge.mBodyB = door;
    hinge.mPoint = Vec3(0.0f, 1.2f, 0.0f);
    hinge.mHingeAxis = Vec3(0.0f, 1.0f, 0.0f);
    hinge.mLimitsMin = -0.5f;
    hinge.mLimitsMax = 0.5f;
    ASSERT_TRUE(Joints().AddHinge(hinge).IsOk());
    float widest = 0.0f, tilt = 0.0f;
    for (int step = 0; step < 90; ++step)
    {
        Step(1);
        const Quat rotation = Bodies().GetRotation(door).Value();
        const Vec3 across = rotation * Vec3::UnitX();
        widest = std::max(widest, std::abs(std::atan2(-across.z(), across.x())));
        tilt = std::max(tilt, std::acos(std::clamp((rotation * Vec3::UnitY()).y(), -1.0f, 1.0f)));
    }
    // The limit's row starts once the angle is past it: one step's travel at 3 rad/s (0.05 rad) at most, and
    // 3 s of 3 rad/s would be far past it
    EXPECT_LT(widest, 0.5f + 3.0f / 60.0f);
    EXPECT_GT(widest, 0.45f); // It did swing to the limit
    EXPECT_LT(tilt, 1.0f * std::numbers::pi_v<float> / 180.0f);
}

TEST_F(JointTest, AHingeWithEqualLimitsTurnsToThatAngleAndHoldsItUnderLoad)
{
    // A beam hinged at its end on a horizontal axis, its limits both 0.3 rad from where it is made: the
    // position pass turns it there and the row holds it against gravity's torque, as a fixed joint would
    BodyCreationSettings beamSettings =
        DynamicSettings(Box(Vec3(0.5f, 0.05f, 0.05f)), Vec3(0.5f, 3.0f, 0.0f));
    beamSettings.mAllowSleeping = false; // The position pass turns it with no speed: it would look at rest
    const BodyID beam = AddDynamic(beamSettings);
    HingeConstraintSettings hinge;
    hinge.mBodyB = beam;
    hinge.mPoint = Vec3(0.0f, 3.0f, 0.0f);
    hinge.mHingeAxis = Vec3(0.0f, 0.0f, 1.0f);
    hinge.mLimitsMin = hinge.mLimitsMax = 0.3f;
    ASSERT_TRUE(Joints().AddHinge(hinge).IsOk());
    Step(120);
    const Vec3 along = Bodies().GetRotation(beam).Value() * Vec3::UnitX();
    EXPECT_NEAR(std::atan2(along.y(), along.x()), 0.3f, 0.01f); // Raised 0.3 rad, not sagging
    EXPECT_LT(Bodies().GetAngularVelocity(beam).Value().norm(), 0.01f);
}

TEST_F(JointTest, AHingePositionMotorFollowsTheImplicitSpringStep)
{
    // A wheel turning about its own centre (no other row pulls on its spin) driven to 1 rad by a position
    // motor: each step its spin is the implicit Euler step of the spring, v' = (v - h w^2 C) / (1 + 2 z h w +
    // h^2 w^2), and its angle C' = C + h v' (relative to the target), whatever its inertia
    const BodyID wheel = AddWheel(0.0f);
    HingeConstraintSettings hinge;
    hinge.mBodyB = wheel;
    hinge.mPoint = Vec3(0.0f, 3.0f, 0.0f);
    hinge.mHingeAxis = Vec3(0.0f, 0.0f, 1.0f);
    hinge.mMotor.mMode = MotorMode::Position;
    hinge.mMotor.mTargetPosition = 1.0f;
    hinge.mMotor.mMaxForce = 1.0e6f; // Never reached: the spring alone
    hinge.mMotor.mSpring = {2.0f, 0.7f};
    const Result<ConstraintID> id = Joints().AddHinge(hinge);
    ASSERT_TRUE(id.IsOk());
    const float h = 1.0f / 60.0f, omega = 2.0f * std::numbers::pi_v<float> * 2.0f, zeta = 0.7f;
    float error = -1.0f, spin = 0.0f, worst = 0.0f;
    for (int step = 0; step < 120; ++step)
    {
        Step(1);
        spin = (spin - h * omega * omega * error) / (1.0f + 2.0f * zeta * h * omega + h * h * omega * omega);
        error += h * spin;
        worst = std::max(worst, std::abs(Joints().GetPosition(id.Value()).Value() - (1.0f + error)));
    }
    EXPECT_LT(worst, 0.002f);
    EXPECT_NEAR(Joints().GetPosition(id.Value()).Value(), 1.0f, 0.01f); // There after 2 s
}

TEST_F(JointTest, ADoorOpensAndClosesAsItsMotorIsToldWhileTheWorldRuns)
{
    // A door hinged at its edge on a vertical axis, limits 0 to 1.6 rad: a velocity motor opens it, then
    // (from outside the step) a position motor closes it; asleep once shut, a new motor wakes it
    BodyCreationSettings doorSettings = DynamicSettings(Box(Vec3(0.5f, 1.0f, 0.05f)), Vec3(0.5f, 1.2f, 0.0f));
    doorSettings.mAngularDamping = 0.0f;
    const BodyID door = AddDynamic(doorSettings);
    HingeConstraintSettings hinge;
    hinge.mBodyB = door;
    hinge.mPoint = Vec3(0.0f, 1.2f, 0.0f);
    hinge.mHingeAxis = Vec3(0.0f, 1.0f, 0.0f);
    hinge.mLimitsMin = 0.0f;
    hinge.mLimitsMax = 1.6f;
    hinge.mMotor = {MotorMode::Velocity, 1.0f, 0.0f, 2000.0f, {}};
    const Result<ConstraintID> id = Joints().AddHinge(hinge);
    ASSERT_TRUE(id.IsOk());
    Step(60);
    EXPECT_NEAR(Joints().GetPosition(id.Value()).Value(), 1.0f, 0.05f); // A second at 1 rad/s
    ASSERT_TRUE(
        Joints().SetMotor(id.Value(), {MotorMode::Position, 0.0f, 0.0f, 2000.0f, {1.5f, 1.0f}}).IsOk());
    Step(180);
    EXPECT_LT(std::abs(Joints().GetPosition(id.Value()).Value()), 0.02f);
    // The position rows read the same angle as the door's own rotation: its face turned about y
    const Vec3 across = Bodies().GetRotation(door).Value() * Vec3::UnitX();
    EXPECT_NEAR(Joints().GetPosition(id.Value()).Value(), std::atan2(-across.z(), across.x()), 1.0e-4f);

    // Motor off: it falls asleep shut; told to open, it wakes and opens
    ASSERT_TRUE(Joints().SetMotor(id.Value(), {}).IsOk());
    for (int step = 0; step < 600 && Bodies().IsActive(door).Value(); ++step)
        Step(1);
    ASSERT_FALSE(Bodies().IsActive(door).Value());
    ASSERT_TRUE(Joints().SetMotor(id.Value(), {MotorMode::Velocity, 1.0f, 0.0f, 2000.0f, {}}).IsOk());
    Step(30);
    EXPECT_GT(Joints().GetPosition(id.Value()).Value(), 0.4f);
}

TEST_F(JointTest, HingeFrictionSlowsASpinAsItsTorqueSays)
{
    // A spinning wheel on a hinge with friction torque T and no motor: its spin drops by T t / I
    const BodyID wheel = AddWheel(5.0f);
    HingeConstraintSettings hinge;
    hinge.mBodyB = wheel;
    hinge.mPoint = Vec3(0.0f, 3.0f, 0.0f);
    hinge.mHingeAxis = Vec3(0.0f, 0.0f, 1.0f);
    hinge.mMaxFrictionTorque = 20.0f;
    ASSERT_TRUE(Joints().AddHinge(hinge).IsOk());
    Step(30);
    // A box of 1 x 1 x 0.2 m at 1000 kg/m^3: 200 kg, I about z = m (1 + 1) / 12
    const float inertia = 200.0f * 2.0f / 12.0f;
    EXPECT_NEAR(Bodies().GetAngularVelocity(wheel).Value().z(), 5.0f - 20.0f * 0.5f / inertia, 0.02f);
}

class SliderTest : public JointTest
{
protected:
    /// A 64 kg box (0.4 m a side at 1000 kg/m^3) at (0, 3, 0), kept awake, undamped
    BodyID AddSliding()
    {
        BodyCreationSettings settings = DynamicSettings(Box(Vec3(0.2f, 0.2f, 0.2f)), Vec3(0.0f, 3.0f, 0.0f));
        settings.mLinearDamping = 0.0f;
        settings.mAngularDamping = 0.0f;
        settings.mAllowSleeping = false;
        return AddDynamic(settings);
    }
    static constexpr float cMass = 64.0f;
    static constexpr float cGravity = 9.81f;
    static constexpr float cStep = 1.0f / 60.0f;
};

TEST_F(SliderTest, ABoxSlidesDownItsAxisAsGravityAlongItSaysAndStopsAtTheLimit)
{
    // A slider to the world along a line 30 degrees below the horizontal: the box slides with a = g sin 30
    // along it, never leaves it, never turns; the limit at 1 m stops it
    const BodyID box = AddSliding();
    const Vec3 axis(std::cos(std::numbers::pi_v<float> / 6.0f), -0.5f, 0.0f);
    const Vec3 start(0.0f, 3.0f, 0.0f);
    SliderConstraintSettings slider;
    slider.mBodyB = box;
    slider.mPoint = start;
    slider.mSliderAxis = axis;
    slider.mLimitsMin = -0.5f;
    slider.mLimitsMax = 1.0f;
    ASSERT_TRUE(Joints().AddSlider(slider).IsOk());
    const float acceleration = cGravity * 0.5f;
    float worstAcross = 0.0f, worstTurn = 0.0f;
    auto track = [&]
    {
        const Vec3 offset = Position(box) - start;
        worstAcross = std::max(worstAcross, (offset - offset.dot(axis) * axis).norm());
        worstTurn = std::max(worstTurn, Bodies().GetRotation(box).Value().angularDistance(Quat::Identity()));
    };
    for (int step = 0; step < 30; ++step)
    {
        Step(1);
        track();
    }
    // Half a second in, 0.61 m along, short of the limit. Symplectic Euler's place under a constant
    // acceleration leads 1/2 a t^2 by exactly 1/2 a h t (the step h): the analytic reference is that
    const float t = 0.5f;
    const float along = (Position(box) - start).dot(axis);
    EXPECT_NEAR(along, 0.5f * acceleration * t * t + 0.5f * acceleration * cStep * t, 0.002f);
    EXPECT_NEAR(Bodies().GetLinearVelocity(box).Value().dot(axis), acceleration * t, 0.01f);
    for (int step = 0; step < 90; ++step)
    {
        Step(1);
        track();
    }
    // Two seconds in it would be 9.8 m along without the limit: it rests at 1 m
    EXPECT_NEAR((Position(box) - start).dot(axis), 1.0f, 0.005f);
    EXPECT_LT(std::abs(Bodies().GetLinearVelocity(box).Value().dot(axis)), 0.05f);
    EXPECT_LT(worstAcross, 0.001f);
    EXPECT_LT(worstTurn, 0.5f * std::numbers::pi_v<float> / 180.0f);
}

TEST_F(SliderTest, AMotorDrivesWithinItsForceAndFrictionBrakesAsItsForceSays)
{
    // Across gravity: the motor reaches its speed (it has force to spare) and the line holds the box up
    const BodyID box = AddSliding();
    SliderConstraintSettings slider;
    slider.mBodyB = box;
    slider.mPoint = Vec3(0.0f, 3.0f, 0.0f);
    slider.mSliderAxis = Vec3(1.0f, 0.0f, 0.0f);
    slider.mMotor.mMode = MotorMode::Velocity;
    slider.mMotor.mTargetVelocity = 1.5f;
    slider.mMotor.mMaxForce = 2000.0f;
    ASSERT_TRUE(Joints().AddSlider(slider).IsOk());
    Step(30);
    EXPECT_NEAR(Bodies().GetLinearVelocity(box).Value().x(), 1.5f, 0.05f * 1.5f); // The 5 %
    EXPECT_NEAR(Position(box).y(), 3.0f, 0.001f);

    // Up a vertical slider, short of force: it accelerates at (F - m g) / m, below its target all along
    ResetWorld(PhysicsSettings{});
    const BodyID lift = AddSliding();
    slider.mBodyB = lift;
    slider.mSliderAxis = Vec3(0.0f, 1.0f, 0.0f);
    slider.mMotor.mTargetVelocity = 2.0f;
    slider.mMotor.mMaxForce = 1000.0f;
    ASSERT_TRUE(Joints().AddSlider(slider).IsOk());
    Step(12);
    const float lifting = (1000.0f - cMass * cGravity) / cMass;
    EXPECT_NEAR(Bodies().GetLinearVelocity(lift).Value().y(), lifting * 12.0f * cStep,
                0.02f * lifting * 0.2f);

    // Down a vertical slider with friction and no motor: it falls at g - F / m
    ResetWorld(PhysicsSettings{});
    const BodyID falling = AddSliding();
    SliderConstraintSettings braked;
    braked.mBodyB = falling;
    braked.mPoint = Vec3(0.0f, 3.0f, 0.0f);
    braked.mSliderAxis = Vec3(0.0f, 1.0f, 0.0f);
    braked.mMaxFrictionForce = 300.0f;
    ASSERT_TRUE(Joints().AddSlider(braked).IsOk());
    Step(30);
    const float falls = cGravity - 300.0f / cMass;
    EXPECT_NEAR(Bodies().GetLinearVelocity(falling).Value().y(), -falls * 0.5f, 0.02f * falls * 0.5f);
}

TEST_F(SliderTest, APositionMotorLiftsToItsTargetLessTheSagOfItsSpringUnderTheLoad)
{
    // A vertical slider's position motor is a spring of frequency f: holding a weight, it rests g / w^2
    // below its target (w = 2 pi f), whatever the mass
    const BodyID lift = AddSliding();
    SliderConstraintSettings slider;
    slider.mBodyB = lift;
    slider.mPoint = Vec3(0.0f, 3.0f, 0.0f);
    slider.mSliderAxis = Vec3(0.0f, 1.0f, 0.0f);
    slider.mMotor = {MotorMode::Position, 0.0f, 0.5f, 1.0e5f, {2.0f, 1.0f}};
    const Result<ConstraintID> id = Joints().AddSlider(slider);
    ASSERT_TRUE(id.IsOk());
    Step(240);
    const float omega = 2.0f * std::numbers::pi_v<float> * 2.0f;
    EXPECT_NEAR(Joints().GetPosition(id.Value()).Value(), 0.5f - cGravity / (omega * omega), 0.002f);
    EXPECT_NEAR(Position(lift).y(), 3.0f + Joints().GetPosition(id.Value()).Value(), 1.0e-4f);
}

TEST_F(SliderTest, TwoBodiesPushedApartAlongTheSliderKeepTheirMomentumAndTheLine)
{
    // No gravity: a piston between a heavy box and a light ball drives them apart at 1 m/s; what one gains
    // the other loses, and the ball stays on the box's line
    PhysicsSettings settings;
    settings.mGravity = Vec3::Zero();
    ResetWorld(settings);
    const BodyID box = AddSliding();
    BodyCreationSettings ballSettings = DynamicSettings(Sphere(0.1f), Vec3(0.5f, 3.0f, 0.0f));
    ballSettings.mLinearDamping = 0.0f;
    ballSettings.mAngularDamping = 0.0f;
    ballSettings.mAllowSleeping = false;
    const BodyID ball = AddDynamic(ballSettings);
    SliderConstraintSettings piston;
    piston.mBodyA = box;
    piston.mBodyB = ball;
    piston.mPoint = Vec3(0.5f, 3.0f, 0.0f);
    piston.mSliderAxis = Vec3(1.0f, 0.0f, 0.0f);
    piston.mMotor.mMode = MotorMode::Velocity;
    piston.mMotor.mTargetVelocity = 1.0f;
    piston.mMotor.mMaxForce = 500.0f;
    ASSERT_TRUE(Joints().AddSlider(piston).IsOk());
    const float ballMass = 1000.0f * 4.0f / 3.0f * std::numbers::pi_v<float> * 0.001f;
    float worstAcross = 0.0f;
    for (int step = 0; step < 60; ++step)
    {
        Step(1);
        const Vec3 offset = Position(ball) - Position(box);
        worstAcross = std::max(worstAcross, std::hypot(offset.y(), offset.z()));
    }
    const Vec3 velocityBox = Bodies().GetLinearVelocity(box).Value();
    const Vec3 velocityBall = Bodies().GetLinearVelocity(ball).Value();
    EXPECT_NEAR(velocityBall.x() - velocityBox.x(), 1.0f, 0.05f);
    EXPECT_LT((cMass * velocityBox + ballMass * velocityBall).norm(), 1.0e-3f * cMass);
    EXPECT_LT(worstAcross, 0.001f);
}

TEST_F(SliderTest, ASpinningBodyCarriesTheSliderLineRoundAndFlingsItsBallToTheLimit)
{
    // No gravity: a box spinning about y with a ball on a slider along the box's x axis. The line turns
    // with the box, so the ball goes round with it (its rows act at the ball, the box's arm reaching there)
    // and slides out to the outer limit; the pair keeps its angular momentum
    PhysicsSettings settings;
    settings.mGravity = Vec3::Zero();
    ResetWorld(settings);
    BodyCreationSettings boxSettings = DynamicSettings(Box(Vec3(0.2f, 0.2f, 0.2f)), Vec3(0.0f, 3.0f, 0.0f));
    boxSettings.mAngularVelocity = Vec3(0.0f, 2.0f, 0.0f);
    boxSettings.mLinearDamping = boxSettings.mAngularDamping = 0.0f;
    boxSettings.mAllowSleeping = false;
    const BodyID box = AddDynamic(boxSettings);
    BodyCreationSettings ballSettings = DynamicSettings(Sphere(0.1f), Vec3(0.6f, 3.0f, 0.0f));
    ballSettings.mLinearVelocity = Vec3(0.0f, 0.0f, -1.2f); // Going round with the box
    ballSettings.mAngularVelocity = Vec3(0.0f, 2.0f, 0.0f);
    ballSettings.mLinearDamping = ballSettings.mAngularDamping = 0.0f;
    ballSettings.mAllowSleeping = false;
    const BodyID ball = AddDynamic(ballSettings);
    SliderConstraintSettings slider;
    slider.mBodyA = box;
    slider.mBodyB = ball;
    slider.mPoint = Vec3(0.6f, 3.0f, 0.0f);
    slider.mSliderAxis = Vec3(1.0f, 0.0f, 0.0f);
    slider.mLimitsMin = 0.0f;
    slider.mLimitsMax = 0.4f;
    ASSERT_TRUE(Joints().AddSlider(slider).IsOk());
    auto angularMomentum = [&]
    {
        // About the pair's centre of mass; each body's own spin through its inertia (a cube: m s^2 / 6 with
        // s its side; a ball: 2/5 m r^2)
        const float ballMass = 1000.0f * 4.0f / 3.0f * std::numbers::pi_v<float> * 0.001f;
        const Vec3 centre = (cMass * Position(box) + ballMass * Position(ball)) / (cMass + ballMass);
        const Vec3 boxSpin = Bodies().GetAngularVelocity(box).Value();
        const Vec3 ballSpin = Bodies().GetAngularVelocity(ball).Value();
        return Vec3((Position(box) - centre).cross(cMass * Bodies().GetLinearVelocity(box).Value()) +
                    (Position(ball) - centre).cross(ballMass * Bodies().GetLinearVelocity(ball).Value()) +
                    cMass * 0.16f / 6.0f * boxSpin + 0.4f * ballMass * 0.01f * ballSpin);
    };
    const Vec3 momentum0 = angularMomentum();
    float worstAcross = 0.0f;
    for (int step = 0; step < 120; ++step)
    {
        Step(1);
        const Quat rotation = Bodies().GetRotation(box).Value();
        const Vec3 line = rotation * Vec3::UnitX();
        const Vec3 offset = Position(ball) - (Position(box) + rotation * Vec3(0.6f, 0.0f, 0.0f));
        worstAcross = std::max(worstAcross, (offset - offset.dot(line) * line).norm());
    }
    const Quat rotation = Bodies().GetRotation(box).Value();
    const Vec3 out = Position(ball) - (Position(box) + rotation * Vec3(0.6f, 0.0f, 0.0f));
    EXPECT_LT(worstAcross, 0.002f);
    EXPECT_NEAR(out.dot(rotation * Vec3::UnitX()), 0.4f, 0.01f); // Flung out to the limit
    EXPECT_LT((angularMomentum() - momentum0).norm(), 0.02f * momentum0.norm());
}

class SwingTwistJointTest : public JointTest
{
protected:
    /// An 8 kg limb (0.1 x 0.8 x 0.1 m) hanging from a socket at (0, 3, 0) on the world, its twist axis down
    /// the limb, its plane axis x (so the normal axis is z), started turning at inSpin; undamped, awake
    BodyID AddLimb(const Vec3& inSpin, float inNormalHalfCone, float inPlaneHalfCone, float inTwistMin,
                   float inTwistMax, float inFriction = 0.0f)
    {
        BodyCreationSettings settings =
            DynamicSettings(Box(Vec3(0.05f, 0.4f, 0.05f)), Vec3(0.0f, 3.0f - 0.4f, 0.0f));
        settings.mLinearDamping = settings.mAngularDamping = 0.0f;
        settings.mAngularVelocity = inSpin;
        settings.mLinearVelocity = inSpin.cross(Vec3(0.0f, -0.4f, 0.0f)); // The socket still
        settings.mAllowSleeping = false;
        const BodyID limb = AddDynamic(settings);
        SwingTwistConstraintSettings joint;
        joint.mBodyB = limb;
        joint.mPoint = cSocket;
        joint.mTwistAxis = Vec3(0.0f, -1.0f, 0.0f);
        joint.mPlaneAxis = Vec3(1.0f, 0.0f, 0.0f);
        joint.mNormalHalfConeAngle = inNormalHalfCone;
        joint.mPlaneHalfConeAngle = inPlaneHalfCone;
        joint.mTwistMinAngle = inTwistMin;
        joint.mTwistMaxAngle = inTwistMax;
        joint.mMaxFrictionTorque = inFriction;
        EXPECT_TRUE(Joints().AddSwingTwist(joint).IsOk());
        return limb;
    }
    /// The limb's end at the socket, where the joint holds it
    Vec3 SocketOf(const BodyID& inLimb)
    {
        return Position(inLimb) + Bodies().GetRotation(inLimb).Value() * Vec3(0.0f, 0.4f, 0.0f);
    }
    static inline const Vec3 cSocket = Vec3(0.0f, 3.0f, 0.0f);
};

TEST_F(SwingTwistJointTest, ALimbSwungPastItsConeStopsAtTheConesEdgeOnEachAxis)
{
    // Swung within the plane (about the normal axis z) the cone's plane half angle stops it, 0.3 rad; swung
    // towards the normal (about the plane axis x) the normal half angle, 0.6 rad. At 4 rad/s it would pass
    // either in a tenth of a second; the row starts once it is past, a step's travel (0.07 rad) at most
    for (const auto& [spin, halfAngle] :
         {std::pair(Vec3(0.0f, 0.0f, 4.0f), 0.3f), std::pair(Vec3(4.0f, 0.0f, 0.0f), 0.6f)})
    {
        ResetWorld(PhysicsSettings{});
        const BodyID limb = AddLimb(spin, 0.6f, 0.3f, -0.5f, 0.5f);
        float widest = 0.0f, gap = 0.0f;
        for (int step = 0; step < 60; ++step)
        {
            Step(1);
            const Vec3 down = Bodies().GetRotation(limb).Value() * Vec3(0.0f, -1.0f, 0.0f);
            widest = std::max(widest, std::acos(std::clamp(-down.y(), -1.0f, 1.0f)));
            gap = std::max(gap, (SocketOf(limb) - cSocket).norm());
        }
        EXPECT_LT(widest, halfAngle + 4.0f / 60.0f + 0.01f) << "half angle " << halfAngle;
        EXPECT_GT(widest, halfAngle - 0.05f) << "half angle " << halfAngle; // It did swing out to it
        // Stopped hard (its end at 3 m/s), the socket opens a few millimetres for a step or two; the position
        // rows close it
        EXPECT_LT(gap, 0.006f);
        EXPECT_LT((SocketOf(limb) - cSocket).norm(), 0.001f);
    }
}

TEST_F(SwingTwistJointTest, ALimbTwistedPastItsRangeStopsAtItsEnd)
{
    // Spun about its own axis at 5 rad/s (world +y: a twist of -5 about the limb's axis, which points down):
    // the twist's lower end, -0.2 rad, stops it
    const BodyID limb = AddLimb(Vec3(0.0f, 5.0f, 0.0f), 0.5f, 0.5f, -0.2f, 0.4f);
    float most = 0.0f;
    for (int step = 0; step < 60; ++step)
    {
        Step(1);
        const Vec3 across = Bodies().GetRotation(limb).Value() * Vec3::UnitX();
        most = std::max(most, std::atan2(-across.z(), across.x())); // The turn about world +y
    }
    EXPECT_LT(most, 0.2f + 5.0f / 60.0f + 0.01f);
    EXPECT_GT(most, 0.15f);
}

TEST_F(SwingTwistJointTest, WithinItsLimitsALimbSwingsAsAPendulumAndFrictionSlowsItsTwist)
{
    // A swing of 0.15 rad inside a cone of 0.6: a physical pendulum about the socket, I = m ((2h)^2 + w^2) /
    // 12 + m h^2 for a limb of half length h and width w, T = 2 pi sqrt(I / (m g h)) (1 + theta0^2 / 16)
    const float theta0 = 0.15f, h = 0.4f, w = 0.1f;
    BodyCreationSettings settings = DynamicSettings(
        Box(Vec3(0.05f, 0.4f, 0.05f)), cSocket + h * Vec3(std::sin(theta0), -std::cos(theta0), 0.0f));
    settings.mRotation = Quat(Eigen::AngleAxisf(theta0, Vec3::UnitZ()));
    settings.mLinearDamping = settings.mAngularDamping = 0.0f;
    settings.mAllowSleeping = false;
    const BodyID limb = AddDynamic(settings);
    SwingTwistConstraintSettings joint;
    joint.mBodyB = limb;
    joint.mPoint = cSocket;
    joint.mTwistAxis = Vec3(0.0f, -1.0f, 0.0f);
    joint.mPlaneAxis = Vec3(1.0f, 0.0f, 0.0f);
    joint.mNormalHalfConeAngle = joint.mPlaneHalfConeAngle = 0.6f;
    joint.mTwistMinAngle = -0.5f;
    joint.mTwistMaxAngle = 0.5f;
    ASSERT_TRUE(Joints().AddSwingTwist(joint).IsOk());
    std::vector<double> crossings;
    float previousX = Position(limb).x();
    for (int step = 1; step <= 240; ++step)
    {
        Step(1);
        const float x = Position(limb).x();
        if (previousX > 0.0f && x <= 0.0f)
            crossings.push_back((step - 1 + previousX / (previousX - x)) / 60.0);
        previousX = x;
    }
    ASSERT_GE(crossings.size(), 3u);
    const double measured = (crossings.back() - crossings.front()) / double(crossings.size() - 1);
    const double inertia = ((2.0 * h) * (2.0 * h) + w * w) / 12.0 + h * h; // Per unit mass
    const double expected =
        2.0 * std::numbers::pi * std::sqrt(inertia / (9.81 * h)) * (1.0 + theta0 * theta0 / 16.0);
    EXPECT_NEAR(measured, expected, 0.01 * expected);

    // Twisting at 3 rad/s with a wide range and a friction torque T: the spin drops by T t / I about the limb
    ResetWorld(PhysicsSettings{});
    const BodyID spinning = AddLimb(Vec3(0.0f, 3.0f, 0.0f), 0.5f, 0.5f, -std::numbers::pi_v<float>,
                                    std::numbers::pi_v<float>, 0.1f);
    Step(15);
    const float axial = 8.0f * (w * w + w * w) / 12.0f; // 8 kg about its long axis
    EXPECT_NEAR(Bodies().GetAngularVelocity(spinning).Value().y(), 3.0f - 0.1f * 0.25f / axial,
                0.02f * 0.1f * 0.25f / axial);
}

TEST_F(JointTest, BadInputGetsClearErrors)
{
    const BodyID bob = AddDynamic(DynamicSettings(Sphere(0.1f), Vec3(0.0f, 1.0f, 0.0f)));
    PointConstraintSettings settings;
    settings.mBodyA = bob;
    settings.mPoint = Vec3(std::nanf(""), 0.0f, 0.0f);
    EXPECT_EQ(Joints().AddPoint(settings).GetError().mCode, ErrorCode::InvalidArgument);
    settings.mPoint = Vec3(1.0e12f, 0.0f, 0.0f); // Beyond the world
    EXPECT_EQ(Joints().AddPoint(settings).GetError().mCode, ErrorCode::InvalidArgument);
    settings.mPoint = Vec3::Zero();
    settings.mBodyB = bob; // Itself
    EXPECT_EQ(Joints().AddPoint(settings).GetError().mCode, ErrorCode::InvalidArgument);
    settings.mBodyA = BodyID();
    settings.mBodyB = BodyID(); // The world to the world
    EXPECT_EQ(Joints().AddPoint(settings).GetError().mCode, ErrorCode::InvalidArgument);
    settings.mBodyB = BodyID(bob.GetIndex(), bob.GetSequence() + 1); // Stale
    EXPECT_EQ(Joints().AddPoint(settings).GetError().mCode, ErrorCode::InvalidBodyID);
    settings.mBodyB = BodyID(123456, 0); // Unknown
    EXPECT_EQ(Joints().AddPoint(settings).GetError().mCode, ErrorCode::InvalidBodyID);
    EXPECT_EQ(Joints().Remove(ConstraintID()).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_EQ(Joints().SetEnabled(ConstraintID(7, 1), true).GetError().mCode, ErrorCode::InvalidArgument);
    DistanceConstraintSettings distance;
    distance.mBodyB = bob;
    distance.mMinDistance = 2.0f;
    distance.mMaxDistance = 1.0f; // min > max
    EXPECT_EQ(Joints().AddDistance(distance).GetError().mCode, ErrorCode::InvalidArgument);
    distance.mMaxDistance = std::nanf("");
    EXPECT_EQ(Joints().AddDistance(distance).GetError().mCode, ErrorCode::InvalidArgument);
    distance.mMaxDistance = 3.0f;
    distance.mLimitsSpring.mFrequency = -1.0f;
    EXPECT_EQ(Joints().AddDistance(distance).GetError().mCode, ErrorCode::InvalidArgument);
    distance.mLimitsSpring = {1.0f, std::numeric_limits<float>::infinity()};
    EXPECT_EQ(Joints().AddDistance(distance).GetError().mCode, ErrorCode::InvalidArgument);
    distance.mLimitsSpring = {};
    distance.mPointA = Vec3(std::nanf(""), 0.0f, 0.0f);
    EXPECT_EQ(Joints().AddDistance(distance).GetError().mCode, ErrorCode::InvalidArgument);
    HingeConstraintSettings hinge;
    hinge.mBodyB = bob;
    hinge.mHingeAxis = Vec3::Zero();
    EXPECT_EQ(Joints().AddHinge(hinge).GetError().mCode, ErrorCode::InvalidArgument);
    hinge.mHingeAxis = Vec3(0.0f, 1.0f, 0.0f);
    hinge.mLimitsMin = 0.5f;
    hinge.mLimitsMax = 0.2f;
    EXPECT_EQ(Joints().AddHinge(hinge).GetError().mCode, ErrorCode::InvalidArgument);
    hinge.mLimitsMin = -4.0f; // Past -pi
    EXPECT_EQ(Joints().AddHinge(hinge).GetError().mCode, ErrorCode::InvalidArgument);
    hinge.mLimitsMin = -0.5f;
    hinge.mMotor.mMaxForce = -1.0f;
    EXPECT_EQ(Joints().AddHinge(hinge).GetError().mCode, ErrorCode::InvalidArgument);
    hinge.mMotor.mMaxForce = 1.0f;
    hinge.mMotor.mTargetVelocity = std::nanf("");
    EXPECT_EQ(Joints().AddHinge(hinge).GetError().mCode, ErrorCode::InvalidArgument);
    SliderConstraintSettings slider;
    slider.mBodyB = bob;
    slider.mSliderAxis = Vec3(std::nanf(""), 0.0f, 0.0f);
    EXPECT_EQ(Joints().AddSlider(slider).GetError().mCode, ErrorCode::InvalidArgument);
    slider.mSliderAxis = Vec3::Zero();
    EXPECT_EQ(Joints().AddSlider(slider).GetError().mCode, ErrorCode::InvalidArgument);
    slider.mSliderAxis = Vec3(1.0f, 0.0f, 0.0f);
    slider.mLimitsMin = 1.0f;
    slider.mLimitsMax = -1.0f;
    EXPECT_EQ(Joints().AddSlider(slider).GetError().mCode, ErrorCode::InvalidArgument);
    slider.mLimitsMax = std::nanf("");
    EXPECT_EQ(Joints().AddSlider(slider).GetError().mCode, ErrorCode::InvalidArgument);
    slider.mLimitsMax = 2.0f;
    slider.mMaxFrictionForce = -1.0f;
    EXPECT_EQ(Joints().AddSlider(slider).GetError().mCode, ErrorCode::InvalidArgument);
    slider.mMaxFrictionForce = 0.0f;
    slider.mMotor.mTargetVelocity = std::numeric_limits<float>::infinity();
    EXPECT_EQ(Joints().AddSlider(slider).GetError().mCode, ErrorCode::InvalidArgument);
    slider.mMotor.mTargetVelocity = 0.0f;
    slider.mMotor.mMode = MotorMode::Position;
    slider.mMotor.mSpring.mFrequency = 0.0f; // A position motor needs a spring
    EXPECT_EQ(Joints().AddSlider(slider).GetError().mCode, ErrorCode::InvalidArgument);
    hinge.mMotor = {MotorMode::Position, 0.0f, 4.0f, 1.0f, {}}; // A target angle past pi
    EXPECT_EQ(Joints().AddHinge(hinge).GetError().mCode, ErrorCode::InvalidArgument);
    hinge.mMotor = {static_cast<MotorMode>(7), 0.0f, 0.0f, 1.0f, {}};
    EXPECT_EQ(Joints().AddHinge(hinge).GetError().mCode, ErrorCode::InvalidArgument);
    SwingTwistConstraintSettings swingTwist;
    swingTwist.mBodyB = bob;
    swingTwist.mPlaneAxis = Vec3(1.0f, 0.1f, 0.0f); // Not across the twist axis
    EXPECT_EQ(Joints().AddSwingTwist(swingTwist).GetError().mCode, ErrorCode::InvalidArgument);
    swingTwist.mPlaneAxis = Vec3::Zero();
    EXPECT_EQ(Joints().AddSwingTwist(swingTwist).GetError().mCode, ErrorCode::InvalidArgument);
    swingTwist.mPlaneAxis = Vec3(0.0f, 1.0f, 0.0f);
    swingTwist.mNormalHalfConeAngle = -0.1f;
    EXPECT_EQ(Joints().AddSwingTwist(swingTwist).GetError().mCode, ErrorCode::InvalidArgument);
    swingTwist.mNormalHalfConeAngle = 0.5f;
    swingTwist.mPlaneHalfConeAngle = std::nanf("");
    EXPECT_EQ(Joints().AddSwingTwist(swingTwist).GetError().mCode, ErrorCode::InvalidArgument);
    swingTwist.mPlaneHalfConeAngle = 0.5f;
    swingTwist.mTwistMinAngle = 0.3f;
    swingTwist.mTwistMaxAngle = 0.1f;
    EXPECT_EQ(Joints().AddSwingTwist(swingTwist).GetError().mCode, ErrorCode::InvalidArgument);
    swingTwist.mTwistMinAngle = -4.0f;
    EXPECT_EQ(Joints().AddSwingTwist(swingTwist).GetError().mCode, ErrorCode::InvalidArgument);
    swingTwist.mTwistMinAngle = -0.1f;
    swingTwist.mMaxFrictionTorque = -1.0f;
    EXPECT_EQ(Joints().AddSwingTwist(swingTwist).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_EQ(Joints().GetNumConstraints().Value(), 0u);
    settings.mBodyA = BodyID();
    settings.mBodyB = bob;
    const Result<ConstraintID> point = Joints().AddPoint(settings);
    ASSERT_TRUE(point.IsOk());
    EXPECT_EQ(Joints().SetMotor(point.Value(), {}).GetError().mCode, ErrorCode::InvalidArgument); // No motor
    EXPECT_EQ(Joints().GetPosition(point.Value()).GetError().mCode, ErrorCode::InvalidArgument);
    hinge.mMotor = {};
    const Result<ConstraintID> door = Joints().AddHinge(hinge);
    ASSERT_TRUE(door.IsOk());
    EXPECT_EQ(Joints()
                  .SetMotor(door.Value(), {MotorMode::Velocity, std::nanf(""), 0.0f, 1.0f, {}})
                  .GetError()
                  .mCode,
              ErrorCode::InvalidArgument);
    ASSERT_TRUE(Joints().Remove(door.Value()).IsOk());
    EXPECT_EQ(Joints().SetMotor(door.Value(), {}).GetError().mCode, ErrorCode::InvalidArgument); // Stale
    EXPECT_EQ(Joints().GetPosition(door.Value()).GetError().mCode, ErrorCode::InvalidArgument);
    ASSERT_TRUE(Joints().Remove(point.Value()).IsOk());
    {
        // Holding a body lock: a joint call could wait for a step that waits for this lock
        const BodyLockRead lock(System().GetBodyManager(), bob);
        settings.mBodyB = bob;
        EXPECT_EQ(Joints().AddPoint(settings).GetError().mCode, ErrorCode::WrongThread);
        EXPECT_EQ(Joints().GetNumConstraints().GetError().mCode, ErrorCode::WrongThread);
    }
}

} // namespace
} // namespace cairn::test
