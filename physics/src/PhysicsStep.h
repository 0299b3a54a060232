#pragma once

// PhysicsStep: the work of one collision step, and the scratch memory it reuses from step to step (so a warm
// scene allocates nothing). Owned by PhysicsSystem; runs on the thread that called Update, which holds every
// body mutex for the whole step: nothing here takes a lock except the broad phase's own.
//
// With a job system, the parallel phases run on its threads (ParallelFor; the updating thread takes part):
// velocities, pair finding (per active body), the narrow phase (per chunk of pairs), islands (largest first),
// bounds and the broad-phase notify. The broad-phase update runs as a job of its own beside the velocities,
// the pair finding and the narrow phase when the broad phase allows it (BroadPhaseUpdate in the .cpp). Each
// parallel task writes only its own bodies or its own chunk's output; everything shared (the constraint list,
// the contact cache, the active list, waking) is merged afterwards in pair order: the updating thread wakes
// bodies and reserves each chunk's places in the constraint list and the contact cache, then the chunks are
// copied into their places in parallel. Results do not depend on the number of threads or their timing.

#include "cairn/jobs/JobSystem.h"
#include "cairn/physics/PhysicsSettings.h"
#include "cairn/physics/StepStatistics.h"
#include "cairn/physics/body/BodyManager.h"
#include "cairn/physics/broadphase/BroadPhase.h"
#include "cairn/physics/islands/AtomicUnionFind.h"
#include "cairn/physics/solver/ContactCache.h"
#include "cairn/physics/solver/ContactConstraint.h"
#include "cairn/physics/solver/SolverBody.h"
#include "solver/WideContactSolver.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <vector>

namespace cairn
{

class PhysicsStep
{
public:
    PhysicsStep(const PhysicsSettings& inSettings, const LayerSetup& inLayers, BodyManager& ioBodies,
                BroadPhase& ioBroadPhase);

