#pragma once

// BroadPhaseUpdate: a step's broad-phase update. With a job interface of two or more threads, a broad phase
// whose pair search may run during its update (BroadPhase::CanFindPairsDuringUpdate) and a scene large
// enough, it runs as a task while the updating thread integrates velocities, finds pairs and contacts on the
// tree as it stands (queries are exact in any state of the tree, so the pairs are the same), builds islands
// and solves; otherwise at once, on this thread. The task is finished by Finish, or by the destructor when
// the step leaves early (an exception): it must not outlive the step's frame. What the task throws is caught
// there (a task must not throw) and rethrown by Finish.
//
// Threads: the updating thread, but for the task's body; the task writes mMilliseconds, mLockWaitNanoseconds
// and mError, read after FinishTask (which orders them).

#include "cairn/jobs/JobInterface.h"
#include "cairn/physics/broadphase/BroadPhase.h"

#include <cstdint>
#include <exception>

namespace cairn::physics
{

class BroadPhaseUpdate
{
public:
    /// Beside the step when inBeside (see PhysicsSettings::mUpdateBesideStepMinActiveBodies) and the job
    /// interface and the broad phase allow it.
    BroadPhaseUpdate(BroadPhase& ioBroadPhase, jobs::JobInterface* ioJobs, bool inBeside);
    ~BroadPhaseUpdate();
    BroadPhaseUpdate(const BroadPhaseUpdate&) = delete;
    BroadPhaseUpdate& operator=(const BroadPhaseUpdate&) = delete;

    /// Runs the update here if no other thread has started it yet: a worker that was awake took it within
    /// microseconds of its start; a sleeping one takes tens of them to wake, and the update is better run
    /// here than waited for.
    void RunHereUnlessStarted();
    /// Waits for the update (running it here if no other thread has started it); returns its duration in ms.
    double Finish();
    /// How long the update waited for locks (its rebuild commit; the global-mutex broad phase's mutex). After
    /// Finish.
    uint64_t GetLockWaitNanoseconds() const { return mLockWaitNanoseconds; }

private:
    /// The update, timed; on whichever thread runs it.
    void Run();

    BroadPhase& mBroadPhase;
    jobs::JobInterface* mJobs;         ///< Null when the update ran in the constructor
    jobs::TaskHandle mTask;            ///< The update task (mJobs only)
    bool mFinished = false;            ///< FinishTask has been called
    double mMilliseconds = 0.0;        ///< Written by the task before it finishes, read after the wait
    uint64_t mLockWaitNanoseconds = 0; ///< The same
    std::exception_ptr mError;         ///< The same
};

} // namespace cairn::physics
