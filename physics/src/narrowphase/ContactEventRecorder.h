#pragma once

// ContactEventRecorder: a collision step's contact events (ContactListener.h), made after the solve from
// what the step keeps anyway: last step's and this step's manifolds, both sorted by key in the contact cache,
// walked side by side (a key in both persists, in this step's only was added, in last step's only was
// removed), then the sensor overlaps against last step's. Key order and body-pair order do not depend on the
// threads, so neither do the events.
//
// Threads: the updating thread, inside the step (it holds every body lock), after the solver's jobs.

#include "cairn/physics/narrowphase/ContactListener.h"

#include <span>
#include <vector>

namespace cairn::physics
{

class BodyManager;
class ContactCache;

/// A dynamic body overlapping a sensor this collision step: A the body of lower index.
struct SensorOverlap
{
    BodyID mBodyA;
    BodyID mBodyB;
    auto operator<=>(const SensorOverlap&) const = default;
};

class ContactEventRecorder
{
public:
    /// Appends this collision step's events to ioEvents. inCache: after its EndStep (its previous manifolds
    /// are last step's). inOverlaps: this step's sensor overlaps, in any order.
    void Record(const BodyManager& inBodies, const ContactCache& inCache,
                std::span<const SensorOverlap> inOverlaps, uint8_t inCollisionStep,
                std::vector<ContactEvent>& ioEvents);
    /// Forgets the sensor overlaps: a step that records no events (the next one that does reports every
    /// overlap as an entry).
    void Forget() { mOverlaps.clear(); }

private:
    void RecordSensors(const BodyManager& inBodies, std::span<const SensorOverlap> inOverlaps,
                       uint8_t inCollisionStep, std::vector<ContactEvent>& ioEvents);

    std::vector<SensorOverlap> mOverlaps; ///< Last recorded step's, sorted; then this step's
    std::vector<SensorOverlap> mScratch;  ///< This step's, sorted, before they become mOverlaps
};

} // namespace cairn::physics
