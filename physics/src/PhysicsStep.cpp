#include "PhysicsStep.h"

#include "body/PublishedPoseStore.h"
#include "cairn/physics/LockWaits.h"
#include "cairn/physics/math/RadixSort.h"
#include "cairn/physics/narrowphase/CollideShapes.h"
#include "cairn/physics/solver/SequentialImpulseSolver.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <exception>
#include <thread>
#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace cairn
{

namespace
{
using Clock = std::chrono::steady_clock;

/// Starts fetching every cache line of a constraint (they lie scattered over the narrow phase's chunks).
void PrefetchConstraint(const ContactConstraint* inConstraint)
{
    const char* bytes = reinterpret_cast<const char*>(inConstraint);
    for (size_t offset = 0; offset < sizeof(ContactConstraint); offset += 64)
        __builtin_prefetch(bytes + offset);
}

double MillisecondsSince(Clock::time_point& ioStart)
{
    const Clock::time_point now = Clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - ioStart).count();
    ioStart = now;
    return ms;
}

/// A bijective 64-bit mix (the finaliser of MurmurHash3): neighbouring keys land far apart.
uint64_t MixBits(uint64_t inKey)
{
    inKey ^= inKey >> 33;
    inKey *= 0xff51afd7ed558ccdULL;
    inKey ^= inKey >> 33;
    inKey *= 0xc4ceb9fe1a85ec53ULL;
    inKey ^= inKey >> 33;
    return inKey;
}

/// A step's broad-phase update. With a job system of two or more threads, a broad phase whose pair search may
/// run during its update (BroadPhase::CanFindPairsDuringUpdate) and a scene large enough, it runs as a job
/// while the updating thread applies forces and finds pairs and contacts on the tree as it stands (queries
/// are exact in any state of the tree, so the pairs are the same); otherwise at once, on this thread. The job
/// is waited for by Finish, or by the destructor when the step leaves early (an exception): it must not
/// outlive the step's frame. What the job throws is caught there (a job must not throw) and rethrown by
/// Finish.
class BroadPhaseUpdate
{
public:
    /// Beside the step when inBeside (see PhysicsSettings::mUpdateBesideStepMinActiveBodies) and the job
    /// system and the broad phase allow it.
    BroadPhaseUpdate(BroadPhase& ioBroadPhase, jobs::JobSystem* ioJobs, bool inBeside)
        : mBroadPhase(ioBroadPhase), mJobs(inBeside && ioJobs != nullptr && ioJobs->GetNumThreads() > 1 &&
                                                   ioBroadPhase.CanFindPairsDuringUpdate()
                                               ? ioJobs
                                               : nullptr)
    {
        if (mJobs == nullptr)
        {
            Clock::time_point start = Clock::now();
            const uint64_t waited = GetThisThreadLockWaitNanoseconds();
            mBroadPhase.Update();
            mLockWaitNanoseconds = GetThisThreadLockWaitNanoseconds() - waited;
            mMilliseconds = MillisecondsSince(start);
            return;
        }
        mJob = mJobs->Schedule("broad-phase update",
                               [this]
                               {
                                   Clock::time_point start = Clock::now();
                                   const uint64_t waited = GetThisThreadLockWaitNanoseconds();
                                   try
                                   {
                                       mBroadPhase.Update();
                                   }
                                   catch (...)
                                   {
                                       mError = std::current_exception();
                                   }
                                   mLockWaitNanoseconds = GetThisThreadLockWaitNanoseconds() - waited;
                                   mMilliseconds = MillisecondsSince(start);
                               });
    }
    ~BroadPhaseUpdate()
    {
        if (mJobs != nullptr && !mFinished) mJobs->Wait(mJob);
    }
    BroadPhaseUpdate(const BroadPhaseUpdate&) = delete;
    BroadPhaseUpdate& operator=(const BroadPhaseUpdate&) = delete;

    /// Runs the update here if no other thread has started it yet: a worker that was awake took it within
    /// microseconds of its scheduling; a sleeping one takes tens of them to wake, and the update is better
    /// run here than waited for.
    void RunHereUnlessStarted()
    {
        if (mJobs != nullptr && !mFinished && mJobs->TryRunHere(mJob))
        {
            mFinished = true;
            if (mError) std::rethrow_exception(mError);
        }
    }
    /// Waits for the update (running it here if no other thread has started it); returns its duration in ms.
    double Finish()
    {
        if (mJobs != nullptr && !mFinished)
        {
            mJobs->Wait(mJob);
            mFinished = true;
            if (mError) std::rethrow_exception(mError);
        }
        return mMilliseconds;
    }
    /// How long the update waited for locks (its rebuild commit; the global-mutex broad phase's mutex). After
    /// Finish.
    uint64_t GetLockWaitNanoseconds() const { return mLockWaitNanoseconds; }

private:
    BroadPhase& mBroadPhase;
    jobs::JobSystem* mJobs;            ///< Null when the update ran in the constructor
    jobs::JobHandle mJob;              ///< The update job (mJobs only)
    bool mFinished = false;            ///< Finish has waited
    double mMilliseconds = 0.0;        ///< Written by the job before it finishes, read after the wait
    uint64_t mLockWaitNanoseconds = 0; ///< The same
    std::exception_ptr mError;         ///< The same
};

Vec3 ClampLength(const Vec3& inV, float inMax)
{
    const float lengthSq = inV.squaredNorm();
    if (!(lengthSq > inMax * inMax)) return inV;
    if (std::isfinite(lengthSq)) return inV * (inMax / std::sqrt(lengthSq));
    // Finite but too long to square (a huge force on a light body): scale it down first, the direction is
    // all that is kept
    const Vec3 scaled = inV / inV.cwiseAbs().maxCoeff();
    return scaled * (inMax / scaled.norm());
}
} // namespace

PhysicsStep::PhysicsStep(const PhysicsSettings& inSettings, const LayerSetup& inLayers, BodyManager& ioBodies,
                         BroadPhase& ioBroadPhase)
    : mSettings(inSettings), mLayers(inLayers), mBodies(ioBodies), mBroadPhase(ioBroadPhase),
      mPairCacheCosHalfMaxAngle(std::cos(0.5f * inSettings.mPairCacheMaxDeltaAngle))
{
}

void PhysicsStep::Run(float inDeltaTime, StepStatistics& ioStatistics, jobs::JobSystem* ioJobs)
{
    mJobs = ioJobs;
    mLockWaitNanoseconds.store(0, std::memory_order_relaxed); // Relaxed: no job of this step runs yet
    Clock::time_point phase = Clock::now();
    const Clock::time_point start = phase;
    BroadPhaseUpdate update(mBroadPhase, mJobs,
                            mBodies.GetActiveBodiesForStep().size() >=
                                mSettings.mUpdateBesideStepMinActiveBodies);

    mContactCache.BeginStep();
    mConstraints.clear();
    mNumChunksUsed = 0;
    mNumBodyPairs = 0;
    mNumWarmStartedPoints = 0;
    mNumReusedPairs = 0;
    mNumContactPoints = 0;
    mCacheInOrder = true;
    mLastCachedPair.reset();
    mLastCachedKey.reset();
    WakeIslandsOfWokenBodies();
    mIslands.Reset(uint32_t(mBodies.GetActiveBodiesForStep().size()));
    update.RunHereUnlessStarted(); // After a few microseconds of other work: see there
    CollideNewlyActive(0, inDeltaTime);
    // The rebuild is the step's: done before the step's moves reach the broad phase (UpdateBoundsAndSleep)
    // and before the next step's Update, which a rebuild still running would refuse
    ioStatistics.mBroadPhaseUpdateMs += update.Finish(); // Its own time: beside the narrow phase when a job
    mLockWaitNanoseconds.fetch_add(update.GetLockWaitNanoseconds(),
                                   std::memory_order_relaxed); // See the member
    ioStatistics.mNarrowPhaseMs += MillisecondsSince(phase);

    // Island finalization and the constraints' ordering are serial (about 18 ns a constraint in a pyramid),
    // the solve's loops follow
    KeepWorkersSpinningFor(mConstraints.size() * 20);
    BuildIslands();
    ioStatistics.mIslandsMs += MillisecondsSince(phase);

    OrderConstraints();
    SolveIslands(inDeltaTime);
    const uint32_t numIslands = mIslands.GetNumIslands();
    const uint32_t largestIsland = numIslands == 0 ? 0 : uint32_t(mIslands.GetBodies(mIslandOrder[0]).size());
    mContactCache.EndStep(mCacheInOrder);
    ioStatistics.mSolveMs += MillisecondsSince(phase);

    ioStatistics.mNumBodyPairs += mNumBodyPairs;
    ioStatistics.mNumWarmStartedPoints += mNumWarmStartedPoints;
    ioStatistics.mNumReusedBodyPairs += mNumReusedPairs;
    ioStatistics.mNumManifolds += uint32_t(mConstraints.size());
    ioStatistics.mNumContactPoints += mNumContactPoints;
    ioStatistics.mNumIslands += numIslands;
    ioStatistics.mNumColoredIslands += mNumColorings[mCurrentColorings]; // A record per colored island
    ioStatistics.mNumColoringsReused += mNumColoringsReused;
    ioStatistics.mNumSolveOrdersReused += mSolveOrderReused ? 1 : 0;
    ioStatistics.mLargestIsland = std::max(ioStatistics.mLargestIsland, largestIsland);

    UpdateBoundsAndSleep(inDeltaTime);
    ioStatistics.mFinishMs += MillisecondsSince(phase);
    ioStatistics.mNumActiveBodies = uint32_t(mBodies.GetActiveBodiesForStep().size());
    ioStatistics.mTotalMs += std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    // Relaxed: every job that added to it was waited for
    ioStatistics.mLockWaitMs += double(mLockWaitNanoseconds.load(std::memory_order_relaxed)) / 1.0e6;
}

