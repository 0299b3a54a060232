#include "SimulationFixture.h"
#include "cairn/physics/body/BodyLock.h"

#include <atomic>
#include <chrono>
#include <thread>

namespace cairn::test
{
using namespace cairn::physics;

class SleepAndWakeTest : public SimulationFixture
{
protected:
    /// Two 1 m boxes stacked on the floor, left until their island sleeps.
    void StackTwoBoxesAndSleep(BodyID& outBottom, BodyID& outTop)
    {
        AddFloor();
        outBottom = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 0.5f, 0)));
        outTop = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 1.5f, 0)));
        Step(120);
        ASSERT_FALSE(IsActive(outBottom));
        ASSERT_FALSE(IsActive(outTop));
    }
};

TEST_F(SleepAndWakeTest, IslandSleepsOnlyAfterHalfASecondOfRest)
{
    AddFloor();
    const BodyID box = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 0.5f, 0)));
    Step(20); // 1/3 s at rest: not yet
    EXPECT_TRUE(IsActive(box));
    Step(40);
    EXPECT_FALSE(IsActive(box));
}

TEST_F(SleepAndWakeTest, MovingABodyThroughTheInterfaceWakesItsIsland)
{
    BodyID bottom, top;
    ASSERT_NO_FATAL_FAILURE(StackTwoBoxesAndSleep(bottom, top));
    // Shove the bottom box sideways out from under the top box
    ASSERT_TRUE(Bodies().SetPosition(bottom, Vec3(2, 0.5f, 0), Activation::Activate).IsOk());
    Step(1);
    EXPECT_TRUE(IsActive(bottom));
    EXPECT_TRUE(IsActive(top)) << "the box resting on it should wake";
    Step(60);
    EXPECT_LT(Position(top).y(), 0.6f) << "the top box should have fallen to the floor";
}

TEST_F(SleepAndWakeTest, RemovingTheSupportWakesTheBodyOnIt)
{
    const BodyID support = AddStatic(Box(Vec3(2, 0.5f, 2)), Vec3(0, 0, 0));
    const BodyID box = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 1.0f, 0)));
    Step(120);
    ASSERT_FALSE(IsActive(box));
    ASSERT_TRUE(Bodies().RemoveBody(support).IsOk());
    EXPECT_TRUE(IsActive(box));
    Step(30);
    EXPECT_LT(Position(box).y(), 0.5f) << "the box should be falling";
}

TEST_F(SleepAndWakeTest, RemovingABodyDoesNotWriteLockItsStaticNeighbours)
{
    // A static neighbour held for read by another thread (a query, a navmesh job) must not hold up a removal
    // beside it: static bodies never wake, so the removal has no reason to take their shard for writing
    const BodyID neighbour = AddStatic(Box(Vec3(2, 0.5f, 2)), Vec3(0, 0, 0));
    const BodyID removed = AddStatic(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 1.0f, 0));
    const BodyID resting = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 2.0f, 0)));
    Step(120);
    ASSERT_FALSE(IsActive(resting));
    const BodyManager& manager = System().GetBodyManager();
    // The neighbour's shard is not one the removal needs: the removed body's, or the resting body's to wake
    // it
    ASSERT_NE(&manager.GetMutexForBody(neighbour.GetIndex()), &manager.GetMutexForBody(removed.GetIndex()));
    ASSERT_NE(&manager.GetMutexForBody(neighbour.GetIndex()), &manager.GetMutexForBody(resting.GetIndex()));

    std::atomic<bool> held{false}, release{false}; // Seq_cst: a test's handshake, not a hot path
    std::thread reader(
        [&]
        {
            BodyLockRead lock(manager, neighbour);
            held = true;
            const auto giveUp = std::chrono::steady_clock::now() + std::chrono::seconds(5);
            while (!release && std::chrono::steady_clock::now() < giveUp)
                std::this_thread::yield();
        });
    while (!held)
        std::this_thread::yield();
    const auto start = std::chrono::steady_clock::now();
    const Status status = Bodies().RemoveBody(removed);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const bool readerStillHeld = !release.exchange(true);
    reader.join();
    ASSERT_TRUE(status.IsOk());
    EXPECT_TRUE(readerStillHeld && seconds < 4.0) << "the removal waited " << seconds << " s for the reader";
    EXPECT_TRUE(IsActive(resting)) << "the dynamic body on the removed one still wakes";
}

TEST_F(SleepAndWakeTest, AWokenIslandWhoseOtherMemberWasDestroyedAndItsSlotReusedStillSteps)
{
    BodyID bottom, top;
    ASSERT_NO_FATAL_FAILURE(StackTwoBoxesAndSleep(bottom, top));
    // Removing the top box wakes the bottom one, whose island ring still names the top box's slot
    ASSERT_TRUE(Bodies().RemoveBody(top).IsOk());
    ASSERT_TRUE(Bodies().DestroyBody(top).IsOk());
    ASSERT_TRUE(IsActive(bottom));
    // The next body made takes the freed slot: a static one, which never wakes
    const BodyID reused = AddStatic(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(10, 0.5f, 0));
    ASSERT_EQ(reused.GetIndex(), top.GetIndex()) << "the test needs the slot to be reused";
    // The step walks the woken island's ring: it looped forever on the static body (holding every body lock)
    Step(1);
    EXPECT_TRUE(IsActive(bottom));
    EXPECT_FALSE(IsActive(reused));
    EXPECT_NEAR(Position(reused).x(), 10.0f, 1e-6f);
}

TEST_F(SleepAndWakeTest, ContactWithAnActiveBodyWakesASleepingOne)
{
    AddFloor();
    const BodyID sleeper = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 0.5f, 0)));
    Step(60);
    ASSERT_FALSE(IsActive(sleeper));
    BodyCreationSettings ball = DynamicSettings(Sphere(0.3f), Vec3(-3, 0.5f, 0));
    ball.mLinearVelocity = Vec3(8, 0, 0);
    AddDynamic(ball);
    bool woke = false;
    for (int i = 0; i < 60 && !woke; ++i)
    {
        Step(1);
        woke = IsActive(sleeper);
    }
    EXPECT_TRUE(woke);
}

TEST_F(SleepAndWakeTest, SleepingCanBeDisabled)
{
    PhysicsSettings settings;
    settings.mAllowSleeping = false;
    ResetWorld(settings);
    AddFloor();
    const BodyID box = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 0.5f, 0)));
    Step(120);
    EXPECT_TRUE(IsActive(box));
}

TEST_F(SleepAndWakeTest, StaticBodiesNeverMoveOrJoinIslands)
{
    const BodyID floor = AddFloor();
    for (int i = 0; i < 5; ++i)
        AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(3.0f * float(i), 0.6f, 0)));
    Step(5);
    // Five boxes on one floor are five islands: the floor does not connect them
    EXPECT_EQ(System().GetLastStepStatistics().mNumIslands, 5u);
    EXPECT_EQ(Position(floor), Vec3(0, -1, 0));
    EXPECT_FALSE(IsActive(floor));
}

} // namespace cairn::test
