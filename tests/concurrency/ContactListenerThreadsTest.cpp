// The contact listener called from the step's job threads: OnContactValidate, OnContactAdded and
// OnContactPersisted run on several threads at once while a sensor, bouncy bodies and a listener that changes
// friction and restitution are in the scene. Under ThreadSanitizer (this suite's label) that must show no
// race inside the engine; and the events (recorded after each collision step, on the updating thread) must be
// the same bit for bit with 4 threads as with 1.

#include "cairn/jobs/JobSystem.h"
#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/body/BodyLock.h"
#include "cairn/physics/narrowphase/ContactListener.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/SphereShape.h"
#include "common/MakePhysicsSystem.h"
#include "common/StaticFloor.h"

#include <atomic>
#include <gtest/gtest.h>
#include <memory>
#include <thread>
#include <vector>

namespace cairn
{
using namespace cairn::physics;
namespace
{

/// Thread-safe by atomics alone: what a game's listener may do inside the step.
class CountingListener : public ContactListener
{
public:
    ContactValidation OnContactValidate(const Body& inA, const Body& inB) override
    {
        mValidated.fetch_add(1, std::memory_order_relaxed); // Relaxed: a count, read after Update
        // Rejects the pairs of two bodies whose indices are both multiples of 11: a fixed rule of the pair
        return inA.GetID().GetIndex() % 11 == 0 && inB.GetID().GetIndex() % 11 == 0
                   ? ContactValidation::Reject
                   : ContactValidation::Accept;
    }
    void OnContactAdded(const Body& inA, const Body& inB, const ContactManifold&,
                        ContactSettings& ioSettings) override
    {
        mAdded.fetch_add(1, std::memory_order_relaxed); // See above
        Change(inA, inB, ioSettings);
    }
    void OnContactPersisted(const Body& inA, const Body& inB, const ContactManifold&,
                            ContactSettings& ioSettings) override
    {
        Change(inA, inB, ioSettings);
    }
    void OnContactEvents(std::span<const ContactEvent> inEvents) override { mEventCount += inEvents.size(); }

    std::atomic<uint64_t> mValidated{0};
    std::atomic<uint64_t> mAdded{0};
    size_t mEventCount = 0; ///< The updating thread's only

private:
    static void Change(const Body& inA, const Body& inB, ContactSettings& ioSettings)
    {
        // Reads both bodies (allowed) and changes the settings by a rule of the pair
        if ((inA.GetID().GetIndex() + inB.GetID().GetIndex()) % 3 == 0) ioSettings.mRestitution = 0.6f;
        if (inB.GetLinearVelocity().y() > 2.0f) ioSettings.mFriction = 0.0f;
    }
};

std::vector<ContactEvent> RunListenerScene(uint32_t inThreads, uint64_t& outAdded)
{
    jobs::JobSystem jobSystem(jobs::JobSystem::Settings{inThreads});
    PhysicsSettings settings;
    settings.mAllowSleeping = false;
    std::unique_ptr<PhysicsSystem> system = test::MakePhysicsSystem(settings);
    CountingListener listener;
    system->SetContactListener(&listener);
    BodyInterface& bodies = system->GetBodyInterface();
    EXPECT_TRUE(bodies.CreateAndAddBody(test::StaticFloorSettings(30.0f), Activation::DontActivate).IsOk());
    BodyCreationSettings sensor;
    sensor.mShape = BoxShape::Create(Vec3(4, 1, 4)).Value();
    sensor.mPosition = Vec3(0, 3, 0);
    sensor.mMotionType = MotionType::Static;
    sensor.mObjectLayer = Layers::cStatic;
    sensor.mIsSensor = true;
    EXPECT_TRUE(bodies.CreateAndAddBody(sensor, Activation::DontActivate).IsOk());
    for (int i = 0; i < 150; ++i)
    {
        BodyCreationSettings body;
        if (i % 2 == 0)
            body.mShape = SphereShape::Create(0.3f).Value();
        else
            body.mShape = BoxShape::Create(Vec3(0.3f, 0.25f, 0.35f)).Value();
        body.mPosition =
            Vec3(float(i % 6) * 0.8f - 2.0f, 1.0f + float(i / 36) * 1.5f, float(i / 6 % 6) * 0.8f - 2.0f);
        body.mMotionType = MotionType::Dynamic;
        body.mObjectLayer = Layers::cMoving;
        body.mRestitution = i % 5 == 0 ? 0.8f : 0.0f;
        body.mMotionQuality = i % 7 == 0 ? MotionQuality::LinearCast : MotionQuality::Discrete;
        EXPECT_TRUE(bodies.CreateAndAddBody(body, Activation::Activate).IsOk());
    }
    std::vector<ContactEvent> events;
    for (int update = 0; update < 40; ++update)
    {
        EXPECT_TRUE(system->Update(1.0f / 60.0f, 2, jobSystem).IsOk());
        events.insert(events.end(), system->GetContactEvents().begin(), system->GetContactEvents().end());
    }
    EXPECT_GT(listener.mValidated.load(std::memory_order_relaxed), 0u); // Relaxed: the jobs were waited for
    EXPECT_EQ(listener.mEventCount, events.size());
    outAdded = listener.mAdded.load(std::memory_order_relaxed); // Relaxed: as above
    return events;
}

TEST(ContactListenerThreadsTest, ListenerOnJobThreadsGivesTheSameEventsAsOneThread)
{
    uint64_t addedOne = 0, addedFour = 0;
    const std::vector<ContactEvent> one = RunListenerScene(1, addedOne);
    const std::vector<ContactEvent> four = RunListenerScene(4, addedFour);
    EXPECT_GT(addedOne, 50u);
    EXPECT_EQ(addedOne, addedFour);
    ASSERT_EQ(one.size(), four.size());
    for (size_t i = 0; i < one.size(); ++i)
    {
        ASSERT_EQ(one[i].mKind, four[i].mKind) << "event " << i;
        ASSERT_EQ(one[i].mBodyA, four[i].mBodyA) << "event " << i;
        ASSERT_EQ(one[i].mBodyB, four[i].mBodyB) << "event " << i;
        ASSERT_EQ(one[i].mNumPoints, four[i].mNumPoints) << "event " << i;
        for (int p = 0; p < one[i].mNumPoints; ++p)
        {
            ASSERT_EQ(one[i].mPointsOnA[p], four[i].mPointsOnA[p]) << "event " << i;
            ASSERT_EQ(one[i].mNormalImpulses[p], four[i].mNormalImpulses[p]) << "event " << i;
        }
    }
}

/// Breaks the listener's rule: calls back into the world from each callback, as a game's listener might by
/// mistake. Counts what those calls returned, on the updating thread and on the others.
class CallingBackListener : public ContactListener
{
public:
    CallingBackListener(PhysicsSystem& ioSystem, std::thread::id inUpdatingThread)
        : mSystem(ioSystem), mUpdatingThread(inUpdatingThread)
    {
    }
    ContactValidation OnContactValidate(const Body& inA, const Body&) override
    {
        CallBack(inA.GetID());
        return ContactValidation::Accept;
    }
    void OnContactAdded(const Body& inA, const Body&, const ContactManifold&, ContactSettings&) override
    {
        CallBack(inA.GetID());
    }
    void OnContactPersisted(const Body& inA, const Body&, const ContactManifold&, ContactSettings&) override
    {
        CallBack(inA.GetID());
    }