void PhysicsStep::SolveIslands(float inDeltaTime)
{
    // The velocity solver works on packed copies of the velocities (SolverBody): one block per active body,
    // at its active index, and after those one private block per constraint side that is static or
    // kinematic. Such a body is shared between islands; with a block of its own per constraint and zero
    // inverse mass, the solver may write to it without a test and without a race
    const std::vector<uint32_t>& active = mBodies.GetActiveBodiesForStep();
    const uint32_t numActive = uint32_t(active.size());
    mPaddingBlocksFirst = numActive + 2 * uint32_t(mIslandConstraints.size());
    mSolverBodies.resize(mPaddingBlocksFirst +
                         WideContactSolver::cPaddingBlocks * (mColorStart.size() + mNumIslandGroups));
    const uint32_t groupPaddingFirst =
        mPaddingBlocksFirst + WideContactSolver::cPaddingBlocks * uint32_t(mColorStart.size());
    ParallelFor(numActive, 512, 7, // ns a body (pile2k, as the estimates below)
                [&](uint32_t inBegin, uint32_t inEnd)
                {
                    for (uint32_t i = inBegin; i < inEnd; ++i)
                        LoadSolverBody(*mBodies.TryGetBodyAtIndex(active[i]), mSolverBodies[i]);
                });

    // The scalar solver walks each island's constraints ten times and more: copied into solve order they are
    // read front to back (the hardware prefetcher streams them), where through the pointers they were a cache
    // miss each (a third of the solver's time). Not the colored islands that the wide solver packs: their
    // iterations read the packed batches, which are made straight from the narrow phase's buffers, and the
    // copy (4.7 MB read and written in a pyramid of 8,500 manifolds) was a tenth of that step
    const bool packColored = CAIRN_WIDE_SOLVER && mSettings.mSolver.mWideColoredIslands;
    mSolveOrder.resize(mIslandConstraints.size());
    mPositionConstraints.resize(mIslandConstraints.size());
    mCopyRanges.clear();
    constexpr uint32_t cCopyTask = 512;
    for (uint32_t island = 0; island < mIslands.GetNumIslands(); ++island)
    {
        if (packColored && mIslandFirstColor[island] != UINT32_MAX) continue;
        // Neighbouring islands share a task up to its size: most islands are a constraint or two
        for (uint32_t begin = mConstraintStart[island], end = mConstraintStart[island + 1]; begin < end;)
        {
            const bool extend = !mCopyRanges.empty() && mCopyRanges.back().second == begin &&
                                mCopyRanges.back().second - mCopyRanges.back().first < cCopyTask;
            if (!extend) mCopyRanges.push_back({begin, begin});
            begin = std::min(end, mCopyRanges.back().first + cCopyTask);
            mCopyRanges.back().second = begin;
        }
    }
    uint32_t numCopied = 0;
    for (const auto& [begin, end] : mCopyRanges)
        numCopied += end - begin;
    constexpr uint32_t cCopyNanoseconds = 110; // A constraint's copy and binding (pile2k)
    ParallelFor(uint32_t(mCopyRanges.size()), 1,
                PerItem(uint64_t(cCopyNanoseconds) * numCopied, mCopyRanges.size()),
                [&](uint32_t inBegin, uint32_t inEnd)
                {
                    for (uint32_t range = inBegin; range < inEnd; ++range)
                    {
                        const auto [begin, end] = mCopyRanges[range];
                        // The sources are scattered over the narrow phase's chunks: fetching each one's cache
                        // lines a few constraints ahead overlaps the misses that the copy otherwise waits for
                        // in turn
                        constexpr uint32_t cAhead = 4;
                        for (uint32_t i = begin; i < std::min(end, begin + cAhead); ++i)
                            PrefetchConstraint(mIslandConstraints[i]);
                        for (uint32_t i = begin; i < end; ++i)
                        {
                            if (i + cAhead < end) PrefetchConstraint(mIslandConstraints[i + cAhead]);
                            mSolveOrder[i] = *mIslandConstraints[i];
                            mIslandConstraints[i] = &mSolveOrder[i];
                            PrepareForSolve(i, numActive);
                        }
                    }
                });

    for (uint32_t index : active)
        if (Body& body = *mBodies.TryGetBodyAtIndex(index); body.IsKinematic())
            IntegratePositions(body, inDeltaTime);
#if CAIRN_WIDE_SOLVER
    mWideBatches.resize(mNumWideBatches); // Each colored island's slice: see ColorIsland
#endif
    // Islands share no dynamic body and no constraint. The colored islands with a quarter of the step first,
    // one at a time with every thread on each; then the others at once, the largest first so that the longest
    // starts early and the small ones fill in around it (colored ones among them by one thread each)
    uint32_t numItemConstraints = uint32_t(mConstraints.size());
    for (uint32_t island : mColoredIslands)
    {
        SolveColoredIsland(island, inDeltaTime, false);
        numItemConstraints -= mConstraintStart[island + 1] - mConstraintStart[island];
    }
    // A constraint's iterations, integration and position passes in an island or a group (pile2k)
    constexpr uint32_t cSolveNanoseconds = 500;
    ParallelFor(uint32_t(mSolveItems.size()), 1,
                PerItem(uint64_t(cSolveNanoseconds) * numItemConstraints, mSolveItems.size()),
                [&](uint32_t inBegin, uint32_t inEnd)
                {
                    for (uint32_t i = inBegin; i < inEnd; ++i)
                    {
                        const SolveItem& item = mSolveItems[i];
                        const uint32_t island = mSolvedIslands[item.mFirst];
                        if (item.mGroup == UINT32_MAX && mIslandFirstColor[island] != UINT32_MAX)
                            SolveColoredIsland(island, inDeltaTime, true);
                        else if (item.mGroup == UINT32_MAX)
                            SolveIsland(island, inDeltaTime);
                        else
                            SolveIslandGroup(
                                std::span<const uint32_t>(mSolvedIslands.data() + item.mFirst, item.mCount),
                                groupPaddingFirst + WideContactSolver::cPaddingBlocks * item.mGroup,
                                inDeltaTime);
                    }
                });
    // A body with nothing to solve keeps the velocity its forces gave it. One chunk per island made the
    // threads fight over the chunk cursor when thousands of bodies fall freely
    ParallelFor(uint32_t(mUnconstrainedBodies.size()), 256, 15, // An integration
                [&](uint32_t inBegin, uint32_t inEnd)
                {
                    for (uint32_t i = inBegin; i < inEnd; ++i)
                        if (Body& body = *mBodies.TryGetBodyAtIndex(active[mUnconstrainedBodies[i]]);
                            body.IsDynamic())
                            IntegratePositions(body, inDeltaTime);
                });
}

void PhysicsStep::WaitABit(uint32_t inSpins)
{
    if (inSpins < 256)
    {
#if defined(__SSE2__)
        _mm_pause();
#endif
    }
    else
        std::this_thread::yield();
}

void PhysicsStep::LoadSolverBody(const Body& inBody, SolverBody& outBlock)
{
    outBlock.mLinearVelocity = inBody.mLinearVelocity;
    outBlock.mAngularVelocity = inBody.mAngularVelocity;
    outBlock.mInverseMass = inBody.IsDynamic() ? inBody.mInvMass : 0.0f;
    outBlock.mPadding = 0.0f;
}

void PhysicsStep::PrepareForSolve(uint32_t inIndex, uint32_t inNumActive)
{
    ContactConstraint& c = *mIslandConstraints[inIndex];
    c.mSolverBodyA = SolverBodyIndex(*c.mBodyA, inNumActive + 2 * inIndex);
    c.mSolverBodyB = SolverBodyIndex(*c.mBodyB, inNumActive + 2 * inIndex + 1);
    SequentialImpulseSolver::MakePositionConstraint(c, mPositionConstraints[inIndex]);
}

