#pragma once

// BroadPhaseBruteForce: the test oracle. Every query tests every body; no cleverness, so that it is obviously
// correct and the fast broad phases can be compared against it. Kept forever; never used by the engine.
//
// Threads: as BroadPhase (any thread; FindCollidingPairs/Update from the physics step only).
// Locking: mMutex guards every member. Queries and FindCollidingPairs take it shared; AddBodiesFinalize,
// RemoveBodies, NotifyBodiesAABBChanged and ChangeBodyLayer take it exclusive (ChangeBodyLayer runs its
// callback under it: a query sees the body in its old layer or its new one, whole). AddBodiesPrepare/Abort
// take no lock (they only touch the batch they own). mActiveScratch is written under the shared lock, which
// is safe because only the physics step calls FindCollidingPairs, one call at a time. Visitors run under the
// shared lock: they must not call any method of this broad phase (a modifying one would deadlock) and must
// not wait for a lock held by a thread that may be calling a modifying method.
//
// Bad input is ignored as BroadPhase.h lists it. It has no LayerSetup and no capacity: an object layer is
// unknown when it is >= cMaxObjectLayers, and any body index has room (the index map grows on demand).

#include "cairn/physics/broadphase/BroadPhase.h"

#include <shared_mutex>
#include <vector>

namespace cairn::physics
{

class BroadPhaseBruteForce final : public BroadPhase
{
public:
    BroadPhaseBruteForce() = default;
    BroadPhaseBruteForce(const BroadPhaseBruteForce&) = delete;
    BroadPhaseBruteForce& operator=(const BroadPhaseBruteForce&) = delete;

    /// Copies the batch; no lock.
    AddState AddBodiesPrepare(std::span<const BroadPhaseBody> inBodies) override;
    /// Appends the batch under the exclusive lock and frees it.
    void AddBodiesFinalize(AddState inState) override;
    /// Frees the batch.
    void AddBodiesAbort(AddState inState) override;
    /// Swap-removes each present body.
    void RemoveBodies(std::span<const BodyID> inBodies) override;
    /// Overwrites the stored bounds (and object layer) of each present body.
    void NotifyBodiesAABBChanged(std::span<const BroadPhaseBody> inBodies) override;
    /// Overwrites the stored object layer and runs inWhileInBoth, both under the exclusive lock.
    bool ChangeBodyLayer(BodyID inBody, ObjectLayer inLayer, FunctionRef<void()> inWhileInBoth) override;
    /// Nothing to optimise.
    void Update() override {}

    /// Tests every body.
    void CollideAABox(const AABB& inBox, const BroadPhaseQueryFilter& inFilter,
                      BodyVisitor inVisitor) const override;
    /// Tests every body.
    void CollideSphere(const Vec3& inCenter, float inRadius, const BroadPhaseQueryFilter& inFilter,
                       BodyVisitor inVisitor) const override;
    /// Tests every body.
    void CollidePoint(const Vec3& inPoint, const BroadPhaseQueryFilter& inFilter,
                      BodyVisitor inVisitor) const override;
    /// Tests every body, in storage order.
    void CastRay(const RayCast& inRay, const BroadPhaseQueryFilter& inFilter,
                 RayBodyVisitor inVisitor) const override;
    /// Tests every body, in storage order.
    void CastAABox(const AABB& inBox, const Vec3& inDisplacement, const BroadPhaseQueryFilter& inFilter,
                   RayBodyVisitor inVisitor) const override;
    /// Every active body against every body.
    void FindCollidingPairs(std::span<const BodyID> inActiveBodies, const LayerSetup& inLayers,
                            BodyPairVisitor inVisitor,
                            const ParallelRanges* inParallel = nullptr) const override;

    /// Number of bodies stored.
    size_t GetBodyCount() const override;

private:
    static constexpr uint32_t cNotPresent = 0xffffffffu; ///< mPositionOfIndex value of an absent body

    /// Position in mBodies of the body with exactly this id, or cNotPresent. Caller holds mMutex.
    uint32_t FindPosition(BodyID inID) const;

    mutable std::shared_mutex mMutex;       ///< Guards everything below
    std::vector<BroadPhaseBody> mBodies;    ///< Unordered; swap-remove
    std::vector<uint32_t> mPositionOfIndex; ///< Body index -> position in mBodies; grown on demand
    mutable std::vector<uint8_t>
        mActiveScratch; ///< Per position: 1 while FindCollidingPairs runs and the body is active
};

} // namespace cairn::physics
