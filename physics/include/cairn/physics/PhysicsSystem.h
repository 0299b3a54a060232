#pragma once

// PhysicsSystem: the world. Owns the bodies, the broad phase and the step.
//
// Threads:
//  - Update: one thread at a time (a second concurrent call gets ErrorCode::WrongThread). While it runs it
//    holds every body mutex for write, so BodyInterface calls and narrow-phase reads from other threads wait
//    for the step; broad-phase queries do not.
//  - GetBodyInterface() / GetWorldQuery(): from any thread, outside step callbacks.
// Exceptions: what the step throws (a BodyChangeListener's exception, std::bad_alloc) leaves Update as it is,
// with every body lock released, so that other threads go on; the next Update starts from a fresh step (the
// warm starts and reused pairs and colorings of the interrupted one are dropped) and works.
// The step: broad-phase update -> velocities (gravity, forces, damping) -> broad-phase pairs -> narrow phase
// (contacts, warm-start lookup, island links) -> islands -> per island: warm start, velocity iterations,
// restitution, symplectic Euler integration, position iterations -> bounds to the broad phase -> sleeping.

#include "cairn/physics/PhysicsSettings.h"
#include "cairn/physics/StepStatistics.h"
#include "cairn/physics/body/BodyInterface.h"
#include "cairn/physics/constraints/ConstraintInterface.h"
#include "cairn/physics/narrowphase/ContactListener.h"
#include "cairn/physics/queries/WorldQuery.h"

#include <atomic>
#include <memory>
#include <span>
#include <vector>

namespace cairn::jobs
{
class JobInterface;
}

namespace cairn::physics
{

class PhysicsStep;

class PhysicsSystem
{
public:
    /// A world, or the error of settings or layers that are out of range (ValidateSettings,
    /// LayerSetup::GetStatus). The only way to make one: a world that exists was made from a valid setup.
    static Result<std::unique_ptr<PhysicsSystem>>
    Create(const PhysicsSettings& inSettings = {}, const LayerSetup& inLayers = LayerSetup::CreateDefault());
    ~PhysicsSystem();
    PhysicsSystem(const PhysicsSystem&) = delete;
    PhysicsSystem& operator=(const PhysicsSystem&) = delete;

    /// Advances the world by inDeltaTime seconds in inCollisionSteps equal steps (1..16), on this thread.
    Status Update(float inDeltaTime, int inCollisionSteps = 1);
    /// The same, with the parallel phases on ioJobs's threads (this thread takes part). Bodies end
    /// bit-identical to the single-threaded Update, whatever the number of threads. While it runs, this
    /// thread may run other queued jobs; those must not call BodyInterface (they get WrongThread).
    Status Update(float inDeltaTime, int inCollisionSteps, jobs::JobInterface& ioJobs);
    /// The broad-phase update of a step, alone: the trees rebuilt and the nodes of removed bodies freed. For
    /// a world that adds and removes many bodies without stepping (a paused game, a loading screen): a body
    /// removed keeps its tree nodes until an update, so adds find the node pool full (OutOfCapacity) after
    /// about one and a half times the capacity in adds. Like Jolt's OptimizeBroadPhase. The thread that
    /// calls Update, between Updates: it takes every body lock, as a step does. Errors: as Update's
    /// (WrongThread inside the step, while holding a body lock, or while an Update runs).
    Status OptimizeBroadPhase();

    BodyInterface& GetBodyInterface() { return *mBodyInterface; }
    /// Joints (ConstraintInterface.h): from any thread, outside step callbacks.
    ConstraintInterface& GetConstraintInterface() { return *mConstraintInterface; }
    const WorldQuery& GetWorldQuery() const { return *mWorldQuery; }
    const BroadPhase& GetBroadPhase() const { return *mBroadPhase; }
    const BodyManager& GetBodyManager() const { return *mBodies; }
    /// Adds one of those told about bodies added, removed, moved by hand, falling asleep and waking (up to
    /// BodyManager::cMaxChangeListeners; false when full). See BodyChangeListener.h; add and remove while no
    /// other thread changes bodies.
    bool AddBodyChangeListener(BodyChangeListener* inListener)
    {
        return mBodies->AddChangeListener(inListener);
    }
    void RemoveBodyChangeListener(BodyChangeListener* inListener)
    {
        mBodies->RemoveChangeListener(inListener);
    }
    const LayerSetup& GetLayers() const { return mLayers; }
    const PhysicsSettings& GetSettings() const { return mSettings; }
    /// Figures of the last Update. Read it from the thread that calls Update.
    const StepStatistics& GetLastStepStatistics() const { return mLastStatistics; }
    /// The contact listener (ContactListener.h), or null for none. Between Updates, from the thread that
    /// calls Update; it must outlive its use.
    void SetContactListener(ContactListener* inListener) { mContactListener = inListener; }
    /// Records contact events without a listener. Between Updates, from the thread that calls Update.
    void SetRecordContactEvents(bool inRecord) { mRecordContactEvents = inRecord; }
    /// The last Update's contact events, in the order ContactListener.h states; empty when none were
    /// recorded. Read it from the thread that calls Update, until the next Update.
    std::span<const ContactEvent> GetContactEvents() const { return mContactEvents; }
    /// A self-check for tests, between updates: the contact cache that the next step warm-starts from is in
    /// key order and every body pair in it finds its manifolds. O(contacts).
    bool IsContactCacheConsistent() const;

private:
    /// Create's, after it has checked inSettings and inLayers: private, so that no world is built from a
    /// setup that was not checked (a public one once fell back to the defaults on a bad setup, silently).
    PhysicsSystem(const PhysicsSettings& inSettings, const LayerSetup& inLayers);

    PhysicsSettings mSettings;
    LayerSetup mLayers;
    std::unique_ptr<BodyManager> mBodies;
    std::unique_ptr<BroadPhase> mBroadPhase;
    std::unique_ptr<BodyInterface> mBodyInterface;
    std::unique_ptr<ConstraintManager> mConstraints;
    std::unique_ptr<ConstraintInterface> mConstraintInterface;
    std::unique_ptr<WorldQuery> mWorldQuery;
    std::unique_ptr<PhysicsStep> mStep;

    Status UpdateImpl(float inDeltaTime, int inCollisionSteps, jobs::JobInterface* ioJobs);
    std::atomic<bool> mUpdating{false}; ///< Guards against concurrent Update calls (acquire/release below)
    StepStatistics mLastStatistics;     ///< Written by the updating thread only
    // The updating thread's only, like mLastStatistics
    ContactListener* mContactListener = nullptr;
    bool mRecordContactEvents = false;
    std::vector<ContactEvent> mContactEvents;
    /// The last step threw halfway: mStep's caches may be half updated, and the next Update replaces it. Read
    /// and written by the updating thread only (ordered from one updater to the next by mUpdating)
    bool mStepInterrupted = false;
};

} // namespace cairn::physics
