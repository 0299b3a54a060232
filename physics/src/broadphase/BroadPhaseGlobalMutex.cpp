#include "broadphase/BroadPhaseGlobalMutex.h"

#include <cassert>
#include <mutex>
#include <shared_mutex>
#include <utility>

namespace cairn::physics
{

// The locks below are plain std::unique_lock/std::shared_lock: WriterFairSharedMutex tries first and counts
// only a wait, so wrapping it in LockedCountingWait would count each wait twice.
using ExclusiveLock = std::unique_lock<WriterFairSharedMutex>;
using SharedLock = std::shared_lock<WriterFairSharedMutex>;

BroadPhaseGlobalMutex::BroadPhaseGlobalMutex(std::unique_ptr<BroadPhase> inWrapped)
    : mWrapped(std::move(inWrapped))
{
    assert(mWrapped != nullptr && "BroadPhaseGlobalMutex: nothing to wrap");
}

BroadPhase::AddState BroadPhaseGlobalMutex::AddBodiesPrepare(std::span<const BroadPhaseBody> inBodies)
{
    return mWrapped->AddBodiesPrepare(inBodies);
}

void BroadPhaseGlobalMutex::AddBodiesFinalize(AddState inState)
{
    const ExclusiveLock lock(mMutex);
    mWrapped->AddBodiesFinalize(inState);
}

void BroadPhaseGlobalMutex::AddBodiesAbort(AddState inState)
{
    mWrapped->AddBodiesAbort(inState);
}

void BroadPhaseGlobalMutex::RemoveBodies(std::span<const BodyID> inBodies)
{
    const ExclusiveLock lock(mMutex);
    mWrapped->RemoveBodies(inBodies);
}

void BroadPhaseGlobalMutex::NotifyBodiesAABBChanged(std::span<const BroadPhaseBody> inBodies)
{
    const ExclusiveLock lock(mMutex);
    mWrapped->NotifyBodiesAABBChanged(inBodies);
}

bool BroadPhaseGlobalMutex::ChangeBodyLayer(BodyID inBody, ObjectLayer inLayer,
                                            FunctionRef<void()> inWhileInBoth)
{
    const ExclusiveLock lock(mMutex);
    return mWrapped->ChangeBodyLayer(inBody, inLayer, inWhileInBoth);
}

void BroadPhaseGlobalMutex::Update()
{
    const ExclusiveLock lock(mMutex);
    mWrapped->Update();
}

void BroadPhaseGlobalMutex::CollideAABox(const AABB& inBox, const BroadPhaseQueryFilter& inFilter,
                                         BodyVisitor inVisitor) const
{
    const SharedLock lock(mMutex);
    mWrapped->CollideAABox(inBox, inFilter, inVisitor);
}

void BroadPhaseGlobalMutex::CollideSphere(const Vec3& inCenter, float inRadius,
                                          const BroadPhaseQueryFilter& inFilter, BodyVisitor inVisitor) const
{
    const SharedLock lock(mMutex);
    mWrapped->CollideSphere(inCenter, inRadius, inFilter, inVisitor);
}

void BroadPhaseGlobalMutex::CollidePoint(const Vec3& inPoint, const BroadPhaseQueryFilter& inFilter,
                                         BodyVisitor inVisitor) const
{
    const SharedLock lock(mMutex);
    mWrapped->CollidePoint(inPoint, inFilter, inVisitor);
}

void BroadPhaseGlobalMutex::CastRay(const RayCast& inRay, const BroadPhaseQueryFilter& inFilter,
                                    RayBodyVisitor inVisitor) const
{
    // Every broad phase ignores such a ray: checked first, it waits for no writer
    if (!IsFiniteCast(inRay.mOrigin, inRay.mDirection)) return;
    const SharedLock lock(mMutex);
    mWrapped->CastRay(inRay, inFilter, inVisitor);
}

void BroadPhaseGlobalMutex::CastAABox(const AABB& inBox, const Vec3& inDisplacement,
                                      const BroadPhaseQueryFilter& inFilter, RayBodyVisitor inVisitor) const
{
    if (!IsFiniteCast(inBox, inDisplacement)) return; // As in CastRay
    const SharedLock lock(mMutex);
    mWrapped->CastAABox(inBox, inDisplacement, inFilter, inVisitor);
}

void BroadPhaseGlobalMutex::FindCollidingPairs(std::span<const BodyID> inActiveBodies,
                                               const LayerSetup& inLayers, BodyPairVisitor inVisitor,
                                               const ParallelRanges* inParallel) const
{
    const SharedLock lock(mMutex);
    mWrapped->FindCollidingPairs(inActiveBodies, inLayers, inVisitor, inParallel);
}

size_t BroadPhaseGlobalMutex::GetBodyCount() const
{
    return mWrapped->GetBodyCount();
}

void BroadPhaseGlobalMutex::WithExclusiveLock(FunctionRef<void(BroadPhase&)> inFunction)
{
    const ExclusiveLock lock(mMutex);
    inFunction(*mWrapped);
}

} // namespace cairn::physics