    /// One collision step of inDeltaTime seconds; adds its figures to ioStatistics. ioJobs (may be null: all
    /// on this thread) runs the parallel phases.
    void Run(float inDeltaTime, StepStatistics& ioStatistics, jobs::JobSystem* ioJobs);
    /// See PhysicsSystem::IsContactCacheConsistent.
    bool IsContactCacheConsistent() const { return mContactCache.IsConsistent(); }

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
            mNumWarmStartedPoints = 0;
            mNumContactPoints = 0;
        }
    };

    /// Work below which a loop does not wake a sleeping worker. A worker sleeps after 50 us without work (a
    /// game's worker between two frames' steps) and takes tens of microseconds to wake on this machine's
    /// hypervisor, while the loop waits for its part: the demo's step (about 30 awake bodies, 40 pairs) spent
    /// 0.09 ms of its 0.4 ms in its two parallel loops' hand-offs. An awake worker (back-to-back loops, as in
    /// the step benchmarks) costs a few microseconds: any loop of more than one chunk is handed out then.
    static constexpr uint32_t cMinWakingNanoseconds = 50'000;
    /// inTotal spread over inItems (0 for none), saturated: a step of millions of constraints must not wrap.
    static uint32_t PerItem(uint64_t inTotal, size_t inItems)
    {
        return inItems == 0 ? 0 : uint32_t(std::min<uint64_t>(inTotal / inItems, UINT32_MAX));
    }
    /// inBody(begin, end) over [0, inCount) in chunks of inGrain: on the job system's threads, unless a
    /// worker sleeps and the items' estimated cost (inItemNanoseconds each, measured on pile2k on one
    /// thread) is under cMinWakingNanoseconds; else here.
    template <class Body>
    void ParallelFor(uint32_t inCount, uint32_t inGrain, uint32_t inItemNanoseconds, const Body& inBody)
    {
        if (mJobs != nullptr && inCount > inGrain &&
            (mJobs->GetNumWorkersAsleep() == 0 ||
             uint64_t(inCount) * inItemNanoseconds >= cMinWakingNanoseconds))
            mJobs->ParallelFor(inCount, inGrain, inBody);
        else if (inCount > 0)
            for (uint32_t begin = 0; begin < inCount; begin += inGrain)
                inBody(begin, std::min(inCount, begin + inGrain));
    }

    /// Before a serial stretch of about inNanoseconds that a parallel loop follows: the workers spinning idle
    /// spin through it (JobSystem::ExtendSpin) instead of falling asleep halfway, so that the loop does not
    /// begin with tens of microseconds of waking one. A stretch under half the spin is left alone (a small
    /// step's): a worker that spins now most likely still spins at its end, and no extension is paid for.
    void KeepWorkersSpinningFor(uint64_t inNanoseconds) const
    {
        if (mJobs != nullptr && mJobs->GetNumThreads() > 1 &&
            inNanoseconds >= uint64_t(jobs::JobSystem::cSpinMicroseconds) * 500)
            mJobs->ExtendSpin(inNanoseconds);
    }

    /// Runs inNumStages stages in order, every thread of the job system on each: stage s has inPartsOf(s)
    /// parts (1 to the thread count) and inRunPart(s, part, parts) does one. A stage starts only when every
    /// part of the one before has finished: the threads wait on a counter, not on a job per part (a colored
    /// island's velocity iterations are a stage per color per iteration, over a hundred a step). Thread t
    /// takes part t first, so it keeps its region of the island in every color; a part whose thread has not
    /// come yet is taken by another, so no thread waits for one that the job system has not started. Which
    /// thread runs a part changes nothing in the results. Called by the updating thread, outside any job;
    /// or with inAlone, by any thread: it then runs every part itself, in order (a job that solves its island
    /// by itself).
    template <class PartsOf, class RunPart>
    void RunStages(bool inAlone, uint32_t inNumStages, const PartsOf& inPartsOf, const RunPart& inRunPart)
    {
        static_assert(jobs::JobSystem::cMaxThreads <= 64, "a stage's claims are one bit per part in 64");
        const uint32_t threads = mJobs == nullptr || inAlone ? 1 : mJobs->GetNumThreads();
        if (threads <= 1)
        {
            for (uint32_t stage = 0; stage < inNumStages; ++stage)
                for (uint32_t part = 0, parts = inPartsOf(stage); part < parts; ++part)
                    inRunPart(stage, part, parts);
            return;
        }
        if (mStageCapacity < inNumStages)
        {
            mStages = std::make_unique<StageCounters[]>(inNumStages);
            mStageCapacity = inNumStages;
        }
        for (uint32_t stage = 0; stage < inNumStages; ++stage)
        {
            // Relaxed: the helper jobs are scheduled below, and scheduling orders these stores before them
            mStages[stage].mClaimed.store(0, std::memory_order_relaxed);
            mStages[stage].mDone.store(0, std::memory_order_relaxed);
        }
        auto team = [&](uint32_t inThread)
        {
            for (uint32_t stage = 0; stage < inNumStages; ++stage)
            {
                const uint32_t parts = inPartsOf(stage);
                StageCounters& counters = mStages[stage];
                auto tryRun = [&](uint32_t inPart)
                {
                    const uint64_t bit = uint64_t(1) << inPart;
                    // Relaxed: a claim only decides who runs the part; the data the part reads was ordered by
                    // the previous stage's completion (the acquire below)
                    if ((counters.mClaimed.load(std::memory_order_relaxed) & bit) != 0 ||
                        (counters.mClaimed.fetch_or(bit, std::memory_order_relaxed) & bit) != 0)
                        return;
                    inRunPart(stage, inPart, parts);
                    // Release: the part's writes happen before the reads of whoever sees the stage complete
                    counters.mDone.fetch_add(1, std::memory_order_release);
                };
                if (inThread < parts) tryRun(inThread);
                for (uint32_t part = 0; part < parts; ++part)
                    if (part != inThread) tryRun(part);
                // Acquire: pairs with every part's release, so the next stage sees all of this one's writes
                for (uint32_t spins = 0; counters.mDone.load(std::memory_order_acquire) < parts; ++spins)
                    WaitABit(spins);
            }
        };
        jobs::JobHandle handles[jobs::JobSystem::cMaxThreads];
        for (uint32_t thread = 1; thread < threads; ++thread)
            handles[thread] = mJobs->Schedule("stages", [&team, thread] { team(thread); });
        team(0);
        mJobs->WaitAll({handles + 1, threads - 1});
    }
    /// The job system's ParallelFor, or all on this thread when inAlone (inside a job that solves its island
    /// by itself). No cost estimate: these loops are parts of a colored island solved by every thread, whose
    /// threads have just left the stages before (awake).
    template <class Body>
    void ParallelForUnlessAlone(bool inAlone, uint32_t inCount, uint32_t inGrain, const Body& inBody)
    {
        if (!inAlone && mJobs != nullptr && inCount > inGrain)
            mJobs->ParallelFor(inCount, inGrain, inBody);
        else if (inCount > 0)
            inBody(0u, inCount);
    }
    /// Parts for inCount items with at least inMinPerPart in each (below that a part costs more than it
    /// saves), at most one per thread.
    uint32_t PartsFor(uint32_t inCount, uint32_t inMinPerPart) const
    {
        return mJobs == nullptr ? 1 : std::min(mJobs->GetNumThreads(), std::max(1u, inCount / inMinPerPart));
    }
    /// A pause while another thread finishes its part: a CPU hint at first, then a yield of the time slice
    /// (two cores: the other part's thread may be waiting for this core).
    static void WaitABit(uint32_t inSpins);

    /// Wakes the sleeping islands of bodies that were woken from outside the step since the last one.
    void WakeIslandsOfWokenBodies();
    void ApplyForces(std::span<const uint32_t> inBodies, float inDeltaTime);
    /// Finds pairs for active-list entries [inBegin, end) and collides them; may activate more bodies.
    void CollideNewlyActive(size_t inBegin, float inDeltaTime);
    /// Finds the pairs of active-list entries [inBegin, end) into mPairs, sorted.
    void FindPairs(size_t inBegin);
    void CollidePair(Body& ioA, Body& ioB, float inDeltaTime, NarrowPhaseChunk& ioOut);
    /// World inverse inertia of a body at the start of the step: zero unless dynamic.
    Mat3 InverseInertiaOf(const Body& inBody) const;
    /// Adds last step's manifolds of the pair if its relative pose has barely changed since they were made;
    /// false if the shapes must be collided. ioRecord: the pose recorded with them.
    bool ReuseManifolds(Body& ioA, Body& ioB, float inDeltaTime, CachedBodyPair& ioRecord,
                        NarrowPhaseChunk& ioOut) const;
    /// inPrevious: last step's manifold with the same key (for the warm start), or null. inTakenOver: the
    /// manifold was made from inPrevious by ReuseManifolds (same points, in the same order).
    void AddConstraint(Body& ioA, Body& ioB, const ContactManifold& inManifold, float inDeltaTime,
                       const CachedManifold* inPrevious, NarrowPhaseChunk& ioOut,
                       bool inTakenOver = false) const;
    /// Finalizes the islands (numbered by lowest body) and groups the constraints by island: O(N).
    void BuildIslands();
    /// The solver's order: hashed within each island; large islands colored. Counted as solver time.
    void OrderConstraints();
    /// Integrates kinematic bodies and solves every island: the colored ones that hold a quarter of the step
    /// first, each by all threads; then the others at once, largest first (colored ones among them by one
    /// thread each).
    void SolveIslands(float inDeltaTime);
    /// An island's constraints, in solve order once OrderConstraints has run.
    std::span<ContactConstraint* const> ConstraintsOf(uint32_t inIsland) const
    {
        return {mIslandConstraints.data() + mConstraintStart[inIsland],
                mIslandConstraints.data() + mConstraintStart[inIsland + 1]};
    }
    /// An island's position constraints (mPositionConstraints), in solve order.
    std::span<const PositionConstraint> PositionConstraintsOf(uint32_t inIsland) const
    {
        return {mPositionConstraints.data() + mConstraintStart[inIsland],
                mPositionConstraints.data() + mConstraintStart[inIsland + 1]};
    }
    /// The constraints of color inColor (of the colored islands), in solve order.
    std::span<ContactConstraint* const> ColorConstraints(uint32_t inColor) const
    {
        return {mIslandConstraints.data() + mColorStart[inColor],
                mIslandConstraints.data() + mColorStart[inColor + 1]};
    }
    /// Part inPart of inItems cut into inParts contiguous parts of (nearly) equal size.
    template <class T> static std::span<T> PartOf(std::span<T> inItems, uint32_t inPart, uint32_t inParts)
    {
        const size_t begin = inPart * inItems.size() / inParts, end = (inPart + 1) * inItems.size() / inParts;
        return inItems.subspan(begin, end - begin);
    }
    void SolveIsland(uint32_t inIsland, float inDeltaTime);
    /// Solves two to four small islands (at most cGroupMaxConstraints constraints each) together, one per
    /// lane of the wide solver, with the same results as SolveIsland on each; inPaddingFirst: the group's
    /// padding blocks.
    void SolveIslandGroup(std::span<const uint32_t> inIslands, uint32_t inPaddingFirst, float inDeltaTime);
    /// An island's restitution pass, integration, position iterations and impulse store, after its
    /// velocities.
    void FinishIsland(uint32_t inIsland, float inDeltaTime);
    /// Orders a large island's constraints by color: within a color no two constraints share a dynamic body.
    void ColorIsland(uint32_t inIsland);
    struct ColoringRecord;
    /// The greedy coloring of ioRecord.mBodyPairs: fills its order and counts.
    void ComputeColoring(ColoringRecord& ioRecord);
    /// Solves a colored island with every thread: each color's constraints in parallel, the colors in turn;
    /// or, inAlone, on this thread only (the same results: within a color the order changes nothing).
    void SolveColoredIsland(uint32_t inIsland, float inDeltaTime, bool inAlone);
    /// The velocity iterations of a colored island whose colors are [inFirstColor, inLastColor], four
    /// manifolds at a time (WideContactSolver), on constraints that were not copied (see SolveIslands): this
    /// also gives them their solver blocks and position constraints. inStoreImpulses: store the impulses in
    /// the contact cache straight from the batches (no restitution pass follows); else unpack them.
    void SolveColoredVelocitiesWide(uint32_t inFirstColor, uint32_t inLastColor, bool inStoreImpulses,
                                    bool inAlone);
    /// Binds constraint inIndex of mIslandConstraints to its solver blocks and makes its position constraint.
    void PrepareForSolve(uint32_t inIndex, uint32_t inNumActive);
    /// Stores the constraints' impulses in the contact cache for next step's warm start.
    void StoreImpulses(std::span<ContactConstraint* const> inConstraints);
    void IntegratePositions(Body& ioBody, float inDeltaTime);
    static void LoadSolverBody(const Body& inBody, SolverBody& outBlock);
    /// Where the solver finds inBody's velocities: its active index if dynamic, else inPrivateBlock (loaded).
    uint32_t SolverBodyIndex(const Body& inBody, uint32_t inPrivateBlock);
    /// Copies a dynamic body's solved velocities back and integrates its position (others: nothing).
    void StoreVelocitiesAndIntegrate(Body& ioBody, float inDeltaTime);
    void UpdateBoundsAndSleep(float inDeltaTime);

    const PhysicsSettings& mSettings;
    const LayerSetup& mLayers;
    BodyManager& mBodies;
    BroadPhase& mBroadPhase;

    ContactCache mContactCache;
    AtomicUnionFind mIslands;            ///< Linked by the narrow phase's threads as they find contacts
    jobs::JobSystem* mJobs = nullptr;    ///< During Run only
    std::vector<BodyPair> mPairs;        ///< Scratch: pairs of the slice being collided
    std::vector<BodyPair> mPairsScratch; ///< Scratch: the radix sort's second buffer
    /// Pairs found by one chunk of active bodies; cache-line aligned for the same reason as NarrowPhaseChunk.
    struct alignas(64) PairChunk
    {
        std::vector<BodyPair> mPairs;
    };
    std::vector<PairChunk> mPairChunks;               ///< Scratch: per chunk of active bodies
    std::vector<NarrowPhaseChunk> mNarrowPhaseChunks; ///< Scratch: per chunk of pairs
    std::vector<uint32_t> mIslandOrder;               ///< Scratch: islands, largest first
    std::vector<uint32_t> mIslandSizeStart;           ///< Scratch: the counting sort of mIslandOrder
    /// Islands with this many constraints or more are colored (with the wide solver; without it, only those
    /// that also hold cColoredIslandMinShare of the step), whatever the number of threads, so results do not
    /// depend on it. Those with a quarter of the step are solved by all threads together: one large island
    /// must not serialise the step
    static constexpr uint32_t cColoredIslandMinConstraints = 128;
    /// The solve-order sort of an island and the sort of the pair list use RadixSort from this many items
    /// (std::sort below; the coloring, only for large islands, always uses RadixSort).
    static constexpr size_t cRadixSortMinItems = 256;
    static constexpr uint32_t cColoredIslandMinShare = 4; ///< ... and at least 1/4 of the step's constraints
    static constexpr uint32_t cSerialColor =
        64; ///< Constraints that found no free color among 64: solved alone
    std::vector<uint32_t>
        mColoredIslands; ///< This step's colored islands solved by all threads, largest first
    /// This step's other islands that have constraints, largest first; and the active indices of the bodies
    /// alone in an island without any (falling, flying): they only integrate, many to a chunk
    std::vector<uint32_t> mSolvedIslands;
    /// A unit of the other islands' solve: one island (mGroup = UINT32_MAX) or up to four small ones solved
    /// together (SolveIslandGroup), mCount islands of mSolvedIslands from mFirst.
    struct SolveItem
    {
        uint32_t mFirst;
        uint32_t mCount;
        uint32_t mGroup; ///< Which group's padding blocks
    };
    std::vector<SolveItem> mSolveItems;
    std::vector<uint32_t> mSmallIslands; ///< Scratch for OrderConstraints: the islands solved in groups
    uint32_t mNumIslandGroups = 0;
    /// An island with at most this many constraints is solved in a group of cGroupIslands, one per SSE lane.
    static constexpr uint32_t cGroupMaxConstraints = 4;
    static constexpr uint32_t cGroupIslands = 4;
    std::vector<uint32_t> mUnconstrainedBodies;
    std::vector<uint32_t> mIslandFirstColor; ///< Per island: first entry in mColorStart (colored ones)
    std::vector<uint32_t>
        mColorStart; ///< Offsets into mIslandConstraints; a color ends where the next starts
    std::vector<uint8_t> mColorIsSerial; ///< Per mColorStart entry: 1 for the range of uncolored constraints
    /// Per mColorStart entry: the color's first batch of four in mWideBatches (the end marker: the island's
    /// end). Every colored island has its own slice, so islands solved alone at once never share batches
    std::vector<uint32_t> mColorFirstBatch;
    uint32_t mNumWideBatches = 0;      ///< The step's wide batches, all colored islands together
    std::vector<uint64_t> mBodyColors; ///< Scratch per active body: colors its constraints took
    /// What the island grouping, the solve-order sort and the coloring need of each constraint of
    /// mConstraints, gathered by the merge's parallel copies: read through the constraint pointers (640 bytes
    /// each, scattered over the chunks), these single-threaded passes took a cache miss per constraint.
    struct ConstraintInfo
    {
        uint64_t mOrderKey;   ///< ContactConstraint::mOrderKey
        uint32_t mCacheIndex; ///< ContactConstraint::mCacheIndex
        uint32_t mBodyA;      ///< Active index of A if it is dynamic, else UINT32_MAX
        uint32_t mBodyB;      ///< Likewise for B (at least one of them is dynamic)
        uint32_t mBounces;    ///< 1 if the constraint has restitution
    };
    std::vector<ConstraintInfo> mConstraintInfo; ///< Per entry of mConstraints
    std::vector<uint32_t> mConstraintIsland;     ///< Scratch for BuildIslands: per entry of mConstraints
    uint32_t mNumContactPoints = 0;              ///< Counter of the running step
    /// Whether this step's contact-cache entries are in key order, as they nearly always are (the pairs are
    /// collided in sorted order): then ContactCache::EndStep has nothing to do. Checked by the merge, the
    /// chunks' own entries in parallel and where chunks (and rounds) meet here, from the last entry so far.
    bool mCacheInOrder = true;
    std::optional<std::pair<BodyID, BodyID>> mLastCachedPair;
    std::optional<ContactKey> mLastCachedKey;
    static std::pair<BodyID, BodyID> PairKeyOf(const CachedBodyPair& inPair)
    {
        return {inPair.mBodyA, inPair.mBodyB};
    }
    struct OrderItem
    {
        uint64_t mOrderKey;
        uint32_t mCacheIndex; ///< Tie-break (unique)
        uint32_t mConstraint; ///< Index into mConstraints and mConstraintInfo
        bool operator==(const OrderItem&) const = default;
    };
    /// Per entry of mIslandConstraints once sorted (until ColorIsland reorders a colored island's entries);
    /// kept for the next step, whose sort input may be the same (OrderConstraints)
    std::vector<OrderItem> mOrderItems;
    /// The sort's input: each island's items in constraint order (BuildIslands); and the input that
    /// mOrderItems holds sorted, with its islands' starts
    std::vector<OrderItem> mUnsortedOrderItems;
    std::vector<OrderItem> mSortedOrderItemsInput;
    std::vector<uint32_t> mSortedOrderItemsStarts;
    bool mSolveOrderReused = false;       ///< This step's (statistics)
    std::vector<OrderItem> mOrderScratch; ///< Scratch: the radix sort's second buffer
    struct ColorItem
    {
        uint64_t mKey;      ///< color << 32 | lowest dynamic active index (the visit order: both bodies)
        uint32_t mPosition; ///< In the island's hashed order
    };
    std::vector<ColorItem> mColorItems;            ///< Scratch per constraint of the island being colored
    std::vector<ColorItem> mColorVisit;            ///< Scratch: the coloring's visit order (bodies, position)
    std::vector<ColorItem> mColorItemsScratch;     ///< Scratch: the radix sort's second buffer
    std::vector<ContactConstraint*> mColorScratch; ///< Scratch: the island's constraints reordered
    /// A coloring, kept for the next step: a resting pile's largest island has the same constraints between
    /// the same bodies in most steps, and its coloring (greedy, then a sort) is serial work
    struct ColoringRecord
    {
        std::vector<uint64_t> mBodyPairs; ///< Per constraint in solve order: active index A << 32 | B
        std::vector<uint32_t> mOrder;     ///< Island positions in color order
        std::array<uint32_t, cSerialColor + 1> mCount{}; ///< Constraints per color
    };
    /// The records of this step [0, mNumColorings[mCurrentColorings]) and of the previous one (the other
    /// index); kept allocated. Physics step thread (OrderConstraints)
    std::array<std::vector<ColoringRecord>, 2> mColorings;
    std::array<uint32_t, 2> mNumColorings{};
    uint32_t mCurrentColorings = 0;
    uint32_t mNumColoringsReused = 0;             ///< This step's (statistics; colored islands: its records)
    std::vector<ContactConstraint*> mConstraints; ///< This step's contacts, in the narrow phase's chunks
    uint32_t mNumChunksUsed = 0;                  ///< Narrow-phase chunks used by this step's rounds
    struct alignas(64) StageCounters
    {
        std::atomic<uint64_t> mClaimed; ///< Bit per part: taken by a thread
        std::atomic<uint32_t> mDone;    ///< Parts finished
    };
    std::unique_ptr<StageCounters[]> mStages; ///< RunStages' counters; threads: see RunStages
    uint32_t mStageCapacity = 0;
    std::vector<uint8_t> mIslandBounces;    ///< Per island: 1 if a constraint has restitution (BuildIslands)
    std::vector<uint32_t> mConstraintStart; ///< Per island offsets into mIslandConstraints
    /// Constraints grouped by island: into mSolveOrder, or into the narrow phase's chunks for the colored
    /// islands that the wide solver packs
    std::vector<ContactConstraint*> mIslandConstraints;
    std::vector<ContactConstraint> mSolveOrder; ///< The other islands' constraints copied in solve order
    /// Ranges of mIslandConstraints copied into mSolveOrder, each one task of the copy
    std::vector<std::pair<uint32_t, uint32_t>> mCopyRanges;
    std::vector<PositionConstraint> mPositionConstraints; ///< Per entry of mIslandConstraints
    std::vector<Mat3> mInverseInertia; ///< Per active dynamic body: world inverse inertia, from ApplyForces
    std::vector<SolverBody> mSolverBodies; ///< Velocities being solved: see SolveIslands
