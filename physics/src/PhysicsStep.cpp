#include "PhysicsStep.h"

#include "step/BroadPhaseUpdate.h"
#include "step/StepContext.h"
#include "step/StepCosts.h"
#include "step/SweptBoxes.h"

#include <algorithm>
#include <chrono>

namespace cairn::physics
{

namespace
{
using Clock = std::chrono::steady_clock;

/// Milliseconds since ioStart, which becomes now: the stages' times one after the other.
double MillisecondsSince(Clock::time_point& ioStart)
{
    const Clock::time_point now = Clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - ioStart).count();
    ioStart = now;
    return ms;
}
} // namespace

PhysicsStep::PhysicsStep(const PhysicsSettings& inSettings, const LayerSetup& inLayers, BodyManager& ioBodies,
                         BroadPhase& ioBroadPhase, ConstraintManager& ioConstraints)
    : mSettings(inSettings), mLayers(inLayers), mBodies(ioBodies), mBroadPhase(ioBroadPhase),
      mConstraints(ioConstraints), mContacts(inSettings.mPairCacheMaxDeltaAngle)
{
}

void PhysicsStep::Run(float inDeltaTime, const CollisionStepInfo& inStep, StepStatistics& ioStatistics,
                      jobs::JobInterface* ioJobs)
{
    mScheduler.BeginStep(ioJobs, mSettings.mMinChunksPerThread);
    mLockWaitNanoseconds.store(0, std::memory_order_relaxed); // Relaxed: no job of this step runs yet
    std::vector<uint32_t>& active = mBodies.GetActiveBodiesForStep();
    const StepContext context{
        mSettings,        mLayers,       mBodies,       active,     mBodies.GetPublishedPosesForStep(),
        mBroadPhase,      mContactCache, mIslands,      mScheduler, mLockWaitNanoseconds,
        inStep.mListener, inDeltaTime,   inStep.mIsLast};
    Clock::time_point phase = Clock::now();
    const Clock::time_point start = phase;

    // 1. The broad-phase update: beside the rounds below when it may, else now. The bar is per helper (see
    // PhysicsSettings::mUpdateBesideStepMinActiveBodies)
    const uint64_t helpers = ioJobs != nullptr ? std::max(ioJobs->GetNumThreads(), 1u) - 1 : 0;
    BroadPhaseUpdate update(mBroadPhase, ioJobs,
                            uint64_t(active.size()) * helpers >= mSettings.mUpdateBesideStepMinActiveBodies);
    mContactCache.BeginStep();
    mContinuous.BeginStep();
    mContacts.BeginStep();
    IslandSleep::WakeIslandsOfWokenBodies(context);
    mJoints.BeginStep(context, mConstraints, mIntegration); // May wake bodies: before the islands are sized
    mIslands.Reset(uint32_t(active.size()));
    update.RunHereUnlessStarted(); // After a few microseconds of other work: see there

    // 2-5. Rounds of velocities, pairs, narrow phase and merge. Bodies woken by a contact join the active
    // list at the merge; they get velocities and pairs of their own in the next round
    for (size_t begin = 0; begin < active.size();)
    {
        const size_t end = active.size();
        const std::span<const uint32_t> round(active.data() + begin, end - begin);
        mIntegration.BeginRound(end);
        mScheduler.ParallelFor(uint32_t(round.size()), StepCosts::cVelocities,
                               [&](uint32_t inBegin, uint32_t inEnd)
                               {
                                   const std::span<const uint32_t> bodies =
                                       round.subspan(inBegin, inEnd - inBegin);
                                   mIntegration.IntegrateVelocities(context, bodies);
                                   SweptBoxes::CoverThisStep(context, bodies);
                                   mContinuous.Count(context, bodies);
                               });
        mContacts.FindPairs(context, begin);
        mContacts.CollidePairs(context, mIntegration);
        mContacts.Merge(context);
        begin = end;
    }
    uint64_t parallelBefore = 0;
    // The phase's time less what the updating thread spent in the phase's parallel regions
    auto serialPart = [&](double inPhaseMs)
    {
        const uint64_t parallel = mScheduler.GetParallelNanoseconds();
        const double serialMs = inPhaseMs - double(parallel - parallelBefore) / 1.0e6;
        parallelBefore = parallel;
        return std::max(0.0, serialMs);
    };
    double phaseMs = MillisecondsSince(phase);
    ioStatistics.mNarrowPhaseMs += phaseMs;
    ioStatistics.mNarrowPhaseSerialMs += serialPart(phaseMs);

    // 6. Islands: serial, the solve's loops follow
    mScheduler.KeepWorkersSpinningFor(mContacts.GetConstraints().size() * StepCosts::cIslandsNanoseconds);
    mJoints.LinkIslands(context);
    mIslandStage.Build(context, mContacts.GetConstraintInfo());
    mJoints.GroupByIsland(context);
    phaseMs = MillisecondsSince(phase);
    ioStatistics.mIslandsMs += phaseMs;
    ioStatistics.mIslandsSerialMs += serialPart(phaseMs);

    // 7. Solve (the constraints' ordering counted as solver time), positions integrated
    mIslandStage.Order(context, mContacts.GetConstraints(), mContacts.GetConstraintInfo(), mJoints);
    mSolver.Solve(context, mIslandStage.GetPlan(), uint32_t(mContacts.GetConstraints().size()), mJoints);
    mJoints.BreakOverloaded();
    mContactCache.EndStep(mContacts.IsCacheInOrder());
    phaseMs = MillisecondsSince(phase);
    ioStatistics.mSolveMs += phaseMs;
    ioStatistics.mSolveSerialMs += serialPart(phaseMs);

    // 7b. Linear casts: fast bodies stopped short of what they would have passed through
    ioStatistics.mNumLinearCastsMovedBack += mContinuous.Run(context);
    phaseMs = MillisecondsSince(phase);
    ioStatistics.mContinuousMs += phaseMs;
    serialPart(phaseMs); // Serial whole (no loop): in mSerialMs only

    const ContactsStage::Counts& counts = mContacts.GetCounts();
    ioStatistics.mNumBodyPairs += counts.mNumBodyPairs;
    ioStatistics.mNumWarmStartedPoints += counts.mNumWarmStartedPoints;
    ioStatistics.mNumReusedBodyPairs += counts.mNumReusedPairs;
    ioStatistics.mNumManifolds += uint32_t(mContacts.GetConstraints().size());
    ioStatistics.mNumContactPoints += counts.mNumContactPoints;
    ioStatistics.mNumIslands += mIslands.GetNumIslands();
    ioStatistics.mNumColoredIslands += mIslandStage.GetNumColoredIslands();
    ioStatistics.mNumColoringsReused += mIslandStage.GetNumColoringsReused();
    ioStatistics.mNumSolveOrdersReused += mIslandStage.WasSolveOrderReused() ? 1 : 0;
    ioStatistics.mLargestIsland =
        std::max(ioStatistics.mLargestIsland, mIslandStage.GetLargestIslandSize(context));

    // The update is the step's: done before the step's moves reach the broad phase (the finish) and before
    // the next step's Update, which a rebuild still running would refuse. Nothing before needs it: the pairs
    // and the linear casts are queries, exact in any state of the trees. Waited for here rather than after
    // the narrow phase, so that with many threads, whose rounds may end before it, the islands and the solve
    // run meanwhile instead of the updating thread waiting
    ioStatistics.mBroadPhaseUpdateMs += update.Finish(); // Its own time, beside the step when a task
    mLockWaitNanoseconds.fetch_add(update.GetLockWaitNanoseconds(),
                                   std::memory_order_relaxed); // See StepContext

    // 8. Finish: bounds, broad-phase moves and published poses; then the resting islands sleep
    mFinish.Run(context);
    mSleep.PutRestingIslandsToSleep(context);
    // 9. Contact events, from the contact cache (the solver's impulses are in it) and the sensor overlaps
    if (inStep.mEvents != nullptr)
    {
        const size_t first = inStep.mEvents->size();
        mEvents.Record(mBodies, mContactCache, mContacts.GetSensorOverlaps(), inStep.mIndex, *inStep.mEvents);
        if (inStep.mListener != nullptr)
            inStep.mListener->OnContactEvents(std::span<const ContactEvent>(*inStep.mEvents).subspan(first));
    }
    else
        mEvents.Forget();
    phaseMs = MillisecondsSince(phase);
    ioStatistics.mFinishMs += phaseMs;
    ioStatistics.mFinishSerialMs += serialPart(phaseMs);
    ioStatistics.mNumActiveBodies = uint32_t(active.size());
    const double totalMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    ioStatistics.mTotalMs += totalMs;
    ioStatistics.mSerialMs += std::max(0.0, totalMs - double(mScheduler.GetParallelNanoseconds()) / 1.0e6);
    // Relaxed: every job that added to it was waited for
    ioStatistics.mLockWaitMs += double(mLockWaitNanoseconds.load(std::memory_order_relaxed)) / 1.0e6;
}

} // namespace cairn::physics
