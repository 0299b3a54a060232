#include "cairn/jobs/BackgroundQueue.h"

#include "ThreadName.h"
#include "cairn/jobs/JobSystem.h"

#include <algorithm>
#include <cmath>
#include <exception>

#if defined(__linux__)
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

namespace cairn::jobs
{

const char* ToString(BackgroundTaskState inState)
{
    switch (inState)
    {
    case BackgroundTaskState::Queued:
        return "queued";
    case BackgroundTaskState::Running:
        return "running";
    case BackgroundTaskState::Done:
        return "done";
    case BackgroundTaskState::Failed:
        return "failed";
    case BackgroundTaskState::Cancelled:
        return "cancelled";
    }
    return "unknown";
}

bool BackgroundTaskContext::IsCancelRequested() const
{
    return mTask.IsCancelRequested();
}

void BackgroundTaskContext::SetProgress(float inFraction)
{
    if (std::isnan(inFraction)) return;
    // Relaxed: a progress figure for display; nothing is read through it
    mTask.mProgress.store(std::clamp(inFraction, 0.0f, 1.0f), std::memory_order_relaxed);
}

void BackgroundTaskContext::SetError(std::string inMessage)
{
    mTask.mError = std::move(inMessage); // Published by the release of the Failed state
}

BackgroundTask::BackgroundTask(std::string inName, int inPriority, BackgroundStepFunction inStep)
    : mName(std::move(inName)), mStep(std::move(inStep)), mPriority(inPriority)
{
}

BackgroundTaskState BackgroundTask::GetState() const
{
    // Acquire: a caller that sees a finished state also sees the task's results and its error text
    return mState.load(std::memory_order_acquire);
}

bool BackgroundTask::IsFinished() const
{
    const BackgroundTaskState state = GetState();
    return state == BackgroundTaskState::Done || state == BackgroundTaskState::Failed ||
           state == BackgroundTaskState::Cancelled;
}

float BackgroundTask::GetProgress() const
{
    return mProgress.load(std::memory_order_relaxed); // Display only
}

int BackgroundTask::GetPriority() const
{
    return mPriority.load(std::memory_order_relaxed); // A scheduling hint, read under the queue's mutex
}

void BackgroundTask::SetPriority(int inPriority)
{
    mPriority.store(inPriority, std::memory_order_relaxed); // As above
}

void BackgroundTask::Cancel()
{
    // Relaxed: the running thread polls it; nothing else is published through it
    mCancelRequested.store(true, std::memory_order_relaxed);
    // A queued task is cancelled now (the queue sweeps it out when it meets it); a running one at its next
    // chunk
    if (TryTransition(BackgroundTaskState::Queued, BackgroundTaskState::Cancelled))
    {
        // No thread calls the step any more (a queue thread that pops it fails to make it Running; the
        // acq_rel exchange ordered the last call before this), so its captures go now, as for a task that ran
        mStep = nullptr;
        std::lock_guard lock(mDoneMutex);
        mDone.notify_all();
    }
}

bool BackgroundTask::IsCancelRequested() const
{
    return mCancelRequested.load(std::memory_order_relaxed); // See Cancel
}

bool BackgroundTask::Wait(std::chrono::milliseconds inTimeout) const
{
    std::unique_lock lock(mDoneMutex);
    return mDone.wait_for(lock, inTimeout, [&] { return IsFinished(); });
}

std::string BackgroundTask::GetError() const
{
    return GetState() == BackgroundTaskState::Failed ? mError : std::string();
}

uint32_t BackgroundTask::GetChunksRun() const
{
    return mChunksRun.load(std::memory_order_relaxed); // Statistic only
}

bool BackgroundTask::TryTransition(BackgroundTaskState inFrom, BackgroundTaskState inTo)
{
    // Acq_rel: a finished state releases the task's work (and error) to GetState's acquire; taking a task
    // acquires what its submitter or a previous thread wrote
    return mState.compare_exchange_strong(inFrom, inTo, std::memory_order_acq_rel);
}

bool BackgroundTask::Finish(BackgroundTaskState inState)
{
    if (!TryTransition(BackgroundTaskState::Running, inState)) return false;
    // Progress is display only; a finished task reads as complete whatever the step last reported
    if (inState == BackgroundTaskState::Done) mProgress.store(1.0f, std::memory_order_relaxed);
    std::lock_guard lock(mDoneMutex); // Orders the notify after a waiter's predicate check
    mDone.notify_all();
    return true;
}

BackgroundQueue::BackgroundQueue() : BackgroundQueue(Settings{}) {}

BackgroundQueue::BackgroundQueue(const Settings& inSettings) : mSettings(inSettings)
{
    // At most 64, as the frame's JobSystem: background threads beyond the cores only contend
    const uint32_t numThreads = std::clamp(mSettings.mNumThreads, 1u, cMaxThreads);
    try
    {
        for (uint32_t i = 0; i < numThreads; ++i)
        {
            mThreads.emplace_back([this] { ThreadMain(); });
            NameThread(mThreads.back(), "cairn-bg", i);
        }
    }
    catch (...)
    {
        // A thread that could not start: stop the ones that did before the exception leaves the constructor
        // (joinable threads of a half-built queue would terminate the program)
        {
            std::lock_guard lock(mMutex);
            mStopping = true;
        }
        mHasWork.notify_all();
        for (std::thread& thread : mThreads)
            thread.join();
        throw;
    }
}

BackgroundQueue::~BackgroundQueue()
{
    std::vector<std::shared_ptr<BackgroundTask>> queued;
    {
        std::lock_guard lock(mMutex);
        mStopping = true;
        queued.swap(mQueued);
    }
    mHasWork.notify_all();
    for (const std::shared_ptr<BackgroundTask>& task : queued)
        task->Cancel();
    for (std::thread& thread : mThreads)
        thread.join();
}

std::shared_ptr<BackgroundTask> BackgroundQueue::Submit(std::string inName, int inPriority,
                                                        BackgroundStepFunction inStep)
{
    const bool valid = static_cast<bool>(inStep);
    auto task = std::make_shared<BackgroundTask>(std::move(inName), inPriority, std::move(inStep));
    if (!valid)
    {
        task->mError = "BackgroundQueue::Submit: empty step function";
        task->TryTransition(BackgroundTaskState::Queued, BackgroundTaskState::Running);
        task->Finish(BackgroundTaskState::Failed);
        return task;
    }
    {
        std::lock_guard lock(mMutex);
        if (mStopping)
        {
            task->Cancel();
            return task;
        }
        task->mSequence = mNextSequence++;
        mQueued.push_back(task);
    }
    mHasWork.notify_one();
    return task;
}

size_t BackgroundQueue::GetNumQueued() const
{
    std::lock_guard lock(mMutex);
    return mQueued.size();
}

BackgroundQueue::Stats BackgroundQueue::GetStats() const
{
    Stats stats;
    // Relaxed: statistics
    stats.mChunksRun = mChunksRun.load(std::memory_order_relaxed);
    stats.mYieldsToFrame = mYieldsToFrame.load(std::memory_order_relaxed);
    stats.mYieldTimeouts = mYieldTimeouts.load(std::memory_order_relaxed);
    stats.mPreemptions = mPreemptions.load(std::memory_order_relaxed);
    stats.mThreadPriorityLowered = mThreadPriorityLowered.load(std::memory_order_relaxed);
    return stats;
}

std::shared_ptr<BackgroundTask> BackgroundQueue::PopBest(std::unique_lock<std::mutex>& ioLock)
{
    for (;;)
    {
        // Sweep out tasks cancelled while queued
        std::erase_if(mQueued, [](const std::shared_ptr<BackgroundTask>& inTask)
                      { return inTask->GetState() != BackgroundTaskState::Queued; });
        if (mStopping) return nullptr;
        if (!mQueued.empty())
        {
            // A linear scan: the queue holds tens of tasks, and priorities may change while they wait
            auto best = std::max_element(mQueued.begin(), mQueued.end(),
                                         [](const auto& inL, const auto& inR)
                                         {
                                             const int l = inL->GetPriority(), r = inR->GetPriority();
                                             return l < r || (l == r && inL->mSequence > inR->mSequence);
                                         });
            std::shared_ptr<BackgroundTask> task = std::move(*best);
            mQueued.erase(best);
            if (task->TryTransition(BackgroundTaskState::Queued, BackgroundTaskState::Running)) return task;
            continue; // Cancelled between the sweep and now
        }
        mHasWork.wait(ioLock);
    }
}

bool BackgroundQueue::HasHigherQueued(int inPriority) const
{
    return std::any_of(mQueued.begin(), mQueued.end(),
                       [&](const std::shared_ptr<BackgroundTask>& inTask) {
                           return inTask->GetPriority() > inPriority &&
                                  inTask->GetState() == BackgroundTaskState::Queued;
                       });
}

void BackgroundQueue::ThreadMain()
{
#if defined(__linux__)
    // Linux applies nice per thread: the frame's threads win the cores while a chunk runs
    sched_param idle{};
    if (mSettings.mIdleScheduling && sched_setscheduler(0, SCHED_IDLE, &idle) == 0)
        mThreadPriorityLowered.store(true, std::memory_order_relaxed); // Statistic only
    else if (mSettings.mLowerThreadPriority &&
             setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 10) == 0)
        mThreadPriorityLowered.store(true, std::memory_order_relaxed);
#endif
    for (;;)
    {
        std::shared_ptr<BackgroundTask> task;
        {
            std::unique_lock lock(mMutex);
            task = PopBest(lock);
        }
        if (task == nullptr) return;
        // The step's captures are released before the state is published, so a submitter that sees the task
        // finished may rely on them being gone
        auto finish = [&task](BackgroundTaskState inState)
        {
            task->mStep = nullptr;
            task->Finish(inState);
        };
        for (;;)
        {
            if (task->IsCancelRequested())
            {
                finish(BackgroundTaskState::Cancelled);
                break;
            }
            {
                std::lock_guard lock(mMutex);
                if (mStopping)
                {
                    finish(BackgroundTaskState::Cancelled);
                    break;
                }
                if (HasHigherQueued(task->GetPriority()))
                {
                    mPreemptions.fetch_add(1, std::memory_order_relaxed); // Statistic only
                    task->TryTransition(BackgroundTaskState::Running, BackgroundTaskState::Queued);
                    mQueued.push_back(task); // Keeps its sequence
                    mHasWork.notify_one();
                    break;
                }
            }
            if (mSettings.mFrameJobs != nullptr && mSettings.mFrameJobs->GetNumJobsInFlight() != 0)
            {
                mYieldsToFrame.fetch_add(1, std::memory_order_relaxed); // Statistic only
                if (!mSettings.mFrameJobs->WaitForFrameIdle(mSettings.mMaxYield))
                    mYieldTimeouts.fetch_add(1, std::memory_order_relaxed); // Statistic only
            }
            BackgroundTaskContext context(*task);
            BackgroundStep step;
            try
            {
                step = task->mStep(context);
            }
            catch (const std::exception& inException)
            {
                context.SetError(std::string("exception: ") + inException.what());
                step = BackgroundStep::Failed;
            }
            catch (...)
            {
                context.SetError("exception of unknown type");
                step = BackgroundStep::Failed;
            }
            task->mChunksRun.fetch_add(1, std::memory_order_relaxed); // Statistic only
            mChunksRun.fetch_add(1, std::memory_order_relaxed);       // Statistic only
            if (step == BackgroundStep::Done)
            {
                finish(BackgroundTaskState::Done);
                break;
            }
            if (step == BackgroundStep::Failed)
            {
                if (task->mError.empty()) task->mError = "the step function reported failure";
                finish(BackgroundTaskState::Failed);
                break;
            }
        }
    }
}

} // namespace cairn::jobs
