#pragma once

// StepScheduler: how the step hands its loops to a JobInterface (or runs them on its own thread when it has
// none): loops with a cost estimate that are not worth waking a sleeping worker for, stages that every
// thread takes part in (a colored island's colors), and the hints that keep workers spinning through a
// serial stretch. Owned by PhysicsStep; used by the thread that runs the step (RunStages, KeepSpinning) and
// by the step's jobs (the others; see each).

#include "cairn/jobs/JobInterface.h"
#include "step/StepCosts.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <span>
#include <thread>

namespace cairn::physics
{

class StepScheduler
{
public:
    /// The most threads RunStages gives a part each (a stage's claims are one bit per part).
    static constexpr uint32_t cMaxThreads = 64;

    /// For one step: ioJobs (null: all on this thread) runs the parallel parts, and GrainFor cuts a loop
    /// finer until each thread has inMinChunksPerThread chunks (PhysicsSettings::mMinChunksPerThread; 0:
    /// every loop keeps its own grain). The calling thread is the updating thread, whose time in parallel
    /// regions is counted (GetParallelNanoseconds).
    void BeginStep(jobs::JobInterface* ioJobs, uint32_t inMinChunksPerThread = 0)
    {
        mJobs = ioJobs;
        mMinChunksPerThread = inMinChunksPerThread;
        mUpdatingThread = std::this_thread::get_id();
        mRegionDepth = 0;
        mParallelNanoseconds = 0;
    }
    jobs::JobInterface* GetJobs() const { return mJobs; }
    uint32_t GetNumThreads() const
    {
        return mJobs == nullptr ? 1 : std::min(cMaxThreads, mJobs->GetNumThreads());
    }

    /// The least estimated work GrainFor puts in a chunk: taking a chunk is an atomic add on a line that
    /// every thread of the loop writes, a fraction of a microsecond when they contend for it
    static constexpr uint64_t cMinChunkNanoseconds = 4'000;

    /// The grain for a loop of inCount items of inLoop (StepCosts.h): its own, or finer where that leaves
    /// fewer than mMinChunksPerThread chunks for each thread, down to chunks of cMinChunkNanoseconds of
    /// estimated work. The threads take chunks as they come free, which evens out chunks of unequal cost
    /// only when each thread has several to take: the grains were set on 2 threads, where a pile's loops
    /// had that, and on 16 its costliest loops had one or two chunks a thread. A function of the count and
    /// the thread count only, so a loop that is cut twice (counted, then filled) gets the same chunks both
    /// times; no chunk reaches the arithmetic. Any thread.
    uint32_t GrainFor(size_t inCount, StepCosts::Loop inLoop) const
    {
        const uint32_t threads = GetNumThreads();
        if (threads <= 1 || mMinChunksPerThread == 0 || inLoop.mGrain <= 1)
            return std::max(1u, inLoop.mGrain);
        const uint64_t chunks = uint64_t(threads) * mMinChunksPerThread;
        const uint64_t even = (inCount + chunks - 1) / chunks;
        const uint64_t smallest =
            (cMinChunkNanoseconds + inLoop.mItemNanoseconds - 1) / std::max(1u, inLoop.mItemNanoseconds);
        return uint32_t(std::clamp<uint64_t>(std::max(even, smallest), 1, inLoop.mGrain));
    }

    /// ParallelFor over inCount items of inLoop, cut by GrainFor.
    template <class Body> void ParallelFor(uint32_t inCount, StepCosts::Loop inLoop, const Body& inBody) const
    {
        ParallelFor(inCount, GrainFor(inCount, inLoop), inLoop.mItemNanoseconds, inBody);
    }
    /// inBody(begin, end) over [0, inCount) in chunks of inGrain: on the job system's threads, unless a
    /// worker sleeps and the items' estimated cost (inItemNanoseconds each, StepCosts.h) is under
    /// cMinWakingNanoseconds; else here. Any thread.
    template <class Body>
    void ParallelFor(uint32_t inCount, uint32_t inGrain, uint32_t inItemNanoseconds, const Body& inBody) const
    {
        const ParallelRegion region(*this, inCount > inGrain);
        if (mJobs != nullptr && inCount > inGrain &&
            (mJobs->GetNumWorkersAsleep() == 0 ||
             uint64_t(inCount) * inItemNanoseconds >= cMinWakingNanoseconds))
            mJobs->ParallelFor(inCount, inGrain, inBody);
        else if (inCount > 0)
            for (uint32_t begin = 0; begin < inCount; begin += inGrain)
                inBody(begin, std::min(inCount, begin + inGrain));
    }
    /// The job system's ParallelFor, or all on this thread when inAlone (inside a job that solves its island
    /// by itself). No cost estimate: these loops are parts of a colored island solved by every thread, whose
    /// threads have just left the stages before (awake).
    template <class Body>
    void ParallelForUnlessAlone(bool inAlone, uint32_t inCount, uint32_t inGrain, const Body& inBody) const
    {
        const ParallelRegion region(*this, !inAlone && inCount > inGrain);
        if (!inAlone && mJobs != nullptr && inCount > inGrain)
            mJobs->ParallelFor(inCount, inGrain, inBody);
        else if (inCount > 0)
            inBody(0u, inCount);
    }

