#pragma once

// IslandSleep: islands go to sleep whole and wake whole. At the end of a step an island whose bodies have all
// been slow for PhysicsSettings::mTimeBeforeSleep is linked into a ring (each body names the next) and
// deactivated; at the start of the next step, a body woken from outside (BodyInterface, a removal nearby)
// wakes its ring. The updating thread, inside the step.

#include <cstdint>
#include <vector>

namespace cairn::physics
{

struct StepContext;

class IslandSleep
{
public:
    /// Wakes the sleeping islands of bodies that were woken from outside the step since the last one.
    static void WakeIslandsOfWokenBodies(const StepContext& inContext);
    /// Puts to sleep the islands whose every body has been slow long enough. After the finish stage (which
    /// keeps the sleep timers); reorders the active list.
    void PutRestingIslandsToSleep(const StepContext& inContext);

private:
    std::vector<uint32_t> mSleepingBodies; ///< Scratch: body indices
};

} // namespace cairn::physics
