// Contact events and the contact listener (ContactListener.h): each contact's life as added, persisted and
// removed, with its points, normal and impulses; a listener that changes friction and restitution or rejects
// a pair; the event order for any thread count; sensors' entries and exits.

#include "SimulationFixture.h"
#include "cairn/physics/narrowphase/ContactListener.h"

#include <atomic>
#include <vector>

namespace cairn::test
{
using namespace cairn::physics;

namespace
{
using Kind = ContactEventKind;

class ContactEventsTest : public SimulationFixture
{
protected:
    ContactEventsTest() { System().SetRecordContactEvents(true); }

    /// A static sensor box of 6 x 2 x 6 m.
    BodyID AddSensorBox(const Vec3& inCenter)
    {
        BodyCreationSettings sensor;
        sensor.mShape = Box(Vec3(3, 1, 3));
        sensor.mPosition = inCenter;
        sensor.mMotionType = MotionType::Static;
        sensor.mObjectLayer = Layers::cStatic;
        sensor.mIsSensor = true;
        return Bodies().CreateAndAddBody(sensor, Activation::DontActivate).Value();
    }

    /// The events of one Update that involve inBody.
    std::vector<ContactEvent> EventsOf(const BodyID& inBody) const
    {
        std::vector<ContactEvent> events;
        for (const ContactEvent& event : mSystem->GetContactEvents())
            if (event.mBodyA == inBody || event.mBodyB == inBody) events.push_back(event);
        return events;
    }
};

// A box dropped on the floor: one Added when it lands, then Persisted every step while it rests (its normal
// up, its points on the floor's top, the normal impulses holding its weight for the step), then one Removed
// when it is lifted away by hand
TEST_F(ContactEventsTest, AContactIsAddedPersistsAndIsRemoved)
{
    const BodyID floor = AddFloor();
    BodyCreationSettings settings = DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 1.0f, 0));
    settings.mAllowSleeping = false;
    const BodyID box = AddDynamic(settings);
    const float mass = 1000.0f; // 1 m^3 of the default density
    int added = 0, persisted = 0, updatesBeforeLanding = 0;
    for (int update = 0; update < 90; ++update)
    {
        Step(1);
        for (const ContactEvent& event : EventsOf(box))
        {
            EXPECT_EQ(event.mBodyA, floor) << "A is the body of lower index";
            EXPECT_EQ(event.mBodyB, box);
            EXPECT_FALSE(event.mIsSensor);
            added += event.mKind == Kind::Added;
            persisted += event.mKind == Kind::Persisted;
            ASSERT_NE(event.mKind, Kind::Removed) << "the box rests on the floor";
            EXPECT_NEAR(event.mNormal.y(), 1.0f, 1.0e-4f);
            ASSERT_GE(event.mNumPoints, 1);
            for (int i = 0; i < event.mNumPoints; ++i)
            {
                EXPECT_NEAR(event.mPointsOnA[i].y(), 0.0f, 1.0e-3f) << "on the floor's top";
                EXPECT_NEAR(event.mPointsOnB[i].y(), 0.0f, 0.01f) << "on the box's bottom";
            }
        }
        if (added == 0) ++updatesBeforeLanding;
    }
    EXPECT_EQ(added, 1);
    EXPECT_EQ(persisted, 90 - updatesBeforeLanding - 1);
    // At rest, the points' impulses carry the box's weight for one step (the solver's tolerance: 1 %)
    const std::vector<ContactEvent> resting = EventsOf(box);
    ASSERT_EQ(resting.size(), 1u);
    float impulse = 0.0f;
    for (int i = 0; i < resting[0].mNumPoints; ++i)
        impulse += resting[0].mNormalImpulses[i];
    EXPECT_NEAR(impulse, mass * 9.81f * cDeltaTime, 0.01f * mass * 9.81f * cDeltaTime);

