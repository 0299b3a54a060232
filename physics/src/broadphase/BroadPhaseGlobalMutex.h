#pragma once

// BroadPhaseGlobalMutex: any broad phase behind one reader-writer mutex, the "before" of the reference engine
// (one read-write lock around its whole broad phase), kept for the benchmarks and the demo's comparison.
// BroadPhaseType::QuadTreeGlobalMutex is the lock-free quad tree wrapped in it: the same trees, so the two
// modes differ in the lock alone.
//
// Threads and locks: every method may be called as BroadPhase says. mMutex, a WriterFairSharedMutex (glibc's
// shared mutex let a stream of queries starve the mover and the step's Update), is taken
//  - exclusive by AddBodiesFinalize, RemoveBodies, NotifyBodiesAABBChanged, ChangeBodyLayer (its callback
//    included), Update and WithExclusiveLock;
//  - shared by the five queries and FindCollidingPairs;
//  - not at all by AddBodiesPrepare/Abort, which build or free the caller's own batch off the live structure
//    (so the loading thread's work stays outside the lock), nor by GetBodyCount, a statistic.
// mWrapped (the pointer) is immutable; the broad phase it owns is called only under the lock above, except by
// the unlocked calls just listed and through GetWrapped. A wait for mMutex is counted as a
// LockKind::BroadPhase wait by the mutex itself. Lock order: mMutex before any lock of the wrapped broad
// phase, which never calls back. Visitors run under the shared lock, so the BroadPhase visitor rules apply.
// Two overlapping Updates (two threads stepping one world: a caller bug) queue on the exclusive lock, so the
// wrapped broad phase never sees them overlap (the lock-free quad tree would refuse and count the second).

#include "broadphase/WriterFairSharedMutex.h"
#include "cairn/physics/broadphase/BroadPhase.h"

#include <memory>

namespace cairn::physics
{

class BroadPhaseGlobalMutex final : public BroadPhase
{
public:
    /// Takes ownership of inWrapped (not null).
    explicit BroadPhaseGlobalMutex(std::unique_ptr<BroadPhase> inWrapped);
    BroadPhaseGlobalMutex(const BroadPhaseGlobalMutex&) = delete;
    BroadPhaseGlobalMutex& operator=(const BroadPhaseGlobalMutex&) = delete;

    /// No lock: builds the batch in the wrapped broad phase, off its live structure.
    AddState AddBodiesPrepare(std::span<const BroadPhaseBody> inBodies) override;
    /// Exclusive.
    void AddBodiesFinalize(AddState inState) override;
    /// No lock: frees the caller's batch.
    void AddBodiesAbort(AddState inState) override;
    /// Exclusive.
    void RemoveBodies(std::span<const BodyID> inBodies) override;
    /// Exclusive.
    void NotifyBodiesAABBChanged(std::span<const BroadPhaseBody> inBodies) override;
    /// Exclusive, for the whole change: no query runs in the wrapped broad phase meanwhile, so the quad
    /// tree's change waits for none.
    bool ChangeBodyLayer(BodyID inBody, ObjectLayer inLayer, FunctionRef<void()> inWhileInBoth) override;
    /// Exclusive. Physics step only.
    void Update() override;
    /// False: the search takes the lock shared and would only wait for the update's exclusive hold, so the
    /// step runs the two one after the other.
    bool CanFindPairsDuringUpdate() const override { return false; }

    /// Shared.
    void CollideAABox(const AABB& inBox, const BroadPhaseQueryFilter& inFilter,
                      BodyVisitor inVisitor) const override;
    /// Shared.
    void CollideSphere(const Vec3& inCenter, float inRadius, const BroadPhaseQueryFilter& inFilter,
                       BodyVisitor inVisitor) const override;
    /// Shared.
    void CollidePoint(const Vec3& inPoint, const BroadPhaseQueryFilter& inFilter,
                      BodyVisitor inVisitor) const override;
    /// Shared; a ray that is not IsFiniteCast reports nothing without taking it.
    void CastRay(const RayCast& inRay, const BroadPhaseQueryFilter& inFilter,
                 RayBodyVisitor inVisitor) const override;
    /// Shared; a sweep that is not IsFiniteCast reports nothing without taking it.
    void CastAABox(const AABB& inBox, const Vec3& inDisplacement, const BroadPhaseQueryFilter& inFilter,
                   RayBodyVisitor inVisitor) const override;
    /// Shared, for the whole search (inParallel's ranges run inside it). Physics step only.
    void FindCollidingPairs(std::span<const BodyID> inActiveBodies, const LayerSetup& inLayers,
                            BodyPairVisitor inVisitor,
                            const ParallelRanges* inParallel = nullptr) const override;

    /// No lock: a statistic.
    size_t GetBodyCount() const override;

    /// Runs inFunction on the wrapped broad phase under the exclusive lock: for what BroadPhase does not have
    /// (the quad tree's RebuildAll) while other threads may call in. inFunction must not call this object.
    void WithExclusiveLock(FunctionRef<void(BroadPhase&)> inFunction);
    /// The wrapped broad phase, without the lock: for checks and statistics where no other thread modifies it
    /// (Validate after the threads joined) or that it makes safe on its own.
    const BroadPhase& GetWrapped() const { return *mWrapped; }

private:
    const std::unique_ptr<BroadPhase> mWrapped; ///< Owned; the pointer is immutable
    mutable WriterFairSharedMutex mMutex;       ///< See the header comment
};

} // namespace cairn::physics