#if CAIRN_WIDE_SOLVER
    /// The colored islands' packed constraints (see mColorFirstBatch). Each island's slice is written by the
    /// thread that solves it alone, or by all threads in parts of a color between two stages of RunStages
    std::vector<WideContactBatch> mWideBatches;
#endif
    uint32_t mPaddingBlocksFirst = 0; ///< In mSolverBodies: WideContactSolver::cPaddingBlocks per color
    std::vector<BroadPhaseBody> mMovedBodies; ///< Scratch for the broad-phase notify
    /// When the finish publishes an active body's pose, against its broad-phase move (UpdateBoundsAndSleep)
    enum class PublishOrder : uint8_t
    {
        BeforeMove,     ///< Its new bounds lie inside the box the broad phase holds for it
        AfterMove,      ///< Its new box covers its published bounds
        AfterGrownMove, ///< Its box is grown over its published bounds until then, and shrunk after
    };
    std::vector<PublishOrder> mPublishOrders; ///< Scratch, by active index
    /// This step's waits for locks (LockWaits), added by whichever of its threads waited. Relaxed: a sum,
    /// read by the stepping thread after it waited for every job that adds to it
    std::atomic<uint64_t> mLockWaitNanoseconds{0};
    std::vector<uint32_t> mSleepingIslands; ///< Scratch
    uint32_t mNumBodyPairs = 0;             ///< Counters of the running step
    uint32_t mNumWarmStartedPoints = 0;
    uint32_t mNumReusedPairs = 0;
    float mPairCacheCosHalfMaxAngle =
        1.0f; ///< cos(mPairCacheMaxDeltaAngle / 2): compared to a quaternion dot
};

} // namespace cairn