    /// inBody() here, counted as parallel unless inAlone (GetParallelNanoseconds): a loop that its caller cut
    /// by the thread count itself, run whole since there is one thread.
    template <class Body> void RunWhole(bool inAlone, const Body& inBody) const
    {
        const ParallelRegion region(*this, !inAlone);
        inBody();
    }

    /// Before a serial stretch of about inNanoseconds that a parallel loop follows: the workers spinning idle
    /// spin through it (JobInterface::ExtendSpin) instead of falling asleep halfway, so that the loop does
    /// not begin with tens of microseconds of waking one. A stretch under half the spin is left alone (a
    /// small step's): a worker that spins now most likely still spins at its end, and no extension is paid
    /// for.
    void KeepWorkersSpinningFor(uint64_t inNanoseconds) const
    {
        if (mJobs != nullptr && mJobs->GetNumThreads() > 1 && inNanoseconds >= cWorthExtendingNanoseconds)
            mJobs->ExtendSpin(inNanoseconds);
    }

    /// Runs inNumStages stages in order, every thread of the job system on each: stage s has
    /// inPartsOf(s, threads) parts (1 to threads, the thread count: PartsFor) and inRunPart(s, part, parts)
    /// does one. A stage that has one part with any number of threads is serial (GetParallelNanoseconds). A
    /// stage starts only when every part of the one before has finished: the threads wait on each part's
    /// progress, not on a job per part (a colored island's velocity iterations are a stage per color per
    /// iteration, over a hundred a step). The threads are the chunks of one ParallelFor, a chunk per thread,
    /// the caller's first. Thread t takes part t first, so it keeps its region of the island in every color;
    /// a part whose thread has not come yet is taken by another, so no thread waits for one that the job
    /// system has not started (and a thread that comes after the last stage leaves at once). Which thread
    /// runs a part changes nothing in the results. Called by the updating thread, outside any job; or with
    /// inAlone, by any thread: it then runs every part itself, in order (a job that solves its island by
    /// itself).
    template <class PartsOf, class RunPart>
    void RunStages(bool inAlone, uint32_t inNumStages, const PartsOf& inPartsOf, const RunPart& inRunPart)
    {
        const uint32_t threads = inAlone ? 1 : GetNumThreads();
        ParallelRegion region(*this, !inAlone);
        if (threads <= 1)
        {
            for (uint32_t stage = 0; stage < inNumStages; ++stage)
            {
                const uint32_t parts = inPartsOf(stage, GetNumThreads());
                const SerialStage serial(region, [&] { return inPartsOf(stage, cMaxThreads) == 1; });
                for (uint32_t part = 0; part < parts; ++part)
                    inRunPart(stage, part, parts);
            }
            return;
        }
        ResetParts(threads);
        auto team = [&](uint32_t inThread)
        {
            // Relaxed: a thread that comes after the stages are over leaves at once; one that reads false
            // finds every part claimed and done, and leaves later
            if (mStagesOver.load(std::memory_order_relaxed)) return;
            const bool updating = std::this_thread::get_id() == mUpdatingThread;
            for (uint32_t stage = 0; stage < inNumStages; ++stage)
            {
                const uint32_t parts = inPartsOf(stage, threads);
                // The updating thread times a serial stage from its start to its end: the other threads only
                // wait through it
                const SerialStage serial(region,
                                         [&] { return updating && inPartsOf(stage, cMaxThreads) == 1; });
                const uint32_t mark = stage + 1; // What the parts' progress reads once they did this stage
                auto tryRun = [&](uint32_t inPart)
                {
                    PartProgress& progress = mParts[inPart];
                    // Relaxed: a claim only decides who runs the part; the data the part reads was ordered by
                    // the previous stage's completion (the acquire below). A claim only ever rises, so a
                    // failed exchange means another thread took the part for this stage
                    uint32_t claimed = progress.mClaimed.load(std::memory_order_relaxed);
                    if (claimed >= mark ||
                        !progress.mClaimed.compare_exchange_strong(claimed, mark, std::memory_order_relaxed))
                        return;
                    inRunPart(stage, inPart, parts);
                    // Release: the part's writes happen before the reads of whoever sees the stage complete
                    progress.mDone.store(mark, std::memory_order_release);
                };
                if (inThread < parts) tryRun(inThread);
                for (uint32_t part = 0; part < parts; ++part)
                    if (part != inThread) tryRun(part);
                // Acquire: pairs with each part's release, so the next stage sees all of this one's writes
                for (uint32_t part = 0; part < parts; ++part)
                    for (uint32_t spins = 0; mParts[part].mDone.load(std::memory_order_acquire) < mark;
                         ++spins)
                        WaitABit(spins);
            }
            mStagesOver.store(true, std::memory_order_relaxed); // Relaxed: see above
        };
        // A chunk per thread: the job system hands them out as it hands out any loop's parts (one
        // atomic add each on JobSystem's loop board), the caller's first
        mJobs->ParallelFor(threads, 1,
                           [&](uint32_t inBegin, uint32_t inEnd)
                           {
                               for (uint32_t thread = inBegin; thread < inEnd; ++thread)
                                   team(thread);
                           });
    }

