#pragma once

// PhysicsStep: one collision step, stage by stage, and the stages' memory, reused from step to step (a warm
// scene allocates nothing). Owned by PhysicsSystem; runs on the thread that called Update, which holds every
// body mutex for the whole step: nothing here takes a lock except the broad phase's own.
//
// The stages, in the order Run calls them (each in a file of its own, with its state):
//  1. the broad-phase update (step/BroadPhaseUpdate), beside stages 2-5 when the broad phase allows it;
//  2. velocities: forces, gravity, damping (body/Integration, its velocity half);
//  3. pairs, 4. narrow phase, 5. merge (narrowphase/ContactsStage); bodies the merge wakes go round 2-5
//     again, so a sleeping pile wakes whole within one step;
//  6. islands: joints link theirs (constraints/JointStage), finalized, constraints ordered, large islands
//     colored (islands/IslandStage);
//  7. solve, with the position half of integration (solver/IslandSolver);
//  8. finish: bounds, broad-phase moves, published poses (step/FinishStage), then sleep
//  (islands/IslandSleep).
//
// With a job interface, the stages' loops run on its threads (StepScheduler; the updating thread takes
// part). Each parallel task writes only its own bodies or its own chunk's output; everything shared (the
// constraint list, the contact cache, the active list, waking) is merged afterwards in pair order. Results
// do not depend on the number of threads or their timing.

#include "body/Integration.h"
#include "cairn/jobs/JobInterface.h"
#include "cairn/physics/PhysicsSettings.h"
#include "cairn/physics/StepStatistics.h"
#include "cairn/physics/body/BodyManager.h"
#include "cairn/physics/broadphase/BroadPhase.h"
#include "constraints/JointStage.h"
#include "islands/AtomicUnionFind.h"
#include "islands/IslandSleep.h"
#include "islands/IslandStage.h"
#include "narrowphase/ContactEventRecorder.h"
#include "narrowphase/ContactsStage.h"
#include "solver/ContactCache.h"
#include "solver/IslandSolver.h"
#include "step/ContinuousCollision.h"
#include "step/FinishStage.h"
#include "step/StepScheduler.h"

#include <atomic>
#include <cstdint>
#include <vector>

namespace cairn::physics
{

/// Which collision step of an Update a step is, and who hears of its contacts.
struct CollisionStepInfo
{
    uint8_t mIndex = 0;
    bool mIsLast = true;
    ContactListener* mListener = nullptr;         ///< ContactListener.h; null: none
    std::vector<ContactEvent>* mEvents = nullptr; ///< Where its contact events go; null: none recorded
};

class PhysicsStep
{
public:
    PhysicsStep(const PhysicsSettings& inSettings, const LayerSetup& inLayers, BodyManager& ioBodies,
                BroadPhase& ioBroadPhase, ConstraintManager& ioConstraints);

    /// One collision step of inDeltaTime seconds; adds its figures to ioStatistics. ioJobs (may be null: all
    /// on this thread) runs the parallel parts.
    void Run(float inDeltaTime, const CollisionStepInfo& inStep, StepStatistics& ioStatistics,
             jobs::JobInterface* ioJobs);
    /// See PhysicsSystem::IsContactCacheConsistent.
    bool IsContactCacheConsistent() const { return mContactCache.IsConsistent(); }

private:
    const PhysicsSettings& mSettings;
    const LayerSetup& mLayers;
    BodyManager& mBodies;
    BroadPhase& mBroadPhase;
    ConstraintManager& mConstraints; ///< Its mutex held by the Update that runs this step

    // What several stages share (StepContext)
    ContactCache mContactCache;
    AtomicUnionFind mIslands;
    StepScheduler mScheduler;
    /// This step's waits for locks: see StepContext
    std::atomic<uint64_t> mLockWaitNanoseconds{0};

    // The stages, in step order
    Integration mIntegration;
    ContactsStage mContacts;
    JointStage mJoints;
    IslandStage mIslandStage;
    IslandSolver mSolver;
    ContinuousCollision mContinuous;
    FinishStage mFinish;
    IslandSleep mSleep;
    ContactEventRecorder mEvents;
};

} // namespace cairn::physics
