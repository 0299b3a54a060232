#include "narrowphase/ContactsStage.h"

#include "cairn/physics/LockWaits.h"
#include "math/RadixSort.h"
#include "step/StepContext.h"
#include "step/StepCosts.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace cairn::physics
{

namespace
{
/// The pair list's sort uses RadixSort from this many pairs (std::sort below).
constexpr size_t cRadixSortMinPairs = 256;
} // namespace

ContactsStage::ContactsStage(float inPairCacheMaxDeltaAngle)
    : mPairCacheCosHalfMaxAngle(std::cos(0.5f * inPairCacheMaxDeltaAngle))
{
}

void ContactsStage::BeginStep()
{
    mConstraints.clear();
    mConstraintInfo.clear();
    mNumChunksUsed = 0;
    mCounts = {};
    mSensorOverlaps.clear();
    mCacheInOrder = true;
    mLastCachedPair.reset();
    mLastCachedKey.reset();
}

void ContactsStage::FindPairs(const StepContext& inContext, size_t inBegin)
{
    const std::vector<uint32_t>& active = inContext.mActive;
    thread_local std::vector<BodyID> sliceIDs;
    sliceIDs.clear();
    for (size_t i = inBegin; i < active.size(); ++i)
        sliceIDs.push_back(inContext.BodyAt(active[i]).GetID());

    // Each chunk of active bodies collects its pairs apart; the chunk of a pair is that of its active body
    const uint32_t bodiesPerChunk = inContext.mScheduler.GrainFor(sliceIDs.size(), StepCosts::cPairs);
    const uint32_t numChunks = uint32_t((sliceIDs.size() + bodiesPerChunk - 1) / bodiesPerChunk);
    if (mPairChunks.size() < numChunks) mPairChunks.resize(numChunks);
    for (uint32_t chunk = 0; chunk < numChunks; ++chunk)
        mPairChunks[chunk].mPairs.clear();
    // Named: a FunctionRef only refers to its callable, which must outlive it (a temporary lambda would not)
    auto runRanges = [&](uint32_t inCount, FunctionRef<void(uint32_t, uint32_t)> inRange) {
        inContext.mScheduler.ParallelFor(inCount, bodiesPerChunk, StepCosts::cPairs.mItemNanoseconds,
                                         inRange);
    };
    const ParallelRanges ranges = runRanges;
    // A broad phase that cannot search during its update locks here (the global mutex). One that can takes no
    // lock, but this thread may run the queued update job inside the search (a helping wait), whose waits the
    // update counts itself: not counted here, or they would count twice
    const bool pairsMayWait = !inContext.mBroadPhase.CanFindPairsDuringUpdate();
    const uint64_t waitedBeforePairs = GetThisThreadLockWaitNanoseconds();
    inContext.mBroadPhase.FindCollidingPairs(
        sliceIDs, inContext.mLayers,
        [&](BodyID inActive, BodyID inOther)
        {
            const Body* self = inContext.mBodies.TryGetBody(inActive);
            const Body* other = inContext.mBodies.TryGetBody(inOther);
            // A body whose batch another thread is finalizing is already in the broad phase (the link is
            // lock-free) but not yet in the world: its adder waits for the body lock this step holds. It
            // takes part from the next step on. Pairs with bodies of an earlier round were collided then.
            if (self == nullptr || other == nullptr || !other->IsInWorld() ||
                (other->IsActive() && other->GetActiveIndex() < inBegin))
                return;
            mPairChunks[(self->GetActiveIndex() - inBegin) / bodiesPerChunk].mPairs.push_back(
                {std::min(inActive.GetIndex(), inOther.GetIndex()),
                 std::max(inActive.GetIndex(), inOther.GetIndex())});
        },
        &ranges);
    if (pairsMayWait)
        inContext.mLockWaitNanoseconds.fetch_add(GetThisThreadLockWaitNanoseconds() - waitedBeforePairs,
                                                 std::memory_order_relaxed); // See StepContext
    // The gathering and the sort are serial, the narrow phase's loop follows
    size_t numPairs = 0;
    for (uint32_t chunk = 0; chunk < numChunks; ++chunk)
        numPairs += mPairChunks[chunk].mPairs.size();
    inContext.mScheduler.KeepWorkersSpinningFor(numPairs * StepCosts::cPairSortNanoseconds);
    mPairs.clear();
    uint32_t largestIndex = 0; // Of the pairs' second bodies, the larger ones
    for (uint32_t chunk = 0; chunk < numChunks; ++chunk)
    {
        mPairs.insert(mPairs.end(), mPairChunks[chunk].mPairs.begin(), mPairChunks[chunk].mPairs.end());
        for (const BodyPair& pair : mPairChunks[chunk].mPairs)
            largestIndex = std::max(largestIndex, pair.mB);
    }
    // Canonical order: the same scene gives the same contacts whatever order the broad phase reports. Each
    // pair is reported once, so the keys are unique and the radix sort's order is the comparison's. The key
    // packs the two indices in as few bits as the largest needs: every bit above costs the radix sort a
    // count per pair, and every byte a pass
    const int indexBits = std::max(1, int(std::bit_width(largestIndex)));
    auto keyOf = [indexBits](const BodyPair& inPair) { return uint64_t(inPair.mA) << indexBits | inPair.mB; };
    if (mPairs.size() < cRadixSortMinPairs)
        std::sort(mPairs.begin(), mPairs.end(),
                  [&](const BodyPair& inL, const BodyPair& inR) { return keyOf(inL) < keyOf(inR); });
    else
        RadixSort(std::span<BodyPair>(mPairs), mPairsScratch, keyOf, 2 * indexBits);
    mCounts.mNumBodyPairs += uint32_t(mPairs.size());
}

void ContactsStage::CollidePairs(const StepContext& inContext, const Integration& inIntegration)
{
    // Chunks of pairs in parallel, each into its own output. Each round has chunks of its own: the
    // constraints stay where the narrow phase wrote them until the step ends (moving the chunk objects keeps
    // their buffers)
    mPairsPerChunk = inContext.mScheduler.GrainFor(mPairs.size(), StepCosts::cNarrowPhase);
    const uint32_t pairsPerChunk = mPairsPerChunk;
    const uint32_t numChunks = uint32_t((mPairs.size() + pairsPerChunk - 1) / pairsPerChunk);
    mFirstChunk = mNumChunksUsed;
    mNumChunksUsed += numChunks;
    if (mNarrowPhaseChunks.size() < mNumChunksUsed) mNarrowPhaseChunks.resize(mNumChunksUsed);
    inContext.mScheduler.ParallelFor(
        numChunks, 1, pairsPerChunk * StepCosts::cNarrowPhase.mItemNanoseconds,
        [&](uint32_t inB, uint32_t inE)
        {
            for (uint32_t chunk = inB; chunk < inE; ++chunk)
            {
                NarrowPhaseChunk& out = mNarrowPhaseChunks[mFirstChunk + chunk];
                out.Clear();
                const size_t last = std::min(mPairs.size(), size_t(chunk + 1) * pairsPerChunk);
                for (size_t p = size_t(chunk) * pairsPerChunk; p < last; ++p)
                    CollidePair(inContext, inIntegration, inContext.BodyAt(mPairs[p].mA),
                                inContext.BodyAt(mPairs[p].mB), out);
            }
        });
}

void ContactsStage::Merge(const StepContext& inContext)
{
    // In pair order: the same constraints, cache entries and wake order whatever the threads did. Here the
    // places and the wakes; the copies (a megabyte in a pyramid of 7,000 manifolds) in parallel
    const uint32_t firstChunk = mFirstChunk, numChunks = mNumChunksUsed - mFirstChunk;
    uint32_t numPairs = 0, numManifolds = 0;
    // Whether inItems' keys go on from the last one so far (ioLast), which becomes their last
    auto continuesInOrder = [&](const auto& inItems, const auto& inKeyOf, auto& ioLast)
    {
        if (inItems.empty()) return;
        if (ioLast.has_value() && inKeyOf(inItems.front()) < *ioLast) mCacheInOrder = false;
        ioLast = inKeyOf(inItems.back());
    };
    for (uint32_t chunk = 0; chunk < numChunks; ++chunk)
    {
        NarrowPhaseChunk& out = mNarrowPhaseChunks[firstChunk + chunk];
        out.mFirstCachedPair = numPairs;
        out.mFirstManifold = numManifolds;
        numPairs += uint32_t(out.mCachedPairs.size());
        numManifolds += uint32_t(out.mConstraints.size());
        // Touching an active body wakes a sleeping one
        for (uint32_t index : out.mToWake)
            if (Body& body = inContext.BodyAt(index); !body.IsActive()) inContext.mBodies.ActivateBody(body);
        mCounts.mNumWarmStartedPoints += out.mNumWarmStartedPoints;
        mCounts.mNumReusedPairs += out.mNumReusedPairs;
        mCounts.mNumContactPoints += out.mNumContactPoints;
        mSensorOverlaps.insert(mSensorOverlaps.end(), out.mSensorOverlaps.begin(), out.mSensorOverlaps.end());
        // The contact cache's order across chunks (and rounds); within each chunk the copies check it
        continuesInOrder(out.mCachedPairs, PairKeyOf, mLastCachedPair);
        continuesInOrder(
            out.mCached, [](const CachedManifold& inM) { return inM.mKey; }, mLastCachedKey);
    }
    ContactCache& cache = inContext.mContactCache;
    const uint32_t firstCachedPair = cache.AppendPairs(numPairs);
    const uint32_t firstCacheIndex = cache.AppendManifolds(numManifolds);
    const size_t firstConstraint = mConstraints.size();
    mConstraints.resize(firstConstraint + numManifolds);
    mConstraintInfo.resize(firstConstraint + numManifolds);
    inContext.mScheduler.ParallelFor(
        numChunks,
        std::max(1u, inContext.mScheduler.GrainFor(mPairs.size(), StepCosts::cMergeCopies) / mPairsPerChunk),
        mPairsPerChunk * StepCosts::cMergeCopies.mItemNanoseconds,
        [&](uint32_t inB, uint32_t inE)
        {
            for (uint32_t chunk = inB; chunk < inE; ++chunk)
            {
                NarrowPhaseChunk& out = mNarrowPhaseChunks[firstChunk + chunk];
                // Each pair's manifolds follow the ones before in the same order: where they start holds
                // once the cache is in key order (else EndStep finds them)
                uint32_t pairManifolds = firstCacheIndex + out.mFirstManifold;
                out.mInOrder = true;
                for (size_t i = 0; i < out.mCachedPairs.size(); ++i)
                {
                    CachedBodyPair& pair =
                        cache.GetPair(firstCachedPair + out.mFirstCachedPair + uint32_t(i));
                    pair = out.mCachedPairs[i];
                    pair.mFirstManifold = pairManifolds;
                    pairManifolds += pair.mNumManifolds;
                    if (i > 0 && PairKeyOf(pair) < PairKeyOf(out.mCachedPairs[i - 1])) out.mInOrder = false;
                }
                for (size_t i = 0; i < out.mConstraints.size(); ++i)
                {
                    if (i > 0 && out.mCached[i].mKey < out.mCached[i - 1].mKey) out.mInOrder = false;
                    const uint32_t place = out.mFirstManifold + uint32_t(i);
                    ContactConstraint& c = out.mConstraints[i];
                    c.mCacheIndex = firstCacheIndex + place;
                    cache.Get(c.mCacheIndex) = out.mCached[i];
                    mConstraints[firstConstraint + place] = &c;
                    // The bodies were woken (given active indices) above
                    auto activeIndex = [](const Body& inBody)
                    { return inBody.IsDynamic() ? inBody.GetActiveIndex() : UINT32_MAX; };
                    mConstraintInfo[firstConstraint + place] = {
                        c.mOrderKey, c.mCacheIndex, activeIndex(*c.mBodyA), activeIndex(*c.mBodyB),
                        c.mRestitution != 0.0f ? 1u : 0u};
                }
            }
        });
    for (uint32_t chunk = 0; chunk < numChunks; ++chunk)
        mCacheInOrder = mCacheInOrder && mNarrowPhaseChunks[firstChunk + chunk].mInOrder;
    inContext.mIslands.Grow(uint32_t(inContext.mActive.size())); // The woken bodies, before their links
    for (uint32_t chunk = 0; chunk < numChunks; ++chunk)
        for (const BodyPair& link : mNarrowPhaseChunks[firstChunk + chunk].mDeferredLinks)
            inContext.mIslands.Union(inContext.BodyAt(link.mA).GetActiveIndex(),
                                     inContext.BodyAt(link.mB).GetActiveIndex());
}

} // namespace cairn::physics