    /// The updating thread's time inside the step's parallel regions since BeginStep: the rest of its time is
    /// serial, what more threads cannot shorten. A region is a loop with more items than a chunk (whether or
    /// not it was handed out: a sleeping worker is not woken for a cheap one) or RunStages less its serial
    /// stages (one part for any thread count); only the outermost counts (a loop nested in a region's part is
    /// in it). Counted on one thread too, where the serial share is the step's Amdahl fraction. The updating
    /// thread, between steps or from the step's serial code.
    uint64_t GetParallelNanoseconds() const { return mParallelNanoseconds; }

    /// Parts for inCount items with at least inMinPerPart in each (below that a part costs more than it
    /// saves), at most one per thread.
    uint32_t PartsFor(uint32_t inCount, uint32_t inMinPerPart) const
    {
        return PartsFor(inCount, inMinPerPart, GetNumThreads());
    }
    /// The same for inThreads threads.
    static uint32_t PartsFor(uint32_t inCount, uint32_t inMinPerPart, uint32_t inThreads)
    {
        return std::min(inThreads, std::max(1u, inCount / inMinPerPart));
    }
    /// Part inPart of inItems cut into inParts contiguous parts of (nearly) equal size.
    template <class T> static std::span<T> PartOf(std::span<T> inItems, uint32_t inPart, uint32_t inParts)
    {
        const size_t begin = inPart * inItems.size() / inParts, end = (inPart + 1) * inItems.size() / inParts;
        return inItems.subspan(begin, end - begin);
    }
    /// inTotal spread over inItems (0 for none), saturated: a step of millions of constraints must not wrap.
    static uint32_t PerItem(uint64_t inTotal, size_t inItems)
    {
        return inItems == 0 ? 0 : uint32_t(std::min<uint64_t>(inTotal / inItems, UINT32_MAX));
    }

private:
    /// Work below which a loop does not wake a sleeping worker. A worker sleeps after about 50 us without
    /// work (a game's worker between two frames' steps) and takes tens of microseconds to wake, while the
    /// loop waits for its part: a small step (about 30 awake bodies, 40 pairs) spent a fifth of its time in
    /// its two parallel loops' hand-offs. An awake worker (back-to-back loops) costs a few microseconds: any
    /// loop of more than one chunk is handed out then.
    static constexpr uint32_t cMinWakingNanoseconds = 50'000;
    /// Half of JobSystem's idle spin (JobSystem::cSpinMicroseconds): see KeepWorkersSpinningFor.
    static constexpr uint64_t cWorthExtendingNanoseconds = 25'000;