uint32_t PhysicsStep::SolverBodyIndex(const Body& inBody, uint32_t inPrivateBlock)
{
    if (inBody.IsDynamic()) return inBody.GetActiveIndex();
    LoadSolverBody(inBody, mSolverBodies[inPrivateBlock]);
    return inPrivateBlock;
}

void PhysicsStep::StoreVelocitiesAndIntegrate(Body& ioBody, float inDeltaTime)
{
    if (!ioBody.IsDynamic()) return;
    const SolverBody& block = mSolverBodies[ioBody.GetActiveIndex()];
    ioBody.mLinearVelocity = block.mLinearVelocity;
    ioBody.mAngularVelocity = block.mAngularVelocity;
    IntegratePositions(ioBody, inDeltaTime);
}

void PhysicsStep::WakeIslandsOfWokenBodies()
{
    std::vector<uint32_t>& active = mBodies.GetActiveBodiesForStep();
    // Bodies appended by this loop were woken by it, not from outside: their flags are clear
    for (size_t i = 0; i < active.size(); ++i)
    {
        Body& body = *mBodies.TryGetBodyAtIndex(active[i]);
        if (!body.mWakeIsland) continue;
        body.mWakeIsland = false;
        // Walk the ring of the island it slept in. Every hop wakes a sleeping body, and the walk stops at an
        // active one (the start, or a body that woke since and whose ring link is stale) and at a link to a
        // body that is gone (the id's sequence no longer matches) or cannot wake (not in the world, static),
        // so it terminates
        for (BodyID next = body.mSleepRingNext;;)
        {
            Body* member = mBodies.TryGetBody(next);
            if (member == nullptr || !member->IsInWorld() || member->IsActive()) break;
            mBodies.ActivateBody(*member);
            if (!member->IsActive()) break; // Could not wake: following its own link would never end
            next = member->mSleepRingNext;
        }
    }
}

void PhysicsStep::ApplyForces(std::span<const uint32_t> inBodies, float inDeltaTime)
{
    for (uint32_t index : inBodies)
    {
        Body& body = *mBodies.TryGetBodyAtIndex(index);
        if (!body.IsDynamic())
        {
            // Kinematic bodies move as set, within the same limits (a limit is what keeps every speed finite)
            body.mLinearVelocity = ClampLength(body.mLinearVelocity, body.mMaxLinearVelocity);
            body.mAngularVelocity = ClampLength(body.mAngularVelocity, body.mMaxAngularVelocity);
            continue;
        }
        // Symplectic Euler, velocity half: v(t + dt) = v(t) + dt * a(t); positions follow with the new
        // velocity
        body.mLinearVelocity +=
            inDeltaTime * (body.mGravityFactor * mSettings.mGravity + body.mInvMass * body.mForce);
        // Kept for the narrow phase: every constraint of the body needs it, and the rotation stays until the
        // solver
        const Mat3& inverseInertia = mInverseInertia[body.GetActiveIndex()] = body.GetInverseInertiaWorld();
        body.mAngularVelocity += inDeltaTime * (inverseInertia * body.mTorque);
        body.mLinearVelocity *= std::max(0.0f, 1.0f - body.mLinearDamping * inDeltaTime);
        body.mAngularVelocity *= std::max(0.0f, 1.0f - body.mAngularDamping * inDeltaTime);
        body.mLinearVelocity = ClampLength(body.mLinearVelocity, body.mMaxLinearVelocity);
        body.mAngularVelocity = ClampLength(body.mAngularVelocity, body.mMaxAngularVelocity);
        body.mForce.setZero();
        body.mTorque.setZero();
    }
}

void PhysicsStep::CollideNewlyActive(size_t inBegin, float inDeltaTime)
{
    std::vector<uint32_t>& active = mBodies.GetActiveBodiesForStep();
    // Bodies woken by a contact join the active list after the narrow phase; they get forces and pairs of
    // their own in the next round, so a sleeping pile wakes as a whole within one step
    for (size_t begin = inBegin; begin < active.size();)
    {
        const size_t end = active.size();
        const std::span<const uint32_t> slice(active.data() + begin, end - begin);
        mInverseInertia.resize(end);
        ParallelFor(uint32_t(slice.size()), 256, 30, // A body's forces and world inertia
                    [&](uint32_t inB, uint32_t inE)
                    { ApplyForces(slice.subspan(inB, inE - inB), inDeltaTime); });
        FindPairs(begin);
        mNumBodyPairs += uint32_t(mPairs.size());

        // Narrow phase: chunks of pairs in parallel, each into its own output
        constexpr uint32_t cPairsPerChunk = 32;
        const uint32_t numChunks = uint32_t((mPairs.size() + cPairsPerChunk - 1) / cPairsPerChunk);
        // Each round has chunks of its own: the constraints stay where the narrow phase wrote them until the
        // step ends (moving the chunk objects keeps their buffers)
        const uint32_t firstChunk = mNumChunksUsed;
        mNumChunksUsed += numChunks;
        if (mNarrowPhaseChunks.size() < mNumChunksUsed) mNarrowPhaseChunks.resize(mNumChunksUsed);
        constexpr uint32_t cPairNanoseconds = 425; // pile2k's boxes; a box on a height field takes more
        ParallelFor(numChunks, 1, cPairsPerChunk * cPairNanoseconds,
                    [&](uint32_t inB, uint32_t inE)
                    {
                        for (uint32_t chunk = inB; chunk < inE; ++chunk)
                        {
                            NarrowPhaseChunk& out = mNarrowPhaseChunks[firstChunk + chunk];
                            out.Clear();
                            const size_t last = std::min(mPairs.size(), size_t(chunk + 1) * cPairsPerChunk);
                            for (size_t p = size_t(chunk) * cPairsPerChunk; p < last; ++p)
                                CollidePair(*mBodies.TryGetBodyAtIndex(mPairs[p].mA),
                                            *mBodies.TryGetBodyAtIndex(mPairs[p].mB), inDeltaTime, out);
                        }
                    });
        // Merge in pair order: the same constraints, cache entries and wake order whatever the threads did.
        // Here the places and the wakes; the copies (a megabyte in a pyramid of 7,000 manifolds) in parallel
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
                if (Body& body = *mBodies.TryGetBodyAtIndex(index); !body.IsActive())
                    mBodies.ActivateBody(body);
            mNumWarmStartedPoints += out.mNumWarmStartedPoints;
            mNumReusedPairs += out.mNumReusedPairs;
            mNumContactPoints += out.mNumContactPoints;
            // The contact cache's order across chunks (and rounds); within each chunk the copies check it
            continuesInOrder(out.mCachedPairs, PairKeyOf, mLastCachedPair);
            continuesInOrder(
                out.mCached, [](const CachedManifold& inM) { return inM.mKey; }, mLastCachedKey);
        }
        const uint32_t firstCachedPair = mContactCache.AppendPairs(numPairs);
        const uint32_t firstCacheIndex = mContactCache.AppendManifolds(numManifolds);
        const size_t firstConstraint = mConstraints.size();
        mConstraints.resize(firstConstraint + numManifolds);
        mConstraintInfo.resize(firstConstraint + numManifolds);
        ParallelFor(numChunks, 4, 1'200, // A chunk's copies
                    [&](uint32_t inB, uint32_t inE)
                    {
                        for (uint32_t chunk = inB; chunk < inE; ++chunk)
                        {
                            NarrowPhaseChunk& out = mNarrowPhaseChunks[firstChunk + chunk];
                            // Each pair's manifolds follow the ones before in the same order: where they
                            // start holds once the cache is in key order (else EndStep finds them)
                            uint32_t pairManifolds = firstCacheIndex + out.mFirstManifold;
                            out.mInOrder = true;
                            for (size_t i = 0; i < out.mCachedPairs.size(); ++i)
                            {
                                CachedBodyPair& pair = mContactCache.GetPair(
                                    firstCachedPair + out.mFirstCachedPair + uint32_t(i));
                                pair = out.mCachedPairs[i];
                                pair.mFirstManifold = pairManifolds;
                                pairManifolds += pair.mNumManifolds;
                                if (i > 0 && PairKeyOf(pair) < PairKeyOf(out.mCachedPairs[i - 1]))
                                    out.mInOrder = false;
                            }
                            for (size_t i = 0; i < out.mConstraints.size(); ++i)
                            {
                                if (i > 0 && out.mCached[i].mKey < out.mCached[i - 1].mKey)
                                    out.mInOrder = false;
                                const uint32_t place = out.mFirstManifold + uint32_t(i);
                                ContactConstraint& c = out.mConstraints[i];
                                c.mCacheIndex = firstCacheIndex + place;
                                mContactCache.Get(c.mCacheIndex) = out.mCached[i];
                                mConstraints[firstConstraint + place] = &c;
                                // The bodies were woken (given active indices) above
                                auto activeIndex = [](const Body& inBody)
                                { return inBody.IsDynamic() ? inBody.GetActiveIndex() : UINT32_MAX; };
                                mConstraintInfo[firstConstraint + place] = {
                                    c.mOrderKey, c.mCacheIndex, activeIndex(*c.mBodyA),
                                    activeIndex(*c.mBodyB), c.mRestitution != 0.0f ? 1u : 0u};
                            }
                        }
                    });
        for (uint32_t chunk = 0; chunk < numChunks; ++chunk)
            mCacheInOrder = mCacheInOrder && mNarrowPhaseChunks[firstChunk + chunk].mInOrder;
        mIslands.Grow(uint32_t(active.size())); // The woken bodies, before their links
        for (uint32_t chunk = 0; chunk < numChunks; ++chunk)
            for (const BodyPair& link : mNarrowPhaseChunks[firstChunk + chunk].mDeferredLinks)
                mIslands.Union(mBodies.TryGetBodyAtIndex(link.mA)->GetActiveIndex(),
                               mBodies.TryGetBodyAtIndex(link.mB)->GetActiveIndex());
        begin = end;
    }
}

