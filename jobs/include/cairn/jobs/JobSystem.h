#pragma once

// JobSystem: the frame's worker pool. A job is a small callable with prerequisites (other jobs); it is queued
// when the last of them finishes, and run by a worker or by a thread that waits (waiting threads help, so the
// caller of Wait is one of the frame's threads and a pool of N threads has N - 1 workers). ParallelFor splits
// a loop over the pool, handing its parts to idle workers on the loop board (no job, no lock) when no other
// thread's loop holds it. Multi-frame work (navmesh tiles, streaming) goes to the BackgroundQueue instead,
// which stands aside while frame jobs are in flight.
//
// Threads: every member function may be called from any thread, including from inside a job, except the
// destructor (the owner, once no other thread uses the system). Jobs must not throw: an escaping exception
// terminates, as from any thread.
//
// Locking (who touches what):
//  - mSlots[i]: its function and name are written by the scheduling thread before the slot is published
//    (queued, under mQueueMutex) and read by the running thread after it pops it; mDependents is guarded by
//    the slot's mutex, which also orders a completion (generation bump) against a registration.
//  - mFree (free slot indices): mFreeMutex. mReady (ready ring): mQueueMutex; workers and waiting threads
//    sleep on mWake with it.
//  - The loop board (mLoop*): lock-free, one owner at a time (mLoopBusy); see its members.
//  - Counters: atomics, each with its memory order's reason where it is used.
//
// Capacity: at most Settings::mMaxJobs jobs exist at once (no allocation after construction). Scheduling when
// all are in use runs the job at once on the calling thread, after its prerequisites (the caller helps them
// finish); GetStats counts it. A job can have at most cMaxDependents jobs waiting on it; a further one makes
// the scheduling thread wait for the prerequisite itself (helping) before it queues the new job.

#include "cairn/jobs/InlineFunction.h"
#include "cairn/jobs/JobInterface.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <mutex>
#include <new>
#include <span>
#include <thread>
#include <type_traits>
#include <vector>

namespace cairn::jobs
{

/// Names a scheduled job. A default handle, or one of a job that has finished, counts as done.
struct JobHandle
{
    static constexpr uint32_t cInvalidIndex = 0xffffffffu;
    uint32_t mIndex = cInvalidIndex;
    uint32_t mGeneration = 0;

    bool IsValid() const { return mIndex != cInvalidIndex; }
};

class JobSystem final : public JobInterface
{
public:
    static constexpr size_t cFunctionCapacity = 64; ///< Bytes of captures a job may carry
    static constexpr uint32_t cMaxDependents = 16;  ///< Jobs that can wait on one job through the queue
    static constexpr uint32_t cMaxThreads = 64;
    /// The most jobs Settings::mMaxJobs may ask for: some 200 bytes of slot and queue each, all made at
    /// construction (a count of 2^32 asked for hundreds of gigabytes)
    static constexpr uint32_t cMaxJobsLimit = 1u << 16;
    /// The workers' thread names begin so (cairn-job-1, cairn-job-2, ...; Linux), for profilers and for tools
    /// that watch the frame's threads
    static constexpr const char* cWorkerThreadNamePrefix = "cairn-job";
    /// A thread that runs out of work spins this long before it sleeps: the frame's parallel phases follow
    /// each other within microseconds, and waking a sleeping thread costs tens of them
    static constexpr uint32_t cSpinMicroseconds = 50;

    struct Settings
    {
        uint32_t mNumThreads = 0; ///< Threads that run frame jobs, the waiting caller included; 0: all cores
        /// Jobs that may exist at once, clamped to [1, cMaxJobsLimit]: each is a slot made at construction
        uint32_t mMaxJobs = 4096;
        /// Worker i runs on the process's i-th allowed core only (wrapping round), leaving the first to the
        /// caller. On a machine with idle time between frames the OS put a waking worker on the caller's
        /// core and took milliseconds to spread them again, so a short loop got no second core
        bool mPinWorkers = false;
        /// ParallelFor hands its parts to idle workers on the loop board (see ParallelFor); false: always as
        /// queued jobs, one per part. For measuring what the board saves, side by side on one machine
        bool mUseLoopBoard = true;
    };