    using Clock = std::chrono::steady_clock;
    static uint64_t NanosecondsSince(Clock::time_point inStart)
    {
        return uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - inStart).count());
    }
    class SerialStage;
    /// Counts its lifetime as parallel when the updating thread enters it outside any other region and
    /// inParallel; on any other thread, or nested, it does nothing.
    class ParallelRegion
    {
    public:
        ParallelRegion(const StepScheduler& inScheduler, bool inParallel)
            : mScheduler(inScheduler), mOutermost(std::this_thread::get_id() == inScheduler.mUpdatingThread &&
                                                  inScheduler.mRegionDepth++ == 0),
              mTimed(mOutermost && inParallel)
        {
            if (mTimed) mStart = Clock::now();
        }
        ~ParallelRegion()
        {
            if (mOutermost) --mScheduler.mRegionDepth;
            if (mTimed) mScheduler.mParallelNanoseconds += NanosecondsSince(mStart) - mSerialNanoseconds;
        }
        ParallelRegion(const ParallelRegion&) = delete;
        ParallelRegion& operator=(const ParallelRegion&) = delete;

    private:
        friend class SerialStage;
        const StepScheduler& mScheduler;
        const bool mOutermost; ///< Entered by the updating thread outside any other region
        const bool mTimed;
        Clock::time_point mStart;
        uint64_t mSerialNanoseconds = 0; ///< Its serial stages: see SerialStage
    };
    /// A stage of RunStages that its region does not count (serial), timed by the updating thread only.
    /// inIsSerial() is asked first, on every thread, and says false on the others: the region lives on the
    /// updating thread's stack, among the lines it writes, and no other thread reads it.
    class SerialStage
    {
    public:
        template <class IsSerial>
        SerialStage(ParallelRegion& inRegion, const IsSerial& inIsSerial)
            : mRegion(inRegion), mTimed(inIsSerial() && inRegion.mTimed)
        {
            if (mTimed) mStart = Clock::now();
        }
        ~SerialStage()
        {
            if (mTimed) mRegion.mSerialNanoseconds += NanosecondsSince(mStart);
        }
        SerialStage(const SerialStage&) = delete;
        SerialStage& operator=(const SerialStage&) = delete;

    private:
        ParallelRegion& mRegion;
        const bool mTimed;
        Clock::time_point mStart;
    };

    /// A part's progress through the stages of one RunStages, on a line of its own: the threads claim their
    /// own parts and mark them done at once, with no line that all of them write in turn. Values are the last
    /// stage + 1 that claimed the part and that finished it: they only rise within a RunStages, so a thread
    /// that is still a stage behind reads its own stage as claimed and done. Written by whichever thread runs
    /// the part, read by every thread of the RunStages.
    struct alignas(64) PartProgress
    {
        std::atomic<uint32_t> mClaimed;
        std::atomic<uint32_t> mDone;
    };
    /// Clears the first inParts parts' progress and mStagesOver. The updating thread, before the threads'
    /// loop.
    void ResetParts(uint32_t inParts);
    /// A pause while another thread finishes its part: a CPU hint at first, then a yield of the time slice
    /// (two cores: the other part's thread may be waiting for this core).
    static void WaitABit(uint32_t inSpins);

    jobs::JobInterface* mJobs = nullptr; ///< During a step only
    uint32_t mMinChunksPerThread = 0;    ///< See BeginStep
    /// The updating thread's bookkeeping of its parallel regions (ParallelRegion), touched by it alone: the
    /// loops are const to their callers, and this is not the scheduler's state but a measure of the step
    /// (a line apart from mJobs and mUpdatingThread, which every thread of a loop reads)
    std::thread::id mUpdatingThread;
    alignas(64) mutable uint32_t mRegionDepth = 0;
    mutable uint64_t mParallelNanoseconds = 0;
    PartProgress mParts[cMaxThreads]; ///< RunStages' progress; threads: see PartProgress
    /// RunStages' last stage is over: set by each thread that saw it end, read by threads joining late; a
    /// line of its own (a write and a read per thread each RunStages)
    alignas(64) std::atomic<bool> mStagesOver{false};
};

} // namespace cairn::physics
