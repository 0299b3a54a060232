// Ragdolls (issue 33): a humanoid made in one call (its bodies in one batch, its joints, its group) and taken
// away whole; dropped on a height field it comes to rest without jitter (the 0.05 m/s after 3 s),
// joints held; a pile of ragdolls the same for any thread count; bad descriptions refused with nothing left
// behind.

#include "JointFixture.h"
#include "cairn/physics/ragdoll/HumanoidRagdoll.h"
#include "cairn/physics/shapes/HeightFieldShape.h"
#include "common/StaticFloor.h"

#include <cmath>
#include <optional>

namespace cairn::test
{
namespace
{

class RagdollTest : public JointTest
{
protected:
    /// A rolling height field 40 m square round the origin: gentle waves, 0.3 m high
    void AddRollingGround()
    {
        const uint32_t samples = 41;
        std::vector<float> heights(samples * samples);
        for (uint32_t z = 0; z < samples; ++z)
            for (uint32_t x = 0; x < samples; ++x)
                heights[x + z * samples] = 0.15f * std::sin(0.5f * float(x)) * std::cos(0.4f * float(z));
        AddStatic(HeightFieldShape::Create(samples, samples, 1.0f, heights).Value(),
                  Vec3(-20.0f, 0.0f, -20.0f));
    }
    /// The largest distance between the two anchors of any of the ragdoll's joints, from the bodies' poses
    float WorstJointGap(const Ragdoll& inRagdoll, const RagdollSettings& inSettings, const Vec3& inPosition,
                        const Quat& inRotation)
    {
        float worst = 0.0f;
        for (size_t part = 1; part < inSettings.mParts.size(); ++part)
        {
            // The joint point in each body's frame at creation, then where each body has taken it
            const Vec3 point = inRotation * inSettings.mParts[part].mJoint.mPoint + inPosition;
            auto carried = [&](size_t inPart)
            {
                const BodyCreationSettings& made = inSettings.mParts[inPart].mBody;
                const Vec3 madeAt = inRotation * made.mPosition + inPosition;
                const Quat madeRotation = inRotation * made.mRotation;
                const BodyID id = inRagdoll.GetBodies()[inPart];
                const Vec3 local = madeRotation.conjugate() * (point - madeAt);
                return Vec3(Bodies().GetPosition(id).Value() + Bodies().GetRotation(id).Value() * local);
            };
            worst =
                std::max(worst, (carried(part) - carried(size_t(inSettings.mParts[part].mParent))).norm());
        }
        return worst;
    }
};

TEST_F(RagdollTest, AHumanoidIsMadeInOneCallAndTakenAwayWhole)
{
    const RagdollSettings humanoid = MakeHumanoidRagdoll();
    ASSERT_EQ(humanoid.mParts.size(), 23u);
    Result<Ragdoll> ragdoll = Ragdoll::Create(System(), humanoid, Vec3(0.0f, 1.0f, 0.0f), Quat::Identity(), 1,
                                              Activation::Activate);
    ASSERT_TRUE(ragdoll.IsOk()) << ragdoll.GetError().mMessage;
    EXPECT_EQ(ragdoll.Value().GetBodies().size(), 23u);
    EXPECT_EQ(Joints().GetNumConstraints().Value(), 22u);
    for (const BodyID& id : ragdoll.Value().GetBodies())
        EXPECT_TRUE(Bodies().IsActive(id).Value());
    ASSERT_TRUE(ragdoll.Value().Destroy(System()).IsOk());
    EXPECT_EQ(Joints().GetNumConstraints().Value(), 0u);
    EXPECT_EQ(System().GetBodyManager().GetNumBodies(), 0u);
}

TEST_F(RagdollTest, DroppedOnAHeightFieldItComesToRestWithoutJitterAndHoldsTogether)
{
    AddRollingGround();
    const RagdollSettings humanoid = MakeHumanoidRagdoll();
    // Lying face down a metre up, turned about y, falling
    const Vec3 position(0.3f, 1.2f, -0.4f);
    const Quat rotation = Quat(Eigen::AngleAxisf(0.7f, Vec3::UnitY())) *
                          Quat(Eigen::AngleAxisf(-0.5f * std::numbers::pi_v<float>, Vec3::UnitX()));
    Result<Ragdoll> ragdoll =
        Ragdoll::Create(System(), humanoid, position, rotation, 1, Activation::Activate);
    ASSERT_TRUE(ragdoll.IsOk()) << ragdoll.GetError().mMessage;
    float worstGap = 0.0f;
    for (int step = 0; step < 180; ++step)
    {
        Step(1);
        worstGap = std::max(worstGap, WorstJointGap(ragdoll.Value(), humanoid, position, rotation));
    }
    // Three seconds after the drop: nothing moves faster than the 0.05 m/s
    float fastest = 0.0f;
    for (const BodyID& id : ragdoll.Value().GetBodies())
    {
        fastest = std::max(fastest, Bodies().GetLinearVelocity(id).Value().norm());
        EXPECT_GT(Bodies().GetPosition(id).Value().y(), -0.2f); // On the ground, not through it
    }
    EXPECT_LT(fastest, 0.05f);
    for (const BodyID& id : ragdoll.Value().GetBodies()) // A jittering body never falls asleep
        EXPECT_FALSE(Bodies().IsActive(id).Value());
    EXPECT_LT(worstGap, 0.02f); // The joints held through the landing
}

TEST_F(RagdollTest, APileOfRagdollsIsTheSameForAnyThreadCount)
{
    // Six ragdolls dropped onto each other: joints, contacts between ragdolls and with the floor, one island.
    // It is the whole step's work, so it is colored, its joints with its contacts, and every thread solves
    // parts of each color
    uint32_t coloredSteps = 0;
    auto run = [&](jobs::JobSystem* ioJobs)
    {
        std::unique_ptr<PhysicsSystem> system = MakePhysicsSystem();
        (void)system->GetBodyInterface().CreateAndAddBody(StaticFloorSettings(20.0f),
                                                          Activation::DontActivate);
        const RagdollSettings humanoid = MakeHumanoidRagdoll();
        std::vector<BodyID> bodies;
        for (uint32_t i = 0; i < 6; ++i)
        {
            const Quat lying = Quat(Eigen::AngleAxisf(0.9f * float(i), Vec3::UnitY())) *
                               Quat(Eigen::AngleAxisf(0.5f * std::numbers::pi_v<float>, Vec3::UnitZ()));
            Result<Ragdoll> ragdoll =
                Ragdoll::Create(*system, humanoid, Vec3(0.1f * float(i), 0.5f + 0.45f * float(i), 0.0f),
                                lying, i + 1, Activation::Activate);
            EXPECT_TRUE(ragdoll.IsOk());
            if (ragdoll)
                bodies.insert(bodies.end(), ragdoll.Value().GetBodies().begin(),
                              ragdoll.Value().GetBodies().end());
        }
        coloredSteps = 0;
        for (int step = 0; step < 120; ++step)
        {
            EXPECT_TRUE(
                (ioJobs != nullptr ? system->Update(1.0f / 60.0f, 1, *ioJobs) : system->Update(1.0f / 60.0f))
                    .IsOk());
            coloredSteps += system->GetLastStepStatistics().mNumColoredIslands > 0 ? 1 : 0;
        }
        std::vector<Vec3> positions;
        for (const BodyID& id : bodies)
            positions.push_back(system->GetBodyInterface().GetPosition(id).Value());
        return positions;
    };
    const std::vector<Vec3> alone = run(nullptr);
    ASSERT_EQ(alone.size(), 6u * 23u);
    EXPECT_GT(coloredSteps, 60u); // Once the pile is one island
    for (uint32_t threads : {1u, 2u, 4u})
    {
        jobs::JobSystem::Settings settings;
        settings.mNumThreads = threads;
        jobs::JobSystem jobSystem(settings);
        const std::vector<Vec3> withJobs = run(&jobSystem);
        ASSERT_EQ(withJobs.size(), alone.size());
        for (size_t i = 0; i < alone.size(); ++i)
            ASSERT_EQ(withJobs[i], alone[i]) << threads << " threads, body " << i;
        EXPECT_GT(coloredSteps, 60u);
    }
}

TEST_F(RagdollTest, BadDescriptionsAreRefusedWithNothingLeftBehind)
{
    const RagdollSettings humanoid = MakeHumanoidRagdoll();
    auto refused = [&](const RagdollSettings& inSettings, const Vec3& inPosition, uint32_t inGroup)
    {
        const Result<Ragdoll> ragdoll = Ragdoll::Create(System(), inSettings, inPosition, Quat::Identity(),
                                                        inGroup, Activation::Activate);
        EXPECT_EQ(System().GetBodyManager().GetNumBodies(), 0u);
        EXPECT_EQ(Joints().GetNumConstraints().Value(), 0u);
        return ragdoll.IsOk() ? std::optional<ErrorCode>() : ragdoll.GetError().mCode;
    };
    EXPECT_EQ(refused(RagdollSettings{}, Vec3::Zero(), 1), ErrorCode::InvalidArgument); // No parts
    RagdollSettings broken = humanoid;
    broken.mParts[5].mParent = 9; // Not an earlier part
    EXPECT_EQ(refused(broken, Vec3::Zero(), 1), ErrorCode::InvalidArgument);
    broken = humanoid;
    broken.mParts[0].mParent = 0; // No root
    EXPECT_EQ(refused(broken, Vec3::Zero(), 1), ErrorCode::InvalidArgument);
    EXPECT_EQ(refused(humanoid, Vec3(std::nanf(""), 0.0f, 0.0f), 1), ErrorCode::InvalidArgument);
    EXPECT_EQ(refused(humanoid, Vec3::Zero(), CollisionGroup::cNoGroup), ErrorCode::InvalidArgument);
    broken = humanoid;
    broken.mParts[7].mBody.mShape = nullptr; // A part no body can be made of: the first seven are taken back
    EXPECT_EQ(refused(broken, Vec3::Zero(), 1), ErrorCode::InvalidArgument);
    broken = humanoid;
    broken.mParts[20].mJoint.mTwistMinAngle = 1.0f; // A joint refused after the bodies are in the world
    broken.mParts[20].mJoint.mTwistMaxAngle = -1.0f;
    EXPECT_EQ(refused(broken, Vec3::Zero(), 1), ErrorCode::InvalidArgument);
    broken = humanoid;
    broken.mParts.resize(RagdollSettings::cMaxParts + 1, humanoid.mParts[1]);
    EXPECT_EQ(refused(broken, Vec3::Zero(), 1), ErrorCode::InvalidArgument);
}

} // namespace
} // namespace cairn::test