    struct Stats
    {
        uint64_t mJobsRun = 0;           ///< Jobs run through the queue
        uint64_t mJobsRunInline = 0;     ///< Jobs run at once because every slot was in use
        uint64_t mDependentOverflow = 0; ///< Prerequisites waited for because cMaxDependents was reached
        uint64_t mLoopPartsJoined = 0;   ///< ParallelFor parts that workers took from the loop board
        /// Times a worker ran out of work, spun cSpinMicroseconds and went to sleep: each costs a wake-up
        /// later, tens of microseconds before that worker helps again
        uint64_t mWorkerSleeps = 0;
    };

    JobSystem(); ///< Default settings
    explicit JobSystem(const Settings& inSettings);
    JobSystem(const JobSystem&) = delete;
    JobSystem& operator=(const JobSystem&) = delete;
    /// Runs what is still queued, then stops the workers.
    ~JobSystem();

    /// Threads that run frame jobs: the workers plus the one that waits.
    uint32_t GetNumThreads() const override { return uint32_t(mWorkers.size()) + 1; }
    /// Workers asleep for want of work (a worker spins about cSpinMicroseconds before it sleeps). A hint for
    /// a caller deciding whether a small loop is worth handing out: a sleeping worker takes tens of
    /// microseconds to wake, a spinning one a few.
    uint32_t GetNumWorkersAsleep() const override
    {
        // Relaxed: a hint, stale by the time it is read
        return mNumWorkersAsleep.load(std::memory_order_relaxed);
    }

    /// Threads spinning idle (workers out of work, waits) spin on as if they had run out of work
    /// inNanoseconds from now (at most cMaxSpinExtensionNanoseconds) instead of going to sleep
    /// cSpinMicroseconds after they did; threads asleep stay asleep. For a serial stretch of about that
    /// length that a parallel loop follows, so that the loop does not begin by waking a worker. Does nothing
    /// when the job system has more threads than the machine has cores: a spinning worker would then take the
    /// core of the thread doing the serial work. Any thread.
    void ExtendSpin(uint64_t inNanoseconds) override;
    static constexpr uint64_t cMaxSpinExtensionNanoseconds = 1'000'000;

    /// Queues inFunction to run once every job of inPrerequisites has finished. inName must outlive the job
    /// (a string literal).
    template <class Function>
    JobHandle Schedule(const char* inName, Function&& inFunction,
                       std::span<const JobHandle> inPrerequisites = {})
    {
        const uint32_t index = AllocateSlot();
        if (index == JobHandle::cInvalidIndex)
        {
            for (const JobHandle& prerequisite : inPrerequisites)
                Wait(prerequisite);
            inFunction();
            mJobsRunInline.fetch_add(1, std::memory_order_relaxed); // Statistic only
            return {};
        }
        mSlots[index].mFunction.Set(std::forward<Function>(inFunction));
        return Publish(index, inName, inPrerequisites);
    }
    template <class Function>
    JobHandle Schedule(const char* inName, Function&& inFunction,
                       std::initializer_list<JobHandle> inPrerequisites)
    {
        return Schedule(inName, std::forward<Function>(inFunction),
                        std::span<const JobHandle>(inPrerequisites.begin(), inPrerequisites.size()));
    }

    /// True once the job has finished (its effects are then visible to this thread).
    bool IsDone(const JobHandle& inJob) const;
    /// Runs inJob on this thread now if it is still queued (no thread has started it; it must be among the
    /// first few queued jobs, see cAwaitedSearch) and returns true; false when it has started, finished or is
    /// further back. For a job scheduled to run beside the caller's own work when a worker is free at once,
    /// and better run here than waited for when none is (a sleeping worker takes tens of microseconds to
    /// wake). From inside a job only for a job that job scheduled.
    bool TryRunHere(const JobHandle& inJob);
    /// Returns when the job has finished, running queued jobs meanwhile. From outside a job it runs the job
    /// itself when it is near the front of the queue, else any queued job. From inside a job it runs only
    /// jobs scheduled inside that job, the awaited job itself and the jobs the awaited job depends on,
    /// through any number of prerequisites: an unrelated job run on this stack could wait for the job below
    /// it and never return (TBB calls this isolation). It runs other jobs only when every worker is stuck the
    /// same way and none of those is queued. Returns true once the job has finished; false at once, waiting
    /// for nothing, when the job is running on this thread's own stack (a job waiting for itself, or for a
    /// job that it runs inside of): that wait could never end.
    bool Wait(const JobHandle& inJob);
    /// Wait for each; false when any of them was refused (see Wait).
    bool WaitAll(std::span<const JobHandle> inJobs);
    /// Returns true when no frame job is queued or running, running queued jobs meanwhile. From inside a job
    /// it returns false at once: the calling job is in flight itself, so it would wait forever.
    bool WaitIdle();

