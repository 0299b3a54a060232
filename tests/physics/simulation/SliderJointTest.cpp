// The slider joint (issue 33): a box sliding down its axis against the analytic slide and stopped by its
// limit; a motor within its force and friction against theirs; a position motor's sag under a load; a piston
// keeping momentum; a spinning body carrying its slider's line round.

#include "JointFixture.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace cairn::test
{
namespace
{

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

} // namespace
} // namespace cairn::test
