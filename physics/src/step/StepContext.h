#pragma once

// StepContext: what every stage of one collision step reads: the world's settings and bodies, the active
// list with the step's privileges, the structures that several stages share, and the scheduler. Made by
// PhysicsStep::Run on the updating thread, which holds every body mutex for the whole step; the stages'
// jobs read it while the updating thread waits for them.

#include "StepScheduler.h"
#include "cairn/physics/PhysicsSettings.h"
#include "cairn/physics/body/BodyManager.h"
#include "cairn/physics/broadphase/BroadPhase.h"
#include "cairn/physics/narrowphase/ContactListener.h"
#include "islands/AtomicUnionFind.h"
#include "solver/ContactCache.h"

#include <atomic>
#include <cstdint>
#include <vector>

namespace cairn::physics
{

class PublishedPoseStore;

struct StepContext
{
    const PhysicsSettings& mSettings;
    const LayerSetup& mLayers;
    BodyManager& mBodies;
    /// The active bodies' indices. Grows while contacts wake sleeping bodies (the contacts stage's merge, on
    /// the updating thread); shrinks when islands go to sleep (the last stage)
    std::vector<uint32_t>& mActive;
    PublishedPoseStore& mPoses;
    BroadPhase& mBroadPhase;
    /// Last step's contacts (for the warm start and reuse) and this step's. Its entries are written by the
    /// contacts stage's merge and the solver's impulse stores, each entry by one task
    ContactCache& mContactCache;
    /// Linked by the narrow phase's threads as they find contacts (lock-free); finalized by the islands stage
    AtomicUnionFind& mIslands;
    StepScheduler& mScheduler;
    /// This step's waits for locks (LockWaits), added by whichever of its threads waited. Relaxed: a sum,
    /// read by the stepping thread after it waited for every job that adds to it
    std::atomic<uint64_t>& mLockWaitNanoseconds;
    /// Told of each contact the narrow phase makes (ContactListener.h), on its job threads; null: none
    ContactListener* mListener;
    float mDeltaTime;
    /// The last collision step of an Update: the forces and torques added before the Update act in each of
    /// its collision steps, and are cleared by this one's velocity half
    bool mLastCollisionStep;

    Body& BodyAt(uint32_t inIndex) const { return *mBodies.TryGetBodyAtIndex(inIndex); }
    /// The body at active index inActiveIndex.
    Body& ActiveBody(uint32_t inActiveIndex) const { return BodyAt(mActive[inActiveIndex]); }
};

} // namespace cairn::physics
