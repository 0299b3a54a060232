#include "broadphase/BroadPhaseBruteForce.h"

#include "broadphase/BroadPhaseOverlap.h"
#include "cairn/physics/LockWaits.h"

#include <cassert>
#include <mutex>

namespace cairn::physics
{

namespace
{

/// A prepared batch: just the copied bodies.
struct BruteForceAddBatch
{
    std::vector<BroadPhaseBody> mBodies; ///< Copy of the span given to AddBodiesPrepare
};

/// Bad input that every method ignores (asserting in debug, as the body interface validates first).
bool IsAcceptable(const BroadPhaseBody& inBody)
{
    const bool ok = !inBody.mID.IsInvalid() && inBody.mLayer < cMaxObjectLayers &&
                    IsValidBroadPhaseBounds(inBody.mBounds);
    assert(ok && "BroadPhase: invalid body id, object layer or bounds");
    return ok;
}

} // namespace

BroadPhase::AddState BroadPhaseBruteForce::AddBodiesPrepare(std::span<const BroadPhaseBody> inBodies)
{
    return new BruteForceAddBatch{std::vector<BroadPhaseBody>(inBodies.begin(), inBodies.end())};
}

void BroadPhaseBruteForce::AddBodiesFinalize(AddState inState)
{
    BruteForceAddBatch* batch = static_cast<BruteForceAddBatch*>(inState);
    {
        const auto lock = LockedCountingWait(mMutex, LockKind::BroadPhase);
        for (const BroadPhaseBody& body : batch->mBodies)
        {
            if (!IsAcceptable(body)) continue;
            const uint32_t index = body.mID.GetIndex();
            if (index >= mPositionOfIndex.size()) mPositionOfIndex.resize(size_t(index) + 1, cNotPresent);
            // A second add of the same index is a caller bug; the first add wins
            if (mPositionOfIndex[index] != cNotPresent) continue;
            mPositionOfIndex[index] = uint32_t(mBodies.size());
            mBodies.push_back(body);
        }
    }
    delete batch;
}

void BroadPhaseBruteForce::AddBodiesAbort(AddState inState)
{
    delete static_cast<BruteForceAddBatch*>(inState);
}

uint32_t BroadPhaseBruteForce::FindPosition(BodyID inID) const
{
    if (inID.IsInvalid() || inID.GetIndex() >= mPositionOfIndex.size()) return cNotPresent;
    const uint32_t position = mPositionOfIndex[inID.GetIndex()];
    // A stale id (same slot, other sequence) is not present
    if (position == cNotPresent || mBodies[position].mID != inID) return cNotPresent;
    return position;
}

void BroadPhaseBruteForce::RemoveBodies(std::span<const BodyID> inBodies)
{
    const auto lock = LockedCountingWait(mMutex, LockKind::BroadPhase);
    for (BodyID id : inBodies)
    {
        const uint32_t position = FindPosition(id);
        if (position == cNotPresent) continue;
        // Swap-remove: the last body takes the hole
        mBodies[position] = mBodies.back();
        mPositionOfIndex[mBodies[position].mID.GetIndex()] = position;
        mBodies.pop_back();
        mPositionOfIndex[id.GetIndex()] = cNotPresent;
    }
}

void BroadPhaseBruteForce::NotifyBodiesAABBChanged(std::span<const BroadPhaseBody> inBodies)
{
    const auto lock = LockedCountingWait(mMutex, LockKind::BroadPhase);
    for (const BroadPhaseBody& body : inBodies)
    {
        const uint32_t position = FindPosition(body.mID);
        if (position == cNotPresent || !IsAcceptable(body)) continue;
        mBodies[position] = body;
    }
}

bool BroadPhaseBruteForce::ChangeBodyLayer(BodyID inBody, ObjectLayer inLayer,
                                           FunctionRef<void()> inWhileInBoth)
{
    const bool known = inLayer < cMaxObjectLayers;
    assert(known && "BroadPhase: invalid object layer");
    if (!known) return false;
    const auto lock = LockedCountingWait(mMutex, LockKind::BroadPhase);
    const uint32_t position = FindPosition(inBody);
    if (position == cNotPresent) return false;
    // Queries hold the lock shared, so each finds the body under one layer or the other, never neither: the
    // callback runs before any query sees the change, and it is found under the new layer meanwhile
    mBodies[position].mLayer = inLayer;
    inWhileInBoth();
    return true;
}

void BroadPhaseBruteForce::CollideAABox(const AABB& inBox, const BroadPhaseQueryFilter& inFilter,
                                        BodyVisitor inVisitor) const
{
    const auto lock = SharedLockedCountingWait(mMutex, LockKind::BroadPhase);
    for (const BroadPhaseBody& body : mBodies)
        if (IsInLayerMask(inFilter.mObjectLayers, body.mLayer) && body.mBounds.Overlaps(inBox))
            inVisitor(body.mID);
}

void BroadPhaseBruteForce::CollideSphere(const Vec3& inCenter, float inRadius,
                                         const BroadPhaseQueryFilter& inFilter, BodyVisitor inVisitor) const
{
    const auto lock = SharedLockedCountingWait(mMutex, LockKind::BroadPhase);
    for (const BroadPhaseBody& body : mBodies)
        if (IsInLayerMask(inFilter.mObjectLayers, body.mLayer) &&
            SphereOverlapsAABB(inCenter, inRadius, body.mBounds))
            inVisitor(body.mID);
}

void BroadPhaseBruteForce::CollidePoint(const Vec3& inPoint, const BroadPhaseQueryFilter& inFilter,
                                        BodyVisitor inVisitor) const
{
    const auto lock = SharedLockedCountingWait(mMutex, LockKind::BroadPhase);
    for (const BroadPhaseBody& body : mBodies)
        if (IsInLayerMask(inFilter.mObjectLayers, body.mLayer) && body.mBounds.Contains(inPoint))
            inVisitor(body.mID);
}

void BroadPhaseBruteForce::CastRay(const RayCast& inRay, const BroadPhaseQueryFilter& inFilter,
                                   RayBodyVisitor inVisitor) const
{
    if (!IsFiniteCast(inRay.mOrigin, inRay.mDirection)) return;
    const Vec3 invDirection = SafeReciprocal(inRay.mDirection);
    float maxFraction = 1.0f;
    const auto lock = SharedLockedCountingWait(mMutex, LockKind::BroadPhase);
    for (const BroadPhaseBody& body : mBodies)
    {
        if (!IsInLayerMask(inFilter.mObjectLayers, body.mLayer)) continue;
        const float fraction = body.mBounds.RayEntryFraction(inRay.mOrigin, invDirection, maxFraction);
        if (fraction > maxFraction) continue;
        // The visitor can only shrink the range (a larger value would mean bodies already skipped were
        // wanted)
        maxFraction = std::min(maxFraction, inVisitor(body.mID, fraction));
        if (maxFraction < 0.0f) return;
    }
}

void BroadPhaseBruteForce::CastAABox(const AABB& inBox, const Vec3& inDisplacement,
                                     const BroadPhaseQueryFilter& inFilter, RayBodyVisitor inVisitor) const
{
    if (!IsFiniteCast(inBox, inDisplacement)) return;
    const SweptAABox sweep(inBox, inDisplacement);
    float maxFraction = 1.0f;
    const auto lock = SharedLockedCountingWait(mMutex, LockKind::BroadPhase);
    for (const BroadPhaseBody& body : mBodies)
    {
        if (!IsInLayerMask(inFilter.mObjectLayers, body.mLayer)) continue;
        const float fraction = sweep.EntryFraction(body.mBounds, maxFraction);
        if (fraction > maxFraction) continue;
        maxFraction = std::min(maxFraction, inVisitor(body.mID, fraction));
        if (maxFraction < 0.0f) return;
    }
}

void BroadPhaseBruteForce::FindCollidingPairs(std::span<const BodyID> inActiveBodies,
                                              const LayerSetup& inLayers, BodyPairVisitor inVisitor,
                                              const ParallelRanges* /*inParallel: runs serially*/) const
{
    const auto lock = SharedLockedCountingWait(mMutex, LockKind::BroadPhase);

    // Mark the active bodies that are present, so that a pair of two active bodies is reported only once
    mActiveScratch.assign(mBodies.size(), 0);
    for (BodyID id : inActiveBodies)
        if (const uint32_t position = FindPosition(id); position != cNotPresent) mActiveScratch[position] = 1;

    for (BodyID id : inActiveBodies)
    {
        const uint32_t self = FindPosition(id);
        if (self == cNotPresent) continue;
        const BroadPhaseBody& active = mBodies[self];
        for (uint32_t other = 0; other < mBodies.size(); ++other)
        {
            const BroadPhaseBody& body = mBodies[other];
            if (other == self || !inLayers.ShouldCollide(active.mLayer, body.mLayer) ||
                !active.mBounds.Overlaps(body.mBounds))
                continue;
            // Two active bodies: only the one with the lower index reports the pair
            if (mActiveScratch[other] != 0 && body.mID.GetIndex() < active.mID.GetIndex()) continue;
            inVisitor(active.mID, body.mID);
        }
    }
}

size_t BroadPhaseBruteForce::GetBodyCount() const
{
    const auto lock = SharedLockedCountingWait(mMutex, LockKind::BroadPhase);
    return mBodies.size();
}

} // namespace cairn::physics