    ASSERT_TRUE(Bodies().SetPosition(box, Vec3(0, 10, 0), Activation::Activate).IsOk());
    Step(1);
    const std::vector<ContactEvent> lifted = EventsOf(box);
    ASSERT_EQ(lifted.size(), 1u);
    EXPECT_EQ(lifted[0].mKind, Kind::Removed);
    EXPECT_EQ(lifted[0].mNumPoints, 0);
    Step(1);
    EXPECT_TRUE(EventsOf(box).empty()) << "removed once";
}

// A body removed from the world ends its contacts
TEST_F(ContactEventsTest, RemovingABodyRemovesItsContacts)
{
    AddFloor();
    BodyCreationSettings settings = DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 0.5f, 0));
    settings.mAllowSleeping = false;
    const BodyID box = AddDynamic(settings);
    Step(5);
    ASSERT_EQ(EventsOf(box).size(), 1u);
    ASSERT_TRUE(Bodies().RemoveBody(box).IsOk());
    Step(1);
    const std::vector<ContactEvent> events = EventsOf(box);
    ASSERT_EQ(events.size(), 1u);
    EXPECT_EQ(events[0].mKind, Kind::Removed);
}

/// Changes what the test asks of every contact; counts the calls (from the step's job threads).
class TestListener : public ContactListener
{
public:
    ContactValidation OnContactValidate(const Body&, const Body&) override
    {
        return mReject ? ContactValidation::Reject : ContactValidation::Accept;
    }
    void OnContactAdded(const Body&, const Body&, const ContactManifold&,
                        ContactSettings& ioSettings) override
    {
        mAdded.fetch_add(1, std::memory_order_relaxed); // Relaxed: a count, read after Update
        Change(ioSettings);
    }
    void OnContactPersisted(const Body&, const Body&, const ContactManifold&,
                            ContactSettings& ioSettings) override
    {
        Change(ioSettings);
    }
    void OnContactEvents(std::span<const ContactEvent> inEvents) override
    {
        mEvents.insert(mEvents.end(), inEvents.begin(), inEvents.end());
    }

    bool mReject = false;
    float mFriction = -1.0f;    ///< < 0: unchanged
    float mRestitution = -1.0f; ///< < 0: unchanged
    std::atomic<int> mAdded{0};
    std::vector<ContactEvent> mEvents; ///< Every OnContactEvents call's, in order

private:
    void Change(ContactSettings& ioSettings) const
    {
        if (mFriction >= 0.0f) ioSettings.mFriction = mFriction;
        if (mRestitution >= 0.0f) ioSettings.mRestitution = mRestitution;
    }
};

// The listener's restitution 1 makes a dead ball bounce back to its height (within the analytic tests' 1 mm);
// its friction 0 lets a thrown box slide on at its speed
TEST_F(ContactEventsTest, AListenerChangesRestitutionAndFriction)
{
    TestListener listener;
    listener.mRestitution = 1.0f;
    System().SetContactListener(&listener);
    AddFloor();
    BodyCreationSettings ball = DynamicSettings(Sphere(0.5f), Vec3(0, 2.5f, 0));
    ball.mLinearDamping = 0.0f;
    const BodyID id = AddDynamic(ball);
    float apex = 0.0f;
    bool bounced = false;
    for (int update = 0; update < 120 && !(bounced && Velocity(id).y() < 0.0f); ++update)
    {
        Step(1);
        bounced |= Velocity(id).y() > 0.0f;
        if (bounced) apex = std::max(apex, Position(id).y() - 0.5f);
    }
    EXPECT_GT(listener.mAdded.load(std::memory_order_relaxed), 0);
    EXPECT_NEAR(apex, 2.0f, 1.0e-3f);

    listener.mRestitution = -1.0f;
    listener.mFriction = 0.0f;
    BodyCreationSettings box = DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(10, 0.5f, 0));
    box.mLinearVelocity = Vec3(3.0f, 0, 0);
    box.mLinearDamping = 0.0f;
    const BodyID boxID = AddDynamic(box);
    Step(30);
    EXPECT_NEAR(Velocity(boxID).x(), 3.0f, 1.0e-3f) << "friction 0 from the listener";
}