    /// inBody(begin, end) over [0, inCount) in chunks of inGrain, on up to GetNumThreads() threads; the
    /// caller takes part and returns when every chunk is done. Each taking part (the caller first) owns one
    /// contiguous region of the chunks and works through it from the front; one that runs out takes chunks
    /// from the back of the others' regions, so uneven work still balances itself. Contiguous regions keep
    /// each thread on its own part of the data (with two threads, the caller on the first half in every
    /// loop): neighbouring chunks handed to both threads in turn, as one shared cursor did, made them write
    /// the same cache lines (bodies, island links) and fetch each other's results.
    ///
    /// The parts are handed out on the loop board when it is free (one loop at a time, see OpenLoop):
    /// idle workers join it with one atomic add each, where a job per part cost the caller a slot, a
    /// queue push and a wake-up each, and every helper a pop under the queue's mutex, all of which the
    /// threads of a many-core machine would take in turn. A helper that never comes costs nothing: the caller
    /// takes its chunks. Otherwise (another thread's loop is on the board) the parts are queued as jobs.
    template <class Body> void ParallelFor(uint32_t inCount, uint32_t inGrain, const Body& inBody)
    {
        if (inCount == 0) return;
        const uint64_t grain = std::max<uint32_t>(1, inGrain);
        const uint64_t chunks = (uint64_t(inCount) + grain - 1) / grain;
        const uint32_t parts = uint32_t(std::min<uint64_t>(chunks, GetNumThreads()));
        if (parts == 1)
        {
            // One thread or one chunk: in order, no claims (the regions below cost an exchange per chunk)
            for (uint64_t begin = 0; begin < inCount; begin += grain)
                inBody(uint32_t(begin), uint32_t(std::min<uint64_t>(inCount, begin + grain)));
            return;
        }
        // The board is taken before the regions are made: its exchange would otherwise wait for their lines
        // (last written by the threads that took from them in the loop before)
        const bool onBoard = mUseLoopBoard && TryTakeLoopBoard();
        // Only the parts' regions are made (all cMaxThreads would be 4 KB written on every call)
        alignas(ChunkRegion) std::byte storage[sizeof(ChunkRegion) * cMaxThreads];
        ChunkRegion* regions = reinterpret_cast<ChunkRegion*>(storage);
        static_assert(std::is_trivially_destructible_v<ChunkRegion>, "the regions are never destroyed");
        for (uint32_t p = 0; p < parts; ++p)
            // Made before the board opens or the helper jobs are scheduled: either orders them before the
            // helpers' claims
            new (&regions[p]) ChunkRegion(ChunkRegion::Pack(chunks * p / parts, chunks * (p + 1) / parts));
        auto work = [regions, &inBody, parts, grain, inCount](uint32_t inPart)
        {
            auto run = [&](uint64_t inChunk)
            {
                const uint64_t begin = inChunk * grain;
                inBody(uint32_t(begin), uint32_t(std::min<uint64_t>(inCount, begin + grain)));
            };
            uint64_t chunk;
            while (regions[inPart].TakeFront(chunk))
                run(chunk);
            for (uint32_t other = 1; other < parts; ++other)
                while (regions[(inPart + other) % parts].TakeBack(chunk))
                    run(chunk);
        };
        using Work = decltype(work);
        if (onBoard)
        {
            OpenLoop(
                parts, [](void* inWork, uint32_t inPart) { (*static_cast<const Work*>(inWork))(inPart); },
                &work);
            work(0);
            CloseLoop();
            return;
        }
        // The board holds another thread's loop: the parts go through the queue, as jobs
        JobHandle handles[cMaxThreads];
        for (uint32_t p = 1; p < parts; ++p)
            handles[p - 1] = Schedule("ParallelFor", [&work, p] { work(p); });
        work(0);
        WaitAll({handles, parts - 1});
    }

