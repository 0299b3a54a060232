#pragma once

// BodyInterface: the locking API to create, add, remove, move, push and change bodies (motion type, object
// layer, shape), callable from any thread outside the physics step. Every call validates its input and
// returns an error without changing anything when the input is bad (stale id, NaN, body in the wrong state).
// Calls made from inside the step (a step callback) return ErrorCode::WrongThread instead of deadlocking.
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

#include <memory>
#include <span>
#include <vector>

namespace cairn::physics
{

class AddBatchRegistry;

class BodyInterface
{
public:
    BodyInterface(BodyManager& ioBodies, BroadPhase& ioBroadPhase, const LayerSetup& inLayers);
    /// Aborts the add batches still prepared (they may outlive the world, and then do nothing when let go).
    /// Waits for a batch being let go on another thread meanwhile.
    ~BodyInterface();
    BodyInterface(const BodyInterface&) = delete;
    BodyInterface& operator=(const BodyInterface&) = delete;

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
    /// Move-only: it owns the broad phase's prepared state, which is finalized or aborted exactly once (a
    /// copy finalized and then the original aborted would free it twice). A batch destroyed or overwritten
    /// before either is aborted, so a loader that bails out on an error leaks nothing and leaves no body
    /// pending:
    /// - on a thread that may call AddBodiesAbort, at once, as that call does (waiting for a running step);
    /// - inside a step or under a body lock, where locking its bodies could deadlock, by the world's
    ///   next call that takes them (AddBody, DestroyBody, SetObjectLayer, the batch calls) and starts
    ///   after the step returned or the lock was released;
    /// - after its world is gone, not at all: the world aborted it as it went.
    /// Like any call that locks bodies, not inside a broad-phase query's visitor (BroadPhase.h).
    struct AddBatch
    {
        bool IsEmpty() const { return mBodies.empty(); }
        size_t GetNumBodies() const { return mBodies.size(); }

        AddBatch() = default;
        AddBatch(AddBatch&& ioOther) noexcept;
        AddBatch& operator=(AddBatch&& ioOther) noexcept;
        AddBatch(const AddBatch&) = delete;
        AddBatch& operator=(const AddBatch&) = delete;
        ~AddBatch();

    private:
        friend class BodyInterface;
        /// Aborts a batch that is neither finalized nor aborted, as the struct's comment says
        void LetGo() noexcept;

        std::vector<BroadPhaseBody> mBodies;
        BroadPhase::AddState mState = nullptr;
        /// The registry of the world that prepared it: its ids and broad-phase state mean nothing to another
        /// world's, and it outlives the world, which tells a batch let go after the world that it is gone
        std::shared_ptr<AddBatchRegistry> mRegistry;
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

    // Changing a live body. Each works on a body in the world or not, from any thread outside the step
    // (inside it, or while this thread holds a body lock: WrongThread), under the body's write lock like the
    // calls above; bad input (a stale id, NaN, a value out of range) is an error that changes nothing.

    /// Makes a body static, kinematic or dynamic, its shape's origin staying where it is. To dynamic: the
    /// shape's mass and inertia at the density the body was created with, after CreateBody's checks (a shape
    /// with volume, a mass in range); the velocities are kept (a kinematic door let go swings on). To
    /// kinematic: no mass, velocities kept, forces dropped. To static: deactivated, velocities and forces
    /// zeroed, and its broad-phase box back to its own bounds (the step gave an active body a swept one); a
    /// static body is never in the active list. Activation::Activate activates a dynamic or kinematic body in
    /// the world (the same motion type again only does that). The published pose names the new motion type at
    /// once. The object layer stays: a body made dynamic in a static layer collides as that layer says (see
    /// SetObjectLayer). Body change listeners hear an in-place move under the old motion type, then one under
    /// the new (a listener that keeps bodies of one type only sees both sides). A sleeping body made static
    /// stays in its island's ring, where it ends the ring's wake walk: the bodies after it wake by contact.
    /// Locks: the body's mutex; the broad phase for a body made static in the world.
    Status SetMotionType(const BodyID& inID, MotionType inMotionType, Activation inActivation);
    /// Moves a body to another object layer (one of the layer setup, as CreateBody requires), and so to that
    /// layer's broad-phase structure, without a moment where a query on another thread misses it: a query
    /// running meanwhile finds it once under the old layer or the new one, and under the layer its published
    /// pose shows at every moment (BroadPhase::ChangeBodyLayer). Refused for a body in an add batch that is
    /// not finalized (its batch holds the old layer); OutOfCapacity, with nothing changed, when the new
    /// broad-phase structure has no room. Listeners hear an in-place move under each layer, as for
    /// SetMotionType. Locks: the body's mutex, then the broad phase's; it may wait, holding the body's lock,
    /// for the queries running on other threads when it starts to finish (microseconds; longer only when such
    /// a thread lost its core).
    Status SetObjectLayer(const BodyID& inID, ObjectLayer inLayer);
    /// Gives a body another shape, the shape's origin staying where it is. A dynamic body's new shape must
    /// have volume (CreateBody's checks at the body's density); with inUpdateMassProperties it gets the new
    /// shape's mass and inertia, otherwise it keeps its own. The centre of mass follows the new shape either
    /// way (the velocities stay those of the same rigid motion). As a move by hand: the broad phase holds
    /// both shapes' bounds while the new shape is published, then the new bounds only, so no query misses the
    /// body; listeners hear a move from the old bounds; inActivation as SetPosition's. The old shape is
    /// retired as DestroyBody retires one: freed once no query can still hold it. Locks: the body's mutex,
    /// then the broad phase's; the retired shapes' mutex after the body's lock is released.
    Status SetShape(const BodyID& inID, ShapeRef inShape, bool inUpdateMassProperties,
                    Activation inActivation);
    /// Sets the velocities of a kinematic body in the world so that it reaches the target pose (the shape's
    /// origin and rotation, the turn taken the short way round) in inDeltaTime seconds, and activates it: an
    /// Update of inDeltaTime (in any number of collision steps) moves it there. The velocities stay
    /// afterwards: call it again each frame with the next target, or set them to zero. Refused, with nothing
    /// changed: a body that is not kinematic or not in the world, a target that is not finite or beyond the
    /// world, a rotation that is not a unit quaternion, inDeltaTime not finite and > 0, and a move faster
    /// than the body's velocity limits (the step would clamp it and stop short). Locks: the body's mutex.
    Status MoveKinematic(const BodyID& inID, const Vec3& inTargetPosition, const Quat& inTargetRotation,
                         float inDeltaTime);

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
    /// A batch let go (AddBatch::LetGo): aborted now, or deferred where this thread may not lock its bodies
    void AbortLetGo(AddBatch& ioBatch);
    /// Aborts the batches let go inside a step or under a body lock; on a thread that may lock bodies only
    void AbortDeferredBatches();
    /// Frees a batch's broad-phase state (if any) and its bodies' pending marks
    void AbortBatchParts(BroadPhase::AddState inState, const std::vector<BroadPhaseBody>& inBodies);

    BodyManager& mBodies;
    BroadPhase& mBroadPhase;
    const LayerSetup& mLayers;
    /// The batches this world prepared and has not finished (AddBatchRegistry.h says which threads)
    std::shared_ptr<AddBatchRegistry> mBatches;
};

} // namespace cairn::physics
