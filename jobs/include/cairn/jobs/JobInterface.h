#pragma once

// JobInterface: the little that the physics step asks of a scheduler, so that a game can run the step on its
// own (as Jolt's abstract JobSystem and Box2D's enqueueTask/finishTask allow). JobSystem is one
// implementation; tests/physics/StepOnOtherSchedulerTest.cpp has a minimal one.
//
// Threads: the step calls every member from the thread that called PhysicsSystem::Update, and, for
// ParallelFor, StartTask and FinishTask, also from inside the tasks and loop bodies it handed out (a task may
// start and finish tasks of its own). An implementation must allow that nesting without deadlock: a thread
// that waits should run queued work meanwhile, or the implementation must have a thread for every task
// that can be waited on at once (GetNumThreads of them).
//
// Tasks and loop bodies must not throw; the step catches what its own tasks throw.

#include <cstdint>

namespace cairn::jobs
{

/// A task started by StartTask, to be finished once by FinishTask. What it holds is the implementation's.
struct TaskHandle
{
    uint64_t mValue = 0;
};

class JobInterface
{
public:
    /// inFunction(inBegin, inEnd, inContext) for a chunk of a ParallelFor.
    using RangeFunction = void (*)(uint32_t inBegin, uint32_t inEnd, void* inContext);
    /// inFunction(inContext) for a task.
    using TaskFunction = void (*)(void* inContext);

    virtual ~JobInterface() = default;

    /// Threads that work on a ParallelFor, the caller included: the step cuts its loops into about this many
    /// parts, and runs stages that every thread takes part in as a ParallelFor of one chunk per thread (a
    /// chunk takes the parts of chunks not started yet, so any order of running them is correct). 1:
    /// everything runs on the calling thread.
    virtual uint32_t GetNumThreads() const = 0;
    /// Threads asleep for want of work now (0 if the scheduler cannot tell): a loop of little work is then
    /// run on the caller rather than paying for a wake. A hint; any answer gives the same results.
    virtual uint32_t GetNumWorkersAsleep() const { return 0; }
    /// A hint that a serial stretch of about inNanoseconds follows, then a parallel loop: idle threads should
    /// spin through it instead of sleeping. Doing nothing is correct.
    virtual void ExtendSpin(uint64_t inNanoseconds) { (void)inNanoseconds; }

    /// inFunction over [0, inCount) in chunks of inGrain items (each chunk once, on any thread; the caller
    /// takes part); returns when every chunk is done, with their writes visible to the caller.
    virtual void ParallelFor(uint32_t inCount, uint32_t inGrain, RangeFunction inFunction,
                             void* inContext) = 0;
    /// Starts inFunction(inContext) on another thread, or queues it. The context must live until FinishTask.
    virtual TaskHandle StartTask(const char* inName, TaskFunction inFunction, void* inContext) = 0;
    /// Runs the task on this thread if no thread has started it, and returns true (it is then done, but
    /// still finished once with FinishTask); false otherwise. Returning false is always correct.
    virtual bool TryRunTaskHere(TaskHandle inTask)
    {
        (void)inTask;
        return false;
    }
    /// Returns when the task has finished, its writes visible to the caller.
    virtual void FinishTask(TaskHandle inTask) = 0;

    /// ParallelFor over a callable inBody(begin, end), which must outlive the call.
    template <class Body> void ParallelFor(uint32_t inCount, uint32_t inGrain, const Body& inBody)
    {
        ParallelFor(
            inCount, inGrain,
            [](uint32_t inBegin, uint32_t inEnd, void* inContext)
            { (*static_cast<const Body*>(inContext))(inBegin, inEnd); },
            const_cast<void*>(static_cast<const void*>(&inBody)));
    }
    /// StartTask over a callable inTask(), which must outlive FinishTask.
    template <class Task> TaskHandle StartTask(const char* inName, Task& inTask)
    {
        return StartTask(
            inName, [](void* inContext) { (*static_cast<Task*>(inContext))(); }, &inTask);
    }
};

} // namespace cairn::jobs
