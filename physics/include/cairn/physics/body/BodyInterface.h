#pragma once

// BodyInterface: the locking API to create, add, remove, move and push bodies, callable from any thread
// outside the physics step. Every call validates its input and returns an error without changing anything
// when the input is bad (stale id, NaN, body in the wrong state). Calls made from inside the step (a step
// callback) return ErrorCode::WrongThread instead of deadlocking.
//
// Locks: each call takes at most one body mutex at a time (BodyLockWrite), then the broad phase's own lock
// (lock order body mutex < broad phase). Waking the neighbours of a removed body happens after its lock is
// released.
// While a physics step runs, every call here waits for it: the step holds every body mutex. With steps back
// to back a call may wait for several (the step takes the mutexes again before the woken caller runs);
// cairn-bench-query-latency measures it. Queries do not wait (WorldQuery reads published poses). A write
// publishes the body's pose under its lock, after the broad phase holds the bounds of both the old and the
// new pose, so no reader sees a half-written pose or misses the body (PublishedPose.h).

#include "cairn/physics/body/BodyManager.h"
#include "cairn/physics/broadphase/BroadPhase.h"

#include <span>
#include <utility>
#include <vector>

namespace cairn::physics
{

class BodyInterface
{
public:
    BodyInterface(BodyManager& ioBodies, BroadPhase& ioBroadPhase, const LayerSetup& inLayers);

    /// Creates a body (not yet in the world).
    Result<BodyID> CreateBody(const BodyCreationSettings& inSettings);
    /// Destroys a body that is not in the world.
    Status DestroyBody(const BodyID& inID);
    /// Puts a body into the world (broad phase, and the active list for Activation::Activate).
    Status AddBody(const BodyID& inID, Activation inActivation);
    /// CreateBody + AddBody; nothing is left behind on failure.
    Result<BodyID> CreateAndAddBody(const BodyCreationSettings& inSettings, Activation inActivation);
    /// Takes a body out of the world; bodies resting on it are woken.
    Status RemoveBody(const BodyID& inID);

    /// A batch of bodies being added: the slow part (broad-phase preparation) runs on the caller's thread
    /// without touching the live world; AddBodiesFinalize then links it quickly.
    /// Move-only: it owns the broad phase's prepared state, which must be finalized or aborted exactly once
    /// (a copy finalized and then the original aborted would free it twice).
    struct AddBatch
    {
        std::vector<BroadPhaseBody> mBodies;
        BroadPhase::AddState mState = nullptr;
        /// The interface that prepared it: its ids and broad-phase state mean nothing to another world's
        const BodyInterface* mOwner = nullptr;
        bool IsEmpty() const { return mBodies.empty(); }

        AddBatch() = default;
        AddBatch(AddBatch&& ioOther) noexcept
            : mBodies(std::move(ioOther.mBodies)), mState(std::exchange(ioOther.mState, nullptr)),
              mOwner(std::exchange(ioOther.mOwner, nullptr))
        {
            ioOther.mBodies.clear();
        }
        AddBatch(const AddBatch&) = delete;
        AddBatch& operator=(const AddBatch&) = delete;
        AddBatch& operator=(AddBatch&&) = delete; ///< Overwriting a prepared batch would leak it
    };
    /// Fails (and marks nothing) if any id is stale, already in the world, or already in another batch.
    Result<AddBatch> AddBodiesPrepare(std::span<const BodyID> inIDs);
    /// Fails (and changes nothing) for a batch already finalized or aborted, one another world prepared, or a
    /// call from inside the step or under a body lock.
    Status AddBodiesFinalize(AddBatch& ioBatch, Activation inActivation);
    /// Frees the batch and frees its bodies for another add. Fails (and changes nothing) for a batch another
    /// world prepared, or a call from inside the step or under a body lock; aborting a finished batch is Ok.
    Status AddBodiesAbort(AddBatch& ioBatch);

    Status SetPosition(const BodyID& inID, const Vec3& inPosition, Activation inActivation);
    Status SetRotation(const BodyID& inID, const Quat& inRotation, Activation inActivation);
    Status SetPositionAndRotation(const BodyID& inID, const Vec3& inPosition, const Quat& inRotation,
                                  Activation inActivation);
    Status SetLinearVelocity(const BodyID& inID, const Vec3& inVelocity);
    Status SetAngularVelocity(const BodyID& inID, const Vec3& inVelocity);
    /// Force through the centre of mass over the whole next Update (each of its collision steps), N.
    Status AddForce(const BodyID& inID, const Vec3& inForce);
    /// Torque over the whole next Update, as AddForce, N m.
    Status AddTorque(const BodyID& inID, const Vec3& inTorque);
    /// Impulse at the centre of mass, N s.
    Status AddImpulse(const BodyID& inID, const Vec3& inImpulse);
    /// Impulse at a world point, N s.
    Status AddImpulse(const BodyID& inID, const Vec3& inImpulse, const Vec3& inWorldPoint);
    Status AddAngularImpulse(const BodyID& inID, const Vec3& inImpulse);
    Status ActivateBody(const BodyID& inID);
    Status DeactivateBody(const BodyID& inID);

    Result<Vec3> GetPosition(const BodyID& inID) const;
    Result<Quat> GetRotation(const BodyID& inID) const;
    Result<Vec3> GetLinearVelocity(const BodyID& inID) const;
    Result<Vec3> GetAngularVelocity(const BodyID& inID) const;
    Result<AABB> GetWorldBounds(const BodyID& inID) const;
    Result<bool> IsActive(const BodyID& inID) const;
    Result<bool> IsAdded(const BodyID& inID) const;

private:
    /// Runs inChange on the body under its write lock after the common checks; inChange returns the status.
    template <class F> Status ModifyBody(const BodyID& inID, bool inMustBeDynamic, F&& inChange);
    /// Validates inAmount (named inWhat in errors), then runs inApply on a dynamic body and activates it.
    template <class F>
    Status PushBody(const BodyID& inID, const Vec3& inAmount, const char* inWhat, F&& inApply);
    template <class T, class F> Result<T> ReadBody(const BodyID& inID, F&& inRead) const;
    /// Pushes the body's new bounds to the broad phase and, for dynamic/kinematic bodies, activates them.
    void OnBodyMoved(Body& ioBody, Activation inActivation);
    /// Activates every sleeping dynamic body of inLayers whose bounds overlap inBounds (after a removal).
    void WakeBodiesIn(const AABB& inBounds, ObjectLayerMask inLayers);

    BodyManager& mBodies;
    BroadPhase& mBroadPhase;
    const LayerSetup& mLayers;
};

} // namespace cairn::physics