    /// JobInterface: the physics step's loops and tasks as the templates above (a task is a job; its handle
    /// holds the JobHandle).
    void ParallelFor(uint32_t inCount, uint32_t inGrain, RangeFunction inFunction, void* inContext) override
    {
        ParallelFor(inCount, inGrain,
                    [inFunction, inContext](uint32_t inBegin, uint32_t inEnd)
                    { inFunction(inBegin, inEnd, inContext); });
    }
    using JobInterface::StartTask;
    TaskHandle StartTask(const char* inName, TaskFunction inFunction, void* inContext) override
    {
        return ToTask(Schedule(inName, [inFunction, inContext] { inFunction(inContext); }));
    }
    bool TryRunTaskHere(TaskHandle inTask) override { return TryRunHere(ToJob(inTask)); }
    void FinishTask(TaskHandle inTask) override { Wait(ToJob(inTask)); }

    /// Frame jobs scheduled and not yet finished.
    uint32_t GetNumJobsInFlight() const
    {
        return mJobsInFlight.load(std::memory_order_relaxed); // A snapshot for schedulers and statistics
    }
    /// Blocks until no frame job is in flight or inTimeout passes; false on timeout. For background threads.
    bool WaitForFrameIdle(std::chrono::microseconds inTimeout) const;

    Stats GetStats() const;

private:
    /// Settings::mPinWorkers: each worker to one allowed core, from the second on.
    void PinWorkers();
    static TaskHandle ToTask(const JobHandle& inJob)
    {
        return {uint64_t(inJob.mIndex) << 32 | inJob.mGeneration};
    }
    static JobHandle ToJob(TaskHandle inTask)
    {
        return {uint32_t(inTask.mValue >> 32), uint32_t(inTask.mValue)};
    }

    /// One ParallelFor part's chunks not yet taken, [front, back), packed in one word so that its owner (from
    /// the front) and threads that ran out of their own (from the back) claim each chunk exactly once. A
    /// cache line each: the parts' owners update theirs at once.
    struct alignas(64) ChunkRegion
    {
        explicit ChunkRegion(uint64_t inRange) : mRange(inRange) {}

        std::atomic<uint64_t> mRange; ///< front in the low 32 bits, back in the high 32

        static uint64_t Pack(uint64_t inFront, uint64_t inBack) { return inBack << 32 | inFront; }
        bool TakeFront(uint64_t& outChunk) { return Take(outChunk, true); }
        bool TakeBack(uint64_t& outChunk) { return Take(outChunk, false); }

    private:
        bool Take(uint64_t& outChunk, bool inFront)
        {
            // Relaxed: the exchange only hands out each chunk once; the chunks' results reach the caller
            // through its WaitAll on the jobs (and its own program order)
            uint64_t range = mRange.load(std::memory_order_relaxed);
            for (;;)
            {
                const uint64_t front = range & 0xffffffffu, back = range >> 32;
                if (front >= back) return false;
                const uint64_t taken = inFront ? Pack(front + 1, back) : Pack(front, back - 1);
                if (mRange.compare_exchange_weak(range, taken, std::memory_order_relaxed,
                                                 std::memory_order_relaxed))
                {
                    outChunk = inFront ? front : back - 1;
                    return true;
                }
            }
        }
    };

    struct JobSlot
    {
        InlineFunction<cFunctionCapacity> mFunction;
        const char* mName = "";
        /// Bumped when the job finishes: a handle of an older generation names a finished job
        std::atomic<uint32_t> mGeneration{0};
        /// Unfinished prerequisites, plus one held by Publish until every prerequisite is registered
        std::atomic<int32_t> mPending{0};
        std::mutex mMutex; ///< Guards mDependents/mNumDependents and orders the generation bump against them
        uint32_t mDependents[cMaxDependents] = {};
        uint32_t mNumDependents = 0;
        /// The run of the job that scheduled it (0: scheduled outside any job); written before it is queued,
        /// read under mQueueMutex by waits inside jobs (see Wait)
        uint64_t mScope = 0;
    };

