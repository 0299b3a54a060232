#include "cairn/jobs/JobSystem.h"

#include "ThreadName.h"

#include <algorithm>
#include <cassert>
#include <chrono>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#include <pthread.h>
#include <sched.h>
#endif

namespace cairn::jobs
{

namespace
{
/// Which job run this thread is inside (0: none). A run's id is unique across threads: the thread's number
/// in the high bits, a per-thread count below, so that taking one needs no shared counter.
thread_local uint64_t tCurrentRun = 0;
thread_local uint64_t tRunIdBase = 0;
thread_local uint64_t tRunCount = 0;
/// The JobSystem this thread is a worker of (set by WorkerMain), or null.
thread_local const JobSystem* tWorkerOf = nullptr;
/// A job that this thread is running, on Run's stack, and the one it runs inside of (null: none): what a Wait
/// on this thread could never see finish. This thread's own.
struct RunningJob
{
    const JobSystem* mSystem;
    uint32_t mIndex;
    uint32_t mGeneration;
    const RunningJob* mOuter;
};
thread_local const RunningJob* tRunningJob = nullptr;
std::atomic<uint64_t> sNextThreadNumber{1};

uint64_t NextRunId()
{
    // Relaxed: only distinct values are needed
    if (tRunIdBase == 0) tRunIdBase = sNextThreadNumber.fetch_add(1, std::memory_order_relaxed) << 40;
    return tRunIdBase | (++tRunCount & ((uint64_t(1) << 40) - 1));
}

void CpuRelax()
{
#if defined(__x86_64__) || defined(__i386__)
    _mm_pause();
#else
    std::this_thread::yield();
#endif
}
} // namespace

template <class Done> bool JobSystem::SpinUntil(const Done& inDone) const
{
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::microseconds(cSpinMicroseconds);
    for (uint32_t i = 0;; ++i)
    {
        if (inDone()) return true;
        // Relaxed: a hint to stop spinning; the queue itself is read under its mutex
        if (mNumReady.load(std::memory_order_relaxed) != 0) return false;
        if ((i & 63) == 63)
        {
            const auto now = std::chrono::steady_clock::now();
            // Relaxed: a deadline only, it orders no data
            if (now > deadline &&
                now.time_since_epoch().count() > mSpinExtendedUntil.load(std::memory_order_relaxed))
                return false;
        }
        CpuRelax();
    }
}

void JobSystem::ExtendSpin(uint64_t inNanoseconds)
{
    if (mMoreThreadsThanCores) return;
    using Clock = std::chrono::steady_clock;
    const Clock::rep until =
        (Clock::now() + std::chrono::duration_cast<Clock::duration>(
                            std::chrono::nanoseconds(std::min(inNanoseconds, cMaxSpinExtensionNanoseconds)) +
                            std::chrono::microseconds(cSpinMicroseconds)))
            .time_since_epoch()
            .count();
    // Relaxed: a deadline only; the later of two concurrent extensions wins
    Clock::rep current = mSpinExtendedUntil.load(std::memory_order_relaxed);
    while (current < until &&
           !mSpinExtendedUntil.compare_exchange_weak(current, until, std::memory_order_relaxed))
    {
    }
}

namespace
{
/// Settings::mMaxJobs in its range (see there).
uint32_t ClampedMaxJobs(const JobSystem::Settings& inSettings)
{
    return std::clamp<uint32_t>(inSettings.mMaxJobs, 1, JobSystem::cMaxJobsLimit);
}
} // namespace

JobSystem::JobSystem() : JobSystem(Settings{}) {}

JobSystem::JobSystem(const Settings& inSettings)
    : mSlots(std::make_unique<JobSlot[]>(ClampedMaxJobs(inSettings))), mMaxJobs(ClampedMaxJobs(inSettings)),
      mReady(mMaxJobs), mUseLoopBoard(inSettings.mUseLoopBoard), mSearchMarks(mMaxJobs, 0u),
      mSearchStack(mMaxJobs)
{
    mFree.reserve(mMaxJobs);
    for (uint32_t i = mMaxJobs; i-- > 0;)
        mFree.push_back(i); // Slot 0 is handed out first
    uint32_t numThreads = inSettings.mNumThreads;
    if (numThreads == 0) numThreads = std::max(1u, std::thread::hardware_concurrency());
    numThreads = std::min(numThreads, cMaxThreads);
    mMoreThreadsThanCores = numThreads > std::max(1u, std::thread::hardware_concurrency());
    mWorkers.reserve(numThreads - 1);
    for (uint32_t i = 1; i < numThreads; ++i)
    {
        mWorkers.emplace_back([this] { WorkerMain(); });
        NameThread(mWorkers.back(), cWorkerThreadNamePrefix, i);
    }
    if (inSettings.mPinWorkers) PinWorkers();
}

void JobSystem::PinWorkers()
{
    cpu_set_t allowed;
    CPU_ZERO(&allowed);
    if (sched_getaffinity(0, sizeof(allowed), &allowed) != 0) return; // Left to the OS: a hint only
    std::vector<int> cores;
    for (int core = 0; core < CPU_SETSIZE; ++core)
        if (CPU_ISSET(core, &allowed)) cores.push_back(core);
    if (cores.size() < 2) return;
    for (size_t i = 0; i < mWorkers.size(); ++i)
    {
        cpu_set_t one;
        CPU_ZERO(&one);
        CPU_SET(cores[(i + 1) % cores.size()], &one);
        (void)pthread_setaffinity_np(mWorkers[i].native_handle(), sizeof(one), &one); // A hint as well
    }
}

JobSystem::~JobSystem()
{
    (void)WaitIdle(); // The owner destroys it outside any of its jobs
    // Relaxed: a deadline only; spinning workers then leave within cSpinMicroseconds, not an extension later
    mSpinExtendedUntil.store(0, std::memory_order_relaxed);
    {
        std::lock_guard lock(mQueueMutex);
        mStopping = true;
    }
    mWake.notify_all();
    for (std::thread& worker : mWorkers)
        worker.join();
}

uint32_t JobSystem::AllocateSlot()
{
    std::lock_guard lock(mFreeMutex);
    if (mFree.empty()) return JobHandle::cInvalidIndex;
    const uint32_t index = mFree.back();
    mFree.pop_back();
    return index;
}

void JobSystem::FreeSlot(uint32_t inIndex)
{
    std::lock_guard lock(mFreeMutex);
    mFree.push_back(inIndex); // Never grows past mMaxJobs: reserved in the constructor
}

JobHandle JobSystem::Publish(uint32_t inIndex, const char* inName, std::span<const JobHandle> inPrerequisites)
{
    JobSlot& slot = mSlots[inIndex];
    slot.mName = inName;
    slot.mScope = tCurrentRun;
    // Relaxed: only a completion changes the generation, and this slot's job has not been queued yet
    const uint32_t generation = slot.mGeneration.load(std::memory_order_relaxed);
    // Relaxed: the slot is private until queued; the hold keeps it from being queued while prerequisites are
    // registered
    slot.mPending.store(1, std::memory_order_relaxed);
    // Relaxed: a counter; WaitIdle/WaitForFrameIdle read it with its decrement's ordering (see Run)
    mJobsInFlight.fetch_add(1, std::memory_order_relaxed);
    for (const JobHandle& prerequisite : inPrerequisites)
    {
        if (!prerequisite.IsValid() || prerequisite.mIndex >= mMaxJobs) continue;
        JobSlot& before = mSlots[prerequisite.mIndex];
        std::unique_lock lock(before.mMutex);
        // Relaxed: the slot mutex orders this against the completion's bump
        if (before.mGeneration.load(std::memory_order_relaxed) != prerequisite.mGeneration) continue; // Done
        if (before.mNumDependents == cMaxDependents)
        {
            lock.unlock();
            mDependentOverflow.fetch_add(1, std::memory_order_relaxed); // Statistic only
            Wait(prerequisite);
            continue;
        }
        before.mDependents[before.mNumDependents++] = inIndex;
        // Relaxed: the prerequisite's decrement (acq_rel) is what orders its effects before this job
        slot.mPending.fetch_add(1, std::memory_order_relaxed);
    }
    // Acq_rel: if this drops the last hold, it acquires the prerequisites' releases before queueing the job
    if (slot.mPending.fetch_sub(1, std::memory_order_acq_rel) == 1) Enqueue(inIndex);
    return {inIndex, generation};
}

void JobSystem::Enqueue(uint32_t inIndex)
{
    bool waiters;
    {
        std::lock_guard lock(mQueueMutex);
        assert(mReadyCount < mMaxJobs);
        mReady[(mReadyHead + mReadyCount) % mMaxJobs] = inIndex;
        ++mReadyCount;
        mNumReady.store(mReadyCount, std::memory_order_relaxed); // A hint for spinners, see SpinUntil
        waiters = mNumIsolatedSleepers > 0;
    }
    // One wake-up could go to a wait inside a job that may not run this job (isolation), and the workers
    // would sleep on with the job queued: then everybody re-checks. Otherwise one thread is enough (waking
    // all made a chain of jobs bounce between threads)
    if (waiters)
        mWake.notify_all();
    else
        mWake.notify_one();
}

int JobSystem::FindRunnableFor(uint64_t inScope, uint32_t inAwaited) const
{
    for (uint32_t i = 0; i < mReadyCount; ++i)
    {
        const uint32_t index = mReady[(mReadyHead + i) % mMaxJobs];
        if (index == inAwaited || mSlots[index].mScope == inScope) return int(i);
    }
    // A prerequisite of the awaited job, or a prerequisite of one of those, and so on: running it is what the
    // wait needs, and it cannot wait for this job (it is not below it on any stack)
    if (inAwaited != JobHandle::cInvalidIndex)
    {
        if (++mSearchEpoch == 0) // Wrapped: marks of 2^32 searches ago could match
        {
            std::fill(mSearchMarks.begin(), mSearchMarks.end(), 0u);
            mSearchEpoch = 1;
        }
        for (uint32_t i = 0; i < mReadyCount; ++i)
            if (LeadsTo(mReady[(mReadyHead + i) % mMaxJobs], inAwaited)) return int(i);
    }
    // Nothing of its own: run anything only when no worker can (each is stuck in a wait inside a job; a
    // worker asking counts itself), or the queued jobs would never run
    const size_t stuck = mNumStuckWorkers + (tWorkerOf == this ? 1 : 0);
    if (mReadyCount > 0 && stuck >= mWorkers.size()) return 0;
    return -1;
}

bool JobSystem::LeadsTo(uint32_t inFrom, uint32_t inAwaited) const
{
    // Depth first through the dependents. A job marked in this search was explored from an earlier start and
    // does not lead to inAwaited (or the search would have ended), so each job is explored once per search:
    // O(jobs + dependencies), and the stack never holds more than mMaxJobs entries
    uint32_t depth = 0;
    mSearchStack[depth++] = inFrom;
    mSearchMarks[inFrom] = mSearchEpoch;
    while (depth > 0)
    {
        JobSlot& slot = mSlots[mSearchStack[--depth]];
        // Slot mutexes are taken under the queue mutex only here, and no thread takes the queue mutex while
        // it holds a slot mutex: no cycle. A job's dependents are jobs not yet queued, whose slots stay
        // theirs
        std::lock_guard slotLock(slot.mMutex);
        for (uint32_t d = 0; d < slot.mNumDependents; ++d)
        {
            const uint32_t dependent = slot.mDependents[d];
            if (dependent == inAwaited) return true;
            if (mSearchMarks[dependent] == mSearchEpoch) continue;
            mSearchMarks[dependent] = mSearchEpoch;
            mSearchStack[depth++] = dependent;
        }
    }
    return false;
}

uint32_t JobSystem::TakeReadyAt(int inPosition)
{
    const uint32_t index = mReady[(mReadyHead + uint32_t(inPosition)) % mMaxJobs];
    // Close the gap: the entries before it move up one (the order of the others is kept)
    for (uint32_t i = uint32_t(inPosition); i > 0; --i)
        mReady[(mReadyHead + i) % mMaxJobs] = mReady[(mReadyHead + i - 1) % mMaxJobs];
    mReadyHead = (mReadyHead + 1) % mMaxJobs;
    --mReadyCount;
    mNumReady.store(mReadyCount, std::memory_order_relaxed); // A hint for spinners
    return index;
}

bool JobSystem::TryPopReady(uint32_t& outIndex)
{
    std::lock_guard lock(mQueueMutex);
    if (mReadyCount == 0) return false;
    outIndex = mReady[mReadyHead];
    mReadyHead = (mReadyHead + 1) % mMaxJobs;
    --mReadyCount;
    mNumReady.store(mReadyCount, std::memory_order_relaxed); // A hint for spinners
    return true;
}

int JobSystem::FindQueuedNearFront(const JobHandle& inJob) const
{
    // Still running means its slot holds it (a finished job's slot may already hold a new one)
    if (!inJob.IsValid() || IsDone(inJob)) return -1;
    const uint32_t searched = std::min(mReadyCount, cAwaitedSearch);
    for (uint32_t position = 0; position < searched; ++position)
        if (mReady[(mReadyHead + position) % mMaxJobs] == inJob.mIndex) return int(position);
    return -1;
}

bool JobSystem::TryPopAwaited(const JobHandle& inJob, uint32_t& outIndex)
{
    std::lock_guard lock(mQueueMutex);
    if (mReadyCount == 0) return false;
    const int position = FindQueuedNearFront(inJob);
    outIndex = TakeReadyAt(position >= 0 ? position : 0); // Else the head
    return true;
}

bool JobSystem::TryRunHere(const JobHandle& inJob)
{
    uint32_t index;
    {
        std::lock_guard lock(mQueueMutex);
        const int position = FindQueuedNearFront(inJob);
        if (position < 0) return false;
        index = TakeReadyAt(position);
    }
    Run(index);
    return true;
}

void JobSystem::Run(uint32_t inIndex)
{
    JobSlot& slot = mSlots[inIndex];
    const uint64_t outerRun = tCurrentRun;
    tCurrentRun = NextRunId();
    // Relaxed: the generation changes only when this run ends (below), on this thread
    const RunningJob running{this, inIndex, slot.mGeneration.load(std::memory_order_relaxed), tRunningJob};
    tRunningJob = &running;
    slot.mFunction();
    tRunningJob = running.mOuter;
    tCurrentRun = outerRun;
    slot.mFunction.Reset();
    uint32_t dependents[cMaxDependents];
    uint32_t numDependents;
    {
        std::lock_guard lock(slot.mMutex);
        numDependents = slot.mNumDependents;
        std::copy_n(slot.mDependents, numDependents, dependents);
        slot.mNumDependents = 0;
        // Seq_cst: a waiter stores mNumWaiters and then loads the generation; this stores the generation and
        // then loads mNumWaiters (below). Seq_cst on both sides means one of them sees the other, so a waiter
        // cannot sleep through the finish. It also releases the job's effects to IsDone's load
        slot.mGeneration.fetch_add(1, std::memory_order_seq_cst);
    }
    for (uint32_t i = 0; i < numDependents; ++i)
    {
        JobSlot& after = mSlots[dependents[i]];
        // Acq_rel: releases this job's effects to whoever drops the last hold and queues the dependent
        if (after.mPending.fetch_sub(1, std::memory_order_acq_rel) == 1) Enqueue(dependents[i]);
    }
    FreeSlot(inIndex);
    mJobsRun.fetch_add(1, std::memory_order_relaxed); // Statistic only
    EndInFlight();
}

void JobSystem::EndInFlight()
{
    // Seq_cst: as the generation bump in Run, against WaitIdle's sleepers
    const bool nowIdle = mJobsInFlight.fetch_sub(1, std::memory_order_seq_cst) == 1;
    if (mNumWaiters.load(std::memory_order_seq_cst) > 0)
    {
        // Taking the mutex puts this notify after a sleeper's predicate check or before it
        {
            std::lock_guard lock(mQueueMutex);
        }
        mWake.notify_all();
    }
    if (nowIdle)
    {
        {
            std::lock_guard lock(mIdleMutex);
        }
        mIdle.notify_all();
    }
}

bool JobSystem::IsDone(const JobHandle& inJob) const
{
    if (!inJob.IsValid() || inJob.mIndex >= mMaxJobs) return true;
    // Seq_cst: see Run (acquire would order the job's effects; the waiter protocol needs seq_cst)
    return mSlots[inJob.mIndex].mGeneration.load(std::memory_order_seq_cst) != inJob.mGeneration;
}

bool JobSystem::Wait(const JobHandle& inJob)
{
    for (const RunningJob* running = tRunningJob; running != nullptr; running = running->mOuter)
        if (running->mSystem == this && running->mIndex == inJob.mIndex &&
            running->mGeneration == inJob.mGeneration)
            return false; // It finishes only when this thread returns to it
    const uint64_t run = tCurrentRun;
    if (run == 0)
    {
        // Outside any job: the awaited job first, then whatever is queued. The head can be a long job that
        // another part of the frame scheduled to run beside this one (the physics step's broad-phase update
        // behind the helpers of its ParallelFor): run here, it no longer ran beside anything
        while (!IsDone(inJob))
        {
            uint32_t index;
            if (TryPopAwaited(inJob, index))
            {
                Run(index);
                continue;
            }
            if (SpinUntil([&] { return IsDone(inJob); })) return true;
            if (mNumReady.load(std::memory_order_relaxed) != 0)
                continue; // Relaxed: a hint, rechecked by the pop
            std::unique_lock lock(mQueueMutex);
            mNumWaiters.fetch_add(1, std::memory_order_seq_cst); // Seq_cst: see Run
            mWake.wait(lock, [&] { return mReadyCount > 0 || IsDone(inJob); });
            mNumWaiters.fetch_sub(1, std::memory_order_relaxed); // Only ever compared with zero by Run
            // Woken for a queued job but leaving because its own finished: pass the wake-up on, or the
            // workers could sleep on with the job queued
            if (mReadyCount > 0 && IsDone(inJob)) mWake.notify_one();
        }
        return true;
    }
    // Inside a job: isolated (see the header). Every check is under the queue mutex; such waits are rare
    const uint32_t awaited = inJob.IsValid() ? inJob.mIndex : JobHandle::cInvalidIndex;
    std::unique_lock lock(mQueueMutex);
    while (!IsDone(inJob))
    {
        if (const int position = FindRunnableFor(run, awaited); position >= 0)
        {
            // The awaited job finishes without the queue mutex: if it did before the search, its slot may
            // already hold a new job, and the match would be a job of that one. Still running now means the
            // search saw the right slot
            if (IsDone(inJob)) break;
            const uint32_t index = TakeReadyAt(position);
            lock.unlock();
            Run(index);
            lock.lock();
            continue;
        }
        // Stuck until something of its own is queued, the job finishes, or every worker is stuck too (then a
        // stuck thread may run anything). A stuck worker is counted, and the others re-check when it is
        const bool isWorker = tWorkerOf == this;
        if (isWorker)
        {
            ++mNumStuckWorkers;
            mWake.notify_all();
        }
        mNumWaiters.fetch_add(1, std::memory_order_seq_cst); // Seq_cst: see Run
        ++mNumIsolatedSleepers;
        // A worker is already counted here, so it must not count itself again in FindRunnableFor
        if (isWorker) tWorkerOf = nullptr;
        mWake.wait(lock, [&] { return IsDone(inJob) || FindRunnableFor(run, awaited) >= 0; });
        --mNumIsolatedSleepers;
        if (isWorker)
        {
            tWorkerOf = this;
            --mNumStuckWorkers;
        }
        mNumWaiters.fetch_sub(1, std::memory_order_relaxed); // Only ever compared with zero by Run
    }
    return true;
}

bool JobSystem::WaitAll(std::span<const JobHandle> inJobs)
{
    bool all = true;
    for (const JobHandle& job : inJobs)
        all = Wait(job) && all;
    return all;
}

bool JobSystem::WaitIdle()
{
    if (tCurrentRun != 0) return false; // Its own job is in flight: it would wait forever
    // Seq_cst loads: see Run
    while (mJobsInFlight.load(std::memory_order_seq_cst) != 0)
    {
        uint32_t index;
        if (TryPopReady(index))
        {
            Run(index);
            continue;
        }
        std::unique_lock lock(mQueueMutex);
        mNumWaiters.fetch_add(1, std::memory_order_seq_cst);
        mWake.wait(lock,
                   [&] { return mReadyCount > 0 || mJobsInFlight.load(std::memory_order_seq_cst) == 0; });
        mNumWaiters.fetch_sub(1, std::memory_order_relaxed); // As in Wait
    }
    return true;
}

bool JobSystem::WaitForFrameIdle(std::chrono::microseconds inTimeout) const
{
    std::unique_lock lock(mIdleMutex);
    // Acquire: a background thread that sees zero also sees the frame's writes (it may read them next)
    return mIdle.wait_for(lock, inTimeout,
                          [&] { return mJobsInFlight.load(std::memory_order_acquire) == 0; });
}

bool JobSystem::TryTakeLoopBoard()
{
    // Relaxed load: a busy board is skipped without writing its line. Acquire exchange: the last owner's
    // joiners have finished with the function and context (their count's release, acquired by that owner's
    // CloseLoop before its release of the flag)
    if (mLoopBusy.load(std::memory_order_relaxed) || mLoopBusy.exchange(true, std::memory_order_acquire))
        return false;
    // Relaxed: a counter, as in Publish
    mJobsInFlight.fetch_add(1, std::memory_order_relaxed);
    return true;
}

void JobSystem::OpenLoop(uint32_t inParts, LoopPartFunction inFunction, void* inContext)
{
    // Workers add to the joined field only after seeing it below the parts less one, so it never passes the
    // parts plus the workers
    static_assert(2 * cMaxThreads <= cLoopJoinedMask, "a loop's joins must fit the state's fields");
    assert(inParts >= 2 && inParts <= cMaxThreads);
    mLoopFunction = inFunction;
    mLoopContext = inContext;
    // Release: a joiner reads the function and context after its add acquires this
    mLoopState.store(cLoopOpen | uint64_t(inParts) << cLoopPartsShift, std::memory_order_release);
    // Relaxed: a worker that falls asleep as the board opens may be missed, which costs the loop a helper,
    // not a part (the owner takes the chunks of parts nobody joined); the next loop or job wakes it. A fence
    // to rule that out would make every opening wait for the stores before it
    const uint32_t asleep = mNumWorkersAsleep.load(std::memory_order_relaxed);
    if (asleep > 0)
    {
        // Taking the mutex puts these wake-ups after a sleeper's look at the board or before it. A wake-up
        // that reaches a thread waiting for a job instead also loses a helper only
        {
            std::lock_guard lock(mQueueMutex);
        }
        for (uint32_t i = std::min(asleep, inParts - 1); i > 0; --i)
            mWake.notify_one();
    }
}

void JobSystem::CloseLoop()
{
    // Relaxed: the joins and this close are ordered by the state's modification order alone (a join after
    // it finds the board shut and touches nothing); the parts' writes reach the owner through the done count
    const uint64_t state = mLoopState.fetch_and(~cLoopOpen, std::memory_order_relaxed);
    const uint32_t joined = uint32_t(state & cLoopJoinedMask);
    // Acquire: pairs with each joiner's release, so their parts' writes happen before the caller goes on.
    // The joiners are running chunks they took before the owner ran out: a short wait. The count only
    // rises (a reset at the opening would write a line that a joiner wrote last), so this loop's parts are
    // done when it has risen by the parts joined
    const uint32_t done = mLoopPartsDoneBefore + joined;
    for (uint32_t spins = 0; mLoopPartsDone.load(std::memory_order_acquire) != done; ++spins)
        if (spins < 256)
            CpuRelax();
        else
            std::this_thread::yield(); // A joiner descheduled (more threads than cores)
    mLoopPartsDoneBefore = done;
    const uint32_t parts = uint32_t(state >> cLoopPartsShift & 0xff);
    mLoopPartsJoined.fetch_add(std::min(joined, parts - 1), std::memory_order_relaxed); // Statistic only
    EndInFlight();
    // Release: the joiners' reads of the function and context happen before the next owner's writes
    mLoopBusy.store(false, std::memory_order_release);
}

bool JobSystem::LoopHasRoom() const
{
    // Relaxed: a hint; TryJoinLoop's add decides
    const uint64_t state = mLoopState.load(std::memory_order_relaxed);
    return (state & cLoopOpen) != 0 && (state & cLoopJoinedMask) + 1 < (state >> cLoopPartsShift & 0xff);
}

bool JobSystem::TryJoinLoop()
{
    if (!LoopHasRoom()) return false;
    // One add, not a compare-exchange: the idle workers of a many-core machine see a loop open at once, and
    // a compare-exchange that fails takes the line again, each worker about as many times as there are
    // joiners before it. Acquire: the owner's function and context, written before its opening store
    // (release); read only when the board was open. The joined field has room for every worker's add beyond
    // the loop's parts (cLoopJoinedMask)
    const uint64_t state = mLoopState.fetch_add(1, std::memory_order_acquire);
    if ((state & cLoopOpen) == 0) return false; // Shut (the add lands in a closed state, which nobody reads)
    const uint32_t part = uint32_t(state & cLoopJoinedMask) + 1;
    const bool hasPart = part < (state >> cLoopPartsShift & 0xff);
    if (hasPart)
    {
        // A run of its own, as a job's: a wait inside the part is isolated to the jobs the part schedules
        const uint64_t outerRun = tCurrentRun;
        tCurrentRun = NextRunId();
        mLoopFunction(mLoopContext, part);
        tCurrentRun = outerRun;
    }
    // Counted joined by the owner's close whether or not a part was left (other workers took the last ones
    // between this worker's look and its add). Release: the part's writes, and this worker's reads of the
    // board, happen before the owner's return
    mLoopPartsDone.fetch_add(1, std::memory_order_release);
    return hasPart;
}

void JobSystem::WorkerMain()
{
    tWorkerOf = this;
    for (;;)
    {
        uint32_t index;
        // Relaxed: a hint that spares the mutex when nothing is queued (a worker going from loop to loop);
        // a job it misses is seen by the spin or the sleep's check below
        if (mNumReady.load(std::memory_order_relaxed) != 0 && TryPopReady(index))
        {
            Run(index);
            continue;
        }
        if (TryJoinLoop()) continue;
        // Relaxed: hints; the wait below rechecks under the mutex
        SpinUntil([this] { return LoopHasRoom(); }); // Returns early when a job is queued
        if (mNumReady.load(std::memory_order_relaxed) != 0 || LoopHasRoom()) continue;
        std::unique_lock lock(mQueueMutex);
        // Relaxed: read as a hint (GetNumWorkersAsleep, OpenLoop)
        mNumWorkersAsleep.fetch_add(1, std::memory_order_relaxed);
        const auto hasWork = [&] { return mReadyCount > 0 || mStopping || LoopHasRoom(); };
        if (!hasWork())
        {
            mWorkerSleeps.fetch_add(1, std::memory_order_relaxed); // Statistic only: a sleep, not a look
            mWake.wait(lock, hasWork);
        }
        // Relaxed: a hint from here on
        mNumWorkersAsleep.fetch_sub(1, std::memory_order_relaxed);
        if (mReadyCount == 0)
        {
            if (mStopping) return; // Nothing left (no loop is open while the system is destroyed)
            continue;              // A loop on the board
        }
        index = mReady[mReadyHead];
        mReadyHead = (mReadyHead + 1) % mMaxJobs;
        --mReadyCount;
        mNumReady.store(mReadyCount, std::memory_order_relaxed); // A hint for spinners
        lock.unlock();
        Run(index);
    }
}

JobSystem::Stats JobSystem::GetStats() const
{
    Stats stats;
    // Relaxed: statistics
    stats.mJobsRun = mJobsRun.load(std::memory_order_relaxed);
    stats.mJobsRunInline = mJobsRunInline.load(std::memory_order_relaxed);
    stats.mDependentOverflow = mDependentOverflow.load(std::memory_order_relaxed);
    stats.mLoopPartsJoined = mLoopPartsJoined.load(std::memory_order_relaxed);
    stats.mWorkerSleeps = mWorkerSleeps.load(std::memory_order_relaxed);
    return stats;
}

} // namespace cairn::jobs
