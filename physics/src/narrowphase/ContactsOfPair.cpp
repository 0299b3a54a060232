// ContactsStage's work on one pair: its manifolds (last step's taken over when the pair has barely moved,
// else collided), the constraints made from them with their warm start, the pair's island link and the
// bodies it wakes. Runs in the narrow phase's chunks, on any of the step's threads.

#include "body/Integration.h"
#include "body/StepCallbackScope.h"
#include "cairn/physics/narrowphase/CollideShapes.h"
#include "narrowphase/ContactsStage.h"
#include "narrowphase/ManifoldMerger.h"
#include "solver/SequentialImpulseSolver.h"
#include "step/StepContext.h"

#include <cmath>

namespace cairn::physics
{

namespace
{
/// A bijective 64-bit mix (the finaliser of MurmurHash3): neighbouring keys land far apart.
uint64_t MixBits(uint64_t inKey)
{
    inKey ^= inKey >> 33;
    inKey *= 0xff51afd7ed558ccdULL;
    inKey ^= inKey >> 33;
    inKey *= 0xc4ceb9fe1a85ec53ULL;
    inKey ^= inKey >> 33;
    return inKey;
}
} // namespace

void ContactsStage::CollidePair(const StepContext& inContext, const Integration& inIntegration, Body& ioA,
                                Body& ioB, NarrowPhaseChunk& ioOut) const
{
    if (!ioA.IsDynamic() && !ioB.IsDynamic()) return;
    // Two parts of one object that its group keeps apart (a ragdoll's jointed limbs): no contact, no record
    if (!inContext.mBodies.BodiesCollide(ioA, ioB)) return;
    if (inContext.mListener != nullptr)
    {
        const StepCallbackScope callback;
        if (inContext.mListener->OnContactValidate(ioA, ioB) == ContactValidation::Reject)
            return; // No record either: the pair is validated again next step
    }
    if (ioA.IsSensor() || ioB.IsSensor())
    {
        CollideSensor(ioA, ioB, ioOut);
        return;
    }
    // Look ahead by how far the bodies can close in this step, so fast bodies get speculative contacts before
    // they tunnel
    CollideSettings settings;
    settings.mMaxSeparation = inContext.mSettings.mSpeculativeDistance +
                              inContext.mDeltaTime * (ioB.mLinearVelocity - ioA.mLinearVelocity).norm();
    const size_t constraintsBefore = ioOut.mConstraints.size();
    const Quat inverseRotationA = ioA.mRotation.conjugate();
    CachedBodyPair record{ioA.GetID(), ioB.GetID(), inverseRotationA * (ioB.mPosition - ioA.mPosition),
                          inverseRotationA * ioB.mRotation, settings.mMaxSeparation};
    record.mShapeGenerationA = ioA.mShapeGeneration;
    record.mShapeGenerationB = ioB.mShapeGeneration;
    if (!ReuseManifolds(inContext, inIntegration, ioA, ioB, record, ioOut))
    {
        auto add = [&](const ContactManifold& inManifold)
        {
            AddConstraint(inContext, inIntegration, ioA, ioB, inManifold,
                          inContext.mContactCache.FindPrevious(
                              {ioA.GetID(), ioB.GetID(), inManifold.mSubShapeA, inManifold.mSubShapeB}),
                          ioOut);
        };
        // A shape against a mesh or height field (or a compound) reports a manifold per triangle (or part):
        // those that face the same way become one (see ManifoldMerger). Two convex shapes give one at most,
        // and skip the merger's copies
        if (!inContext.mSettings.mMergeManifolds || (ioA.mShape->IsConvex() && ioB.mShape->IsConvex()))
            CollideShapes(*ioA.mShape, ioA.GetTransform(), *ioB.mShape, ioB.GetTransform(), settings, add);
        else
        {
            ManifoldMerger merger;
            CollideShapes(*ioA.mShape, ioA.GetTransform(), *ioB.mShape, ioB.GetTransform(), settings,
                          [&](const ContactManifold& inManifold)
                          {
                              if (!merger.Add(inManifold)) add(inManifold);
                          });
            merger.ForEach(add);
        }
    }
    // Recorded even without manifolds: a pair that stays apart is not collided again either
    record.mNumManifolds = uint32_t(ioOut.mConstraints.size() - constraintsBefore);
    ioOut.mCachedPairs.push_back(record);
    if (record.mNumManifolds == 0) return;
    // Islands: only a contact between two dynamic bodies links (a static or kinematic body would merge
    // everything that touches it). Linked now, lock-free, while other threads find other contacts; a body
    // still asleep has no active index yet, so its link waits for the merge that wakes it
    if (ioA.IsDynamic() && ioB.IsDynamic())
    {
        if (ioA.IsActive() && ioB.IsActive())
            inContext.mIslands.Union(ioA.GetActiveIndex(), ioB.GetActiveIndex());
        else
            ioOut.mDeferredLinks.push_back({ioA.GetID().GetIndex(), ioB.GetID().GetIndex()});
    }
    // Touching an active body wakes a sleeping one: at the merge, in pair order (the active list is shared)
    if (!ioA.IsActive() && ioA.IsDynamic()) ioOut.mToWake.push_back(ioA.GetID().GetIndex());
    if (!ioB.IsActive() && ioB.IsDynamic()) ioOut.mToWake.push_back(ioB.GetID().GetIndex());
}

void ContactsStage::CollideSensor(Body& ioA, Body& ioB, NarrowPhaseChunk& ioOut) const
{
    const Body& other = ioA.IsSensor() ? ioB : ioA;
    if (other.IsSensor() || !other.IsDynamic()) return;
    // Touching counts as inside: a body resting on a sensor's face is in it
    CollideSettings settings;
    settings.mMaxSeparation = 0.0f;
    bool overlap = false;
    CollideShapes(*ioA.mShape, ioA.GetTransform(), *ioB.mShape, ioB.GetTransform(), settings,
                  [&](const ContactManifold& inManifold)
                  {
                      for (int i = 0; i < inManifold.mNumPoints; ++i)
                          overlap |= inManifold.mPoints[i].mPenetration >= 0.0f;
                  });
    if (overlap) ioOut.mSensorOverlaps.push_back({ioA.GetID(), ioB.GetID()});
}

bool ContactsStage::ReuseManifolds(const StepContext& inContext, const Integration& inIntegration, Body& ioA,
                                   Body& ioB, CachedBodyPair& ioRecord, NarrowPhaseChunk& ioOut) const
{
    const PhysicsSettings& settings = inContext.mSettings;
    if (settings.mPairCacheMaxDeltaPosition <= 0.0f) return false;
    const ContactCache& cache = inContext.mContactCache;
    const CachedBodyPair* previous =
        cache.FindPreviousPair(ioRecord.mBodyA, ioRecord.mBodyB, &ioOut.mPreviousPairHint);
    if (previous == nullptr) return false;
    // Compared with the pose the manifolds were made at, not last step's: slow drift adds up and is caught.
    // The look-ahead grows with the closing speed: a pair that starts to move fast needs speculative points
    // further out than the old manifolds have (up to the same tolerance)
    const float maxDelta = settings.mPairCacheMaxDeltaPosition;
    if ((ioRecord.mDeltaPosition - previous->mDeltaPosition).squaredNorm() > maxDelta * maxDelta ||
        std::abs(ioRecord.mDeltaRotation.dot(previous->mDeltaRotation)) < mPairCacheCosHalfMaxAngle ||
        ioRecord.mMaxSeparation > previous->mMaxSeparation + maxDelta ||
        ioRecord.mShapeGenerationA != previous->mShapeGenerationA ||
        ioRecord.mShapeGenerationB != previous->mShapeGenerationB)
        return false;
    ioRecord = *previous;
    // The points stay fixed on both bodies; where they are now, and how far apart, follows from the poses
    for (const CachedManifold& cached : cache.GetPreviousManifolds(*previous))
    {
        ContactManifold manifold;
        manifold.mNormal = ioA.mRotation * cached.mNormalOnA;
        manifold.mNumPoints = cached.mNumPoints;
        manifold.mSubShapeA = cached.mKey.mSubShapeA;
        manifold.mSubShapeB = cached.mKey.mSubShapeB;
        for (int i = 0; i < cached.mNumPoints; ++i)
        {
            ContactPoint& point = manifold.mPoints[i];
            point.mPositionOnA = ioA.mPosition + ioA.mRotation * cached.mLocalOnA[i];
            point.mPositionOnB = ioB.mPosition + ioB.mRotation * cached.mLocalOnB[i];
            point.mPenetration = (point.mPositionOnA - point.mPositionOnB).dot(manifold.mNormal);
        }
        AddConstraint(inContext, inIntegration, ioA, ioB, manifold, &cached, ioOut, true);
    }
    ++ioOut.mNumReusedPairs;
    return true;
}

void ContactsStage::AddConstraint(const StepContext& inContext, const Integration& inIntegration, Body& ioA,
                                  Body& ioB, const ContactManifold& inManifold,
                                  const CachedManifold* inPrevious, NarrowPhaseChunk& ioOut,
                                  bool inTakenOver) const
{
    if (inManifold.mNumPoints <= 0) return;
    ContactConstraint& c = ioOut.mConstraints.emplace_back();
    // A manifold taken over from the cache has its points in the bodies' frames already, and its points are
    // last step's, one for one
    SequentialImpulseSolver::InitConstraint(
        ioA, ioB, inIntegration.InverseInertiaOf(ioA), inIntegration.InverseInertiaOf(ioB), inManifold,
        inContext.mDeltaTime, c, inTakenOver ? inPrevious->mLocalOnA : nullptr,
        inTakenOver ? inPrevious->mLocalOnB : nullptr);
    if (inContext.mListener != nullptr)
    {
        ContactSettings settings{c.mFriction, c.mRestitution};
        {
            const StepCallbackScope callback;
            if (inPrevious == nullptr)
                inContext.mListener->OnContactAdded(ioA, ioB, inManifold, settings);
            else
                inContext.mListener->OnContactPersisted(ioA, ioB, inManifold, settings);
        }
        // A listener's NaN or out-of-range value keeps the combined one: the step cannot report an error,
        // and a NaN friction would spread to every body of the island
        if (settings.mFriction >= 0.0f && settings.mFriction < cLargeFloat) c.mFriction = settings.mFriction;
        if (settings.mRestitution >= 0.0f && settings.mRestitution <= 1.0f)
            c.mRestitution = settings.mRestitution;
    }
    if (c.mRestitution > 0.0f)
        SequentialImpulseSolver::InitBounces(inIntegration.ForceVelocityChangeOf(inContext, ioA),
                                             inIntegration.ForceVelocityChangeOf(inContext, ioB),
                                             inContext.mDeltaTime, inContext.mSettings.mSolver, c);

    CachedManifold& cached = ioOut.mCached.emplace_back();
    cached.mKey = {ioA.GetID(), ioB.GetID(), inManifold.mSubShapeA, inManifold.mSubShapeB};
    cached.mNumPoints = c.mNumPoints;
    cached.mNormalOnA = inTakenOver ? inPrevious->mNormalOnA : Vec3(ioA.mRotation.conjugate() * c.mNormal);
    const CachedManifold* previous = inPrevious;
    if (previous != nullptr)
    {
        for (int t = 0; t < 2; ++t)
            c.mPatch.mTangent[t].mAccumulated = c.mTangent[t].dot(previous->mFrictionImpulse);
        c.mPatch.mTwistAccumulated = previous->mTwistImpulse;
    }
    for (int i = 0; i < c.mNumPoints; ++i)
    {
        ContactConstraintPoint& p = c.mPoints[i];
        cached.mLocalOnA[i] = p.mLocalOnA;
        cached.mLocalOnB[i] = p.mLocalOnB;
        cached.mNormalImpulse[i] = 0.0f;
        if (previous == nullptr) continue;
        if (inTakenOver)
        {
            p.mNormal.mAccumulated = previous->mNormalImpulse[i];
            ++ioOut.mNumWarmStartedPoints;
            continue;
        }
        // Warm start from the nearest point of last step's manifold, if it is the same contact
        for (int j = 0; j < previous->mNumPoints; ++j)
            if ((previous->mLocalOnA[j] - p.mLocalOnA).squaredNorm() <
                ContactCache::cPointMatchDistance * ContactCache::cPointMatchDistance)
            {
                p.mNormal.mAccumulated = previous->mNormalImpulse[j];
                ++ioOut.mNumWarmStartedPoints;
                break;
            }
    }
    ioOut.mNumContactPoints += uint32_t(c.mNumPoints);
    c.mOrderKey = MixBits((uint64_t(ioA.GetID().GetIndex()) << 32 | ioB.GetID().GetIndex()) ^
                          (uint64_t(inManifold.mSubShapeA) << 40) ^ inManifold.mSubShapeB);
}

} // namespace cairn::physics
