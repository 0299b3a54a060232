// The quad-tree broad phase's "no missed collisions" stress, short run (see common/NoMissStress.h): part of
// the test command and run under ThreadSanitizer in CI. The 2-million-check run is tests/long/.

#include "broadphase/BroadPhaseGlobalMutex.h"
#include "broadphase/BroadPhaseQuadTree.h"
#include "common/NoMissStress.h"
#include "common/SlowBuild.h"

#include <gtest/gtest.h>
#include <memory>
#include <random>
#include <thread>

namespace cairn
{
using namespace cairn::physics;
namespace
{

/// The short run's settings.
test::NoMissStressConfig ShortRun()
{
    test::NoMissStressConfig config;
    config.mTargetChecks = 50000;
    config.mMinDuration = std::chrono::milliseconds(1000);
    // Under ThreadSanitizer the global mutex's run never reaches the target: each check waits for the
    // writers, which the sanitizer slows most, so the cap ends it
    config.mMaxDuration = std::chrono::milliseconds(test::cSlowBuild ? 8000 : 20000);
    return config;
}

/// A quad tree with room for the stress's bodies.
std::unique_ptr<BroadPhaseQuadTree> MakeQuadTree(const test::NoMissStressConfig& inConfig)
{
    return std::make_unique<BroadPhaseQuadTree>(inConfig.mNumPermanent + inConfig.mNumChurned,
                                                LayerSetup::CreateDefault());
}

TEST(BroadPhaseQuadTreeNoMissTest, LockFreeShortRun)
{
    const test::NoMissStressConfig config = ShortRun();
    const std::unique_ptr<BroadPhaseQuadTree> broadPhase = MakeQuadTree(config);
    const test::NoMissStressResult result =
        test::RunNoMissStress(*broadPhase, config, [&] { broadPhase->RebuildAll(); });
    test::ExpectNoMisses(result, config, broadPhase->GetBodyCount());
    EXPECT_TRUE(broadPhase->Validate());
}

TEST(BroadPhaseQuadTreeNoMissTest, GlobalMutexShortRun)
{
    const test::NoMissStressConfig config = ShortRun();
    std::unique_ptr<BroadPhaseQuadTree> owned = MakeQuadTree(config);
    BroadPhaseQuadTree& quadTree = *owned;
    BroadPhaseGlobalMutex broadPhase(std::move(owned));
    // The full rebuild under the exclusive lock, where this mode's Update runs
    const test::NoMissStressResult result = test::RunNoMissStress(
        broadPhase, config,
        [&] { broadPhase.WithExclusiveLock([&](BroadPhase&) { quadTree.RebuildAll(); }); });
    test::ExpectNoMisses(result, config, broadPhase.GetBodyCount());
    EXPECT_TRUE(quadTree.Validate());
}

} // namespace
} // namespace cairn

namespace cairn
{
using namespace cairn::physics;
namespace
{

// Two threads stepping one world is a caller bug: the overlapping step calls must be refused and counted, not
// race on the rebuild state (ThreadSanitizer would see that) or corrupt the trees (Validate would).
TEST(BroadPhaseQuadTreeNoMissTest, OverlappingStepCallsAreRefused)
{
    BroadPhaseQuadTree broadPhase(2000, LayerSetup::CreateDefault());
    std::vector<BroadPhaseBody> bodies;
    std::vector<BodyID> active;
    for (uint32_t i = 0; i < 2000; ++i)
    {
        const Vec3 p(float(i % 50) * 2.0f, 0.0f, float(i / 50) * 2.0f);
        bodies.push_back(
            {BodyID(i, 1), AABB(p, p + Vec3::Constant(1.5f)), i % 2 ? Layers::cStatic : Layers::cMoving});
        if (i % 2 == 0) active.push_back(bodies.back().mID);
    }
    broadPhase.AddBodiesFinalize(broadPhase.AddBodiesPrepare(bodies));
    std::atomic<bool> stop{false};
    auto stepper = [&](bool inFull)
    {
        // Relaxed: a stop flag only
        while (!stop.load(std::memory_order_relaxed))
        {
            if (inFull)
                broadPhase.RebuildAll();
            else
                broadPhase.Update();
            broadPhase.FindCollidingPairs(active, LayerSetup::CreateDefault(), [](BodyID, BodyID) {});
        }
    };
    std::thread mover(
        [&]
        {
            std::mt19937 random(3);
            std::vector<BroadPhaseBody> moved = bodies;
            while (!stop.load(std::memory_order_relaxed)) // Relaxed: a stop flag only
            {
                for (BroadPhaseBody& body : moved)
                    body.mBounds = AABB(body.mBounds.mMin + Vec3(0.01f, 0.0f, 0.0f),
                                        body.mBounds.mMax + Vec3(0.01f, 0.0f, 0.0f));
                broadPhase.NotifyBodiesAABBChanged(moved);
            }
        });
    std::thread first(stepper, false), second(stepper, true);
    const auto start = std::chrono::steady_clock::now();
    while (broadPhase.GetRefusedStepCalls() < 10 &&
           std::chrono::steady_clock::now() - start < std::chrono::seconds(10))
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    stop.store(true, std::memory_order_relaxed);
    for (std::thread* thread : {&mover, &first, &second})
        thread->join();
    EXPECT_GE(broadPhase.GetRefusedStepCalls(), 10u);
    EXPECT_TRUE(broadPhase.Validate());
    EXPECT_EQ(broadPhase.GetBodyCount(), bodies.size());
}

} // namespace
} // namespace cairn
