// Add batches let go on several threads at the moment their world is destroyed: each is aborted by the world
// (which waits for it) or finds the world gone and does nothing, and nothing is freed twice, leaked or used
// after it is freed. Under ThreadSanitizer (this suite's label) a race between the two shows; under the
// address sanitizer, a leak or a use after free. And a batch whose abort was deferred (let go under a body
// lock): a call that needs its bodies, made while another thread is aborting it, waits for that abort.

#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/body/BodyLock.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/SphereShape.h"
#include "common/MakePhysicsSystem.h"

#include <atomic>
#include <gtest/gtest.h>
#include <latch>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

namespace cairn
{
using namespace cairn::physics;
namespace
{

TEST(AddBatchLetGoConcurrencyTest, BatchesLetGoOnManyThreadsAsTheWorldIsDestroyed)
{
    constexpr int cThreads = 4;
    constexpr int cBodiesPerThread = 32;
    constexpr int cRounds = 25;
    const ShapeRef sphere = SphereShape::Create(0.4f).Value();
    for (int round = 0; round < cRounds; ++round)
    {
        std::unique_ptr<PhysicsSystem> world = test::MakePhysicsSystem();
        std::latch prepared(cThreads + 1);
        std::atomic<bool> go{false};
        std::atomic<int> preparedOk{0};
        std::vector<std::thread> threads;
        for (int t = 0; t < cThreads; ++t)
            threads.emplace_back(
                [&, t]
                {
                    BodyInterface& bodies = world->GetBodyInterface();
                    std::vector<BodyID> ids;
                    for (int i = 0; i < cBodiesPerThread; ++i)
                    {
                        BodyCreationSettings settings;
                        settings.mShape = sphere;
                        settings.mPosition = Vec3(float(i), 5.0f, float(t));
                        settings.mObjectLayer = Layers::cMoving;
                        ids.push_back(bodies.CreateBody(settings).Value());
                    }
                    std::optional<BodyInterface::AddBatch> batch;
                    if (Result<BodyInterface::AddBatch> made = bodies.AddBodiesPrepare(ids); made)
                    {
                        batch.emplace(std::move(made.Value()));
                        preparedOk.fetch_add(1, std::memory_order_relaxed); // Relaxed: read after the join
                    }
                    prepared.count_down();
                    // Acquire: pairs with the release below, though nothing is handed over but the moment
                    while (!go.load(std::memory_order_acquire))
                        std::this_thread::yield();
                    batch.reset(); // Beside the world's destruction: before, during or after it
                });
        prepared.arrive_and_wait();
        go.store(true, std::memory_order_release); // Release: see the workers' acquire
        world.reset();
        for (std::thread& thread : threads)
            thread.join();
        ASSERT_EQ(preparedOk.load(std::memory_order_relaxed), cThreads) << "round " << round;
    }
}

TEST(AddBatchLetGoConcurrencyTest, ACallMadeWhileAnotherThreadAbortsADeferredBatchWaitsForIt)
{
    // Large enough that its abort (a body lock each) is still running when the second call starts
    constexpr int cBodies = 2048;
    constexpr int cRounds = 20;
    const ShapeRef sphere = SphereShape::Create(0.4f).Value();
    for (int round = 0; round < cRounds; ++round)
    {
        std::unique_ptr<PhysicsSystem> world = test::MakePhysicsSystem();
        BodyInterface& bodies = world->GetBodyInterface();
        BodyCreationSettings settings;
        settings.mShape = sphere;
        settings.mObjectLayer = Layers::cMoving;
        std::vector<BodyID> ids;
        for (int i = 0; i < cBodies; ++i)
        {
            settings.mPosition = Vec3(float(i % 64), 5.0f, float(i / 64));
            ids.push_back(bodies.CreateBody(settings).Value());
        }
        const BodyID other = bodies.CreateBody(settings).Value();
        settings.mShape = BoxShape::Create(Vec3(40, 1, 40)).Value();
        settings.mMotionType = MotionType::Static;
        settings.mObjectLayer = Layers::cStatic;
        const BodyID floor = bodies.CreateAndAddBody(settings, Activation::DontActivate).Value();
        {
            Result<BodyInterface::AddBatch> batch = bodies.AddBodiesPrepare(ids);
            ASSERT_TRUE(batch.IsOk());
            BodyLockRead lock(world->GetBodyManager(), floor);
            batch.Value() = BodyInterface::AddBatch(); // Deferred: this thread holds a body lock
        }
        std::atomic<bool> started{false};
        // Its AddBody aborts the deferred batch first
        std::thread aborter(
            [&]
            {
                started.store(true, std::memory_order_relaxed); // Relaxed: only a moment, nothing handed over
                EXPECT_TRUE(bodies.AddBody(other, Activation::Activate).IsOk());
            });
        while (!started.load(std::memory_order_relaxed))
            std::this_thread::yield();
        Result<BodyInterface::AddBatch> again = bodies.AddBodiesPrepare(ids);
        EXPECT_TRUE(again.IsOk()) << "round " << round << ": " << again.GetError().mMessage;
        aborter.join();
        if (again.IsOk())
        {
            EXPECT_TRUE(bodies.AddBodiesFinalize(again.Value(), Activation::Activate).IsOk());
        }
    }
}

} // namespace
} // namespace cairn
