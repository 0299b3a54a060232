// IslandStage::Build: the islands the narrow phase linked, numbered, and the constraints grouped by them.

#include "islands/IslandStage.h"
#include "narrowphase/ContactsStage.h"
#include "step/StepContext.h"

namespace cairn::physics
{

void IslandStage::Build(const StepContext& inContext, std::span<const ConstraintInfo> inInfo)
{
    // The links were made during the narrow phase; what is left is numbering, in O(N) on this thread
    AtomicUnionFind& islands = inContext.mIslands;
    islands.Finalize();

    const uint32_t numIslands = islands.GetNumIslands();
    const uint32_t numConstraints = uint32_t(inInfo.size());
    std::vector<uint32_t>& constraintStart = mPlan.mConstraintStart;
    constraintStart.assign(numIslands + 1, 0);
    mPlan.mIslandBounces.assign(numIslands, 0);
    mConstraintIsland.resize(numConstraints);
    for (uint32_t i = 0; i < numConstraints; ++i)
    {
        const ConstraintInfo& info = inInfo[i];
        const uint32_t island = islands.GetIsland(info.mBodyA != UINT32_MAX ? info.mBodyA : info.mBodyB);
        mConstraintIsland[i] = island;
        ++constraintStart[island + 1];
        mPlan.mIslandBounces[island] |= uint8_t(info.mBounces);
    }
    for (uint32_t i = 0; i < numIslands; ++i)
        constraintStart[i + 1] += constraintStart[i];
    // The sort items of Order, in island order (each island's are then sorted)
    mUnsortedOrderItems.resize(numConstraints);
    thread_local std::vector<uint32_t> cursor;
    cursor.assign(constraintStart.begin(), constraintStart.end() - 1);
    for (uint32_t i = 0; i < numConstraints; ++i)
        mUnsortedOrderItems[cursor[mConstraintIsland[i]]++] = {inInfo[i].mOrderKey, inInfo[i].mCacheIndex, i};
}

uint32_t IslandStage::GetLargestIslandSize(const StepContext& inContext) const
{
    return mIslandOrder.empty() ? 0 : uint32_t(inContext.mIslands.GetBodies(mIslandOrder[0]).size());
}

} // namespace cairn::physics
