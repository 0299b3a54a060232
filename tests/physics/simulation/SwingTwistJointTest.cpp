// The swing-twist joint (issue 33): a limb stopped at its elliptic cone's edge on each axis and at its twist
// range's end; inside its limits a pendulum with the analytic period; friction slowing its twist.

#include "JointFixture.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace cairn::test
{
namespace
{

class SwingTwistJointTest : public JointTest
{
protected:
    /// An 8 kg limb (0.1 x 0.8 x 0.1 m) hanging from a socket at (0, 3, 0) on the world, its twist axis down
    /// the limb, its plane axis x (so the normal axis is z), swung inTilt about z from hanging straight and
    /// started turning at inSpin; undamped, awake
    BodyID AddLimb(const Vec3& inSpin, float inNormalHalfCone, float inPlaneHalfCone, float inTwistMin,
                   float inTwistMax, float inFriction = 0.0f, float inTilt = 0.0f)
    {
        const Quat tilt(Eigen::AngleAxisf(inTilt, Vec3::UnitZ()));
        BodyCreationSettings settings =
            DynamicSettings(Box(Vec3(0.05f, 0.4f, 0.05f)), cSocket + tilt * Vec3(0.0f, -0.4f, 0.0f));
        settings.mRotation = tilt;
        settings.mLinearDamping = settings.mAngularDamping = 0.0f;
        settings.mAngularVelocity = inSpin;
        settings.mLinearVelocity = inSpin.cross(tilt * Vec3(0.0f, -0.4f, 0.0f)); // The socket still
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
    const BodyID limb = AddLimb(Vec3::Zero(), 0.6f, 0.6f, -0.5f, 0.5f, 0.0f, theta0);
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

} // namespace
} // namespace cairn::test
