#pragma once

// Contact events: the game's view of the contacts a step makes, and its say in them.
//
// A contact is one manifold, keyed by (body A, body B, sub-shape A, sub-shape B), A the body of lower index.
// It is Added in the first collision step that makes it, Persisted in each one after that makes it again,
// and Removed in the first that does not (the bodies moved apart, one was removed or destroyed, a listener
// rejected the pair, or both bodies fell asleep: a sleeping body has no contacts, and they are Added again
// when it wakes). A sensor body (BodyCreationSettings::mIsSensor) makes no contacts that push: each body
// overlapping it gives one event per body pair, Added when it enters and Removed when it leaves; a dynamic
// body that falls asleep inside a sensor stays inside it. Sensors see dynamic bodies only.
//
// Two ways to hear of them:
//  - PhysicsSystem::GetContactEvents after an Update: every event of its collision steps, in one order that
//    does not depend on the number of threads (step by step; in each, contacts in key order, then sensor
//    events in body-pair order), with the points, the normal and the impulses the solver applied. Recorded
//    when a listener is set or PhysicsSystem::SetRecordContactEvents(true).
//  - A ContactListener (PhysicsSystem::SetContactListener), which may also change a contact's friction and
//    restitution or reject a body pair.
//
// Threads. OnContactValidate, OnContactAdded and OnContactPersisted run inside the step, on the step's job
// threads, several at once and in no fixed order: they must be thread-safe, may read the two bodies they are
// given (their poses and velocities are this step's, before the solver), and must not call BodyInterface,
// ConstraintInterface, PhysicsSystem or WorldQuery (the step holds every body lock: such a call returns
// ErrorCode::WrongThread on any of these threads, and a BodyLock does not lock: WasWrongThread), nor keep
// the references. OnContactEvents runs on the thread that called Update, after each collision step,
// with the same restrictions on the world; its events are in the order above.

#include "cairn/physics/body/BodyID.h"
#include "cairn/physics/narrowphase/ContactManifold.h"

#include <cstdint>
#include <span>

namespace cairn::physics
{

class Body;

/// What a contact's constraint uses this step: the listener may change it when the contact is added or
/// persists.
struct ContactSettings
{
    float mFriction;    ///< Combined sqrt(fA * fB); >= 0
    float mRestitution; ///< Combined max(eA, eB); in [0, 1]
};

enum class ContactValidation : uint8_t
{
    Accept,
    Reject, ///< No contacts between the pair in this collision step
};

enum class ContactEventKind : uint8_t
{
    Added,     ///< The contact began this collision step (a sensor: the body entered it)
    Persisted, ///< It was there in the collision step before too
    Removed,   ///< It was there in the collision step before, and not in this one (a sensor: the body left)
};

struct ContactEvent
{
    static constexpr int cMaxPoints = ContactManifold::cMaxPoints;

    ContactEventKind mKind = ContactEventKind::Added;
    bool mIsSensor = false;     ///< One body is a sensor: no points, no impulses, sub-shapes 0
    uint8_t mCollisionStep = 0; ///< Which collision step of the Update made it, from 0
    uint8_t mNumPoints = 0;     ///< 0 for Removed and sensor events
    BodyID mBodyA;              ///< The body of lower index
    BodyID mBodyB;
    SubShapeID mSubShapeA = 0;
    SubShapeID mSubShapeB = 0;
    Vec3 mNormal = Vec3::Zero();            ///< World, from A to B, at the end of the step
    Vec3 mPointsOnA[cMaxPoints] = {};       ///< World, on A's surface, at the end of the step
    Vec3 mPointsOnB[cMaxPoints] = {};       ///< World, on B's surface
    float mNormalImpulses[cMaxPoints] = {}; ///< N s applied at each point this collision step
    Vec3 mFrictionImpulse = Vec3::Zero();   ///< N s, the manifold's friction (at the points' centre)
};

class ContactListener
{
public:
    virtual ~ContactListener() = default;

    /// Before the narrow phase collides a body pair whose bounds overlap, each collision step (sensors too).
    virtual ContactValidation OnContactValidate(const Body& /*inBodyA*/, const Body& /*inBodyB*/)
    {
        return ContactValidation::Accept;
    }
    /// A contact begins. ioSettings holds the combined friction and restitution; changes apply at once.
    virtual void OnContactAdded(const Body& /*inBodyA*/, const Body& /*inBodyB*/,
                                const ContactManifold& /*inManifold*/, ContactSettings& /*ioSettings*/)
    {
    }
    /// A contact goes on: as OnContactAdded, each collision step.
    virtual void OnContactPersisted(const Body& /*inBodyA*/, const Body& /*inBodyB*/,
                                    const ContactManifold& /*inManifold*/, ContactSettings& /*ioSettings*/)
    {
    }
    /// After each collision step, that step's events (removals and sensor events among them), with impulses.
    virtual void OnContactEvents(std::span<const ContactEvent> /*inEvents*/) {}
};

} // namespace cairn::physics