// A rejected pair makes no contact: the ball falls through the floor
TEST_F(ContactEventsTest, AListenerRejectsAPair)
{
    TestListener listener;
    listener.mReject = true;
    System().SetContactListener(&listener);
    AddFloor();
    const BodyID ball = AddDynamic(DynamicSettings(Sphere(0.5f), Vec3(0, 0.6f, 0)));
    Step(60); // 4.9 m of free fall
    EXPECT_LT(Position(ball).y(), -3.0f);
    EXPECT_EQ(listener.mAdded.load(std::memory_order_relaxed), 0);
    EXPECT_TRUE(System().GetContactEvents().empty());
}

/// A pile of boxes and balls falling onto a floor and each other, on inThreads threads (0: no job system);
/// returns every event of every update, the listener's copy checked against GetContactEvents.
std::vector<ContactEvent> EventsOfAPile(int inThreads)
{
    std::unique_ptr<jobs::JobSystem> jobSystem;
    if (inThreads > 0)
    {
        jobs::JobSystem::Settings settings;
        settings.mNumThreads = uint32_t(inThreads);
        jobSystem = std::make_unique<jobs::JobSystem>(settings);
    }
    std::unique_ptr<PhysicsSystem> system = MakePhysicsSystem();
    TestListener listener;
    system->SetContactListener(&listener);
    BodyInterface& bodies = system->GetBodyInterface();
    BodyCreationSettings floor;
    floor.mShape = BoxShape::Create(Vec3(20, 1, 20)).Value();
    floor.mPosition = Vec3(0, -1, 0);
    floor.mMotionType = MotionType::Static;
    floor.mObjectLayer = Layers::cStatic;
    EXPECT_TRUE(bodies.CreateAndAddBody(floor, Activation::DontActivate).IsOk());
    for (int i = 0; i < 120; ++i)
    {
        BodyCreationSettings settings;
        if (i % 3 == 0)
            settings.mShape = SphereShape::Create(0.4f).Value();
        else
            settings.mShape = BoxShape::Create(Vec3(0.4f, 0.3f, 0.5f)).Value();
        settings.mPosition =
            Vec3(float(i % 5) * 0.9f - 2.0f, 0.5f + float(i / 25) * 0.8f, float(i / 5 % 5) * 0.9f - 2.0f);
        settings.mRotation = Quat(Eigen::AngleAxisf(0.1f * float(i), Vec3(1, 1, 0).normalized()));
        settings.mMotionType = MotionType::Dynamic;
        settings.mObjectLayer = Layers::cMoving;
        settings.mRestitution = i % 7 == 0 ? 0.5f : 0.0f;
        EXPECT_TRUE(bodies.CreateAndAddBody(settings, Activation::Activate).IsOk());
    }
    std::vector<ContactEvent> all;
    for (int update = 0; update < 90; ++update)
    {
        const Status status = jobSystem != nullptr ? system->Update(1.0f / 60.0f, 2, *jobSystem)
                                                   : system->Update(1.0f / 60.0f, 2);
        EXPECT_TRUE(status.IsOk());
        const std::span<const ContactEvent> events = system->GetContactEvents();
        all.insert(all.end(), events.begin(), events.end());
    }
    EXPECT_EQ(listener.mEvents.size(), all.size()) << "the listener heard each collision step's events";
    return all;
}

bool SameEvent(const ContactEvent& inA, const ContactEvent& inB)
{
    bool same = inA.mKind == inB.mKind && inA.mIsSensor == inB.mIsSensor &&
                inA.mCollisionStep == inB.mCollisionStep && inA.mNumPoints == inB.mNumPoints &&
                inA.mBodyA == inB.mBodyA && inA.mBodyB == inB.mBodyB && inA.mSubShapeA == inB.mSubShapeA &&
                inA.mSubShapeB == inB.mSubShapeB && inA.mNormal == inB.mNormal &&
                inA.mFrictionImpulse == inB.mFrictionImpulse;
    for (int i = 0; i < inA.mNumPoints; ++i)
        same = same && inA.mPointsOnA[i] == inB.mPointsOnA[i] && inA.mPointsOnB[i] == inB.mPointsOnB[i] &&
               inA.mNormalImpulses[i] == inB.mNormalImpulses[i];
    return same;
}

