#include "step/BroadPhaseUpdate.h"

#include "cairn/physics/LockWaits.h"

#include <chrono>

namespace cairn::physics
{

BroadPhaseUpdate::BroadPhaseUpdate(BroadPhase& ioBroadPhase, jobs::JobInterface* ioJobs, bool inBeside)
    : mBroadPhase(ioBroadPhase), mJobs(inBeside && ioJobs != nullptr && ioJobs->GetNumThreads() > 1 &&
                                               ioBroadPhase.CanFindPairsDuringUpdate()
                                           ? ioJobs
                                           : nullptr)
{
    if (mJobs == nullptr)
    {
        Run();
        if (mError) std::rethrow_exception(mError);
        return;
    }
    mTask = mJobs->StartTask(
        "broad-phase update", [](void* inUpdate) { static_cast<BroadPhaseUpdate*>(inUpdate)->Run(); }, this);
}

BroadPhaseUpdate::~BroadPhaseUpdate()
{
    if (mJobs != nullptr && !mFinished) mJobs->FinishTask(mTask);
}

void BroadPhaseUpdate::Run()
{
    const auto start = std::chrono::steady_clock::now();
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
    mMilliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void BroadPhaseUpdate::RunHereUnlessStarted()
{
    if (mJobs != nullptr && !mFinished && mJobs->TryRunTaskHere(mTask))
    {
        mJobs->FinishTask(mTask);
        mFinished = true;
        if (mError) std::rethrow_exception(mError);
    }
}

double BroadPhaseUpdate::Finish()
{
    if (mJobs != nullptr && !mFinished)
    {
        mJobs->FinishTask(mTask);
        mFinished = true;
        if (mError) std::rethrow_exception(mError);
    }
    return mMilliseconds;
}

} // namespace cairn::physics
