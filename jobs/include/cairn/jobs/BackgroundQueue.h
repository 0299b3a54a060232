#pragma once

// BackgroundQueue: work that spans several frames (navmesh tiles, streaming loads), run in chunks on threads
// of its own. A task is a step function called again and again until it reports Done or Failed; between two
// chunks the thread
//  - stands aside while the frame's jobs are in flight (JobSystem::WaitForFrameIdle, up to
//  Settings::mMaxYield,
//    so that back-to-back frames still leave it some time),
//  - switches to a queued task of higher priority (the current one goes back to the queue),
//  - honours cancellation.
// The threads also run at a lower OS priority (nice), so that a chunk already running when a frame starts
// gives way to the frame's threads. The frame never waits for background work: there is no lock shared with
// it.
//
// Threads: Submit and every BackgroundTask method may be called from any thread. Step functions run on the
// queue's threads, one chunk at a time per task (a task is never run by two threads at once). The destructor
// (owner thread) cancels what is queued, asks running tasks to cancel at their next chunk and joins.
// Locking: mMutex guards mQueued and mStopping; mHasWork sleeps the threads. A task's state, progress,
// priority and cancel flag are atomics; its error text is written before its state turns Failed (release)
// and read after it is seen Failed (acquire); mDoneMutex/mDone serve Wait.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace cairn::jobs
{

class JobSystem;

enum class BackgroundTaskState : uint8_t
{
    Queued,
    Running,
    Done,
    Failed,
    Cancelled
};

const char* ToString(BackgroundTaskState inState);

enum class BackgroundStep : uint8_t
{
    Continue, ///< Call again for the next chunk
    Done,
    Failed ///< Give the reason with BackgroundTaskContext::SetError first
};

class BackgroundTask;

/// What a step function may ask of its task while it runs.
class BackgroundTaskContext
{
public:
    explicit BackgroundTaskContext(BackgroundTask& ioTask) : mTask(ioTask) {}
    /// Long chunks should check this and return early.
    bool IsCancelRequested() const;
    /// Fraction done, clamped to [0, 1]; NaN is ignored.
    void SetProgress(float inFraction);
    void SetError(std::string inMessage);

private:
    BackgroundTask& mTask;
};

using BackgroundStepFunction = std::function<BackgroundStep(BackgroundTaskContext&)>;

/// A submitted task: its ticket for the submitter, shared with the queue.
class BackgroundTask
{
public:
    BackgroundTask(std::string inName, int inPriority, BackgroundStepFunction inStep);

    const std::string& GetName() const { return mName; }
    BackgroundTaskState GetState() const;
    bool IsFinished() const; ///< Done, Failed or Cancelled
    float GetProgress() const;
    int GetPriority() const;
    /// Higher runs first; a running task is switched out at its next chunk if a queued one is higher.
    void SetPriority(int inPriority);
    /// A queued task is cancelled at once; a running one at its next chunk (or when it checks).
    void Cancel();
    bool IsCancelRequested() const;
    /// Waits until the task is finished or inTimeout passes; true when finished.
    bool Wait(std::chrono::milliseconds inTimeout) const;
    /// Why it failed (empty unless Failed).
    std::string GetError() const;
    uint32_t GetChunksRun() const;

private:
    friend class BackgroundQueue;
    friend class BackgroundTaskContext;

    /// Moves to a finished state and wakes Wait; false if already finished.
    bool Finish(BackgroundTaskState inState);
    bool TryTransition(BackgroundTaskState inFrom, BackgroundTaskState inTo);

    const std::string mName;
    BackgroundStepFunction mStep; ///< Called by the running queue thread only
    std::atomic<int> mPriority;
    std::atomic<BackgroundTaskState> mState{BackgroundTaskState::Queued};
    std::atomic<float> mProgress{0.0f};
    std::atomic<bool> mCancelRequested{false};
    std::atomic<uint32_t> mChunksRun{0};
    std::string mError;     ///< Written by the running thread before the state turns Failed
    uint64_t mSequence = 0; ///< Submission order, for FIFO among equal priorities; BackgroundQueue::mMutex
    mutable std::mutex mDoneMutex;
    mutable std::condition_variable mDone;
};

class BackgroundQueue
{
public:
    static constexpr uint32_t cMaxThreads = 64;

    struct Settings
    {
        uint32_t mNumThreads = 1; ///< 1 to cMaxThreads (clamped)
        /// Frame jobs to stand aside for between chunks (may be null: then only the OS priority applies)
        const JobSystem* mFrameJobs = nullptr;
        /// Longest a thread stands aside per chunk while frame jobs stay in flight
        std::chrono::microseconds mMaxYield{4000};
        /// Lower the threads' OS priority (nice 10)
        bool mLowerThreadPriority = true;
        /// Linux: run the threads only when no other thread wants a core (SCHED_IDLE) instead of nice 10.
        /// Best when the frame leaves idle time (a 60 Hz game): a background thread then never preempts a
        /// frame thread. Frames that keep every core busy would starve background work
        bool mIdleScheduling = false;
    };

    struct Stats
    {
        uint64_t mChunksRun = 0;
        uint64_t mYieldsToFrame = 0; ///< Chunks that waited for frame jobs first
        uint64_t mYieldTimeouts = 0; ///< Of which the frame stayed busy for all of mMaxYield
        uint64_t mPreemptions = 0;   ///< Tasks switched out for a higher-priority one
        bool mThreadPriorityLowered = false;
    };

    BackgroundQueue(); ///< Default settings
    explicit BackgroundQueue(const Settings& inSettings);
    BackgroundQueue(const BackgroundQueue&) = delete;
    BackgroundQueue& operator=(const BackgroundQueue&) = delete;
    ~BackgroundQueue();

    /// Queues a task; an empty step function gives a task that is already Failed.
    std::shared_ptr<BackgroundTask> Submit(std::string inName, int inPriority, BackgroundStepFunction inStep);
    /// Threads running tasks (the settings' count, clamped to 1..cMaxThreads).
    uint32_t GetNumThreads() const { return uint32_t(mThreads.size()); }
    /// Tasks waiting for a thread (cancelled ones not yet swept out included).
    size_t GetNumQueued() const;
    Stats GetStats() const;

private:
    void ThreadMain();
    /// Takes the highest-priority queued task (FIFO among equals); null when stopping. mMutex held.
    std::shared_ptr<BackgroundTask> PopBest(std::unique_lock<std::mutex>& ioLock);
    /// True when a queued task has a higher priority than inPriority. mMutex held.
    bool HasHigherQueued(int inPriority) const;

    Settings mSettings;
    mutable std::mutex mMutex;
    std::condition_variable mHasWork;
    std::vector<std::shared_ptr<BackgroundTask>> mQueued; ///< mMutex
    uint64_t mNextSequence = 0;                           ///< mMutex
    bool mStopping = false;                               ///< mMutex

    std::atomic<uint64_t> mChunksRun{0};
    std::atomic<uint64_t> mYieldsToFrame{0};
    std::atomic<uint64_t> mYieldTimeouts{0};
    std::atomic<uint64_t> mPreemptions{0};
    std::atomic<bool> mThreadPriorityLowered{false};
    std::vector<std::thread> mThreads;
};

} // namespace cairn::jobs