    uint32_t AllocateSlot();
    void FreeSlot(uint32_t inIndex);
    JobHandle Publish(uint32_t inIndex, const char* inName, std::span<const JobHandle> inPrerequisites);
    void Enqueue(uint32_t inIndex);
    bool TryPopReady(uint32_t& outIndex);
    /// For a wait outside a job: takes inJob itself if it is among the first cAwaitedSearch queued jobs (it
    /// runs what it waits for before other queued work), else the head; false when nothing is queued.
    bool TryPopAwaited(const JobHandle& inJob, uint32_t& outIndex);
    /// Position (from the head) of inJob among the first cAwaitedSearch queued jobs; -1 when it is not there
    /// (started, finished or further back). mQueueMutex held.
    int FindQueuedNearFront(const JobHandle& inJob) const;
    /// Queued jobs a wait outside a job looks through for its own: enough for a ParallelFor's helpers behind
    /// a job scheduled before them, and a bounded cost for a wait on each of a thousand queued jobs.
    static constexpr uint32_t cAwaitedSearch = 8;
    /// Index in the ready ring (from its head) of a job a wait inside job run inScope may run for inAwaited:
    /// one scheduled in inScope, the awaited job itself or a job it depends on (through any number of
    /// prerequisites), else any job when every worker is stuck in such a wait; -1 when none. mQueueMutex
    /// held.
    int FindRunnableFor(uint64_t inScope, uint32_t inAwaited) const;
    /// True if inAwaited depends on the job in slot inFrom, directly or through other jobs. mQueueMutex held;
    /// uses mSearchMarks/mSearchStack with the current mSearchEpoch.
    bool LeadsTo(uint32_t inFrom, uint32_t inAwaited) const;
    /// Removes entry inPosition (from the head) of the ready ring and returns its slot. mQueueMutex held.
    uint32_t TakeReadyAt(int inPosition);
    void Run(uint32_t inIndex);
    /// A frame job or loop is over: mJobsInFlight drops, and the threads waiting for that are woken.
    void EndInFlight();
    void WorkerMain();

    /// Part inPart of the loop on the board, in its context.
    using LoopPartFunction = void (*)(void* inContext, uint32_t inPart);
    /// Takes the loop board for this thread's loop; false when it holds another thread's. The loop counts as
    /// frame work from here to CloseLoop (background queues stand aside, WaitIdle waits for it).
    bool TryTakeLoopBoard();
    /// Puts a loop of inParts parts (2 to cMaxThreads) on the board taken, for idle workers to join, and
    /// wakes sleeping workers for it (up to inParts - 1). The caller runs part 0 (and the chunks of parts
    /// nobody joined), then calls CloseLoop. inContext must live until then.
    void OpenLoop(uint32_t inParts, LoopPartFunction inFunction, void* inContext);
    /// Closes the board to joins and waits for the workers that joined to finish their parts: the loop's
    /// writes are then visible to the caller, and the board is free.
    void CloseLoop();
    /// A worker out of work: takes the next part of the loop on the board, if it has one nobody took, and
    /// runs it; false when there is none (or other workers took the last one first).
    bool TryJoinLoop();
    /// The board holds an open loop with a part nobody took. A hint for spinning and sleeping workers.
    bool LoopHasRoom() const;
    /// Spins for up to about cSpinMicroseconds while inDone() is false and nothing is queued; true if
    /// inDone().
    template <class Done> bool SpinUntil(const Done& inDone) const;

    std::unique_ptr<JobSlot[]> mSlots;
    uint32_t mMaxJobs;

    std::mutex mFreeMutex;
    std::vector<uint32_t> mFree; ///< Free slot indices (a stack); mFreeMutex

