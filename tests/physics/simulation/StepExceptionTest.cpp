// An exception from inside the step leaves Update with the world usable: every body lock released (other
// threads' BodyInterface calls go on), the updating thread no longer inside the step, and the next Update
// steps. Before, the body locks stayed held for good, and every later Update reported "already running".
//
// What throws is a BodyChangeListener told inside the step that a sleeping island wakes: a listener whose own
// queue cannot grow gets std::bad_alloc from its push_back, and nothing in the listener's contract forbids
// letting it out.

#include "SimulationFixture.h"

#include <atomic>
#include <chrono>
#include <new>
#include <thread>

namespace cairn::test
{
using namespace cairn::physics;
namespace
{

/// Throws std::bad_alloc at the first change it is told of once armed, as a listener whose queue is out of
/// memory would. Any thread (the contract's).
class FailingListener final : public BodyChangeListener
{
public:
    void OnBodyChanged(const BodyChange&) override
    {
        // Seq_cst, both: a test's handshake, not a hot path
        if (!mArmed.exchange(false)) return;
        mThrewInsideStep = BodyManager::IsInsideStep();
        throw std::bad_alloc();
    }

    std::atomic<bool> mArmed{false};
    std::atomic<bool> mThrewInsideStep{false};
};

} // namespace

class StepExceptionTest : public SimulationFixture
{
protected:
    StepExceptionTest() { EXPECT_TRUE(System().AddBodyChangeListener(&mListener)); }
    ~StepExceptionTest() override { System().RemoveBodyChangeListener(&mListener); }

    FailingListener mListener;
};

TEST_F(StepExceptionTest, AListenerThrowingInsideTheStepLeavesTheWorldUnlockedAndTheNextUpdateSteps)
{
    // Two boxes stacked on the floor, left until their island sleeps
    AddFloor();
    const BodyID bottom = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 0.5f, 0)));
    const BodyID top = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 1.5f, 0)));
    Step(120);
    ASSERT_FALSE(IsActive(bottom));
    ASSERT_FALSE(IsActive(top));
    // The bottom box shoved out from under the top one (woken here, outside the step): the next step wakes
    // the rest of its island, the top box, and tells the listener, which throws
    ASSERT_TRUE(Bodies().SetPosition(bottom, Vec3(2, 0.5f, 0), Activation::Activate).IsOk());
    mListener.mArmed = true;
    EXPECT_THROW((void)UpdateWorld(cDeltaTime), std::bad_alloc);
    ASSERT_FALSE(mListener.mArmed) << "the listener was not called: the test throws nothing";
    EXPECT_TRUE(mListener.mThrewInsideStep);

    // Another thread finds every body mutex free, then reads and writes bodies. It tries the mutexes first,
    // so that locks left held fail the test instead of hanging it
    const BodyManager& manager = System().GetBodyManager();
    bool allFree = false, callsOk = false;
    std::thread other(
        [&]
        {
            allFree = true;
            for (uint32_t m = 0; m < BodyManager::cNumBodyMutexes; ++m)
            {
                std::shared_mutex& mutex = manager.GetMutexForBody(m);
                const bool locked = mutex.try_lock();
                if (locked) mutex.unlock();
                allFree &= locked;
            }
            if (!allFree) return;
            const BodyID ball = Bodies()
                                    .CreateAndAddBody(DynamicSettings(Sphere(0.25f), Vec3(-3, 0.25f, 0)),
                                                      Activation::Activate)
                                    .Value();
            callsOk = !ball.IsInvalid() && Bodies().GetPosition(top).IsOk() &&
                      Bodies().SetLinearVelocity(ball, Vec3(0, 0, 1)).IsOk();
        });
    other.join();
    ASSERT_TRUE(allFree) << "a body mutex is still locked after the step threw";
    EXPECT_TRUE(callsOk);

    // This thread is no longer inside the step, and the next Update is not refused as "already running"
    EXPECT_TRUE(Bodies().GetPosition(bottom).IsOk());
    const Status next = UpdateWorld(cDeltaTime);
    ASSERT_TRUE(next.IsOk()) << next.GetError().mMessage;
    EXPECT_TRUE(IsActive(top)) << "woken before the listener threw";
    Step(60);
    EXPECT_LT(Position(top).y(), 0.6f) << "the top box should have fallen to the floor";
    EXPECT_TRUE(System().IsContactCacheConsistent());
}

} // namespace cairn::test
