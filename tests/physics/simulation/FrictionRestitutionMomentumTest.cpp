#include "SimulationFixture.h"

namespace cairn::test
{
using namespace cairn::physics;

class FrictionTest : public SimulationFixture
{
protected:
    /// A 30-degree slope (a static box rotated about z) and a box resting on it; returns the box.
    BodyID MakeSlopeScene(float inFriction)
    {
        const float angle = cSlopeAngle;
        const Quat tilt(Eigen::AngleAxisf(angle, Vec3::UnitZ()));
        AddStatic(Box(Vec3(30, 0.5f, 5)), Vec3(0, 0, 0), tilt, inFriction);
        // Up the slope's surface normal by the slab's half thickness plus the box's
        const Vec3 normal = tilt * Vec3::UnitY();
        BodyCreationSettings settings = DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), normal * 1.0f);
        settings.mRotation = tilt;
        settings.mFriction = inFriction;
        settings.mLinearDamping = 0.0f;
        settings.mAngularDamping = 0.0f;
        settings.mAllowSleeping = false;
        return AddDynamic(settings);
    }

    static constexpr float cSlopeAngle = 30.0f * cPi / 180.0f;
};

TEST_F(FrictionTest, BoxStaysOnSlopeWithHighFriction)
{
    const BodyID box = MakeSlopeScene(1.0f);
    Step(30); // settle
    const Vec3 start = Position(box);
    Step(120);
    EXPECT_LT((Position(box) - start).norm(), 0.01f);
}

TEST_F(FrictionTest, BoxSlidesWithCoulombAcceleration)
{
    const float mu = 0.2f;
    const BodyID box = MakeSlopeScene(mu);
    const Vec3 downSlope = Quat(Eigen::AngleAxisf(cSlopeAngle, Vec3::UnitZ())) * Vec3(-1, 0, 0);
    Step(30);
    const float v1 = Velocity(box).dot(downSlope);
    Step(60);
    const float v2 = Velocity(box).dot(downSlope);
    const float measured = (v2 - v1) / (60 * cDeltaTime);
    const float expected = 9.81f * (std::sin(cSlopeAngle) - mu * std::cos(cSlopeAngle));
    EXPECT_NEAR(measured, expected, 0.05f * expected);
}

using RestitutionTest = SimulationFixture;

TEST_F(RestitutionTest, SphereBouncesToRestitutionSquaredHeight)
{
    AddFloor();
    const float radius = 0.25f;
    BodyCreationSettings settings = DynamicSettings(Sphere(radius), Vec3(0, 1.0f + radius, 0));
    settings.mRestitution = 0.8f;
    settings.mLinearDamping = 0.0f;
    const BodyID sphere = AddDynamic(settings);

    bool bounced = false;
    float apex = 0.0f;
    for (int i = 0; i < 120; ++i)
    {
        Step(1);
        const float vy = Velocity(sphere).y();
        bounced |= vy > 0.0f;
        if (bounced) apex = std::max(apex, Position(sphere).y() - radius);
        if (bounced && vy < 0.0f) break;
    }
    ASSERT_TRUE(bounced);
    EXPECT_NEAR(apex, 0.64f, 0.05f * 0.64f);
}

TEST_F(RestitutionTest, ZeroRestitutionDoesNotBounce)
{
    AddFloor();
    BodyCreationSettings settings = DynamicSettings(Sphere(0.25f), Vec3(0, 1.25f, 0));
    settings.mLinearDamping = 0.0f;
    const BodyID sphere = AddDynamic(settings);
    // Fall until the sphere has stopped on the floor, then it must not rise again
    int frame = 0;
    while (frame < 120 && Velocity(sphere).y() < -0.1f)
    {
        Step(1);
        ++frame;
    }
    ASSERT_LT(frame, 120) << "the sphere never landed";
    const float landed = Position(sphere).y();
    float highest = landed;
    for (int i = 0; i < 60; ++i)
    {
        Step(1);
        highest = std::max(highest, Position(sphere).y());
    }
    EXPECT_LT(highest - landed, 0.005f);
    EXPECT_NEAR(Position(sphere).y(), 0.25f, 0.006f);
}

using MomentumTest = SimulationFixture;

TEST_F(MomentumTest, HeadOnCollisionKeepsLinearMomentum)
{
    PhysicsSettings settings;
    settings.mGravity = Vec3::Zero();
    // The heavy sphere leaves at a few mm/s: asleep, its velocity (and momentum) would be zeroed
    settings.mAllowSleeping = false;
    ResetWorld(settings);
    BodyCreationSettings a = DynamicSettings(Sphere(0.5f), Vec3(-2, 0, 0));
    a.mLinearVelocity = Vec3(3, 0, 0);
    a.mLinearDamping = 0.0f;
    BodyCreationSettings b = DynamicSettings(Sphere(0.7f), Vec3(2, 0, 0));
    b.mLinearVelocity = Vec3(-2, 0, 0);
    b.mLinearDamping = 0.0f;
    b.mRestitution = 0.5f;
    const BodyID idA = AddDynamic(a);
    const BodyID idB = AddDynamic(b);
    const float massA = 1000.0f * 4.0f / 3.0f * cPi * 0.125f;
    const float massB = 1000.0f * 4.0f / 3.0f * cPi * 0.343f;
    const Vec3 before = massA * a.mLinearVelocity + massB * b.mLinearVelocity;

    Step(120);
    const Vec3 after = massA * Velocity(idA) + massB * Velocity(idB);
    EXPECT_LT(Velocity(idA).x(), 0.0f) << "the light sphere should bounce back";
    EXPECT_LE((after - before).norm(), 1.0e-4f * before.norm());
}

} // namespace cairn::test