void PhysicsStep::FindPairs(size_t inBegin)
{
    const std::vector<uint32_t>& active = mBodies.GetActiveBodiesForStep();
    thread_local std::vector<BodyID> sliceIDs;
    sliceIDs.clear();
    for (size_t i = inBegin; i < active.size(); ++i)
        sliceIDs.push_back(mBodies.TryGetBodyAtIndex(active[i])->GetID());

    // Each chunk of active bodies collects its pairs apart; the chunk of a pair is that of its active body
    constexpr uint32_t cBodiesPerChunk = 64;
    const uint32_t numChunks = uint32_t((sliceIDs.size() + cBodiesPerChunk - 1) / cBodiesPerChunk);
    if (mPairChunks.size() < numChunks) mPairChunks.resize(numChunks);
    for (uint32_t chunk = 0; chunk < numChunks; ++chunk)
        mPairChunks[chunk].mPairs.clear();
    // Named: a FunctionRef only refers to its callable, which must outlive it (a temporary lambda would not)
    auto runRanges = [&](uint32_t inCount, FunctionRef<void(uint32_t, uint32_t)> inRange)
    { ParallelFor(inCount, cBodiesPerChunk, 300, inRange); }; // A body's walks of the trees
    const ParallelRanges ranges = runRanges;
    // A broad phase that cannot search during its update locks here (the global mutex). One that can takes no
    // lock, but this thread may run the queued update job inside the search (a helping wait), whose waits the
    // update counts itself: not counted here, or they would count twice
    const bool pairsMayWait = !mBroadPhase.CanFindPairsDuringUpdate();
    const uint64_t waitedBeforePairs = GetThisThreadLockWaitNanoseconds();
    mBroadPhase.FindCollidingPairs(
        sliceIDs, mLayers,
        [&](BodyID inActive, BodyID inOther)
        {
            const Body* self = mBodies.TryGetBody(inActive);
            const Body* other = mBodies.TryGetBody(inOther);
            // A body whose batch another thread is finalizing is already in the broad phase (the link is
            // lock-free) but not yet in the world: its adder waits for the body lock this step holds. It
            // takes part from the next step on. Pairs with bodies of an earlier round were collided then.
            if (self == nullptr || other == nullptr || !other->IsInWorld() ||
                (other->IsActive() && other->GetActiveIndex() < inBegin))
                return;
            mPairChunks[(self->GetActiveIndex() - inBegin) / cBodiesPerChunk].mPairs.push_back(
                {std::min(inActive.GetIndex(), inOther.GetIndex()),
                 std::max(inActive.GetIndex(), inOther.GetIndex())});
        },
        &ranges);
    if (pairsMayWait)
        mLockWaitNanoseconds.fetch_add(GetThisThreadLockWaitNanoseconds() - waitedBeforePairs,
                                       std::memory_order_relaxed); // See the member
    // The gathering and the sort are serial (6 ns a pair in a pyramid), the narrow phase's loop follows
    size_t numPairs = 0;
    for (uint32_t chunk = 0; chunk < numChunks; ++chunk)
        numPairs += mPairChunks[chunk].mPairs.size();
    KeepWorkersSpinningFor(numPairs * 10);
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
    if (mPairs.size() < cRadixSortMinItems)
        std::sort(mPairs.begin(), mPairs.end(),
                  [&](const BodyPair& inL, const BodyPair& inR) { return keyOf(inL) < keyOf(inR); });
    else
        RadixSort(std::span<BodyPair>(mPairs), mPairsScratch, keyOf, 2 * indexBits);
}

void PhysicsStep::CollidePair(Body& ioA, Body& ioB, float inDeltaTime, NarrowPhaseChunk& ioOut)
{
    if (!ioA.IsDynamic() && !ioB.IsDynamic()) return;
    // Look ahead by how far the bodies can close in this step, so fast bodies get speculative contacts before
    // they tunnel
    CollideSettings settings;
    settings.mMaxSeparation =
        mSettings.mSpeculativeDistance + inDeltaTime * (ioB.mLinearVelocity - ioA.mLinearVelocity).norm();
    const size_t constraintsBefore = ioOut.mConstraints.size();
    const Quat inverseRotationA = ioA.mRotation.conjugate();
    CachedBodyPair record{ioA.GetID(), ioB.GetID(), inverseRotationA * (ioB.mPosition - ioA.mPosition),
                          inverseRotationA * ioB.mRotation, settings.mMaxSeparation};
    if (!ReuseManifolds(ioA, ioB, inDeltaTime, record, ioOut))
        CollideShapes(*ioA.mShape, ioA.GetTransform(), *ioB.mShape, ioB.GetTransform(), settings,
                      [&](const ContactManifold& inManifold)
                      {
                          AddConstraint(
                              ioA, ioB, inManifold, inDeltaTime,
                              mContactCache.FindPrevious(
                                  {ioA.GetID(), ioB.GetID(), inManifold.mSubShapeA, inManifold.mSubShapeB}),
                              ioOut);
                      });
    // Recorded even without manifolds: a pair that stays apart is not collided again either
    record.mNumManifolds = uint32_t(ioOut.mConstraints.size() - constraintsBefore);
    ioOut.mCachedPairs.push_back(record);
    if (record.mNumManifolds == 0) return;
    // Islands: only a contact between two dynamic bodies links (a static or kinematic body would merge
    // everything that touches it). Linked now, lock-free, while other threads find other contacts; a body
    // still asleep has no active index yet, so its link waits for the merge that wakes it
    if (ioA.IsDynamic() && ioB.IsDynamic())
    {
        if (ioA.IsActive() && ioB.IsActive())
            mIslands.Union(ioA.GetActiveIndex(), ioB.GetActiveIndex());
        else
            ioOut.mDeferredLinks.push_back({ioA.GetID().GetIndex(), ioB.GetID().GetIndex()});
    }
    // Touching an active body wakes a sleeping one: at the merge, in pair order (the active list is shared)
    if (!ioA.IsActive() && ioA.IsDynamic()) ioOut.mToWake.push_back(ioA.GetID().GetIndex());
    if (!ioB.IsActive() && ioB.IsDynamic()) ioOut.mToWake.push_back(ioB.GetID().GetIndex());
}

Mat3 PhysicsStep::InverseInertiaOf(const Body& inBody) const
{
    if (!inBody.IsDynamic()) return Mat3::Zero();
    // A body still asleep (woken by this contact at the merge) had no forces applied: nothing kept for it
    return inBody.IsActive() ? mInverseInertia[inBody.GetActiveIndex()] : inBody.GetInverseInertiaWorld();
}

bool PhysicsStep::ReuseManifolds(Body& ioA, Body& ioB, float inDeltaTime, CachedBodyPair& ioRecord,
                                 NarrowPhaseChunk& ioOut) const
{
    if (mSettings.mPairCacheMaxDeltaPosition <= 0.0f) return false;
    const CachedBodyPair* previous =
        mContactCache.FindPreviousPair(ioRecord.mBodyA, ioRecord.mBodyB, &ioOut.mPreviousPairHint);
    if (previous == nullptr) return false;
    // Compared with the pose the manifolds were made at, not last step's: slow drift adds up and is caught.
    // The look-ahead grows with the closing speed: a pair that starts to move fast needs speculative points
    // further out than the old manifolds have (up to the same tolerance)
    const float maxDelta = mSettings.mPairCacheMaxDeltaPosition;
    if ((ioRecord.mDeltaPosition - previous->mDeltaPosition).squaredNorm() > maxDelta * maxDelta ||
        std::abs(ioRecord.mDeltaRotation.dot(previous->mDeltaRotation)) < mPairCacheCosHalfMaxAngle ||
        ioRecord.mMaxSeparation > previous->mMaxSeparation + maxDelta)
        return false;
    ioRecord = *previous;
    // The points stay fixed on both bodies; where they are now, and how far apart, follows from the poses
    for (const CachedManifold& cached : mContactCache.GetPreviousManifolds(*previous))
    {
        ContactManifold manifold;
        manifold.mNormal = ioA.mRotation * cached.mNormalOnA;
        manifold.mNumPoints = cached.mNumPoints;
        manifold.mSubShapeA = cached.mKey.mSubShapeA;
        manifold.mSubShapeB = cached.mKey.mSubShapeB;
        for (int i = 0; i < cached.mNumPoints; ++i)
        {
            ContactPoint& point = manifold.mPoints[i];
            point.mPositionOnA = ioA.mPosition + ioA.mRotation * cached.mLocalOnA[i];
            point.mPositionOnB = ioB.mPosition + ioB.mRotation * cached.mLocalOnB[i];
            point.mPenetration = (point.mPositionOnA - point.mPositionOnB).dot(manifold.mNormal);
        }
        AddConstraint(ioA, ioB, manifold, inDeltaTime, &cached, ioOut, true);
    }
    ++ioOut.mNumReusedPairs;
    return true;
}

