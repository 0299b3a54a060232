// Settings and layer setups out of range are refused with an error naming the field, never used: before these
// checks, an object layer past the 64-entry tables was written out of bounds in Release builds, and NaN
// gravity or a negative speculative distance silently broke every step.

#include "cairn/physics/PhysicsSystem.h"

#include <gtest/gtest.h>
#include <limits>
#include <string>

namespace cairn::test
{
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
    EXPECT_TRUE(system.Value()->GetSetupStatus().IsOk());
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
    EXPECT_NE(refused.GetError().mMessage.find("layer setup"), std::string::npos);
}

TEST(SetupValidationTest, AWorldBuiltFromBadSettingsNeverSteps)
{
    PhysicsSettings settings;
    settings.mGravity = Vec3(0, std::numeric_limits<float>::quiet_NaN(), 0);
    PhysicsSystem system(settings);
    ASSERT_FALSE(system.GetSetupStatus().IsOk());
    EXPECT_TRUE(system.GetSettings().mGravity.allFinite()) << "built on the defaults instead";
    const Status stepped = system.Update(1.0f / 60.0f);
    ASSERT_FALSE(stepped.IsOk());
    EXPECT_NE(stepped.GetError().mMessage.find("mGravity"), std::string::npos);
}

} // namespace cairn::test
