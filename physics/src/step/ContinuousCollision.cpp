#include "step/ContinuousCollision.h"

#include "body/Integration.h"
#include "cairn/physics/narrowphase/CollideShapes.h"
#include "step/StepContext.h"

#include <algorithm>
#include <limits>
#include <optional>

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

/// The fraction of inDisplacement at which shape A, translated from inStart, first sinks into body inOther
/// (at its pose) by inAllowed, to within inTolerance, approaching it; none if it does not within the
/// displacement.
std::optional<float> TimeOfImpact(const Shape& inShape, const Transform& inStart, const Vec3& inDisplacement,
                                  const Body& inOther, float inAllowed, float inTolerance)
{
    const float length = inDisplacement.norm();
    const Transform otherTransform = inOther.GetTransform();
    float t = 0.0f;
    for (int iteration = 0; iteration < cMaxIterations; ++iteration)
    {
        Transform at = inStart;
        at.mPosition += t * inDisplacement;
        CollideSettings settings;
        settings.mMaxSeparation = std::max((1.0f - t) * length + inTolerance - inAllowed, 0.0f);
        // Each manifold is a separating plane (its normal, from A to B) with the points' gaps along it: the
        // body can advance by gap / (displacement . normal) before that plane stops separating. The smallest
        // advance over the approaching manifolds is safe against all of them
        std::optional<float> advance;
        bool touching = false;
        CollideShapes(inShape, at, *inOther.GetShape(), otherTransform, settings,
                      [&](const ContactManifold& inManifold)
                      {
                          const float approach = inDisplacement.dot(inManifold.mNormal);
                          if (!(approach > 1.0e-6f * length)) return; // Parallel or moving away
                          // The gap to the allowed depth
                          float gap = std::numeric_limits<float>::max();
                          for (int i = 0; i < inManifold.mNumPoints; ++i)
                              gap = std::min(gap, inAllowed - inManifold.mPoints[i].mPenetration);
                          touching |= gap <= inTolerance;
                          // Aim for half the tolerance: the next gap is then within it, never below zero
                          const float step = (gap - 0.5f * inTolerance) / approach;
                          advance = advance.has_value() ? std::min(*advance, step) : step;
                      });
        if (touching) return t;
        if (!advance.has_value()) return std::nullopt; // Nothing it approaches within reach
        t += std::max(*advance, 0.0f);
        if (t >= 1.0f) return std::nullopt;
    }
    return t;
}
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
    const float tolerance = 0.25f * inContext.mSettings.mSpeculativeDistance;
    const float allowed = cAllowedPenetration * smallestHalfExtent;
    float earliest = 1.0f;
    BroadPhaseQueryFilter filter;
    filter.mObjectLayers = inContext.mLayers.GetCollisionMask(ioBody.GetObjectLayer());
    // Candidates in no particular order: the earliest time of impact is their minimum whatever the order
    inContext.mBroadPhase.CastAABox(shape.GetWorldBounds(start), displacement, filter,
                                    [&](BodyID inID, float inEntry) -> float
                                    {
                                        if (inID == ioBody.GetID() || inEntry >= earliest) return earliest;
                                        const Body* other = inContext.mBodies.TryGetBody(inID);
                                        if (other == nullptr || !other->IsInWorld() || other->IsSensor() ||
                                            !inContext.mBodies.BodiesCollide(ioBody, *other))
                                            return earliest;
                                        if (const std::optional<float> impact = TimeOfImpact(
                                                shape, start, displacement, *other, allowed, tolerance))
                                            earliest = std::min(earliest, *impact);
                                        return earliest;
                                    });
    if (earliest >= 1.0f) return false;
    Integration::CorrectPose(ioBody, -(1.0f - earliest) * displacement, Vec3::Zero());
    return true;
}

} // namespace cairn::physics
