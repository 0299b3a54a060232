// Simple scenes against their analytic solutions, for 1, 2 and 4 collision steps per update: the checks a
// physics programmer runs first. Each tolerance is argued where it is set. Where the closed form is of the
// continuous motion, symplectic Euler's own error (first order in the step) is part of the tolerance; where a
// scalar reference integrator of the same scheme is the reference, only float rounding is.

#include "SimulationFixture.h"

#include <cmath>
#include <vector>

namespace cairn::test
{
using namespace cairn::physics;

namespace
{
constexpr float cGravity = 9.81f;

class AnalyticTest : public SimulationFixture, public ::testing::WithParamInterface<int>
{
protected:
    int CollisionSteps() const { return GetParam(); }
    /// The time one collision step covers.
    float StepTime() const { return cDeltaTime / float(CollisionSteps()); }
    void Update() { ASSERT_TRUE(UpdateWorld(cDeltaTime, CollisionSteps()).IsOk()); }
    /// A body that keeps its velocity but for what the test does: no damping, no sleep.
    static BodyCreationSettings Undamped(const ShapeRef& inShape, const Vec3& inPosition)
    {
        BodyCreationSettings settings = DynamicSettings(inShape, inPosition);
        settings.mLinearDamping = 0.0f;
        settings.mAngularDamping = 0.0f;
        settings.mAllowSleeping = false;
        return settings;
    }
    static float SphereMass(float inRadius)
    {
        return 1000.0f * 4.0f / 3.0f * cPi * inRadius * inRadius * inRadius;
    }
};

// Free fall from rest: the height after each update is symplectic Euler's, h(n) = h0 - g dt^2 n (n + 1) / 2
// over n collision steps of dt (float rounding only: 0.1 mm over the 2 s), and within g t dt / 2 (the
// scheme's lag behind the parabola) of h0 - g t^2 / 2
TEST_P(AnalyticTest, FreeFallFollowsTheParabola)
{
    const float start = 100.0f;
    const BodyID ball = AddDynamic(Undamped(Sphere(0.5f), Vec3(0, start, 0)));
    const float dt = StepTime();
    for (int update = 1; update <= 120; ++update)
    {
        Update();
        const float n = float(update * CollisionSteps());
        const float t = float(update) * cDeltaTime;
        const float height = Position(ball).y();
        ASSERT_NEAR(height, start - cGravity * dt * dt * n * (n + 1.0f) / 2.0f, 1.0e-4f)
            << "update " << update;
        ASSERT_NEAR(height, start - 0.5f * cGravity * t * t, 0.5f * cGravity * t * dt + 1.0e-4f);
        ASSERT_NEAR(Velocity(ball).y(), -cGravity * t, 1.0e-4f);
    }
}

// A force added before each update acts over the whole update, in every collision step: after 2 s of a
// constant 100 N on a body of mass m, v = 100 t / m exactly (the sum of equal steps: float rounding), and the
// position is the scalar reference integrator's
TEST_P(AnalyticTest, ConstantForceActsOverEveryCollisionStep)
{
    BodyCreationSettings settings = Undamped(Sphere(0.5f), Vec3::Zero());
    settings.mGravityFactor = 0.0f;
    const BodyID ball = AddDynamic(settings);
    const float mass = SphereMass(0.5f);
    const Vec3 force(100.0f, 0.0f, -50.0f);
    double referenceVelocity = 0.0, referencePosition = 0.0; // Along the force, per newton
    for (int update = 1; update <= 120; ++update)
    {
        ASSERT_TRUE(Bodies().AddForce(ball, force).IsOk());
        Update();
        for (int step = 0; step < CollisionSteps(); ++step)
        {
            referenceVelocity += double(StepTime()) / double(mass);
            referencePosition += referenceVelocity * double(StepTime());
        }
    }
    const Vec3 expectedVelocity = force * float(referenceVelocity);
    const Vec3 expectedPosition = force * float(referencePosition);
    EXPECT_LT((Velocity(ball) - expectedVelocity).norm(), 1.0e-4f * expectedVelocity.norm())
        << "velocity " << Velocity(ball).transpose() << ", expected " << expectedVelocity.transpose();
    EXPECT_LT((Position(ball) - expectedPosition).norm(), 1.0e-4f * expectedPosition.norm());
    // And the force is gone after the update it was added for
    const Vec3 before = Velocity(ball);
    Update();
    EXPECT_LT((Velocity(ball) - before).norm(), 1.0e-6f);
}

// A constant torque about a principal axis: w = T t / I, and the body turns about that axis by the scalar
// reference integrator's angle (theta += w dt after each velocity half). The rotation itself must be exact
// for each step's turn: the first-order quaternion update falls behind by w^3 dt^3 / 12 a step, which over
// the 2 s adds up to 2.5e-3 rad at 1 collision step and 1.6e-4 at 4; the tolerance is float rounding over up
// to 480 quaternion products
TEST_P(AnalyticTest, ConstantTorqueTurnsByTheExactAngle)
{
    const float radius = 0.5f;
    BodyCreationSettings settings = Undamped(Sphere(radius), Vec3::Zero());
    settings.mGravityFactor = 0.0f;
    const BodyID ball = AddDynamic(settings);
    const float inertia = 0.4f * SphereMass(radius) * radius * radius;
    const Vec3 axis = Vec3(1.0f, 2.0f, -2.0f).normalized();
    const float angularAcceleration = 3.0f; // rad/s^2
    double omega = 0.0, angle = 0.0;
    for (int update = 1; update <= 120; ++update)
    {
        ASSERT_TRUE(Bodies().AddTorque(ball, inertia * angularAcceleration * axis).IsOk());
        Update();
        for (int step = 0; step < CollisionSteps(); ++step)
        {
            omega += double(angularAcceleration) * double(StepTime());
            angle += omega * double(StepTime());
        }
    }
    EXPECT_NEAR(Bodies().GetAngularVelocity(ball).Value().dot(axis), float(omega), 1.0e-4f);
    const Quat expected(Eigen::AngleAxisf(float(angle), axis));
    const float error = Bodies().GetRotation(ball).Value().angularDistance(expected);
    EXPECT_LT(error, 5.0e-5f) << "turned " << angle << " rad";
}

/// Drops a sphere of the given restitution from inHeight (its lowest point above the floor) and returns the
/// heights of its first inBounces apexes (its lowest point above the floor at the highest sample of each arc
/// after a bounce), with the speeds just before and after each bounce.
class AnalyticBounceTest : public AnalyticTest
{
public:
    std::vector<float> Apexes(float inRestitution, float inHeight, int inBounces,
                              std::vector<float>* outImpacts = nullptr,
                              std::vector<float>* outRebounds = nullptr)
    {
        AddFloor();
        const float radius = 0.5f;
        BodyCreationSettings settings = Undamped(Sphere(radius), Vec3(0, inHeight + radius, 0));
        settings.mRestitution = inRestitution;
        const BodyID ball = AddDynamic(settings);
        std::vector<float> apexes;
        float apex = 0.0f, previousVy = 0.0f;
        bool rising = false;
        const int maxUpdates = 60 * 60;
        for (int update = 0; update < maxUpdates && int(apexes.size()) < inBounces; ++update)
        {
            Update();
            const float vy = Velocity(ball).y();
            const float height = Position(ball).y() - radius;
            if (!rising && vy > 0.0f)
            {
                rising = true;
                apex = height;
                if (outImpacts != nullptr) outImpacts->push_back(-previousVy);
                if (outRebounds != nullptr) outRebounds->push_back(vy);
            }
            if (rising) apex = std::max(apex, height);
            if (rising && vy < 0.0f)
            {
                rising = false;
                apexes.push_back(apex);
            }
            previousVy = vy;
        }
        return apexes;
    }
};

// Restitution 1 from 5 m: every apex over 20 bounces within 1 mm of the start. Symplectic Euler's positions
// lie on a parabola whose top is g dt^2 / 8 (0.34 mm at 60 Hz) above its highest sample, so the samples of
// one arc and the next may differ by that much; no bounce may add or lose height, which the impact step's
// gravity in the rebound did (+0.16 m a bounce)
TEST_P(AnalyticBounceTest, ElasticBounceKeepsItsHeight)
{
    const float start = 5.0f;
    std::vector<float> impacts, rebounds;
    const std::vector<float> apexes = Apexes(1.0f, start, 20, &impacts, &rebounds);
    ASSERT_EQ(apexes.size(), 20u);
    for (size_t i = 0; i < apexes.size(); ++i)
        EXPECT_NEAR(apexes[i], start, 1.0e-3f) << "bounce " << i;
    // The rebound speed is the impact speed: the speed before the impact step and after it are the two
    // samples of one parabola mirrored about the bounce, g dt apart at most
    for (size_t i = 0; i < impacts.size(); ++i)
        EXPECT_NEAR(rebounds[i], impacts[i], cGravity * StepTime() * float(CollisionSteps()) + 1.0e-3f);
}

// Restitution 0.9: each rebound is 0.9 times the impact speed, so the n-th apex is 0.81^n times the drop
// height (measured from the modified parabola's top, g dt^2 / 8 above the start sample). Tolerance: that
// sampling, g dt^2 / 8, plus 1 mm; the apexes came out 0.18-0.28 m high when bounces started from the top of
// the gap with the impact step's gravity in them
TEST_P(AnalyticBounceTest, PartialRestitutionFollowsTheGeometricSequence)
{
    const float start = 5.0f, e = 0.9f;
    const float dt = cDeltaTime; // Sampled per update
    const float top = start + cGravity * StepTime() * StepTime() / 8.0f;
    const std::vector<float> apexes = Apexes(e, start, 10);
    ASSERT_EQ(apexes.size(), 10u);
    float expected = top;
    for (size_t i = 0; i < apexes.size(); ++i)
    {
        expected *= e * e;
        EXPECT_NEAR(apexes[i], expected, cGravity * dt * dt / 8.0f + 1.0e-3f) << "bounce " << i + 1;
    }
}

// Two spheres meet head on in free space, restitution 1: the 1D elastic collision's velocities,
// v1' = ((m1 - e m2) v1 + (1 + e) m2 v2) / (m1 + m2) and its mirror; one contact point, solved exactly (float
// rounding: 1e-4 relative)
TEST_P(AnalyticTest, ElasticHeadOnCollisionExchangesMomentum)
{
    const float r1 = 0.5f, r2 = 0.35f;
    BodyCreationSettings a = Undamped(Sphere(r1), Vec3(-2.0f, 0, 0));
    BodyCreationSettings b = Undamped(Sphere(r2), Vec3(2.0f, 0, 0));
    for (BodyCreationSettings* settings : {&a, &b})
    {
        settings->mGravityFactor = 0.0f;
        settings->mRestitution = 1.0f;
        settings->mFriction = 0.0f;
    }
    const float v1 = 6.0f, v2 = -3.0f;
    a.mLinearVelocity = Vec3(v1, 0, 0);
    b.mLinearVelocity = Vec3(v2, 0, 0);
    const BodyID first = AddDynamic(a), second = AddDynamic(b);
    const float m1 = SphereMass(r1), m2 = SphereMass(r2);
    for (int update = 0; update < 60; ++update)
        Update();
    const float expected1 = ((m1 - m2) * v1 + 2.0f * m2 * v2) / (m1 + m2);
    const float expected2 = ((m2 - m1) * v2 + 2.0f * m1 * v1) / (m1 + m2);
    EXPECT_NEAR(Velocity(first).x(), expected1, 1.0e-4f * std::abs(v1));
    EXPECT_NEAR(Velocity(second).x(), expected2, 1.0e-4f * std::abs(v1));
    EXPECT_LT(Velocity(first).tail<2>().norm() + Velocity(second).tail<2>().norm(), 1.0e-5f);
}

// A box thrown along the floor at 5 m/s, friction 0.5: Coulomb friction decelerates it by mu g until it
// stops, after v0^2 / (2 mu g) = 2.55 m. The reference integrator runs the same scheme (v -= mu g dt,
// stopping at 0; x += v dt); the tolerance, 1 cm, is for the first contact step's impulses before the normal
// load is settled, and it turns no more than 1 degree
TEST_P(AnalyticTest, BoxSlidesToAStopAtTheCoulombDistance)
{
    AddFloor(0.5f);
    BodyCreationSettings settings = Undamped(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 0.5f, 0));
    settings.mFriction = 0.5f;
    const float v0 = 5.0f;
    settings.mLinearVelocity = Vec3(v0, 0, 0);
    const BodyID box = AddDynamic(settings);
    const float mu = 0.5f; // sqrt(0.5 * 0.5)
    double velocity = v0, distance = 0.0;
    for (int update = 0; update < 120; ++update)
    {
        Update();
        for (int step = 0; step < CollisionSteps(); ++step)
        {
            velocity = std::max(0.0, velocity - double(mu * cGravity * StepTime()));
            distance += velocity * double(StepTime());
        }
    }
    EXPECT_NEAR(Position(box).x(), float(distance), 0.01f);
    EXPECT_NEAR(float(distance), v0 * v0 / (2.0f * mu * cGravity), v0 * StepTime());
    EXPECT_LT(Velocity(box).norm(), 1.0e-3f);
    EXPECT_LT(Bodies().GetRotation(box).Value().angularDistance(Quat::Identity()), cPi / 180.0f);
}

// A 30-degree slope. Friction 0.7 > tan 30 (0.577): the box stays, within 1 mm over 2 s. Friction 0.3: it
// slides with g (sin 30 - mu cos 30) = 2.36 m/s^2; measured over 1 s of sliding, the velocity change is exact
// for the scheme but for the first contact step, so 1 % holds
class AnalyticSlopeTest : public AnalyticTest
{
public:
    BodyID BoxOnSlope(float inFriction)
    {
        const Quat tilt(Eigen::AngleAxisf(cSlope, Vec3::UnitZ()));
        AddStatic(Box(Vec3(30, 0.5f, 5)), Vec3::Zero(), tilt, inFriction);
        BodyCreationSettings settings = Undamped(Box(Vec3(0.5f, 0.5f, 0.5f)), tilt * Vec3(0, 1.0f, 0));
        settings.mRotation = tilt;
        settings.mFriction = inFriction;
        return AddDynamic(settings);
    }
    static constexpr float cSlope = 30.0f * cPi / 180.0f;
};

TEST_P(AnalyticSlopeTest, BoxRestsWhereFrictionIsEnough)
{
    const BodyID box = BoxOnSlope(0.7f);
    for (int update = 0; update < 30; ++update)
        Update();
    const Vec3 start = Position(box);
    for (int update = 0; update < 120; ++update)
        Update();
    EXPECT_LT((Position(box) - start).norm(), 1.0e-3f);
}

TEST_P(AnalyticSlopeTest, BoxSlidesWithTheCoulombAcceleration)
{
    const float mu = 0.3f;
    const BodyID box = BoxOnSlope(mu);
    const Vec3 downSlope = Quat(Eigen::AngleAxisf(cSlope, Vec3::UnitZ())) * Vec3(-1, 0, 0);
    for (int update = 0; update < 30; ++update)
        Update();
    const float before = Velocity(box).dot(downSlope);
    for (int update = 0; update < 60; ++update)
        Update();
    const float measured = (Velocity(box).dot(downSlope) - before) / (60.0f * cDeltaTime);
    const float expected = cGravity * (std::sin(cSlope) - mu * std::cos(cSlope));
    EXPECT_NEAR(measured, expected, 0.01f * expected);
}

// Friction on the angular motion: a sphere thrown sliding without spin is slowed and spun up by friction
// until it rolls, at 5/7 of its speed (the classic result: the friction impulse takes 2/7 of the momentum and
// gives the matching spin), after 2 v0 / (7 mu g); then it rolls on at that speed, w r = v. The tolerance,
// 0.5 %, covers the step in which sliding ends (the last friction step overshoots rolling by at most mu g dt)
TEST_P(AnalyticTest, SlidingSphereEndsUpRollingAtFiveSevenths)
{
    AddFloor(0.3f);
    const float radius = 0.5f, v0 = 5.0f;
    BodyCreationSettings settings = Undamped(Sphere(radius), Vec3(0, radius, 0));
    settings.mFriction = 0.3f;
    settings.mLinearVelocity = Vec3(v0, 0, 0);
    const BodyID ball = AddDynamic(settings);
    for (int update = 0; update < 90; ++update) // 1.5 s; rolling starts after 0.49 s
        Update();
    const float v = Velocity(ball).x();
    const float spin = -Bodies().GetAngularVelocity(ball).Value().z(); // Rolling along +x turns about -z
    EXPECT_NEAR(v, 5.0f / 7.0f * v0, 0.005f * v0);
    EXPECT_NEAR(spin * radius, v, 0.005f * v0) << "not rolling";
}

// A body added with a high speed finds its pairs in its first step: a box falling at 60 m/s, 1.8 cm above the
// floor, stops on it. Before the broad phase held the swept box of a new body, it found no pair in its first
// step and ended 0.98 m inside the floor. The same for a body moved by hand and one whose velocity is set by
// hand (0.1 m up, at rest, then 60 m/s down: even a quarter step goes 0.25 m). Tolerance: the penetration
// slop (5 mm) and the position iterations' remainder
class AnalyticFirstStepTest : public AnalyticTest
{
public:
    float LowestPointAfterOneUpdate(BodyID inBox)
    {
        Update();
        return Position(inBox).y() - 0.5f;
    }
};

TEST_P(AnalyticFirstStepTest, FastBodyJustAddedStopsOnTheFloor)
{
    AddFloor();
    BodyCreationSettings settings = Undamped(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 0.518f, 0));
    settings.mLinearVelocity = Vec3(0, -60.0f, 0);
    const BodyID box = AddDynamic(settings);
    EXPECT_GT(LowestPointAfterOneUpdate(box), -0.01f);
    EXPECT_GT(LowestPointAfterOneUpdate(box), -0.01f);
}

