#include "cairn/physics/queries/WorldQuery.h"

#include "cairn/physics/body/BodyLock.h"
#include "cairn/physics/narrowphase/CollideShapes.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/SphereShape.h"
#include "narrowphase/ShapeCast.h"
#include "queries/QueryShape.h"

#include <algorithm>
#include <string>

namespace cairn::physics
{

namespace
{
struct Candidate
{
    BodyID mBody;
    float mEntry;
};

// Per-thread scratch so queries allocate nothing once warm; a query never re-enters another on the same
// thread
thread_local std::vector<Candidate> tCandidates;
thread_local std::vector<BodyID> tBodies;

BroadPhaseQueryFilter ToBroadPhase(const QueryFilter& inFilter)
{
    return {inFilter.mObjectLayers};
}

/// The bodies a cast enters (inCast runs the broad-phase cast with the visitor it is given), the filter's
/// ignored body left out, nearest entry first: a closest search stops once entries pass its best hit.
const std::vector<Candidate>& CastCandidates(const QueryFilter& inFilter,
                                             FunctionRef<void(RayBodyVisitor)> inCast)
{
    std::vector<Candidate>& candidates = tCandidates;
    candidates.clear();
    inCast(
        [&](BodyID inBody, float inFraction)
        {
            if (inBody != inFilter.mIgnoreBody) candidates.push_back({inBody, inFraction});
            return 1.0f;
        });
    std::sort(candidates.begin(), candidates.end(),
              [](const Candidate& inA, const Candidate& inB)
              { return inA.mEntry < inB.mEntry || (inA.mEntry == inB.mEntry && inA.mBody < inB.mBody); });
    return candidates;
}

/// Cast results by fraction, then by body: the same order whatever order the broad phase found them in.
template <class CastResult> void SortByFraction(std::vector<CastResult>& ioHits)
{
    std::sort(ioHits.begin(), ioHits.end(),
              [](const CastResult& inA, const CastResult& inB) {
                  return inA.mFraction < inB.mFraction ||
                         (inA.mFraction == inB.mFraction && inA.mBody < inB.mBody);
              });
}

/// WrongThread when this thread may not read bodies under their locks now, else Ok. Published poses need no
/// lock: any thread may read them.
Status CheckThread(bool inReadsBodyLocks)
{
    if (!inReadsBodyLocks) return Status::Ok();
    if (BodyManager::IsInsideStep())
        return MakeError(ErrorCode::WrongThread, "world query called from inside the physics step");
    if (BodyManager::GetBodyLocksHeldByThisThread() > 0)
        return MakeError(
            ErrorCode::WrongThread,
            "world query called while this thread holds a body lock (it could not read the bodies)");
    return Status::Ok();
}

Status InvalidQuery(const char* inWhat)
{
    return MakeError(ErrorCode::InvalidArgument, std::string("world query: ") + inWhat);
}

/// InvalidArgument unless the shape and its transform make a query shape; else Ok, with its world bounds.
Status CheckQueryShape(const Shape& inShape, const Transform& inTransform, AABB& outBounds)
{
    if (!IsValidWorldPosition(inTransform.mPosition))
        return InvalidQuery("shape position is NaN, infinite or beyond the world");
    if (!IsValidRotation(inTransform.mRotation))
        return InvalidQuery("shape rotation is not a finite unit quaternion");
    if (!CanBeQueryShape(inShape))
        return InvalidQuery(
            "a query shape must be convex or a compound of convex shapes, not a triangle mesh or "
            "height field");
    // A shape built around its checked Create (a NaN radius, an inverted box) has bounds the broad phase
    // drops: the query would answer "nothing there"
    outBounds = inShape.GetWorldBounds(inTransform);
    if (!outBounds.IsFinite() || outBounds.IsEmpty())
        return InvalidQuery("query shape's bounds are NaN, infinite or empty");
    return Status::Ok();
}

/// Keeps query boxes usable as shapes: a flat or inverted box becomes a very thin one.
Vec3 QueryHalfExtent(const AABB& inBox)
{
    return inBox.HalfExtent().cwiseMax(Vec3::Constant(1.0e-5f));
}
} // namespace

WorldQuery::WorldQuery(const BodyManager& inBodies, const BroadPhase& inBroadPhase, QueryReads inReads)
    : mBodies(inBodies), mBroadPhase(inBroadPhase), mReads(inReads)
{
}

bool WorldQuery::ReadBody(const PoseReader& inPoses, const BodyID& inID, BodyView& outBody) const
{
    if (mReads == QueryReads::PublishedPoses)
    {
        PublishedPose pose;
        if (!inPoses.Read(inID, pose)) return false;
        outBody.mShape = pose.mShape; // Alive while inPoses is
        outBody.mTransform = pose.mTransform;
        return true;
    }
    BodyLockRead lock(mBodies, inID);
    const Body* body = lock.GetBody();
    if (body == nullptr || !body->IsInWorld()) return false;
    outBody.mHold = body->GetShape();
    outBody.mShape = outBody.mHold.get();
    outBody.mTransform = body->GetTransform();
    return true;
}

Status WorldQuery::CastRay(const RayCast& inRay, const QueryFilter& inFilter, bool inAny,
                           std::vector<RayCastResult>& outHits, bool inClosestOnly) const
{
    outHits.clear();
    if (Status thread = CheckThread(mReads == QueryReads::BodyLocks); !thread) return thread;
    if (!IsValidWorldPosition(inRay.mOrigin))
        return InvalidQuery("ray origin is NaN, infinite or beyond the world");
    if (!(inRay.mDirection.norm() <= cMaxRayLength))
        return InvalidQuery("ray direction is NaN, infinite or longer than cMaxRayLength (4e6 m)");
    // One read section for the whole query: the shapes it reads stay alive until it returns
    const PoseReader poses(mBodies);
    const std::vector<Candidate>& candidates =
        CastCandidates(inFilter, [&](RayBodyVisitor inVisitor)
                       { mBroadPhase.CastRay(inRay, ToBroadPhase(inFilter), inVisitor); });
    float best = 1.0f;
    for (const Candidate& candidate : candidates)
    {
        if (inClosestOnly && candidate.mEntry > best) break;
        BodyView body;
        if (!ReadBody(poses, candidate.mBody, body)) continue;
        const RayCast local{body.mTransform.InverseTransformPoint(inRay.mOrigin),
                            body.mTransform.InverseRotateVector(inRay.mDirection)};
        RayHit hit;
        hit.mFraction = inClosestOnly ? std::nextafter(best, 2.0f) : 1.0f + 1.0e-6f;
        if (!body.mShape->CastRay(local, hit)) continue;
        const RayCastResult result{candidate.mBody, std::min(hit.mFraction, 1.0f),
                                   body.mTransform.RotateVector(hit.mNormal), hit.mSubShape};
        if (inClosestOnly)
        {
            outHits.assign(1, result);
            best = result.mFraction;
        }
        else
            outHits.push_back(result);
        if (inAny) return Status::Ok();
    }
    SortByFraction(outHits);
    return Status::Ok();
}

Result<std::optional<RayCastResult>> WorldQuery::CastRayClosest(const RayCast& inRay,
                                                                const QueryFilter& inFilter) const
{
    thread_local std::vector<RayCastResult> hits;
    if (Status status = CastRay(inRay, inFilter, false, hits, true); !status) return status.GetError();
    if (hits.empty()) return std::optional<RayCastResult>();
    return std::optional<RayCastResult>(hits.front());
}

Result<bool> WorldQuery::CastRayAny(const RayCast& inRay, const QueryFilter& inFilter) const
{
    thread_local std::vector<RayCastResult> hits;
    if (Status status = CastRay(inRay, inFilter, true, hits, false); !status) return status.GetError();
    return !hits.empty();
}

Status WorldQuery::CastRayAll(const RayCast& inRay, std::vector<RayCastResult>& outHits,
                              const QueryFilter& inFilter) const
{
    return CastRay(inRay, inFilter, false, outHits, false);
}

Status WorldQuery::CastShape(const Shape& inShape, const Transform& inStart, const Vec3& inDisplacement,
                             const QueryFilter& inFilter, std::vector<ShapeCastResult>& outHits,
                             bool inClosestOnly) const
{
    outHits.clear();
    if (Status thread = CheckThread(mReads == QueryReads::BodyLocks); !thread) return thread;
    AABB shapeBounds;
    if (Status shape = CheckQueryShape(inShape, inStart, shapeBounds); !shape) return shape;
    if (!(inDisplacement.norm() <= cMaxRayLength))
        return InvalidQuery("cast displacement is NaN, infinite or longer than cMaxRayLength (4e6 m)");
    ShapeCastSettings settings;
    settings.mTolerance = QueryCastTolerance(inStart.mPosition);
    const PoseReader poses(mBodies); // See CastRay
    // Grown by the tolerance: a body the shape stops short of by less is still a touch
    const AABB swept = shapeBounds.Expanded(settings.mTolerance);
    const std::vector<Candidate>& candidates =
        CastCandidates(inFilter, [&](RayBodyVisitor inVisitor)
                       { mBroadPhase.CastAABox(swept, inDisplacement, ToBroadPhase(inFilter), inVisitor); });
    for (const Candidate& candidate : candidates)
    {
        if (inClosestOnly && !outHits.empty())
        {
            if (candidate.mEntry > outHits.front().mFraction) break;
            // A later body wins only by touching first; a best hit at 0 cannot be beaten
            if (outHits.front().mFraction == 0.0f) break;
            settings.mMaxFraction = outHits.front().mFraction;
        }
        BodyView body;
        if (!ReadBody(poses, candidate.mBody, body)) continue;
        const std::optional<ShapeCastHit> hit =
            CastShapeAgainst(inShape, inStart, inDisplacement, *body.mShape, body.mTransform, settings);
        if (!hit.has_value()) continue;
        const ContactPoint& point = hit->mManifold.mPoints[hit->mDeepestPoint];
        const ShapeCastResult result{candidate.mBody,         hit->mFraction,     point.mPositionOnB,
                                     -hit->mManifold.mNormal, point.mPenetration, hit->mManifold.mSubShapeB};
        if (inClosestOnly)
            outHits.assign(1, result);
        else
            outHits.push_back(result);
    }
    SortByFraction(outHits);
    return Status::Ok();
}

Result<std::optional<ShapeCastResult>> WorldQuery::CastShapeClosest(const Shape& inShape,
                                                                    const Transform& inStart,
                                                                    const Vec3& inDisplacement,
                                                                    const QueryFilter& inFilter) const
{
    thread_local std::vector<ShapeCastResult> hits;
    if (Status status = CastShape(inShape, inStart, inDisplacement, inFilter, hits, true); !status)
        return status.GetError();
    if (hits.empty()) return std::optional<ShapeCastResult>();
    return std::optional<ShapeCastResult>(hits.front());
}

Status WorldQuery::CastShapeAll(const Shape& inShape, const Transform& inStart, const Vec3& inDisplacement,
                                std::vector<ShapeCastResult>& outHits, const QueryFilter& inFilter) const
{
    return CastShape(inShape, inStart, inDisplacement, inFilter, outHits, false);
}

Status WorldQuery::CollideShape(const Shape& inShape, const Transform& inTransform,
                                std::vector<ShapeQueryHit>& outHits, const QueryFilter& inFilter,
                                float inMaxSeparation) const
{
    outHits.clear();
    if (Status thread = CheckThread(mReads == QueryReads::BodyLocks); !thread) return thread;
    AABB shapeBounds;
    if (Status shape = CheckQueryShape(inShape, inTransform, shapeBounds); !shape) return shape;
    if (!std::isfinite(inMaxSeparation)) return InvalidQuery("maximum separation is NaN or infinite");
    const PoseReader poses(mBodies); // See CastRay
    std::vector<BodyID>& bodies = tBodies;
    bodies.clear();
    const AABB bounds = shapeBounds.Expanded(std::max(inMaxSeparation, 0.0f));
    mBroadPhase.CollideAABox(bounds, ToBroadPhase(inFilter),
                             [&](BodyID inBody)
                             {
                                 if (inBody != inFilter.mIgnoreBody) bodies.push_back(inBody);
                             });
    std::sort(bodies.begin(), bodies.end());
    CollideSettings settings;
    settings.mMaxSeparation = std::max(inMaxSeparation, 0.0f);
    for (const BodyID& id : bodies)
    {
        BodyView body;
        if (!ReadBody(poses, id, body)) continue;
        // Keep only the deepest manifold per body: callers ask "which bodies, and how"
        ShapeQueryHit hit{id, {}};
        float deepest = -cLargeFloat;
        CollideShapes(inShape, inTransform, *body.mShape, body.mTransform, settings,
                      [&](const ContactManifold& inManifold)
                      {
                          for (int i = 0; i < inManifold.mNumPoints; ++i)
                              if (inManifold.mPoints[i].mPenetration > deepest)
                              {
                                  deepest = inManifold.mPoints[i].mPenetration;
                                  hit.mManifold = inManifold;
                              }
                      });
        if (deepest >= -settings.mMaxSeparation) outHits.push_back(hit);
    }
    return Status::Ok();
}

Status WorldQuery::CollideAABox(const AABB& inBox, std::vector<BodyID>& outBodies,
                                const QueryFilter& inFilter) const
{
    outBodies.clear();
    if (!IsValidWorldPosition(inBox.mMin) || !IsValidWorldPosition(inBox.mMax))
        return InvalidQuery("box corner is NaN, infinite or beyond the world");
    if (inBox.IsEmpty()) return InvalidQuery("box min is above its max");
    const BoxShape box(QueryHalfExtent(inBox));
    thread_local std::vector<ShapeQueryHit> hits;
    if (Status status = CollideShape(box, {inBox.Center(), Quat::Identity()}, hits, inFilter); !status)
        return status;
    for (const ShapeQueryHit& hit : hits)
        outBodies.push_back(hit.mBody);
    return Status::Ok();
}

Status WorldQuery::CollideSphere(const Vec3& inCenter, float inRadius, std::vector<BodyID>& outBodies,
                                 const QueryFilter& inFilter) const
{
    outBodies.clear();
    if (!IsValidWorldPosition(inCenter))
        return InvalidQuery("sphere centre is NaN, infinite or beyond the world");
    if (!(inRadius > 0.0f && inRadius <= cMaxWorldCoordinate))
        return InvalidQuery("sphere radius must be in (0, 1e6] m");
    const SphereShape sphere(inRadius);
    thread_local std::vector<ShapeQueryHit> hits;
    if (Status status = CollideShape(sphere, {inCenter, Quat::Identity()}, hits, inFilter); !status)
        return status;
    for (const ShapeQueryHit& hit : hits)
        outBodies.push_back(hit.mBody);
    return Status::Ok();
}

Status WorldQuery::CollidePoint(const Vec3& inPoint, std::vector<BodyID>& outBodies,
                                const QueryFilter& inFilter) const
{
    outBodies.clear();
    if (Status thread = CheckThread(mReads == QueryReads::BodyLocks); !thread) return thread;
    if (!IsValidWorldPosition(inPoint)) return InvalidQuery("point is NaN, infinite or beyond the world");
    const PoseReader poses(mBodies); // See CastRay
    std::vector<BodyID>& bodies = tBodies;
    bodies.clear();
    mBroadPhase.CollidePoint(inPoint, {inFilter.mObjectLayers},
                             [&](BodyID inBody)
                             {
                                 if (inBody != inFilter.mIgnoreBody) bodies.push_back(inBody);
                             });
    std::sort(bodies.begin(), bodies.end());
    for (const BodyID& id : bodies)
    {
        BodyView body;
        if (!ReadBody(poses, id, body)) continue;
        // A zero-length ray hits a solid shape exactly when it starts inside
        RayHit hit;
        hit.mFraction = 1.0f;
        if (body.mShape->CastRay({body.mTransform.InverseTransformPoint(inPoint), Vec3::Zero()}, hit))
            outBodies.push_back(id);
    }
    return Status::Ok();
}

} // namespace cairn::physics
