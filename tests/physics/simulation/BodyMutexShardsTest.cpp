// The body mutex shards: body i is guarded by mutex i % shards, with 32 shards by default and 1 for the
// "before" mode that measures a single global body lock; a world with one shard steps, queries and edits as
// one with 32 and gives the same bodies' states.

#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "common/MakePhysicsSystem.h"
#include "common/StaticFloor.h"

#include <gtest/gtest.h>
#include <thread>

namespace cairn
{
using namespace cairn::physics;
namespace
{

TEST(BodyMutexShardsTest, BodiesShareTheShardsAsConfigured)
{
    const BodyManager sharded(64);
    EXPECT_NE(&sharded.GetMutexForBody(0), &sharded.GetMutexForBody(1));
    EXPECT_EQ(&sharded.GetMutexForBody(3), &sharded.GetMutexForBody(35));
    EXPECT_NE(&sharded.GetStaticMutexForBody(0), &sharded.GetStaticMutexForBody(1));
    const BodyManager single(64, 1);
    EXPECT_EQ(&single.GetMutexForBody(0), &single.GetMutexForBody(1));
    EXPECT_EQ(&single.GetMutexForBody(0), &single.GetMutexForBody(63));
    EXPECT_EQ(&single.GetStaticMutexForBody(0), &single.GetStaticMutexForBody(17));
    EXPECT_NE(&single.GetMutexForBody(0), &single.GetStaticMutexForBody(0));
    // Out of range or not a power of two: rounded down into 1..32
    const BodyManager six(64, 6);
    EXPECT_EQ(&six.GetMutexForBody(0), &six.GetMutexForBody(4));
    EXPECT_NE(&six.GetMutexForBody(0), &six.GetMutexForBody(3));
    const BodyManager none(64, 0);
    EXPECT_EQ(&none.GetMutexForBody(0), &none.GetMutexForBody(9));
}

/// Drops a stack of boxes for inSteps steps with inShards body mutexes while another thread reads them; the
/// boxes' final positions.
std::vector<Vec3> DropBoxes(uint32_t inShards, int inSteps)
{
    PhysicsSettings settings;
    settings.mMaxBodies = 256;
    settings.mNumBodyMutexes = inShards;
    const std::unique_ptr<PhysicsSystem> physics = test::MakePhysicsSystem(settings);
    (void)physics->GetBodyInterface().CreateAndAddBody(test::StaticFloorSettings(20.0f),
                                                       Activation::DontActivate);
    std::vector<BodyID> boxes;
    for (int i = 0; i < 40; ++i)
    {
        BodyCreationSettings box;
        box.mShape = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
        box.mPosition = Vec3(float(i % 5) * 1.5f - 3.0f, 1.0f + float(i / 5) * 1.2f, 0.0f);
        boxes.push_back(physics->GetBodyInterface().CreateAndAddBody(box, Activation::Activate).Value());
    }
    std::atomic<bool> done{false};
    std::thread reader(
        [&]
        {
            // Relaxed: only a stop signal
            while (!done.load(std::memory_order_relaxed))
                for (const BodyID& id : boxes)
                    (void)physics->GetBodyInterface().GetPosition(id);
        });
    for (int step = 0; step < inSteps; ++step)
        EXPECT_TRUE(physics->Update(1.0f / 60.0f).IsOk());
    done.store(true, std::memory_order_relaxed);
    reader.join();
    std::vector<Vec3> positions;
    for (const BodyID& id : boxes)
        positions.push_back(physics->GetBodyInterface().GetPosition(id).Value());
    return positions;
}

TEST(BodyMutexShardsTest, OneShardSimulatesAsThirtyTwo)
{
    const std::vector<Vec3> one = DropBoxes(1, 120), many = DropBoxes(32, 120);
    ASSERT_EQ(one.size(), many.size());
    for (size_t i = 0; i < one.size(); ++i)
        EXPECT_EQ(one[i], many[i]) << "box " << i; // Locks change nothing the step computes
    for (const Vec3& position : one)
        EXPECT_GT(position.y(), 0.0f); // Resting on the floor, not through it
}

} // namespace
} // namespace cairn