TEST_P(AnalyticFirstStepTest, FastBodyMovedByHandStopsOnTheFloor)
{
    AddFloor();
    BodyCreationSettings settings = Undamped(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(20, 10, 0));
    settings.mLinearVelocity = Vec3(0, -60.0f, 0);
    settings.mGravityFactor = 0.0f;
    const BodyID box = AddDynamic(settings);
    Update(); // Far above: its box from this step's finish reaches 1 m down, nowhere near the floor
    ASSERT_TRUE(Bodies().SetPosition(box, Vec3(0, 0.518f, 0), Activation::Activate).IsOk());
    EXPECT_GT(LowestPointAfterOneUpdate(box), -0.01f);
}

TEST_P(AnalyticFirstStepTest, VelocitySetByHandIsSweptAtOnce)
{
    AddFloor();
    BodyCreationSettings settings = Undamped(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 0.6f, 0));
    settings.mGravityFactor = 0.0f;
    const BodyID box = AddDynamic(settings);
    Update(); // At rest, 0.1 m up: its box reaches the speculative distance past it, 2 cm
    ASSERT_TRUE(Bodies().SetLinearVelocity(box, Vec3(0, -60.0f, 0)).IsOk());
    EXPECT_GT(LowestPointAfterOneUpdate(box), -0.01f);
}

std::string StepsName(const ::testing::TestParamInfo<int>& inInfo)
{
    return std::to_string(inInfo.param) + "CollisionSteps";
}

INSTANTIATE_TEST_SUITE_P(CollisionSteps, AnalyticTest, ::testing::Values(1, 2, 4), StepsName);
INSTANTIATE_TEST_SUITE_P(CollisionSteps, AnalyticBounceTest, ::testing::Values(1, 2, 4), StepsName);
INSTANTIATE_TEST_SUITE_P(CollisionSteps, AnalyticSlopeTest, ::testing::Values(1, 2, 4), StepsName);
INSTANTIATE_TEST_SUITE_P(CollisionSteps, AnalyticFirstStepTest, ::testing::Values(1, 2, 4), StepsName);

} // namespace
} // namespace cairn::test
