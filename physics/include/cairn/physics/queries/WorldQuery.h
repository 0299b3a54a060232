#pragma once

// WorldQuery: ray casts and shape / box / sphere / point overlap queries against the world, from any thread
// outside step callbacks. Each query first asks the broad phase (under its own shared lock) for candidates,
// collected in a thread-local buffer; then, with the broad-phase lock released, it reads each candidate's
// shape and transform under that body's read lock, releases it, and runs the exact test on the copy (shapes
// are immutable, and the ShapeRef keeps the shape alive). So a query never holds two locks at once, and it
// waits for a body only while the physics step is writing it.

#include "cairn/physics/body/BodyManager.h"
#include "cairn/physics/broadphase/BroadPhase.h"
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

    /// The closest hit along the segment, if any.
    std::optional<RayCastResult> CastRayClosest(const RayCast& inRay, const QueryFilter& inFilter = {}) const;
    /// True as soon as any body is hit (cheapest: stops at the first).
    bool CastRayAny(const RayCast& inRay, const QueryFilter& inFilter = {}) const;
    /// Every body hit (its closest hit each), sorted by fraction; outHits is cleared first.
    void CastRayAll(const RayCast& inRay, std::vector<RayCastResult>& outHits,
                    const QueryFilter& inFilter = {}) const;

    /// Bodies whose shape overlaps inShape at inTransform (penetration >= -inMaxSeparation); outHits is
    /// cleared.
    void CollideShape(const Shape& inShape, const Transform& inTransform, std::vector<ShapeQueryHit>& outHits,
                      const QueryFilter& inFilter = {}, float inMaxSeparation = 0.0f) const;
    /// Bodies whose shape overlaps the box (exact test); outBodies is cleared.
    void CollideAABox(const AABB& inBox, std::vector<BodyID>& outBodies,
                      const QueryFilter& inFilter = {}) const;
    /// Bodies whose shape overlaps the sphere (exact test); outBodies is cleared.
    void CollideSphere(const Vec3& inCenter, float inRadius, std::vector<BodyID>& outBodies,
                       const QueryFilter& inFilter = {}) const;
    /// Bodies whose solid shape contains the point (meshes and height fields have no inside); outBodies is
    /// cleared.
    void CollidePoint(const Vec3& inPoint, std::vector<BodyID>& outBodies,
                      const QueryFilter& inFilter = {}) const;

private:
    /// Shape and transform of a body, read under its read lock; false for a stale id or a removed body.
    bool ReadBody(const BodyID& inID, ShapeRef& outShape, Transform& outTransform) const;
    /// Runs the ray against candidate bodies; inAny stops at the first hit.
    void CastRay(const RayCast& inRay, const QueryFilter& inFilter, bool inAny,
                 std::vector<RayCastResult>& outHits, bool inClosestOnly) const;

    const BodyManager& mBodies;
    const BroadPhase& mBroadPhase;
};

} // namespace cairn