void PhysicsStep::AddConstraint(Body& ioA, Body& ioB, const ContactManifold& inManifold, float inDeltaTime,
                                const CachedManifold* inPrevious, NarrowPhaseChunk& ioOut,
                                bool inTakenOver) const
{
    if (inManifold.mNumPoints <= 0) return;
    ContactConstraint& c = ioOut.mConstraints.emplace_back();
    // A manifold taken over from the cache has its points in the bodies' frames already, and its points are
    // last step's, one for one
    SequentialImpulseSolver::InitConstraint(
        ioA, ioB, InverseInertiaOf(ioA), InverseInertiaOf(ioB), inManifold, inDeltaTime, c,
        inTakenOver ? inPrevious->mLocalOnA : nullptr, inTakenOver ? inPrevious->mLocalOnB : nullptr);

    CachedManifold& cached = ioOut.mCached.emplace_back();
    cached.mKey = {ioA.GetID(), ioB.GetID(), inManifold.mSubShapeA, inManifold.mSubShapeB};
    cached.mNumPoints = c.mNumPoints;
    cached.mNormalOnA = inTakenOver ? inPrevious->mNormalOnA : Vec3(ioA.mRotation.conjugate() * c.mNormal);
    const CachedManifold* previous = inPrevious;
    if (previous != nullptr)
    {
        for (int t = 0; t < 2; ++t)
            c.mPatch.mTangent[t].mAccumulated = c.mTangent[t].dot(previous->mFrictionImpulse);
        c.mPatch.mTwistAccumulated = previous->mTwistImpulse;
    }
    for (int i = 0; i < c.mNumPoints; ++i)
    {
        ContactConstraintPoint& p = c.mPoints[i];
        cached.mLocalOnA[i] = p.mLocalOnA;
        cached.mLocalOnB[i] = p.mLocalOnB;
        cached.mNormalImpulse[i] = 0.0f;
        cached.mDeferredBounce[i] = 0.0f;
        if (previous == nullptr) continue;
        if (inTakenOver)
        {
            p.mNormal.mAccumulated = previous->mNormalImpulse[i];
            p.mApproachVelocity = std::min(p.mApproachVelocity, previous->mDeferredBounce[i]); // As below
            ++ioOut.mNumWarmStartedPoints;
            continue;
        }
        // Warm start from the nearest point of last step's manifold, if it is the same contact
        for (int j = 0; j < previous->mNumPoints; ++j)
            if ((previous->mLocalOnA[j] - p.mLocalOnA).squaredNorm() <
                ContactCache::cPointMatchDistance * ContactCache::cPointMatchDistance)
            {
                p.mNormal.mAccumulated = previous->mNormalImpulse[j];
                // A bounce deferred by last step (its point was still a gap away) happens now
                p.mApproachVelocity = std::min(p.mApproachVelocity, previous->mDeferredBounce[j]);
                ++ioOut.mNumWarmStartedPoints;
                break;
            }
    }
    ioOut.mNumContactPoints += uint32_t(c.mNumPoints);
    c.mOrderKey = MixBits((uint64_t(ioA.GetID().GetIndex()) << 32 | ioB.GetID().GetIndex()) ^
                          (uint64_t(inManifold.mSubShapeA) << 40) ^ inManifold.mSubShapeB);
}

void PhysicsStep::BuildIslands()
{
    // The links were made during the narrow phase; what is left is numbering, in O(N) on this thread
    mIslands.Finalize();

    const uint32_t numIslands = mIslands.GetNumIslands();
    const uint32_t numConstraints = uint32_t(mConstraints.size());
    mConstraintStart.assign(numIslands + 1, 0);
    mIslandBounces.assign(numIslands, 0);
    mConstraintIsland.resize(numConstraints);
    for (uint32_t i = 0; i < numConstraints; ++i)
    {
        const ConstraintInfo& info = mConstraintInfo[i];
        const uint32_t island = mIslands.GetIsland(info.mBodyA != UINT32_MAX ? info.mBodyA : info.mBodyB);
        mConstraintIsland[i] = island;
        ++mConstraintStart[island + 1];
        mIslandBounces[island] |= uint8_t(info.mBounces);
    }
    for (uint32_t i = 0; i < numIslands; ++i)
        mConstraintStart[i + 1] += mConstraintStart[i];
    // The sort items of OrderConstraints, in island order (each island's are then sorted)
    mUnsortedOrderItems.resize(numConstraints);
    thread_local std::vector<uint32_t> cursor;
    cursor.assign(mConstraintStart.begin(), mConstraintStart.end() - 1);
    for (uint32_t i = 0; i < numConstraints; ++i)
        mUnsortedOrderItems[cursor[mConstraintIsland[i]]++] = {mConstraintInfo[i].mOrderKey,
                                                               mConstraintInfo[i].mCacheIndex, i};
}

