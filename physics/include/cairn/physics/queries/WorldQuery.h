#pragma once

// WorldQuery: ray casts and shape / box / sphere / point overlap queries against the world, from any thread
// outside step callbacks. Each query first asks the broad phase (under its own shared lock) for candidates,
// collected in a thread-local buffer; then, with the broad-phase lock released, it reads each candidate's
// shape and transform under that body's read lock, releases it, and runs the exact test on the copy (shapes
// are immutable, and the ShapeRef keeps the shape alive). So a query never holds two locks at once, and it
// waits for a body only while the physics step is writing it.
// Errors: a query refuses bad input (a NaN or out-of-world origin or centre, a direction or radius that is
// not finite, a rotation that is not a unit quaternion) with InvalidArgument, and a call from inside the step
// or from a thread that holds a body lock (it could not read the bodies) with WrongThread, instead of
// returning "nothing there": a caller must be able to tell a clear line of sight from a failed query.

#include "cairn/physics/body/BodyManager.h"
#include "cairn/physics/broadphase/BroadPhase.h"
#include "cairn/physics/math/Result.h"
#include "cairn/physics/narrowphase/ContactManifold.h"

#include <optional>
#include <vector>

namespace cairn
{

struct QueryFilter
{
    ObjectLayerMask mObjectLayers = cAllObjectLayers; ///< Only bodies in these object layers
    BodyID mIgnoreBody;                               ///< Skipped when valid (e.g. the querying character)
};

struct RayCastResult
{
    BodyID mBody;
    float mFraction = 1.0f;      ///< Along the ray's displacement, in [0, 1]
    Vec3 mNormal = Vec3::Zero(); ///< World space surface normal
    SubShapeID mSubShape = 0;
};

/// A body that a shape query touches, with the contact (normal from the query shape towards the body).
struct ShapeQueryHit
{
    BodyID mBody;
    ContactManifold mManifold;
};

class WorldQuery
{
public:
    WorldQuery(const BodyManager& inBodies, const BroadPhase& inBroadPhase);

    /// The closest hit along the segment, or nullopt when there is none.
    Result<std::optional<RayCastResult>> CastRayClosest(const RayCast& inRay,
                                                        const QueryFilter& inFilter = {}) const;
    /// True as soon as any body is hit (cheapest: stops at the first).
    Result<bool> CastRayAny(const RayCast& inRay, const QueryFilter& inFilter = {}) const;
    /// Every body hit (its closest hit each), sorted by fraction; outHits is cleared first.
    Status CastRayAll(const RayCast& inRay, std::vector<RayCastResult>& outHits,
                      const QueryFilter& inFilter = {}) const;

    /// Bodies whose shape overlaps inShape at inTransform (penetration >= -inMaxSeparation, which must be
    /// finite; negative counts as 0); outHits is cleared.
    Status CollideShape(const Shape& inShape, const Transform& inTransform,
                        std::vector<ShapeQueryHit>& outHits, const QueryFilter& inFilter = {},
                        float inMaxSeparation = 0.0f) const;
    /// Bodies whose shape overlaps the box (exact test; a flat box is a very thin one); outBodies is cleared.
    Status CollideAABox(const AABB& inBox, std::vector<BodyID>& outBodies,
                        const QueryFilter& inFilter = {}) const;
    /// Bodies whose shape overlaps the sphere (exact test, radius > 0); outBodies is cleared.
    Status CollideSphere(const Vec3& inCenter, float inRadius, std::vector<BodyID>& outBodies,
                         const QueryFilter& inFilter = {}) const;
    /// Bodies whose solid shape contains the point (meshes and height fields have no inside); outBodies is
    /// cleared.
    Status CollidePoint(const Vec3& inPoint, std::vector<BodyID>& outBodies,
                        const QueryFilter& inFilter = {}) const;

private:
    /// Shape and transform of a body, read under its read lock; false for a stale id or a removed body.
    bool ReadBody(const BodyID& inID, ShapeRef& outShape, Transform& outTransform) const;
    /// Runs the ray against candidate bodies; inAny stops at the first hit.
    Status CastRay(const RayCast& inRay, const QueryFilter& inFilter, bool inAny,
                   std::vector<RayCastResult>& outHits, bool inClosestOnly) const;

    const BodyManager& mBodies;
    const BroadPhase& mBroadPhase;
};

} // namespace cairn