// The same events in the same order, bit for bit, for no job system and 1, 2 and 4 threads
TEST(ContactEventsOrderTest, TheSameEventsInTheSameOrderForAnyThreadCount)
{
    const std::vector<ContactEvent> reference = EventsOfAPile(0);
    int kinds[3] = {0, 0, 0};
    for (const ContactEvent& event : reference)
        ++kinds[int(event.mKind)];
    EXPECT_GT(kinds[int(Kind::Added)], 100);
    EXPECT_GT(kinds[int(Kind::Persisted)], 1000);
    EXPECT_GT(kinds[int(Kind::Removed)], 10) << "balls roll off and boxes tumble";
    for (int threads : {1, 2, 4})
    {
        const std::vector<ContactEvent> events = EventsOfAPile(threads);
        ASSERT_EQ(events.size(), reference.size()) << threads << " threads";
        for (size_t i = 0; i < events.size(); ++i)
            ASSERT_TRUE(SameEvent(events[i], reference[i])) << threads << " threads, event " << i;
    }
}

// A sensor box; balls fall through it. Each ball enters once and leaves once, and falls as if the sensor were
// not there (free fall, to float rounding)
TEST_F(ContactEventsTest, ASensorReportsEachBodyEnteringAndLeavingOnce)
{
    const BodyID sensorID = AddSensorBox(Vec3(0, 5, 0));
    std::vector<BodyID> balls;
    for (int i = 0; i < 5; ++i)
    {
        BodyCreationSettings ball = DynamicSettings(Sphere(0.3f), Vec3(float(i) - 2.0f, 8.0f + float(i), 0));
        ball.mLinearDamping = 0.0f;
        balls.push_back(AddDynamic(ball));
    }
    std::vector<int> entered(balls.size(), 0), left(balls.size(), 0);
    for (int update = 0; update < 120; ++update)
    {
        Step(1);
        for (const ContactEvent& event : System().GetContactEvents())
        {
            ASSERT_TRUE(event.mIsSensor);
            ASSERT_EQ(event.mBodyA, sensorID) << "created first: the lower index";
            ASSERT_NE(event.mKind, Kind::Persisted) << "sensors report entries and exits only";
            for (size_t b = 0; b < balls.size(); ++b)
            {
                if (event.mBodyB != balls[b]) continue;
                if (event.mKind == Kind::Added)
                {
                    EXPECT_EQ(++entered[b], left[b] + 1) << "entered twice";
                }
                else
                {
                    EXPECT_EQ(++left[b], entered[b]) << "left before entering";
                }
            }
        }
    }
    for (size_t b = 0; b < balls.size(); ++b)
    {
        EXPECT_EQ(entered[b], 1) << "ball " << b;
        EXPECT_EQ(left[b], 1) << "ball " << b;
        const float t = 2.0f;
        EXPECT_NEAR(Velocity(balls[b]).y(), -9.81f * t, 1.0e-3f) << "the sensor pushed";
    }
}

// A body that falls asleep inside a sensor is still inside it: no exit
TEST_F(ContactEventsTest, ABodyAsleepInASensorStaysInside)
{
    AddFloor();
    AddSensorBox(Vec3(0, 0.5f, 0));
    const BodyID box = AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0, 0.5f, 0)));
    int entered = 0, left = 0;
    for (int update = 0; update < 180; ++update)
    {
        Step(1);
        for (const ContactEvent& event : EventsOf(box))
            if (event.mIsSensor)
            {
                entered += event.mKind == Kind::Added;
                left += event.mKind == Kind::Removed;
            }
    }
    ASSERT_FALSE(IsActive(box)) << "the box was meant to fall asleep";
    EXPECT_EQ(entered, 1);
    EXPECT_EQ(left, 0);
}

} // namespace
} // namespace cairn::test