    std::mutex mQueueMutex;
    std::condition_variable mWake;      ///< Workers and waiters: a job was queued or finished, or stopping
    std::vector<uint32_t> mReady;       ///< Ring of queued slot indices (capacity mMaxJobs: never overflows)
    std::atomic<uint32_t> mNumReady{0}; ///< mReadyCount's mirror, for spinning without the mutex
    uint32_t mReadyHead = 0;            ///< mQueueMutex
    uint32_t mReadyCount = 0;           ///< mQueueMutex
    bool mStopping = false;             ///< mQueueMutex

    /// A line apart from what spinning threads poll (mNumReady, mSpinExtendedUntil): every job and loop
    /// writes it, and a line that other cores read must first be taken back from them
    alignas(64) std::atomic<uint32_t> mJobsInFlight{0};
    std::atomic<uint32_t> mNumWaiters{0}; ///< Threads asleep in Wait/WaitIdle (or about to be)
    /// Workers asleep in WorkerMain's wait (changed under mQueueMutex)
    alignas(64) std::atomic<uint32_t> mNumWorkersAsleep{0};
    /// ExtendSpin's deadline: steady_clock ticks since its epoch. Any thread; read by spinners
    std::atomic<std::chrono::steady_clock::rep> mSpinExtendedUntil{0};
    bool mMoreThreadsThanCores = false; ///< Set by the constructor: ExtendSpin does nothing
    const bool mUseLoopBoard;           ///< Settings::mUseLoopBoard
    size_t mNumStuckWorkers = 0;        ///< mQueueMutex: workers in a wait inside a job with nothing to run
    /// The prerequisite search of waits inside jobs (see LeadsTo), sized mMaxJobs so that it never allocates:
    /// a slot is marked when its mark equals mSearchEpoch. All three under mQueueMutex
    mutable std::vector<uint32_t> mSearchMarks;
    mutable std::vector<uint32_t> mSearchStack;
    mutable uint32_t mSearchEpoch = 0;
    uint32_t mNumIsolatedSleepers = 0; ///< mQueueMutex: waits inside jobs asleep (Enqueue wakes them all)
    mutable std::mutex mIdleMutex;
    mutable std::condition_variable mIdle; ///< Notified when mJobsInFlight drops to zero

    /// The loop board (ParallelFor, OpenLoop). mLoopBusy: taken by the thread whose loop it holds, with an
    /// exchange, released by its CloseLoop; that thread alone writes the function, context and count, while
    /// no worker is on the board. mLoopState: open flag, parts and workers joined (see cLoop*): its owner
    /// opens it with a store and shuts it, idle workers join by adding to it and read the function and
    /// context only when their add found it open. mLoopPartsDone: the joiners' finished parts (or joins that
    /// found no part left), counted up by them (it wraps), read by the owner. Three lines: the owner's own
    /// (mLoopBusy), the one that joiners poll and take (the state, with the function and context that they
    /// read next), and the count
    alignas(64) std::atomic<bool> mLoopBusy{false};
    uint32_t mLoopPartsDoneBefore = 0;         ///< mLoopPartsDone as the board's last loop closed
    std::atomic<uint64_t> mLoopPartsJoined{0}; ///< Statistic (Stats), added to by owners
    alignas(64) std::atomic<uint64_t> mLoopState{0};
    LoopPartFunction mLoopFunction = nullptr;
    void* mLoopContext = nullptr;
    alignas(64) std::atomic<uint32_t> mLoopPartsDone{0};
    /// Workers joined (part 0 is the owner's; worker j takes part j + 1 if the loop has it)
    static constexpr uint64_t cLoopJoinedMask = 0xff;
    static constexpr uint32_t cLoopPartsShift = 8; ///< Then the loop's parts, 8 bits
    static constexpr uint64_t cLoopOpen = uint64_t(1) << 16;

    alignas(64) std::atomic<uint64_t> mJobsRun{0};
    std::atomic<uint64_t> mJobsRunInline{0};
    std::atomic<uint64_t> mDependentOverflow{0};
    std::atomic<uint64_t> mWorkerSleeps{0}; ///< Statistic (Stats), added to by workers going to sleep

    std::vector<std::thread> mWorkers;
};

} // namespace cairn::jobs
