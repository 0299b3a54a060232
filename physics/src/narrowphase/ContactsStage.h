#pragma once

// ContactsStage: from the active bodies to the step's contact constraints. Each round of the step runs its
// three parts in order: FindPairs (the broad phase's pairs of the round's bodies, sorted), CollidePairs (the
// narrow phase: manifolds, warm starts and island links, chunks of pairs in parallel, each into its own
// output) and Merge (in pair order, on the updating thread: wakes the sleeping bodies touched, places every
// chunk's constraints and cache entries, then copies them in parallel). Bodies the merge wakes make the next
// round. Results do not depend on the number of threads or their timing.
//
// Threads: the methods on the updating thread; their loops on the step's jobs, each writing only its own
// chunk's output, the island links (lock-free) and the contact cache entries the merge gave it.

#include "cairn/physics/body/Body.h"
#include "math/UninitializedAllocator.h"
#include "narrowphase/ContactEventRecorder.h"
#include "solver/ContactCache.h"
#include "solver/ContactConstraint.h"

#include <cstdint>
#include <optional>
#include <span>
#include <utility>
#include <vector>

namespace cairn::physics
{

struct StepContext;
class Integration;
struct ContactManifold;

/// What the islands stage, the ordering and the coloring need of each constraint, gathered by the merge's
/// parallel copies: read through the constraint pointers (640 bytes each, scattered over the chunks), those
/// single-threaded passes took a cache miss per constraint.
struct ConstraintInfo
{
    uint64_t mOrderKey;   ///< ContactConstraint::mOrderKey
    uint32_t mCacheIndex; ///< ContactConstraint::mCacheIndex
    uint32_t mBodyA;      ///< Active index of A if it is dynamic, else UINT32_MAX
    uint32_t mBodyB;      ///< Likewise for B (at least one of them is dynamic)
    uint32_t mBounces;    ///< 1 if the constraint has restitution
};

class ContactsStage
{
public:
    /// This step's counts, for StepStatistics.
    struct Counts
    {
        uint32_t mNumBodyPairs = 0;
        uint32_t mNumWarmStartedPoints = 0;
        uint32_t mNumReusedPairs = 0;
        uint32_t mNumContactPoints = 0;
    };

    explicit ContactsStage(float inPairCacheMaxDeltaAngle);

    void BeginStep();
    /// The pairs of active-list entries [inBegin, end), sorted: the round's pairs.
    void FindPairs(const StepContext& inContext, size_t inBegin);
    /// The narrow phase of the round's pairs; inIntegration holds the bodies' world inertia.
    void CollidePairs(const StepContext& inContext, const Integration& inIntegration);
    /// Merges the round's chunks in pair order; wakes the bodies touched (they join the active list) and
    /// links them into the islands.
    void Merge(const StepContext& inContext);

    /// This step's contacts, in the narrow phase's chunks; and what the islands stage needs of each.
    std::span<ContactConstraint* const> GetConstraints() const { return mConstraints; }
    std::span<const ConstraintInfo> GetConstraintInfo() const { return mConstraintInfo; }
    /// Whether this step's contact-cache entries are in key order (ContactCache::EndStep).
    bool IsCacheInOrder() const { return mCacheInOrder; }
    const Counts& GetCounts() const { return mCounts; }
    /// This step's sensor overlaps (ContactEventRecorder), in pair order within each round.
    std::span<const SensorOverlap> GetSensorOverlaps() const { return mSensorOverlaps; }

private:
    struct BodyPair
    {
        uint32_t mA; ///< Body indices, mA < mB
        uint32_t mB;
    };
    /// What the narrow phase of one chunk of pairs produced, merged in chunk order afterwards. Cache-line
    /// aligned: neighbouring chunks run on different threads at once, and every append writes the vectors'
    /// ends (sharing lines, the chunks' threads took them from each other all through the narrow phase).
    struct alignas(64) NarrowPhaseChunk
    {
        std::vector<ContactConstraint> mConstraints; ///< mCacheIndex set at the merge
        std::vector<CachedManifold> mCached;         ///< One per constraint
        std::vector<CachedBodyPair> mCachedPairs;    ///< One per pair collided, with its count of constraints
        std::vector<uint32_t> mToWake;               ///< Sleeping dynamic bodies touched, in pair order
        std::vector<BodyPair> mDeferredLinks;        ///< Island links with a body woken at the merge
        std::vector<SensorOverlap> mSensorOverlaps;  ///< Dynamic bodies overlapping sensors, in pair order
        uint32_t mNumWarmStartedPoints = 0;
        uint32_t mNumReusedPairs = 0;
        uint32_t mNumContactPoints = 0;
        uint32_t mPreviousPairHint = 0; ///< See ContactCache::FindPreviousPair
        uint32_t mFirstCachedPair = 0;  ///< Set at the merge: where its pairs go in the contact cache
        uint32_t mFirstManifold = 0;    ///< Set at the merge: the first of its manifolds in this step's order
        bool mInOrder = true; ///< Set by the merge's copy: its cache entries are in the cache's key order
        void Clear()
        {
            mPreviousPairHint = 0;
            mConstraints.clear();
            mCached.clear();
            mCachedPairs.clear();
            mNumReusedPairs = 0;
            mToWake.clear();
            mDeferredLinks.clear();
            mSensorOverlaps.clear();
            mNumWarmStartedPoints = 0;
            mNumContactPoints = 0;
        }
    };
    /// Pairs found by one chunk of active bodies; cache-line aligned for the same reason as NarrowPhaseChunk.
    struct alignas(64) PairChunk
    {
        std::vector<BodyPair> mPairs;
    };

