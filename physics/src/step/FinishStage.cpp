#include "step/FinishStage.h"

#include "body/PublishedPoseStore.h"
#include "cairn/physics/LockWaits.h"
#include "step/StepContext.h"
#include "step/StepCosts.h"
#include "step/SweptBoxes.h"

namespace cairn::physics
{

void FinishStage::Run(const StepContext& inContext)
{
    const float deltaTime = inContext.mDeltaTime;
    const PhysicsSettings& settings = inContext.mSettings;
    // A body whose new bounds lie this far inside the box the broad phase holds for it may publish before it
    // moves (m): far below the speculative distance by which that box reaches past the body, far above
    // rounding
    constexpr float cHeldBoxTolerance = 1.0e-4f;
    const std::vector<uint32_t>& active = inContext.mActive;
    mMovedBodies.resize(active.size());
    // The broad phase gets the bounds swept over the next step (by inSweep: the step's velocity times its
    // time) plus the speculative distance, so the next step finds the pairs this body can reach
    auto sweptBounds = [&](const AABB& inBounds, const Vec3& inSweep)
    { return SweptBoxes::Of(inBounds, inSweep, settings.mSpeculativeDistance); };
    PublishedPoseStore& poses = inContext.mPoses;
    mPublishOrders.resize(active.size());
    inContext.mScheduler.ParallelFor(
        uint32_t(active.size()), StepCosts::cFinish,
        [&](uint32_t inBegin, uint32_t inEnd)
        {
            // The broad phase must hold a body's published bounds at every moment (PublishedPose.h).
            // A body whose new bounds lie inside the box the broad phase holds for it (the box this
            // step's last finish gave it, if nobody published the body since) publishes first, then
            // moves: a falling or sliding body, whose box reached ahead. Another moves first and
            // publishes after, with a box grown over its published bounds meanwhile where its new
            // box does not cover them, shrunk back once published.
            bool anyGrown = false;
            for (uint32_t i = inBegin; i < inEnd; ++i)
            {
                const uint32_t index = active[i];
                Body& body = inContext.BodyAt(index);
                poses.Prefetch(index);
                const AABB published = body.mBounds;
                // Forces act over the whole Update (each collision step's velocity half and bounces read
                // them)
                if (inContext.mLastCollisionStep)
                {
                    body.mForce.setZero();
                    body.mTorque.setZero();
                }
                body.UpdateBounds();
                const Vec3 sweep = deltaTime * body.mLinearVelocity;
                const AABB swept = sweptBounds(body.mBounds, sweep);
                AABB box = swept;
                PublishOrder order = PublishOrder::AfterMove;
                // The box held is made again as it was made, and checked a little inside, so that a
                // rounding difference could only make the check fail
                PublishedPoseStore::StepMemory& memory = poses.GetStepMemory(index);
                if (poses.GetVersion(index) == memory.mVersion &&
                    sweptBounds(published, memory.mSweep).Expanded(-cHeldBoxTolerance).Contains(body.mBounds))
                {
                    memory.mVersion = poses.PublishMotion(body);
                    order = PublishOrder::BeforeMove;
                }
                else if (!swept.Contains(published))
                {
                    box.Encapsulate(published);
                    order = PublishOrder::AfterGrownMove;
                    anyGrown = true;
                }
                memory.mSweep = sweep;
                mPublishOrders[i] = order;
                mMovedBodies[i] = {body.GetID(), box, body.GetObjectLayer()};

                const float radius = body.mShape->GetLocalBounds().HalfExtent().norm();
                const float speed = body.mLinearVelocity.norm() + radius * body.mAngularVelocity.norm();
                const bool slow =
                    settings.mAllowSleeping && body.mAllowSleeping && speed < settings.mSleepVelocity;
                body.mSleepTimer = slow ? body.mSleepTimer + deltaTime : 0.0f;
            }
            // Any thread may move bodies in the broad phase (each body here is in one range only)
            const uint64_t waited = GetThisThreadLockWaitNanoseconds();
            inContext.mBroadPhase.NotifyBodiesAABBChanged(
                std::span<const BroadPhaseBody>(mMovedBodies.data() + inBegin, inEnd - inBegin));
            // The broad phase holds the new bounds: this collision step's positions are final. The
            // grown boxes go to the front of the range, shrunk to the swept bounds, so that the next
            // step's pairs are those of the swept bounds alone
            uint32_t grown = inBegin;
            for (uint32_t i = inBegin; i < inEnd; ++i)
            {
                if (mPublishOrders[i] == PublishOrder::BeforeMove) continue;
                const Body& body = inContext.BodyAt(active[i]);
                PublishedPoseStore::StepMemory& memory = poses.GetStepMemory(active[i]);
                memory.mVersion = poses.PublishMotion(body);
                if (mPublishOrders[i] == PublishOrder::AfterGrownMove)
                    mMovedBodies[grown++] = {body.GetID(), sweptBounds(body.mBounds, memory.mSweep),
                                             body.GetObjectLayer()};
            }
            if (anyGrown)
                inContext.mBroadPhase.NotifyBodiesAABBChanged(
                    std::span<const BroadPhaseBody>(mMovedBodies.data() + inBegin, grown - inBegin));
            inContext.mLockWaitNanoseconds.fetch_add(GetThisThreadLockWaitNanoseconds() - waited,
                                                     std::memory_order_relaxed); // See StepContext
        });
}

} // namespace cairn::physics
