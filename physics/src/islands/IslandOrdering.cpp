// IslandStage::Order: each island's constraints in solve order, the islands by size, and how each island is
// solved (colored by every thread, colored or whole by one thread, or in a group of small ones).

#include "constraints/JointStage.h"
#include "islands/IslandStage.h"
#include "math/RadixSort.h"
#include "narrowphase/ContactsStage.h"
#include "solver/WideContactSolver.h"
#include "step/StepContext.h"

#include <algorithm>

namespace cairn::physics
{

void IslandStage::Order(const StepContext& inContext, std::span<ContactConstraint* const> inConstraints,
                        std::span<const ConstraintInfo> inInfo, const JointStage& inJoints)
{
    const AtomicUnionFind& islands = inContext.mIslands;
    const uint32_t numIslands = islands.GetNumIslands();
    const std::vector<uint32_t>& constraintStart = mPlan.mConstraintStart;
    // Solve order: a hash of the bodies and sub-shapes, the same on every run. Creation order follows body
    // indices, which usually follow the geometry (a stack is built bottom-up); a solver sweeping in geometric
    // order drifts in that direction, and a wall of boxes leaned over
    // The keys are in a compact array (Build): a comparator that read them through the constraint pointers
    // took a cache miss per comparison
    auto byKeyThenCacheIndex = [](const OrderItem& inL, const OrderItem& inR)
    {
        return inL.mOrderKey < inR.mOrderKey ||
               (inL.mOrderKey == inR.mOrderKey && inL.mCacheIndex < inR.mCacheIndex);
    };
    // A resting pile or pyramid finds the same contacts in the same order step after step: the same sort
    // input, whose sorted order mOrderItems still holds (a compare instead of a sort)
    mSolveOrderReused = inContext.mSettings.mSolver.mReuseColorings && !mUnsortedOrderItems.empty() &&
                        mUnsortedOrderItems == mSortedOrderItemsInput &&
                        constraintStart == mSortedOrderItemsStarts;
    if (!mSolveOrderReused)
    {
        mOrderItems = mUnsortedOrderItems;
        std::swap(mUnsortedOrderItems, mSortedOrderItemsInput);
        mSortedOrderItemsStarts = constraintStart;
        for (uint32_t island = 0; island < numIslands; ++island)
        {
            const std::span<OrderItem> items(mOrderItems.data() + constraintStart[island],
                                             mOrderItems.data() + constraintStart[island + 1]);
            // A large island (a pile or a pyramid: thousands of constraints) by radix on the key's high half,
            // which took a third of the time of std::sort there; items whose high halves are equal (rare) are
            // then put in the comparison's order, so the result is that of sorting by the whole key and cache
            // index
            if (items.size() < cRadixSortMinItems)
                std::sort(items.begin(), items.end(), byKeyThenCacheIndex);
            else
                RadixSortByHighHalf(
                    items, mOrderScratch, [](const OrderItem& inItem) { return inItem.mOrderKey; },
                    byKeyThenCacheIndex);
        }
    }
    mPlan.mIslandConstraints.resize(mOrderItems.size());
    for (size_t i = 0; i < mOrderItems.size(); ++i)
        mPlan.mIslandConstraints[i] = inConstraints[mOrderItems[i].mConstraint];

    // Only an island that holds a good share of the step's work is colored: smaller ones are better solved
    // whole, several at once. Both limits ignore the thread count, so results do not depend on it
    // Joints count as constraints here: a large island of jointed bodies is colored as a pile is
    const uint32_t coloredMin =
        std::max(cColoredIslandMinConstraints,
                 uint32_t((inConstraints.size() + inJoints.GetNumStepJoints()) / cColoredIslandMinShare));
    // Islands by size, largest first (ties by number): the order both the colored ones and the others are
    // solved in. A counting sort: most islands are one or two bodies, and comparing thousands of them took a
    // tenth of a step of falling bodies
    size_t largest = 0;
    for (uint32_t island = 0; island < numIslands; ++island)
        largest = std::max(largest, islands.GetBodies(island).size());
    mIslandSizeStart.assign(largest + 2, 0);
    for (uint32_t island = 0; island < numIslands; ++island)
        ++mIslandSizeStart[largest - islands.GetBodies(island).size() + 1]; // Bucket 0: the largest
    for (size_t bucket = 1; bucket < mIslandSizeStart.size(); ++bucket)
        mIslandSizeStart[bucket] += mIslandSizeStart[bucket - 1];
    mIslandOrder.resize(numIslands);
    for (uint32_t island = 0; island < numIslands; ++island) // In number order: ties stay so
        mIslandOrder[mIslandSizeStart[largest - islands.GetBodies(island).size()]++] = island;
    mPlan.mIslandFirstColor.assign(numIslands, UINT32_MAX);
    // This step's colorings go to the other set of records; the previous step's stay for reuse
    mCurrentColorings = 1 - mCurrentColorings;
    mNumColorings[mCurrentColorings] = 0;
    mNumColoringsReused = 0;
    mPlan.mColorStart.clear();
    mPlan.mColorFirstBatch.clear();
    mPlan.mNumWideBatches = 0;
    mPlan.mColorIsSerial.clear();
    mPlan.mColorJointStart.clear();
    mPlan.mColorJoints.clear();
    mPlan.mColoredIslands.clear();
    // The other islands with at most cGroupMaxConstraints constraints are solved in groups (see below)
    const bool wide = CAIRN_WIDE_SOLVER && inContext.mSettings.mSolver.mWideColoredIslands;
    auto isSmall = [&](uint32_t inNumConstraints)
    { return wide && inNumConstraints <= SolvePlan::cGroupMaxConstraints; };
    mSmallIslands.clear();
    mPlan.mSolvedIslands.clear();
    mPlan.mUnconstrainedBodies.clear();
    for (uint32_t island : mIslandOrder)
    {
        const uint32_t numConstraints = constraintStart[island + 1] - constraintStart[island];
        const uint32_t numJoints = uint32_t(inJoints.GetIslandJoints(island).size());
        if (numConstraints + numJoints >= coloredMin)
            mPlan.mColoredIslands.push_back(island);
        else if (numJoints > 0)
            mPlan.mSolvedIslands.push_back(island); // Whole, by one thread: see Order's declaration
        else if (wide && numConstraints >= cColoredIslandMinConstraints)
        {
            // Large, but not a share of the step that needs every thread: colored all the same, for the wide
            // solver, and solved by one thread (a pyramid's layers before they settle into one island were
            // solved by the scalar solver, a tenth of those steps)
            ColorIsland(inContext, inInfo, inJoints, island);
            mPlan.mSolvedIslands.push_back(island);
        }
        else if (numConstraints > 0)
            (isSmall(numConstraints) ? mSmallIslands : mPlan.mSolvedIslands).push_back(island);
        else
            for (uint32_t activeIndex : islands.GetBodies(island)) // One body: contacts would link more
                mPlan.mUnconstrainedBodies.push_back(activeIndex);
    }
    for (uint32_t island : mPlan.mColoredIslands)
        ColorIsland(inContext, inInfo, inJoints, island);

    // What the other islands' solve runs over: the larger ones one by one (largest first), then the small
    // ones (a crate on the ground, two touching) four at a time in the wide solver's lanes, where one at a
    // time the scalar solver waited on one short chain of operations after another. Neither depends on the
    // thread count
    mPlan.mSolveItems.clear();
    mPlan.mNumIslandGroups = 0;
    std::vector<uint32_t>& solved = mPlan.mSolvedIslands;
    const uint32_t numLarge = uint32_t(solved.size());
    for (uint32_t i = 0; i < numLarge; ++i)
        mPlan.mSolveItems.push_back({i, 1, UINT32_MAX});
    solved.insert(solved.end(), mSmallIslands.begin(), mSmallIslands.end());
    for (uint32_t first = numLarge; first < solved.size(); first += SolvePlan::cGroupIslands)
    {
        const uint32_t count = std::min(SolvePlan::cGroupIslands, uint32_t(solved.size()) - first);
        mPlan.mSolveItems.push_back({first, count, count == 1 ? UINT32_MAX : mPlan.mNumIslandGroups++});
    }
}

} // namespace cairn::physics
