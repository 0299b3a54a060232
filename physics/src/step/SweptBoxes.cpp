#include "step/SweptBoxes.h"

#include "body/PublishedPoseStore.h"
#include "cairn/physics/LockWaits.h"
#include "step/StepContext.h"

#include <vector>

namespace cairn::physics
{

AABB SweptBoxes::Of(const AABB& inBounds, const Vec3& inSweep, float inSpeculativeDistance)
{
    AABB swept = inBounds;
    swept.Encapsulate(AABB(inBounds.mMin + inSweep, inBounds.mMax + inSweep));
    return swept.Expanded(inSpeculativeDistance);
}

void SweptBoxes::CoverThisStep(const StepContext& inContext, std::span<const uint32_t> inBodies)
{
    const float deltaTime = inContext.mDeltaTime;
    const float speculative = inContext.mSettings.mSpeculativeDistance;
    PublishedPoseStore& poses = inContext.mPoses;
    thread_local std::vector<BroadPhaseBody> uncovered;
    uncovered.clear();
    for (uint32_t index : inBodies)
    {
        Body& body = inContext.BodyAt(index);
        const Vec3 sweep = deltaTime * body.GetLinearVelocity();
        PublishedPoseStore::StepMemory& memory = poses.GetStepMemory(index);
        const uint32_t version = poses.GetVersion(index);
        if (version == memory.mVersion)
        {
            // Boxed by the last finish, from the bounds the body still has: the box covers this step's motion
            // when the sweep grew by no more than the speculative distance it was given, on each side
            // (gravity alone grows it by g dt^2, millimetres)
            const Vec3 held = memory.mSweep;
            if ((sweep.cwiseMax(0.0f).array() <= held.cwiseMax(0.0f).array() + speculative).all() &&
                (sweep.cwiseMin(0.0f).array() >= held.cwiseMin(0.0f).array() - speculative).all())
                continue;
        }
        else if (sweep == Vec3::Zero())
            continue; // Boxed by whoever published it, at least its bounds: all a body at rest needs
        // The body's pose is the published one (no hand moves during the step), inside both the old box and
        // this one: replacing the box keeps it findable at every moment
        uncovered.push_back(
            {body.GetID(), Of(body.GetWorldBounds(), sweep, speculative), body.GetObjectLayer()});
        memory.mVersion = version;
        memory.mSweep = sweep;
    }
    if (uncovered.empty()) return;
    const uint64_t waited = GetThisThreadLockWaitNanoseconds();
    inContext.mBroadPhase.NotifyBodiesAABBChanged(uncovered);
    inContext.mLockWaitNanoseconds.fetch_add(GetThisThreadLockWaitNanoseconds() - waited,
                                             std::memory_order_relaxed); // See StepContext
}

} // namespace cairn::physics
