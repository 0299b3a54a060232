// The demo's guards (Guards.h) in a world of the default seed's terrain alone, stepped on one thread: the
// player walks its path and shoots each guard as it nears; a guard hit goes limp as a ragdoll, which comes
// to rest on the ground, every part above the terrain's surface once at rest; the guards the player passed
// are replaced by new ones ahead.

#include "Guards.h"

#include "Projectiles.h"
#include "WorldGenerator.h"
#include "cairn/physics/PhysicsSystem.h"
#include "common/MakePhysicsSystem.h"

#include <gtest/gtest.h>
#include <vector>

namespace cairn::demo
{
namespace
{
using namespace cairn::physics;

TEST(GuardsTest, ShotGuardsGoLimpAndComeToRestOnTheGround)
{
    PhysicsSettings settings;
    settings.mMaxBodies = 4096;
    const std::unique_ptr<PhysicsSystem> physics = cairn::test::MakePhysicsSystem(settings);
    const WorldGenerator generator(WorldSettings{});
    // The terrain of the tiles the player crosses in the first 20 s (8 m/s: 160 m) and their neighbours
    for (int x = -1; x <= 4; ++x)
        for (int z = -1; z <= 1; ++z)
            ASSERT_TRUE(physics->GetBodyInterface().CreateAndAddBody(
                generator.GenerateTile({x, z}, false).mTerrain, Activation::DontActivate));
    Projectiles projectiles(*physics, generator, 3);
    Guards guards(*physics, generator);
    const float dt = 1.0f / 60.0f;
    uint64_t partsAtRestBelowGround = 0, partsAtRest = 0;
    for (int frame = 0; frame < 1200; ++frame)
    {
        const float seconds = float(frame) * dt;
        guards.Update(frame, seconds, generator.GetPlayerPosition(seconds), projectiles, true);
        ASSERT_TRUE(physics->Update(dt).IsOk());
        guards.AfterStep(frame, projectiles);
        if (frame % 30 != 0) continue;
        std::vector<BodyID> limp;
        guards.GetLimpBodies(limp);
        for (const BodyID& part : limp)
        {
            // At rest: a ball landing on a limb may press it under the surface for a moment (540 kg on 2)
            if (physics->GetBodyInterface().IsActive(part).Value()) continue;
            const Vec3 at = physics->GetBodyInterface().GetPosition(part).Value();
            partsAtRestBelowGround += at.y() < generator.GetTerrainHeight(at.x(), at.z()) - 0.05f ? 1 : 0;
            ++partsAtRest;
        }
    }
    const GuardStats& stats = guards.GetStats();
    EXPECT_TRUE(stats.mErrors.empty()) << stats.mErrors.front();
    EXPECT_GE(stats.mPlaced, 8u);
    EXPECT_GE(stats.mHits, 5u) << "shots " << stats.mShots;
    EXPECT_EQ(stats.mMakeMs.size(), stats.mHits);
    EXPECT_GE(stats.mAtRest, 3u);
    for (const double seconds : stats.mSecondsToRest)
        EXPECT_LT(seconds, 10.0);
    // No part of a resting ragdoll went through the height field (the swept parts, the stance on high ground)
    EXPECT_GT(partsAtRest, 0u);
    EXPECT_EQ(partsAtRestBelowGround, 0u);
}

} // namespace
} // namespace cairn::demo
