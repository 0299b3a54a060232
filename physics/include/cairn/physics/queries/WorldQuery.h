#pragma once

// WorldQuery: ray casts, shape casts and shape / box / sphere / point overlap queries against the world, from
// any thread.
// Each query first asks the broad phase (lock-free) for candidates, collected in a thread-local buffer, then
// tests each candidate's shape at its published pose (PublishedPose.h), read with no lock: a query never
// waits for the physics step, also while the step runs. It sees every body as the last collision step (or
// the last move by hand) published it: a pose is never torn, a body removed meanwhile is reported with its
// last pose or not at all, a stale id never, and a body whose published pose overlaps the query is never
// missed (the broad phase's bounds contain the published pose's).
// QueryReads::BodyLocks is the reference engine's "before", for measuring: each candidate is read under its
// body's read lock, so a query waits for a step that holds it; from inside the step or from a thread that
// holds a body lock such a query is refused (WrongThread).
// Errors: a query refuses bad input (a NaN or out-of-world origin or centre, a direction or radius that is
// not finite, a rotation that is not a unit quaternion) with InvalidArgument, instead of returning "nothing
// there": a caller must be able to tell a clear line of sight from a failed query.
// Shape casts sweep a shape without turning it (as a character or a thrown object probes its way). They
// report where it first touches each body: never past the touch, and short of it by at most the cast's
// tolerance (about 0.1 mm near the origin) along the surface normal. A body the shape already overlaps at the
// start is a hit at fraction 0 when the sweep moves deeper into it, and no hit when the sweep leaves it or
// slides along it, so a character standing on the floor can probe sideways. A zero displacement reports what
// the shape touches, at fraction 0. Against a mesh or height field the normal at a seam between two triangles
// is the seam's; the step's contacts take the face's there (CollideSettings::mFaceNormalsAtInternalEdges).

#include "cairn/physics/PhysicsSettings.h"
#include "cairn/physics/body/BodyManager.h"
#include "cairn/physics/body/PublishedPose.h"
#include "cairn/physics/broadphase/BroadPhase.h"
#include "cairn/physics/math/Result.h"
#include "cairn/physics/narrowphase/ContactManifold.h"

#include <optional>
#include <vector>

namespace cairn::physics
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

/// Where a swept shape first touches a body.
struct ShapeCastResult
{
    BodyID mBody;
    float mFraction = 1.0f;            ///< Along the displacement, in [0, 1)
    Vec3 mContactPoint = Vec3::Zero(); ///< World space, on the body's surface, where the shape touches it
    Vec3 mNormal = Vec3::Zero(); ///< World space unit surface normal of the body there, towards the shape
    /// How deep the shape is in the body at that fraction: about 0 at a touch (within the tolerance), more
    /// where it started overlapping the body
    float mPenetration = 0.0f;
    SubShapeID mSubShape = 0; ///< The body's part that it touches
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
    WorldQuery(const BodyManager& inBodies, const BroadPhase& inBroadPhase,
               QueryReads inReads = QueryReads::PublishedPoses);

    /// The closest hit along the segment, or nullopt when there is none.
    Result<std::optional<RayCastResult>> CastRayClosest(const RayCast& inRay,
                                                        const QueryFilter& inFilter = {}) const;
    /// True as soon as any body is hit (cheapest: stops at the first).
    Result<bool> CastRayAny(const RayCast& inRay, const QueryFilter& inFilter = {}) const;
    /// Every body hit (its closest hit each), sorted by fraction; outHits is cleared first.
    Status CastRayAll(const RayCast& inRay, std::vector<RayCastResult>& outHits,
                      const QueryFilter& inFilter = {}) const;

    /// The first body that inShape (convex, or a compound of convex shapes) touches when swept from inStart
    /// along inDisplacement (at most cMaxRayLength), or nullopt when there is none.
    Result<std::optional<ShapeCastResult>> CastShapeClosest(const Shape& inShape, const Transform& inStart,
                                                            const Vec3& inDisplacement,
                                                            const QueryFilter& inFilter = {}) const;
    /// Every body it touches (where it first touches each), sorted by fraction; outHits is cleared first.
    Status CastShapeAll(const Shape& inShape, const Transform& inStart, const Vec3& inDisplacement,
                        std::vector<ShapeCastResult>& outHits, const QueryFilter& inFilter = {}) const;

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
    /// A candidate as a query tests it.
    struct BodyView
    {
        const Shape* mShape = nullptr; ///< Kept alive by the query's PoseReader, or by mHold
        ShapeRef mHold;                ///< QueryReads::BodyLocks: the reference copied under the lock
        Transform mTransform;
    };
    /// A candidate's shape and transform, as mReads says; false for a stale id or a body not in the world.
    bool ReadBody(const PoseReader& inPoses, const BodyID& inID, BodyView& outBody) const;
    /// Runs the ray against candidate bodies; inAny stops at the first hit.
    Status CastRay(const RayCast& inRay, const QueryFilter& inFilter, bool inAny,
                   std::vector<RayCastResult>& outHits, bool inClosestOnly) const;
    /// Sweeps the shape against candidate bodies; inClosestOnly keeps the first hit only.
    Status CastShape(const Shape& inShape, const Transform& inStart, const Vec3& inDisplacement,
                     const QueryFilter& inFilter, std::vector<ShapeCastResult>& outHits,
                     bool inClosestOnly) const;

    const BodyManager& mBodies;
    const BroadPhase& mBroadPhase;
    QueryReads mReads;
};

} // namespace cairn::physics
