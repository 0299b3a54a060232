// Settings and layer setups out of range are refused by PhysicsSystem::Create with an error naming the field,
// never used: before these checks, an object layer past the 64-entry tables was written out of bounds in
// Release builds, and NaN gravity or a negative speculative distance silently broke every step. Create is the
// only way to a world, so no world is built from a setup it refused (a constructor once built one on the
// defaults instead, which only failed at its first Update).

#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/shapes/SphereShape.h"

#include <gtest/gtest.h>
#include <limits>
#include <string>

namespace cairn::test
{
using namespace cairn::physics;
namespace
{

/// The error of creating a world with inSettings and the default layers (empty when it was created).
std::string CreateError(const PhysicsSettings& inSettings)
{
    Result<std::unique_ptr<PhysicsSystem>> system = PhysicsSystem::Create(inSettings);
    if (system.IsOk()) return "";
    EXPECT_EQ(system.GetError().mCode, ErrorCode::InvalidArgument);
    return system.GetError().mMessage;
}

} // namespace

TEST(SetupValidationTest, TheDefaultsAreValid)
{
    EXPECT_TRUE(ValidateSettings(PhysicsSettings{}).IsOk());
    EXPECT_TRUE(LayerSetup::CreateDefault().GetStatus().IsOk());
    Result<std::unique_ptr<PhysicsSystem>> system = PhysicsSystem::Create();
    ASSERT_TRUE(system.IsOk());
    EXPECT_TRUE(system.Value()->Update(1.0f / 60.0f).IsOk());
}

TEST(SetupValidationTest, EachSettingOutOfRangeIsNamed)
{
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    struct Case
    {
        const char* mField;
        void (*mBreak)(PhysicsSettings&, float, float);
    };
    const Case cases[] = {
        {"mMaxBodies", [](PhysicsSettings& s, float, float) { s.mMaxBodies = 0; }},
        {"mMaxBodies",
         [](PhysicsSettings& s, float, float) { s.mMaxBodies = PhysicsSettings::cMaxBodiesLimit + 1; }},
        {"mGravity", [](PhysicsSettings& s, float n, float) { s.mGravity.y() = n; }},
        {"mGravity", [](PhysicsSettings& s, float, float i) { s.mGravity.x() = i; }},
        {"mSpeculativeDistance", [](PhysicsSettings& s, float, float) { s.mSpeculativeDistance = -0.01f; }},
        {"mSpeculativeDistance", [](PhysicsSettings& s, float n, float) { s.mSpeculativeDistance = n; }},
        {"mTimeBeforeSleep", [](PhysicsSettings& s, float n, float) { s.mTimeBeforeSleep = n; }},
        {"mSleepVelocity", [](PhysicsSettings& s, float, float) { s.mSleepVelocity = -1.0f; }},
        {"mBroadPhase", [](PhysicsSettings& s, float, float) { s.mBroadPhase = BroadPhaseType(200); }},
        {"mNumBodyMutexes", [](PhysicsSettings& s, float, float) { s.mNumBodyMutexes = 0; }},
        {"mNumBodyMutexes", [](PhysicsSettings& s, float, float) { s.mNumBodyMutexes = 12; }},
        {"mNumBodyMutexes", [](PhysicsSettings& s, float, float) { s.mNumBodyMutexes = 64; }},
        {"mPairCacheMaxDeltaPosition",
         [](PhysicsSettings& s, float n, float) { s.mPairCacheMaxDeltaPosition = n; }},
        {"mPairCacheMaxDeltaAngle",
         [](PhysicsSettings& s, float, float) { s.mPairCacheMaxDeltaAngle = -1.0f; }},
        {"mBroadPhaseCandidateMargin",
         [](PhysicsSettings& s, float n, float) { s.mBroadPhaseCandidateMargin = n; }},
        {"mBroadPhaseCandidateMargin",
         [](PhysicsSettings& s, float, float) { s.mBroadPhaseCandidateMargin = -0.1f; }},
        {"mBroadPhaseCandidateMargin",
         [](PhysicsSettings& s, float, float i) { s.mBroadPhaseCandidateMargin = i; }},
        {"mVelocityIterations", [](PhysicsSettings& s, float, float) { s.mSolver.mVelocityIterations = 0; }},
        {"mVelocityIterations",
         [](PhysicsSettings& s, float, float) { s.mSolver.mVelocityIterations = 100000; }},
        {"mPositionIterations", [](PhysicsSettings& s, float, float) { s.mSolver.mPositionIterations = -1; }},
        {"mPenetrationSlop", [](PhysicsSettings& s, float n, float) { s.mSolver.mPenetrationSlop = n; }},
        {"mBaumgarte", [](PhysicsSettings& s, float, float) { s.mSolver.mBaumgarte = 2.0f; }},
        {"mMaxPenetrationCorrection",
         [](PhysicsSettings& s, float, float) { s.mSolver.mMaxPenetrationCorrection = -0.2f; }},
        {"mRestitutionThreshold",
         [](PhysicsSettings& s, float, float i) { s.mSolver.mRestitutionThreshold = i; }},
    };
    for (const Case& c : cases)
    {
        PhysicsSettings settings;
        c.mBreak(settings, nan, inf);
        const std::string error = CreateError(settings);
        EXPECT_NE(error.find(c.mField), std::string::npos) << c.mField << ": got '" << error << "'";
    }
}

TEST(SetupValidationTest, LayerMisuseIsReportedAndWritesNothing)
{
    LayerSetup tooMany(100, 2);
    EXPECT_EQ(tooMany.GetNumObjectLayers(), cMaxObjectLayers);
    EXPECT_FALSE(tooMany.GetStatus().IsOk());
    EXPECT_NE(tooMany.GetStatus().GetError().mMessage.find("object layers"), std::string::npos);

    LayerSetup tooManyTrees(4, 9);
    EXPECT_EQ(tooManyTrees.GetNumBroadPhaseLayers(), cMaxBroadPhaseLayers);
    EXPECT_FALSE(tooManyTrees.GetStatus().IsOk());

    LayerSetup layers = LayerSetup::CreateDefault();
    layers.SetBroadPhaseLayer(Layers::cMoving, 2); // The default setup has broad-phase layers 0 and 1
    ASSERT_FALSE(layers.GetStatus().IsOk());
    EXPECT_NE(layers.GetStatus().GetError().mMessage.find("SetBroadPhaseLayer(1, 2)"), std::string::npos);
    EXPECT_EQ(layers.GetBroadPhaseLayer(Layers::cMoving), BroadPhaseLayers::cMoving)
        << "the call was ignored";

    LayerSetup collides = LayerSetup::CreateDefault();
    collides.SetCollides(Layers::cMoving, 70, true);
    EXPECT_FALSE(collides.GetStatus().IsOk());
    EXPECT_EQ(collides.GetCollisionMask(Layers::cMoving),
              LayerSetup::CreateDefault().GetCollisionMask(Layers::cMoving));

    Result<std::unique_ptr<PhysicsSystem>> refused = PhysicsSystem::Create(PhysicsSettings{}, layers);
    ASSERT_FALSE(refused.IsOk());
    EXPECT_EQ(refused.GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_NE(refused.GetError().mMessage.find("layer setup"), std::string::npos);
    EXPECT_NE(refused.GetError().mMessage.find("SetBroadPhaseLayer(1, 2)"), std::string::npos)
        << refused.GetError().mMessage;
    for (const LayerSetup* bad : {&tooMany, &tooManyTrees, &collides})
    {
        Result<std::unique_ptr<PhysicsSystem>> also = PhysicsSystem::Create(PhysicsSettings{}, *bad);
        ASSERT_FALSE(also.IsOk());
        EXPECT_EQ(also.GetError().mCode, ErrorCode::InvalidArgument);
        EXPECT_NE(also.GetError().mMessage.find("layer setup"), std::string::npos)
            << also.GetError().mMessage;
    }
}

TEST(SetupValidationTest, BadSettingsAndBadLayersTogetherAreRefused)
{
    PhysicsSettings settings;
    settings.mGravity = Vec3(0, std::numeric_limits<float>::quiet_NaN(), 0);
    LayerSetup layers = LayerSetup::CreateDefault();
    layers.SetCollides(Layers::cMoving, 70, true);
    Result<std::unique_ptr<PhysicsSystem>> refused = PhysicsSystem::Create(settings, layers);
    ASSERT_FALSE(refused.IsOk());
    EXPECT_EQ(refused.GetError().mCode, ErrorCode::InvalidArgument);
    // The settings are checked first
    EXPECT_NE(refused.GetError().mMessage.find("mGravity"), std::string::npos) << refused.GetError().mMessage;
}

TEST(SetupValidationTest, AValidSetupCreatesAWorldOnThatSetupThatSteps)
{
    // Valid, and none of it the default: the world must keep every value given (no fallback to the defaults)
    PhysicsSettings settings;
    settings.mMaxBodies = 64;
    settings.mGravity = Vec3(0.0f, -4.0f, 0.0f);
    settings.mNumBodyMutexes = 4;
    settings.mBroadPhase = BroadPhaseType::BruteForce;
    LayerSetup layers(3, 2);
    layers.SetBroadPhaseLayer(2, 1);
    layers.SetCollides(2, 2, true);
    ASSERT_TRUE(layers.GetStatus().IsOk()) << layers.GetStatus().GetError().mMessage;

    Result<std::unique_ptr<PhysicsSystem>> created = PhysicsSystem::Create(settings, layers);
    ASSERT_TRUE(created.IsOk()) << created.GetError().mMessage;
    PhysicsSystem& system = *created.Value();
    EXPECT_EQ(system.GetSettings().mMaxBodies, 64u);
    EXPECT_EQ(system.GetSettings().mGravity, settings.mGravity);
    EXPECT_EQ(system.GetSettings().mNumBodyMutexes, 4u);
    EXPECT_EQ(system.GetSettings().mBroadPhase, BroadPhaseType::BruteForce);
    EXPECT_EQ(system.GetLayers().GetNumObjectLayers(), 3u);
    EXPECT_EQ(system.GetLayers().GetBroadPhaseLayer(2), 1u);

    // A ball in the third layer falls under the given gravity: v = g t after one second
    BodyCreationSettings ball;
    ball.mShape = SphereShape::Create(0.5f).Value();
    ball.mPosition = Vec3(0.0f, 100.0f, 0.0f);
    ball.mObjectLayer = 2;
    ball.mLinearDamping = 0.0f; // So that its speed is g t exactly
    const Result<BodyID> id = system.GetBodyInterface().CreateAndAddBody(ball, Activation::Activate);
    ASSERT_TRUE(id.IsOk()) << id.GetError().mMessage;
    for (int i = 0; i < 60; ++i)
        ASSERT_TRUE(system.Update(1.0f / 60.0f).IsOk());
    EXPECT_NEAR(system.GetBodyInterface().GetLinearVelocity(id.Value()).Value().y(), -4.0f, 0.05f);
    EXPECT_LT(system.GetBodyInterface().GetPosition(id.Value()).Value().y(), 99.0f);
}

} // namespace cairn::test