    // Relaxed: counts, read after Update returned (the step's jobs were waited for)
    std::atomic<uint64_t> mCallsOnOtherThreads{0};
    std::atomic<uint64_t> mCallsNotRefused{0};

private:
    void CallBack(const BodyID& inID)
    {
        if (std::this_thread::get_id() != mUpdatingThread)
            mCallsOnOtherThreads.fetch_add(1, std::memory_order_relaxed);
        const Result<Vec3> position = mSystem.GetBodyInterface().GetPosition(inID);
        const BodyLockRead lock(mSystem.GetBodyManager(), inID);
        const Status step = mSystem.Update(1.0f / 60.0f);
        if (position || position.GetError().mCode != ErrorCode::WrongThread || lock.Succeeded() ||
            !lock.WasWrongThread() || step || step.GetError().mCode != ErrorCode::WrongThread)
            mCallsNotRefused.fetch_add(1, std::memory_order_relaxed);
    }

    PhysicsSystem& mSystem;
    const std::thread::id mUpdatingThread;
};

// A listener that calls the world from the step's job threads gets WrongThread there, as on the updating
// thread. Those calls used to wait for ever on the body locks the step holds (the flag that refuses them was
// set on the updating thread only); with the bug this test hangs until its time-out
TEST(ContactListenerThreadsTest, CallsBackIntoTheWorldAreRefusedOnEveryThread)
{
    jobs::JobSystem jobSystem(jobs::JobSystem::Settings{4});
    std::unique_ptr<PhysicsSystem> system = test::MakePhysicsSystem(PhysicsSettings{});
    CallingBackListener listener(*system, std::this_thread::get_id());
    system->SetContactListener(&listener);
    BodyInterface& bodies = system->GetBodyInterface();
    ASSERT_TRUE(bodies.CreateAndAddBody(test::StaticFloorSettings(30.0f), Activation::DontActivate));
    for (int i = 0; i < 400; ++i)
    {
        BodyCreationSettings body;
        body.mShape = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
        body.mPosition = Vec3(float(i % 20) * 1.2f - 12.0f, 0.49f, float(i / 20) * 1.2f - 12.0f);
        body.mMotionType = MotionType::Dynamic;
        body.mObjectLayer = Layers::cMoving;
        ASSERT_TRUE(bodies.CreateAndAddBody(body, Activation::Activate));
    }
    for (int update = 0; update < 10; ++update)
        ASSERT_TRUE(system->Update(1.0f / 60.0f, 1, jobSystem));
    EXPECT_GT(listener.mCallsOnOtherThreads.load(std::memory_order_relaxed), 0u)
        << "no callback ran on a job thread: the test tested nothing";
    EXPECT_EQ(listener.mCallsNotRefused.load(std::memory_order_relaxed), 0u);
}

} // namespace
} // namespace cairn
