#include "islands/IslandSleep.h"

#include "step/StepContext.h"

namespace cairn::physics
{

void IslandSleep::WakeIslandsOfWokenBodies(const StepContext& inContext)
{
    std::vector<uint32_t>& active = inContext.mActive;
    // Bodies appended by this loop were woken by it, not from outside: their flags are clear
    for (size_t i = 0; i < active.size(); ++i)
    {
        Body& body = inContext.BodyAt(active[i]);
        if (!body.mWakeIsland) continue;
        body.mWakeIsland = false;
        // Walk the ring of the island it slept in. Every hop wakes a sleeping body, and the walk stops at an
        // active one (the start, or a body that woke since and whose ring link is stale) and at a link to a
        // body that is gone (the id's sequence no longer matches) or cannot wake (not in the world, static),
        // so it terminates
        for (BodyID next = body.mSleepRingNext;;)
        {
            Body* member = inContext.mBodies.TryGetBody(next);
            if (member == nullptr || !member->IsInWorld() || member->IsActive()) break;
            inContext.mBodies.ActivateBody(*member);
            if (!member->IsActive()) break; // Could not wake: following its own link would never end
            next = member->mSleepRingNext;
        }
    }
}

void IslandSleep::PutRestingIslandsToSleep(const StepContext& inContext)
{
    const AtomicUnionFind& islands = inContext.mIslands;
    mSleepingBodies.clear();
    for (uint32_t island = 0; island < islands.GetNumIslands(); ++island)
    {
        bool canSleep = true;
        for (uint32_t activeIndex : islands.GetBodies(island))
            canSleep &= inContext.ActiveBody(activeIndex).mSleepTimer >= inContext.mSettings.mTimeBeforeSleep;
        if (!canSleep) continue;
        // Link the island into a ring, so that waking one of its bodies from outside wakes them all
        const std::span<const uint32_t> members = islands.GetBodies(island);
        for (size_t i = 0; i < members.size(); ++i)
        {
            Body& body = inContext.ActiveBody(members[i]);
            body.mSleepRingNext = inContext.ActiveBody(members[(i + 1) % members.size()]).GetID();
            mSleepingBodies.push_back(inContext.mActive[members[i]]);
        }
    }
    // Deactivating reorders the active list, so the islands' indices are resolved to bodies first
    for (uint32_t bodyIndex : mSleepingBodies)
        inContext.mBodies.DeactivateBody(inContext.BodyAt(bodyIndex));
}

} // namespace cairn::physics
