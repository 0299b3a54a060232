#include "step/ContinuousCollision.h"

#include "body/Integration.h"
#include "narrowphase/ShapeCast.h"
#include "step/StepContext.h"

#include <algorithm>

namespace cairn::physics
{

namespace
{
/// A body moving less than this share of its smallest half extent in a step cannot pass through anything
/// that its speculative contacts did not stop.
constexpr float cCastThreshold = 0.5f;
/// A cast lets the body sink this share of its smallest half extent into what it meets before it stops it:
/// the discrete contacts resolve that much from the right side, and a body resting or rolling on a surface
/// (a hair of penetration, a hair of approach) is not pinned where it started the step.
constexpr float cAllowedPenetration = 0.25f;
/// Conservative advancement stops this many iterations in, where it is (short of the surface, never past it).
constexpr int cMaxIterations = 32;
} // namespace

void ContinuousCollision::Count(const StepContext& inContext, std::span<const uint32_t> inBodies)
{
    uint32_t count = 0;
    for (uint32_t index : inBodies)
        count += inContext.BodyAt(index).GetMotionQuality() == MotionQuality::LinearCast;
    if (count != 0) mNumLinearCast.fetch_add(count, std::memory_order_relaxed); // See mNumLinearCast
}

uint32_t ContinuousCollision::Run(const StepContext& inContext)
{
    if (mNumLinearCast.load(std::memory_order_relaxed) == 0) return 0; // See mNumLinearCast
    uint32_t movedBack = 0;
    for (uint32_t index : inContext.mActive)
    {
        Body& body = inContext.BodyAt(index);
        if (body.GetMotionQuality() == MotionQuality::LinearCast && body.IsDynamic())
            movedBack += Cast(inContext, body) ? 1 : 0;
    }
    return movedBack;
}

bool ContinuousCollision::Cast(const StepContext& inContext, Body& ioBody) const
{
    const Vec3 displacement = inContext.mDeltaTime * ioBody.GetLinearVelocity();
    const Shape& shape = *ioBody.GetShape();
    const float smallestHalfExtent = shape.GetLocalBounds().HalfExtent().minCoeff();
    const float threshold = cCastThreshold * smallestHalfExtent;
    if (!(displacement.squaredNorm() > threshold * threshold)) return false;
    Transform start = ioBody.GetTransform();
    start.mPosition -= displacement;
    ShapeCastSettings cast;
    cast.mTolerance = 0.25f * inContext.mSettings.mSpeculativeDistance;
    cast.mAllowedPenetration = cAllowedPenetration * smallestHalfExtent;
    cast.mMaxIterations = cMaxIterations;
    float earliest = 1.0f;
    BroadPhaseQueryFilter filter;
    filter.mObjectLayers = inContext.mLayers.GetCollisionMask(ioBody.GetObjectLayer());
    // Candidates in no particular order: the earliest time of impact is their minimum whatever the order
    inContext.mBroadPhase.CastAABox(
        shape.GetWorldBounds(start), displacement, filter,
        [&](BodyID inID, float inEntry) -> float
        {
            if (inID == ioBody.GetID() || inEntry >= earliest) return earliest;
            const Body* other = inContext.mBodies.TryGetBody(inID);
            if (other == nullptr || !other->IsInWorld() || other->IsSensor() ||
                !inContext.mBodies.BodiesCollide(ioBody, *other))
                return earliest;
            if (const std::optional<ShapeCastHit> impact = CastShapeAgainst(
                    shape, start, displacement, *other->GetShape(), other->GetTransform(), cast))
                earliest = std::min(earliest, impact->mFraction);
            return earliest;
        });
    if (earliest >= 1.0f) return false;
    Integration::CorrectPose(ioBody, -(1.0f - earliest) * displacement, Vec3::Zero());
    return true;
}

} // namespace cairn::physics