    /// The pair's manifolds (reused or collided) into ioOut, its island link and the bodies it wakes.
    void CollidePair(const StepContext& inContext, const Integration& inIntegration, Body& ioA, Body& ioB,
                     NarrowPhaseChunk& ioOut) const;
    /// A pair with a sensor: whether the two overlap (no constraints).
    void CollideSensor(Body& ioA, Body& ioB, NarrowPhaseChunk& ioOut) const;
    /// Adds last step's manifolds of the pair if its relative pose has barely changed since they were made;
    /// false if the shapes must be collided. ioRecord: the pose recorded with them.
    bool ReuseManifolds(const StepContext& inContext, const Integration& inIntegration, Body& ioA, Body& ioB,
                        CachedBodyPair& ioRecord, NarrowPhaseChunk& ioOut) const;
    /// inPrevious: last step's manifold with the same key (for the warm start), or null. inTakenOver: the
    /// manifold was made from inPrevious by ReuseManifolds (same points, in the same order).
    void AddConstraint(const StepContext& inContext, const Integration& inIntegration, Body& ioA, Body& ioB,
                       const ContactManifold& inManifold, const CachedManifold* inPrevious,
                       NarrowPhaseChunk& ioOut, bool inTakenOver = false) const;
    static std::pair<BodyID, BodyID> PairKeyOf(const CachedBodyPair& inPair)
    {
        return {inPair.mBodyA, inPair.mBodyB};
    }

    const float mPairCacheCosHalfMaxAngle; ///< cos(mPairCacheMaxDeltaAngle / 2): compared to a quaternion dot

    std::vector<BodyPair> mPairs;                     ///< Scratch: pairs of the round being collided
    std::vector<BodyPair> mPairsScratch;              ///< Scratch: the radix sort's second buffer
    std::vector<PairChunk> mPairChunks;               ///< Scratch: per chunk of active bodies
    std::vector<NarrowPhaseChunk> mNarrowPhaseChunks; ///< Scratch: per chunk of pairs, of every round
    uint32_t mFirstChunk = 0;                         ///< The round's first chunk in mNarrowPhaseChunks
    uint32_t mPairsPerChunk = 1; ///< The round's narrow-phase chunks (StepScheduler::GrainFor)
    uint32_t mNumChunksUsed = 0; ///< Narrow-phase chunks used by this step's rounds so far

    /// This step's contacts, in the narrow phase's chunks, and a record per entry. Grown by the merge on the
    /// updating thread and filled by its parallel copies, every entry: the growth writes nothing
    /// (UninitializedAllocator), where zeroing them was a serial pass over a quarter of a megabyte in a
    /// pyramid
    std::vector<ContactConstraint*, UninitializedAllocator<ContactConstraint*>> mConstraints;
    std::vector<ConstraintInfo, UninitializedAllocator<ConstraintInfo>> mConstraintInfo;
    Counts mCounts;
    std::vector<SensorOverlap> mSensorOverlaps; ///< This step's, from the merges
    /// Whether this step's contact-cache entries are in key order, as they nearly always are (the pairs are
    /// collided in sorted order): then ContactCache::EndStep has nothing to do. Checked by the merge, the
    /// chunks' own entries in parallel and where chunks (and rounds) meet here, from the last entry so far.
    bool mCacheInOrder = true;
    std::optional<std::pair<BodyID, BodyID>> mLastCachedPair;
    std::optional<ContactKey> mLastCachedKey;
};

} // namespace cairn::physics
