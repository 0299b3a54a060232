#include "narrowphase/ContactEventRecorder.h"

#include "cairn/physics/body/BodyManager.h"
#include "solver/ContactCache.h"

#include <algorithm>

namespace cairn::physics
{

namespace
{
ContactEvent EventOf(ContactEventKind inKind, const ContactKey& inKey, uint8_t inCollisionStep)
{
    ContactEvent event;
    event.mKind = inKind;
    event.mCollisionStep = inCollisionStep;
    event.mBodyA = inKey.mBodyA;
    event.mBodyB = inKey.mBodyB;
    event.mSubShapeA = inKey.mSubShapeA;
    event.mSubShapeB = inKey.mSubShapeB;
    return event;
}

/// An added or persisting contact with its points and impulses: the points are fixed on the bodies, so the
/// poses after the solve place them where the step left them.
ContactEvent ContactEventOf(const BodyManager& inBodies, ContactEventKind inKind,
                            const CachedManifold& inManifold, uint8_t inCollisionStep)
{
    ContactEvent event = EventOf(inKind, inManifold.mKey, inCollisionStep);
    const Body* a = inBodies.TryGetBody(inManifold.mKey.mBodyA);
    const Body* b = inBodies.TryGetBody(inManifold.mKey.mBodyB);
    if (a == nullptr || b == nullptr) return event; // Not in a manifold of this step: cannot happen
    event.mNumPoints = uint8_t(inManifold.mNumPoints);
    event.mNormal = a->GetRotation() * inManifold.mNormalOnA;
    for (int i = 0; i < inManifold.mNumPoints; ++i)
    {
        event.mPointsOnA[i] = a->GetCenterOfMassPosition() + a->GetRotation() * inManifold.mLocalOnA[i];
        event.mPointsOnB[i] = b->GetCenterOfMassPosition() + b->GetRotation() * inManifold.mLocalOnB[i];
        event.mNormalImpulses[i] = inManifold.mNormalImpulse[i];
    }
    event.mFrictionImpulse = inManifold.mFrictionImpulse;
    return event;
}
} // namespace

void ContactEventRecorder::Record(const BodyManager& inBodies, const ContactCache& inCache,
                                  std::span<const SensorOverlap> inOverlaps, uint8_t inCollisionStep,
                                  std::vector<ContactEvent>& ioEvents)
{
    const std::span<const CachedManifold> before = inCache.GetAllPreviousManifolds();
    const std::span<const CachedManifold> now = inCache.GetManifolds();
    size_t i = 0, j = 0;
    while (i < before.size() || j < now.size())
    {
        if (j == now.size() || (i < before.size() && before[i].mKey < now[j].mKey))
            ioEvents.push_back(EventOf(ContactEventKind::Removed, before[i++].mKey, inCollisionStep));
        else if (i == before.size() || now[j].mKey < before[i].mKey)
            ioEvents.push_back(ContactEventOf(inBodies, ContactEventKind::Added, now[j++], inCollisionStep));
        else
        {
            ioEvents.push_back(
                ContactEventOf(inBodies, ContactEventKind::Persisted, now[j++], inCollisionStep));
            ++i;
        }
    }
    RecordSensors(inBodies, inOverlaps, inCollisionStep, ioEvents);
}

void ContactEventRecorder::RecordSensors(const BodyManager& inBodies,
                                         std::span<const SensorOverlap> inOverlaps, uint8_t inCollisionStep,
                                         std::vector<ContactEvent>& ioEvents)
{
    mScratch.assign(inOverlaps.begin(), inOverlaps.end());
    // A body asleep inside a sensor is not collided with it, and stays inside: its overlap carries over
    // while both bodies are in the world and it sleeps
    for (const SensorOverlap& overlap : mOverlaps)
    {
        const Body* a = inBodies.TryGetBody(overlap.mBodyA);
        const Body* b = inBodies.TryGetBody(overlap.mBodyB);
        if (a == nullptr || b == nullptr || !a->IsInWorld() || !b->IsInWorld()) continue;
        const Body& other = a->IsSensor() ? *b : *a;
        if (other.IsDynamic() && !other.IsActive()) mScratch.push_back(overlap);
    }
    std::sort(mScratch.begin(), mScratch.end());
    mScratch.erase(std::unique(mScratch.begin(), mScratch.end()), mScratch.end());
    auto sensorEvent = [&](ContactEventKind inKind, const SensorOverlap& inOverlap)
    {
        ContactEvent& event = ioEvents.emplace_back(
            EventOf(inKind, {inOverlap.mBodyA, inOverlap.mBodyB, 0, 0}, inCollisionStep));
        event.mIsSensor = true;
    };
    // Side by side, as the contacts: only entries and exits are reported
    size_t i = 0, j = 0;
    while (i < mOverlaps.size() || j < mScratch.size())
    {
        if (j == mScratch.size() || (i < mOverlaps.size() && mOverlaps[i] < mScratch[j]))
            sensorEvent(ContactEventKind::Removed, mOverlaps[i++]);
        else if (i == mOverlaps.size() || mScratch[j] < mOverlaps[i])
            sensorEvent(ContactEventKind::Added, mScratch[j++]);
        else
            ++i, ++j;
    }
    std::swap(mOverlaps, mScratch);
}

} // namespace cairn::physics
