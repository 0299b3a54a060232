// IslandStage's coloring of a large island: its constraints ordered by color and its joints listed by color,
// no two of a color sharing a dynamic body, so that every thread can solve a part of each color at once. A
// coloring is reused while the island's constraints join the same bodies in the same order (a resting pile).

#include "constraints/JointStage.h"
#include "islands/IslandStage.h"
#include "math/RadixSort.h"
#include "narrowphase/ContactsStage.h"
#include "step/StepContext.h"

#include <algorithm>
#include <bit>

namespace cairn::physics
{

void IslandStage::ColorIsland(const StepContext& inContext, std::span<const ConstraintInfo> inInfo,
                              const JointStage& inJoints, uint32_t inIsland)
{
    const uint32_t begin = mPlan.mConstraintStart[inIsland], end = mPlan.mConstraintStart[inIsland + 1];
    const uint32_t numContacts = end - begin;
    const std::span<const uint32_t> joints = inJoints.GetIslandJoints(inIsland);
    const uint32_t size = numContacts + uint32_t(joints.size());
    // This step's record; the previous step's of the same size is the candidate for reuse
    std::vector<ColoringRecord>& records = mColorings[mCurrentColorings];
    if (records.size() <= mNumColorings[mCurrentColorings]) records.emplace_back();
    ColoringRecord& record = records[mNumColorings[mCurrentColorings]++];
    ColoringRecord* previous = nullptr;
    if (inContext.mSettings.mSolver.mReuseColorings)
        for (uint32_t r = 0; r < mNumColorings[1 - mCurrentColorings]; ++r)
            if (ColoringRecord& candidate = mColorings[1 - mCurrentColorings][r];
                candidate.mBodyPairs.size() == size)
                previous = &candidate;
    // The coloring is a function of the constraints' bodies in solve order and the joints' in slot order
    // alone: a joint is one more pair of bodies to keep apart
    record.mBodyPairs.resize(size);
    bool same = previous != nullptr;
    for (uint32_t i = 0; i < size; ++i)
    {
        uint32_t indexA, indexB;
        if (i < numContacts)
        {
            const ConstraintInfo& info = inInfo[mOrderItems[begin + i].mConstraint];
            indexA = info.mBodyA;
            indexB = info.mBodyB;
        }
        else
            inJoints.GetActiveIndices(joints[i - numContacts], indexA, indexB);
        record.mBodyPairs[i] = uint64_t(indexA) << 32 | indexB;
        same = same && record.mBodyPairs[i] == previous->mBodyPairs[i];
    }
    if (same)
    {
        std::swap(record.mOrder, previous->mOrder); // The previous step's records are not read again
        record.mCount = previous->mCount;
        previous->mBodyPairs.clear(); // Nor matched twice
        ++mNumColoringsReused;
    }
    else
        ComputeColoring(inContext, record);

    // The contacts into color order in place; the joints, by color, to the plan's list
    std::vector<ContactConstraint*>& constraints = mPlan.mIslandConstraints;
    mColorScratch.clear();
    mPlan.mIslandFirstColor[inIsland] = uint32_t(mPlan.mColorStart.size());
    uint32_t position = 0;
    for (uint32_t color = 0; color <= cSerialColor; ++color)
    {
        const uint32_t count = record.mCount[color];
        if (count == 0) continue;
        const uint32_t contactsBefore = uint32_t(mColorScratch.size());
        mPlan.mColorStart.push_back(begin + contactsBefore);
        mPlan.mColorJointStart.push_back(uint32_t(mPlan.mColorJoints.size()));
        for (const uint32_t item : std::span(record.mOrder).subspan(position, count))
            if (item < numContacts)
                mColorScratch.push_back(constraints[begin + item]);
            else
                mPlan.mColorJoints.push_back(joints[item - numContacts]);
        position += count;
        const uint32_t contacts = uint32_t(mColorScratch.size()) - contactsBefore;
        mPlan.mColorIsSerial.push_back(color == cSerialColor ? 1 : 0);
        mPlan.mColorFirstBatch.push_back(mPlan.mNumWideBatches);
        if (color != cSerialColor) mPlan.mNumWideBatches += (contacts + 3) / 4;
    }
    std::copy(mColorScratch.begin(), mColorScratch.end(), constraints.begin() + begin);
    mPlan.mColorStart.push_back(end);
    mPlan.mColorJointStart.push_back(uint32_t(mPlan.mColorJoints.size()));
    mPlan.mColorIsSerial.push_back(0); // The end marker
    mPlan.mColorFirstBatch.push_back(mPlan.mNumWideBatches);
}

void IslandStage::ComputeColoring(const StepContext& inContext, ColoringRecord& ioRecord)
{
    const uint32_t size = uint32_t(ioRecord.mBodyPairs.size());
    mBodyColors.resize(inContext.mActive.size(), 0);
    mColorItems.resize(size);
    std::array<uint32_t, cSerialColor + 1>& count = ioRecord.mCount;
    count.fill(0);
    // Greedy, body by body: the constraints in the order of their lowest dynamic body, then their other one
    // (a static or kinematic side counts as numActive, after every dynamic body), then solve order. Each
    // takes the lowest color that neither of its dynamic bodies has yet (static and kinematic bodies are only
    // read by the solver, so they may repeat in a color). A body's constraints then take the colors its
    // neighbours left free: a pyramid's 8,400 constraints in 16 colors of 340-610, where the hashed solve
    // order took 20, down to colors of 15 and of 1 constraint (each a stage of its own in every pass)
    const uint32_t numActive = uint32_t(mBodyColors.size());
    const int indexBits = std::max(1, int(std::bit_width(numActive)));
    mColorVisit.resize(size);
    for (uint32_t i = 0; i < size; ++i)
    {
        const uint32_t indexA = uint32_t(ioRecord.mBodyPairs[i] >> 32),
                       indexB = uint32_t(ioRecord.mBodyPairs[i]);
        const uint32_t low = std::min(indexA, indexB), high = std::max(indexA, indexB);
        mColorVisit[i] = {uint64_t(low) << indexBits | (high == UINT32_MAX ? numActive : high), i};
    }
    RadixSort(
        std::span<ColorItem>(mColorVisit), mColorItemsScratch,
        [](const ColorItem& inItem) { return inItem.mKey; }, 2 * indexBits);
    for (const ColorItem& visit : mColorVisit)
    {
        const uint32_t i = visit.mPosition;
        const uint32_t indexA = uint32_t(ioRecord.mBodyPairs[i] >> 32),
                       indexB = uint32_t(ioRecord.mBodyPairs[i]);
        const bool dynamicA = indexA != UINT32_MAX, dynamicB = indexB != UINT32_MAX;
        const uint64_t taken = (dynamicA ? mBodyColors[indexA] : 0) | (dynamicB ? mBodyColors[indexB] : 0);
        const uint32_t color = taken == ~uint64_t(0) ? cSerialColor : uint32_t(std::countr_zero(~taken));
        if (color != cSerialColor)
        {
            if (dynamicA) mBodyColors[indexA] |= uint64_t(1) << color;
            if (dynamicB) mBodyColors[indexB] |= uint64_t(1) << color;
        }
        // Within a color the order changes nothing (no two constraints share a dynamic body): by lowest
        // dynamic body, so that one contiguous part per thread gives each thread the same region of the
        // island in every color, and a body's velocities stay in one core's cache
        mColorItems[i] = {uint64_t(color) << 32 | std::min(indexA, indexB), i};
        ++count[color];
    }
    for (const uint64_t pair : ioRecord.mBodyPairs)
        for (const uint32_t activeIndex : {uint32_t(pair >> 32), uint32_t(pair)})
            if (activeIndex != UINT32_MAX) mBodyColors[activeIndex] = 0;
    // Keys computed once: the sort does not chase the constraints' body pointers. The items are in position
    // order, so a stable sort by key gives the (key, position) order. Radix: a key has few significant bytes
    // (the color and an active index), and the digit passes that are the same for all items are skipped
    static_assert(cSerialColor < 256, "the color must fit the key's 40 bits");
    RadixSort(
        std::span<ColorItem>(mColorItems), mColorItemsScratch,
        [](const ColorItem& inItem) { return inItem.mKey; }, 40);
    ioRecord.mOrder.resize(size);
    for (uint32_t i = 0; i < size; ++i)
        ioRecord.mOrder[i] = mColorItems[i].mPosition;
}

} // namespace cairn::physics