void PhysicsStep::OrderConstraints()
{
    const uint32_t numIslands = mIslands.GetNumIslands();
    // Solve order: a hash of the bodies and sub-shapes, the same on every run. Creation order follows body
    // indices, which usually follow the geometry (a stack is built bottom-up); a solver sweeping in geometric
    // order drifts in that direction, and a wall of boxes leaned over
    // The keys are in a compact array (BuildIslands): a comparator that read them through the constraint
    // pointers took a cache miss per comparison
    auto byKeyThenCacheIndex = [](const OrderItem& inL, const OrderItem& inR)
    {
        return inL.mOrderKey < inR.mOrderKey ||
               (inL.mOrderKey == inR.mOrderKey && inL.mCacheIndex < inR.mCacheIndex);
    };
    // A resting pile or pyramid finds the same contacts in the same order step after step: the same sort
    // input, whose sorted order mOrderItems still holds (a compare, where a pyramid's sort took 60 us)
    mSolveOrderReused = mSettings.mSolver.mReuseColorings && !mUnsortedOrderItems.empty() &&
                        mUnsortedOrderItems == mSortedOrderItemsInput &&
                        mConstraintStart == mSortedOrderItemsStarts;
    if (!mSolveOrderReused)
    {
        mOrderItems = mUnsortedOrderItems;
        std::swap(mUnsortedOrderItems, mSortedOrderItemsInput);
        mSortedOrderItemsStarts = mConstraintStart;
        for (uint32_t island = 0; island < numIslands; ++island)
        {
            const std::span<OrderItem> items(mOrderItems.data() + mConstraintStart[island],
                                             mOrderItems.data() + mConstraintStart[island + 1]);
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
    mIslandConstraints.resize(mOrderItems.size());
    for (size_t i = 0; i < mOrderItems.size(); ++i)
        mIslandConstraints[i] = mConstraints[mOrderItems[i].mConstraint];

    // Only an island that holds a good share of the step's work is colored: smaller ones are better solved
    // whole, several at once. Both limits ignore the thread count, so results do not depend on it
    const uint32_t coloredMin =
        std::max(cColoredIslandMinConstraints, uint32_t(mConstraints.size() / cColoredIslandMinShare));
    // Islands by size, largest first (ties by number): the order both the colored ones and the others are
    // solved in. A counting sort: most islands are one or two bodies, and comparing thousands of them took a
    // tenth of a step of falling bodies
    size_t largest = 0;
    for (uint32_t island = 0; island < numIslands; ++island)
        largest = std::max(largest, mIslands.GetBodies(island).size());
    mIslandSizeStart.assign(largest + 2, 0);
    for (uint32_t island = 0; island < numIslands; ++island)
        ++mIslandSizeStart[largest - mIslands.GetBodies(island).size() + 1]; // Bucket 0: the largest
    for (size_t bucket = 1; bucket < mIslandSizeStart.size(); ++bucket)
        mIslandSizeStart[bucket] += mIslandSizeStart[bucket - 1];
    mIslandOrder.resize(numIslands);
    for (uint32_t island = 0; island < numIslands; ++island) // In number order: ties stay so
        mIslandOrder[mIslandSizeStart[largest - mIslands.GetBodies(island).size()]++] = island;
    mIslandFirstColor.assign(numIslands, UINT32_MAX);
    // This step's colorings go to the other set of records; the previous step's stay for reuse
    mCurrentColorings = 1 - mCurrentColorings;
    mNumColorings[mCurrentColorings] = 0;
    mNumColoringsReused = 0;
    mColorStart.clear();
    mColorFirstBatch.clear();
    mNumWideBatches = 0;
    mColorIsSerial.clear();
    mColoredIslands.clear();
    // The other islands with at most cGroupMaxConstraints constraints are solved in groups (see below)
    const bool wide = CAIRN_WIDE_SOLVER && mSettings.mSolver.mWideColoredIslands;
    auto isSmall = [&](uint32_t inNumConstraints)
    { return wide && inNumConstraints <= cGroupMaxConstraints; };
    mSmallIslands.clear();
    mSolvedIslands.clear();
    mUnconstrainedBodies.clear();
    for (uint32_t island : mIslandOrder)
    {
        const uint32_t numConstraints = mConstraintStart[island + 1] - mConstraintStart[island];
        if (numConstraints >= coloredMin)
            mColoredIslands.push_back(island);
        else if (wide && numConstraints >= cColoredIslandMinConstraints)
        {
            // Large, but not a share of the step that needs every thread: colored all the same, for the wide
            // solver, and solved by one thread (a pyramid's layers before they settle into one island were
            // solved by the scalar solver, a tenth of those steps)
            ColorIsland(island);
            mSolvedIslands.push_back(island);
        }
        else if (numConstraints > 0)
            (isSmall(numConstraints) ? mSmallIslands : mSolvedIslands).push_back(island);
        else
            for (uint32_t activeIndex : mIslands.GetBodies(island)) // One body: contacts would link more
                mUnconstrainedBodies.push_back(activeIndex);
    }
    for (uint32_t island : mColoredIslands)
        ColorIsland(island);

    // What the other islands' solve runs over: the larger ones one by one (largest first), then the small
    // ones (a crate on the ground, two touching) four at a time in the wide solver's lanes, where one at a
    // time the scalar solver waited on one short chain of operations after another. Neither depends on the
    // thread count
    mSolveItems.clear();
    mNumIslandGroups = 0;
    const uint32_t numLarge = uint32_t(mSolvedIslands.size());
    for (uint32_t i = 0; i < numLarge; ++i)
        mSolveItems.push_back({i, 1, UINT32_MAX});
    mSolvedIslands.insert(mSolvedIslands.end(), mSmallIslands.begin(), mSmallIslands.end());
    for (uint32_t first = numLarge; first < mSolvedIslands.size(); first += cGroupIslands)
    {
        const uint32_t count = std::min(cGroupIslands, uint32_t(mSolvedIslands.size()) - first);
        mSolveItems.push_back({first, count, count == 1 ? UINT32_MAX : mNumIslandGroups++});
    }
}

void PhysicsStep::ColorIsland(uint32_t inIsland)
{
    const uint32_t begin = mConstraintStart[inIsland], end = mConstraintStart[inIsland + 1];
    const uint32_t size = end - begin;
    // This step's record; the previous step's of the same size is the candidate for reuse
    std::vector<ColoringRecord>& records = mColorings[mCurrentColorings];
    if (records.size() <= mNumColorings[mCurrentColorings]) records.emplace_back();
    ColoringRecord& record = records[mNumColorings[mCurrentColorings]++];
    ColoringRecord* previous = nullptr;
    if (mSettings.mSolver.mReuseColorings)
        for (uint32_t r = 0; r < mNumColorings[1 - mCurrentColorings]; ++r)
            if (ColoringRecord& candidate = mColorings[1 - mCurrentColorings][r];
                candidate.mBodyPairs.size() == size)
                previous = &candidate;
    // The coloring is a function of the constraints' bodies in solve order alone
    record.mBodyPairs.resize(size);
    bool same = previous != nullptr;
    for (uint32_t i = 0; i < size; ++i)
    {
        const ConstraintInfo& info = mConstraintInfo[mOrderItems[begin + i].mConstraint];
        record.mBodyPairs[i] = uint64_t(info.mBodyA) << 32 | info.mBodyB;
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
        ComputeColoring(record);
    const std::array<uint32_t, cSerialColor + 1>& count = record.mCount;
    mColorScratch.resize(size);
    for (uint32_t i = 0; i < size; ++i)
        mColorScratch[i] = mIslandConstraints[begin + record.mOrder[i]];
    std::copy(mColorScratch.begin(), mColorScratch.end(), mIslandConstraints.begin() + begin);

    mIslandFirstColor[inIsland] = uint32_t(mColorStart.size());
    uint32_t offset = begin;
    for (uint32_t color = 0; color <= cSerialColor; ++color)
    {
        if (count[color] != 0)
        {
            mColorStart.push_back(offset);
            mColorIsSerial.push_back(color == cSerialColor ? 1 : 0);
            mColorFirstBatch.push_back(mNumWideBatches);
            if (color != cSerialColor) mNumWideBatches += (count[color] + 3) / 4;
        }
        offset += count[color];
    }
    mColorStart.push_back(end);
    mColorIsSerial.push_back(0); // The end marker
    mColorFirstBatch.push_back(mNumWideBatches);
}

void PhysicsStep::ComputeColoring(ColoringRecord& ioRecord)
{
    const uint32_t size = uint32_t(ioRecord.mBodyPairs.size());
    mBodyColors.resize(mBodies.GetActiveBodiesForStep().size(), 0);
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

void PhysicsStep::SolveColoredIsland(uint32_t inIsland, float inDeltaTime, bool inAlone)
{
    const uint32_t firstColor = mIslandFirstColor[inIsland];
    // The island's colors are the ranges [mColorStart[k], mColorStart[k + 1]) up to its end
    uint32_t lastColor = firstColor;
    while (mColorStart[lastColor + 1] != mConstraintStart[inIsland + 1])
        ++lastColor;
    // inPasses passes over the colors in turn, each color a stage: inSolve(pass, constraints). Within a color
    // no two constraints share a dynamic body, so its parts may run at once (one per thread, the same region
    // for the same thread in every color); the range of constraints that found no color shares bodies and
    // runs as one part
    // inItems: per entry of mIslandConstraints (the constraints or their position constraints)
    const uint32_t numColors = lastColor - firstColor + 1;
    auto colorPasses = [&](int inPasses, auto inItems, const auto& inSolve)
    {
        RunStages(
            inAlone, uint32_t(std::max(inPasses, 0)) * numColors,
            [&](uint32_t inStage)
            {
                const uint32_t color = firstColor + inStage % numColors;
                return mColorIsSerial[color] != 0 ? 1u
                                                  : PartsFor(uint32_t(ColorConstraints(color).size()), 32);
            },
            [&](uint32_t inStage, uint32_t inPart, uint32_t inParts)
            {
                const uint32_t color = firstColor + inStage % numColors;
                inSolve(
                    int(inStage / numColors),
                    PartOf(inItems.subspan(mColorStart[color], mColorStart[color + 1] - mColorStart[color]),
                           inPart, inParts));
            });
    };
    const std::span<ContactConstraint* const> constraints(mIslandConstraints);
    const SolverSettings& solver = mSettings.mSolver;
    const std::span<SolverBody> solverBodies(mSolverBodies);
    // Without a restitution pass the impulses go from the wide solver's batches to the cache directly
    const bool bounces = mIslandBounces[inIsland] != 0;
    const bool wide = CAIRN_WIDE_SOLVER && solver.mWideColoredIslands;
    if (wide)
        SolveColoredVelocitiesWide(firstColor, lastColor, !bounces, inAlone); // The warm start too
    else
        colorPasses(1 + solver.mVelocityIterations, constraints,
                    [&](int inPass, std::span<ContactConstraint* const> inC)
                    {
                        if (inPass == 0)
                            SequentialImpulseSolver::WarmStart(inC, solverBodies);
                        else
                            SequentialImpulseSolver::SolveVelocities(inC, solverBodies, inPass - 1);
                    });
    // Only where something bounces: the pass costs a stage per color
    if (bounces)
        colorPasses(1, constraints,
                    [&](int, std::span<ContactConstraint* const> inC)
                    { SequentialImpulseSolver::ApplyRestitution(inC, solverBodies, solver); });

    const std::vector<uint32_t>& active = mBodies.GetActiveBodiesForStep();
    const std::span<const uint32_t> bodies = mIslands.GetBodies(inIsland);
    ParallelForUnlessAlone(inAlone, uint32_t(bodies.size()), 256,
                           [&](uint32_t inBegin, uint32_t inEnd)
                           {
                               for (uint32_t i = inBegin; i < inEnd; ++i)
                                   StoreVelocitiesAndIntegrate(*mBodies.TryGetBodyAtIndex(active[bodies[i]]),
                                                               inDeltaTime);
                           });
    colorPasses(solver.mPositionIterations, std::span<const PositionConstraint>(mPositionConstraints),
                [&](int, std::span<const PositionConstraint> inC)
                { SequentialImpulseSolver::SolvePositions(inC, solver); });

    if (wide && !bounces) return; // Stored already
    const std::span<ContactConstraint* const> all = ConstraintsOf(inIsland);
    ParallelForUnlessAlone(inAlone, uint32_t(all.size()), 256,
                           [&](uint32_t inBegin, uint32_t inEnd)
                           { StoreImpulses(all.subspan(inBegin, inEnd - inBegin)); });
}

void PhysicsStep::SolveColoredVelocitiesWide([[maybe_unused]] uint32_t inFirstColor,
                                             [[maybe_unused]] uint32_t inLastColor,
                                             [[maybe_unused]] bool inStoreImpulses,
                                             [[maybe_unused]] bool inAlone)
{
#if CAIRN_WIDE_SOLVER
    // Each color's constraints in batches of four, in order; the last batch of a color may be partial. The
    // island's batches are its own slice of the step's (mColorFirstBatch): islands solved alone run at once
    const uint32_t islandFirstBatch = mColorFirstBatch[inFirstColor];
    const uint32_t numBatches = mColorFirstBatch[inLastColor + 1] - islandFirstBatch;
    for (uint32_t color = inFirstColor; color <= inLastColor; ++color)
    {
        const uint32_t firstBatch = mColorFirstBatch[color];
        for (uint32_t batch = firstBatch; batch < mColorFirstBatch[color + 1]; ++batch)
        {
            WideContactBatch& b = mWideBatches[batch];
            b.mFirst = mColorStart[color] + 4 * (batch - firstBatch);
            b.mCount = std::min(4u, mColorStart[color + 1] - b.mFirst);
            b.mPaddingFirst = mPaddingBlocksFirst + WideContactSolver::cPaddingBlocks * color;
        }
    }
    const std::span<SolverBody> solverBodies(mSolverBodies);
    auto constraintsOf = [&](const WideContactBatch& inBatch) {
        return std::span<ContactConstraint* const>(mIslandConstraints.data() + inBatch.mFirst,
                                                   inBatch.mCount);
    };
    // The batches of a color (they share no dynamic body) are solved in one contiguous part per thread, as
    // in SolveColoredIsland (8 batches are the 32 constraints a part needs). Packed and stored in the same
    // parts, part p by the thread that runs the loop's part p, which is normally the one that runs the
    // stages' part p too (each thread takes its own part first): a batch is 2 KB, and one packed on the other
    // core (a loop over all the batches in chunks gave half of them to it) crossed between the cores twice a
    // step
    auto batchesOf = [&](uint32_t inColor)
    {
        return std::span<WideContactBatch>(mWideBatches.data() + mColorFirstBatch[inColor],
                                           mWideBatches.data() + mColorFirstBatch[inColor + 1]);
    };
    auto partsOfColor = [&](uint32_t inColor) { return PartsFor(uint32_t(batchesOf(inColor).size()), 8); };
    auto forEachPartOfThreads = [&](const auto& inRunBatches)
    {
        const uint32_t threads = inAlone || mJobs == nullptr ? 1 : mJobs->GetNumThreads();
        if (threads == 1)
        {
            inRunBatches(std::span<WideContactBatch>(mWideBatches.data() + islandFirstBatch, numBatches));
            return;
        }
        mJobs->ParallelFor(threads, 1,
                           [&](uint32_t inBegin, uint32_t inEnd)
                           {
                               for (uint32_t part = inBegin; part < inEnd; ++part)
                                   for (uint32_t color = inFirstColor; color <= inLastColor; ++color)
                                       if (const uint32_t parts = partsOfColor(color); part < parts)
                                           inRunBatches(PartOf(batchesOf(color), part, parts));
                           });
    };

    // The constraints are where the narrow phase made them (not copied: see SolveIslands), scattered over its
    // chunks: each batch's are fetched a batch ahead, and bound and given position constraints as they are
    // packed, while their cache lines are at hand. The range that found no color is prepared here
    const uint32_t numActive = uint32_t(mBodies.GetActiveBodiesForStep().size());
    for (uint32_t color = inFirstColor; color <= inLastColor; ++color)
        if (mColorIsSerial[color] != 0)
            for (uint32_t i = mColorStart[color]; i < mColorStart[color + 1]; ++i)
                PrepareForSolve(i, numActive);
    forEachPartOfThreads(
        [&](std::span<WideContactBatch> inBatches)
        {
            for (size_t i = 0; i < inBatches.size(); ++i)
            {
                if (i + 1 < inBatches.size())
                    for (ContactConstraint* next : constraintsOf(inBatches[i + 1]))
                        PrefetchConstraint(next);
                WideContactBatch& batch = inBatches[i];
                for (uint32_t lane = 0; lane < batch.mCount; ++lane)
                    PrepareForSolve(batch.mFirst + lane, numActive);
                WideContactSolver::Pack(constraintsOf(batch), solverBodies, batch);
            }
        });

    // The warm start, then the iterations: each a pass over the colors in turn, each color a stage. The
    // serial range by the scalar solver in one part; the batches of a color in their parts
    const uint32_t numColors = inLastColor - inFirstColor + 1;
    RunStages(
        inAlone, (1 + uint32_t(mSettings.mSolver.mVelocityIterations)) * numColors,
        [&](uint32_t inStage)
        {
            const uint32_t color = inFirstColor + inStage % numColors;
            return mColorIsSerial[color] != 0 ? 1u : partsOfColor(color);
        },
        [&](uint32_t inStage, uint32_t inPart, uint32_t inParts)
        {
            const uint32_t color = inFirstColor + inStage % numColors;
            const int pass = int(inStage / numColors); // 0: the warm start; then iteration pass - 1
            if (mColorIsSerial[color] != 0)
            {
                const std::span<ContactConstraint* const> constraints = ColorConstraints(color);
                if (pass == 0)
                    SequentialImpulseSolver::WarmStart(constraints, solverBodies);
                else
                    SequentialImpulseSolver::SolveVelocities(constraints, solverBodies, pass - 1);
                return;
            }
            const std::span<WideContactBatch> part = PartOf(batchesOf(color), inPart, inParts);
            if (pass == 0)
                WideContactSolver::WarmStart(part, solverBodies);
            else
                WideContactSolver::SolveVelocities(part, solverBodies, pass - 1);
        });

    forEachPartOfThreads(
        [&](std::span<WideContactBatch> inBatches)
        {
            for (WideContactBatch& batch : inBatches)
                if (inStoreImpulses)
                    WideContactSolver::StoreImpulses(batch, mContactCache);
                else
                    WideContactSolver::Unpack(batch, constraintsOf(batch));
        });
    if (inStoreImpulses)
        for (uint32_t color = inFirstColor; color <= inLastColor; ++color)
            if (mColorIsSerial[color] != 0) StoreImpulses(ColorConstraints(color));
#endif
}

void PhysicsStep::SolveIsland(uint32_t inIsland, float inDeltaTime)
{
    const std::span<ContactConstraint* const> constraints = ConstraintsOf(inIsland);
    const SolverSettings& solver = mSettings.mSolver;
    const std::span<SolverBody> solverBodies(mSolverBodies);
    SequentialImpulseSolver::WarmStart(constraints, solverBodies);
    for (int i = 0; i < solver.mVelocityIterations; ++i)
        SequentialImpulseSolver::SolveVelocities(constraints, solverBodies, i);
    FinishIsland(inIsland, inDeltaTime);
}

void PhysicsStep::SolveIslandGroup([[maybe_unused]] std::span<const uint32_t> inIslands,
                                   [[maybe_unused]] uint32_t inPaddingFirst,
                                   [[maybe_unused]] float inDeltaTime)
{
#if CAIRN_WIDE_SOLVER
    // Row r holds constraint r of each island, one island per lane (null: padding). Each lane then does its
    // island's scalar arithmetic in its order, so the result is SolveIsland's bit for bit
    std::array<std::array<ContactConstraint*, cGroupIslands>, cGroupMaxConstraints> rows{};
    uint32_t numRows = 0;
    for (uint32_t lane = 0; lane < inIslands.size(); ++lane)
    {
        const std::span<ContactConstraint* const> constraints = ConstraintsOf(inIslands[lane]);
        for (uint32_t row = 0; row < constraints.size(); ++row)
            rows[row][lane] = constraints[row];
        numRows = std::max(numRows, uint32_t(constraints.size()));
    }
    const std::span<SolverBody> solverBodies(mSolverBodies);
    WideContactBatch batches[cGroupMaxConstraints];
    for (uint32_t row = 0; row < numRows; ++row)
    {
        batches[row].mFirst = 0;
        batches[row].mCount = cGroupIslands;
        batches[row].mPaddingFirst = inPaddingFirst;
        WideContactSolver::Pack(rows[row], solverBodies, batches[row]);
    }
    const std::span<WideContactBatch> all(batches, numRows);
    WideContactSolver::WarmStart(all, solverBodies);
    for (int i = 0; i < mSettings.mSolver.mVelocityIterations; ++i)
        WideContactSolver::SolveVelocities(all, solverBodies, i);
    for (uint32_t row = 0; row < numRows; ++row)
        WideContactSolver::Unpack(batches[row], rows[row]);
    for (uint32_t island : inIslands)
        FinishIsland(island, inDeltaTime);
#endif
}

void PhysicsStep::FinishIsland(uint32_t inIsland, float inDeltaTime)
{
    const std::span<ContactConstraint* const> constraints = ConstraintsOf(inIsland);
    const SolverSettings& solver = mSettings.mSolver;
    SequentialImpulseSolver::ApplyRestitution(constraints, std::span<SolverBody>(mSolverBodies), solver);

    const std::vector<uint32_t>& active = mBodies.GetActiveBodiesForStep();
    for (uint32_t activeIndex : mIslands.GetBodies(inIsland))
        StoreVelocitiesAndIntegrate(*mBodies.TryGetBodyAtIndex(active[activeIndex]), inDeltaTime);

    for (int i = 0; i < solver.mPositionIterations; ++i)
        SequentialImpulseSolver::SolvePositions(PositionConstraintsOf(inIsland), solver);

    StoreImpulses(constraints);
}

void PhysicsStep::StoreImpulses(std::span<ContactConstraint* const> inConstraints)
{
    for (const ContactConstraint* c : inConstraints)
    {
        CachedManifold& cached = mContactCache.Get(c->mCacheIndex);
        for (int i = 0; i < c->mNumPoints; ++i)
        {
            cached.mNormalImpulse[i] = c->mPoints[i].mNormal.mAccumulated;
            cached.mDeferredBounce[i] = c->mPoints[i].mDeferredBounce;
        }
        cached.mFrictionImpulse = c->mPatch.mTangent[0].mAccumulated * c->mTangent[0] +
                                  c->mPatch.mTangent[1].mAccumulated * c->mTangent[1];
        cached.mTwistImpulse = c->mPatch.mTwistAccumulated;
    }
}

void PhysicsStep::IntegratePositions(Body& ioBody, float inDeltaTime)
{
    // Symplectic Euler, position half: uses the velocity after gravity and contacts
    ioBody.mPosition += inDeltaTime * ioBody.mLinearVelocity;
    ioBody.mRotation = IntegrateRotation(ioBody.mRotation, inDeltaTime * ioBody.mAngularVelocity);
}

void PhysicsStep::UpdateBoundsAndSleep(float inDeltaTime)
{
    // A body whose new bounds lie this far inside the box the broad phase holds for it may publish before it
    // moves (m): far below the speculative distance by which that box reaches past the body, far above
    // rounding
    constexpr float cHeldBoxTolerance = 1.0e-4f;
    std::vector<uint32_t>& active = mBodies.GetActiveBodiesForStep();
    mMovedBodies.resize(active.size());
    // The broad phase gets the bounds swept over the next step (by inSweep: the step's velocity times its
    // time) plus the speculative distance, so the next step finds the pairs this body can reach
    auto sweptBounds = [&](const AABB& inBounds, const Vec3& inSweep)
    {
        AABB swept = inBounds;
        swept.Encapsulate(AABB(inBounds.mMin + inSweep, inBounds.mMax + inSweep));
        return swept.Expanded(mSettings.mSpeculativeDistance);
    };
    PublishedPoseStore& poses = mBodies.GetPublishedPosesForStep();
    mPublishOrders.resize(active.size());
    ParallelFor(
        uint32_t(active.size()), 256, 90, // A body's bounds, broad-phase move and publication
        [&](uint32_t inBegin, uint32_t inEnd)
        {
            // The broad phase must hold a body's published bounds at every moment (PublishedPose.h).
            // A body whose new bounds lie inside the box the broad phase holds for it (the box this
            // step's last finish gave it, if nobody published the body since) publishes first, then
            // moves: a falling or sliding body, whose box reached ahead. Another moves first and
            // publishes after, with a box grown over its published bounds meanwhile where its new
            // box does not cover them, shrunk back once published.
            bool anyGrown = false;
            for (uint32_t i = inBegin; i < inEnd; ++i)
            {
                const uint32_t index = active[i];
                Body& body = *mBodies.TryGetBodyAtIndex(index);
                poses.Prefetch(index);
                const AABB published = body.mBounds;
                body.UpdateBounds();
                const Vec3 sweep = inDeltaTime * body.mLinearVelocity;
                const AABB swept = sweptBounds(body.mBounds, sweep);
                AABB box = swept;
                PublishOrder order = PublishOrder::AfterMove;
                // The box held is made again as it was made, and checked a little inside, so that a
                // rounding difference could only make the check fail
                PublishedPoseStore::StepMemory& memory = poses.GetStepMemory(index);
                if (poses.GetVersion(index) == memory.mVersion &&
                    sweptBounds(published, memory.mSweep).Expanded(-cHeldBoxTolerance).Contains(body.mBounds))
                {
                    memory.mVersion = poses.PublishMotion(body);
                    order = PublishOrder::BeforeMove;
                }
                else if (!swept.Contains(published))
                {
                    box.Encapsulate(published);
                    order = PublishOrder::AfterGrownMove;
                    anyGrown = true;
                }
                memory.mSweep = sweep;
                mPublishOrders[i] = order;
                mMovedBodies[i] = {body.GetID(), box, body.GetObjectLayer()};

                const float radius = body.mShape->GetLocalBounds().HalfExtent().norm();
                const float speed = body.mLinearVelocity.norm() + radius * body.mAngularVelocity.norm();
                const bool slow =
                    mSettings.mAllowSleeping && body.mAllowSleeping && speed < mSettings.mSleepVelocity;
                body.mSleepTimer = slow ? body.mSleepTimer + inDeltaTime : 0.0f;
            }
            // Any thread may move bodies in the broad phase (each body here is in one range only)
            const uint64_t waited = GetThisThreadLockWaitNanoseconds();
            mBroadPhase.NotifyBodiesAABBChanged(
                std::span<const BroadPhaseBody>(mMovedBodies.data() + inBegin, inEnd - inBegin));
            // The broad phase holds the new bounds: this collision step's positions are final. The
            // grown boxes go to the front of the range, shrunk to the swept bounds, so that the next
            // step's pairs are those of the swept bounds alone
            uint32_t grown = inBegin;
            for (uint32_t i = inBegin; i < inEnd; ++i)
            {
                if (mPublishOrders[i] == PublishOrder::BeforeMove) continue;
                const Body& body = *mBodies.TryGetBodyAtIndex(active[i]);
                PublishedPoseStore::StepMemory& memory = poses.GetStepMemory(active[i]);
                memory.mVersion = poses.PublishMotion(body);
                if (mPublishOrders[i] == PublishOrder::AfterGrownMove)
                    mMovedBodies[grown++] = {body.GetID(), sweptBounds(body.mBounds, memory.mSweep),
                                             body.GetObjectLayer()};
            }
            if (anyGrown)
                mBroadPhase.NotifyBodiesAABBChanged(
                    std::span<const BroadPhaseBody>(mMovedBodies.data() + inBegin, grown - inBegin));
            mLockWaitNanoseconds.fetch_add(GetThisThreadLockWaitNanoseconds() - waited,
                                           std::memory_order_relaxed); // See the member
        });

    // An island sleeps as a whole when every body in it has been slow long enough
    mSleepingIslands.clear();
    for (uint32_t island = 0; island < mIslands.GetNumIslands(); ++island)
    {
        bool canSleep = true;
        for (uint32_t activeIndex : mIslands.GetBodies(island))
            canSleep &=
                mBodies.TryGetBodyAtIndex(active[activeIndex])->mSleepTimer >= mSettings.mTimeBeforeSleep;
        if (!canSleep) continue;
        // Link the island into a ring, so that waking one of its bodies from outside wakes them all
        const std::span<const uint32_t> members = mIslands.GetBodies(island);
        for (size_t i = 0; i < members.size(); ++i)
        {
            Body& body = *mBodies.TryGetBodyAtIndex(active[members[i]]);
            body.mSleepRingNext =
                mBodies.TryGetBodyAtIndex(active[members[(i + 1) % members.size()]])->GetID();
            mSleepingIslands.push_back(active[members[i]]);
        }
    }
    // Deactivating reorders the active list, so the islands' indices are resolved to bodies first
    for (uint32_t bodyIndex : mSleepingIslands)
        mBodies.DeactivateBody(*mBodies.TryGetBodyAtIndex(bodyIndex));
}

} // namespace cairn
