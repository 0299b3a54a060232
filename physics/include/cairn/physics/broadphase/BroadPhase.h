#pragma once

// BroadPhase: finds bodies whose AABBs overlap a query or each other. It keeps its own copy of every added
// body's world AABB and object layer (pushed to it by the body interface and the physics step), so it never
// reads body memory and takes no body lock.
//
// Threads: every method may be called from any thread at any time, except
//  - FindCollidingPairs and Update: the physics step only (one thread at a time each; the two at once only
//    where CanFindPairsDuringUpdate says so);
//  - AddBodiesFinalize / AddBodiesAbort: exactly once per AddState, from any one thread.
// A body id is added at most once; the caller (BodyInterface) serialises add/remove of the same body.
// Queries report every body whose stored AABB overlaps; a body added, moved or removed concurrently with a
// query is reported with either its old or its new state. A body whose object layer ChangeBodyLayer changes
// is reported by every query that runs meanwhile whose filter takes either layer, once (not by
// FindCollidingPairs, which the engine never runs beside a layer change: BodyInterface calls wait for the
// step).
// Visitors may run while the broad phase holds an internal lock (the reference implementations hold a shared
// lock): a visitor must not call back into the broad phase and must not wait for a lock that a thread calling
// a modifying method may hold (e.g. a body write lock); collect the ids and lock after the query returns.
// Bad input (the BodyInterface validates before calling; these are caller bugs) is ignored, never stored:
//  - non-finite or inverted bounds, an invalid id, an index the broad phase has no room for, an object layer
//    it does not know: assert in debug, ignored in release (for NotifyBodiesAABBChanged: the old bounds
//    stay);
//  - adding a body index that is already present (whatever its sequence): ignored, the first add stays;
//  - removing or moving a body that is not present (index and sequence must match): ignored;
//  - a cast that is not IsFiniteCast: reports nothing.
// Each implementation says what "no room" and "does not know" mean for it.

#include "cairn/physics/body/BodyID.h"
#include "cairn/physics/body/Layers.h"
#include "cairn/physics/math/AABB.h"
#include "cairn/physics/math/FunctionRef.h"
#include "cairn/physics/shapes/Shape.h"

#include <span>

namespace cairn::physics
{

/// What the broad phase stores of a body.
struct BroadPhaseBody
{
    BodyID mID;
    AABB mBounds; ///< World space, finite
    ObjectLayer mLayer = 0;
};

/// Which bodies a query may report.
struct BroadPhaseQueryFilter
{
    ObjectLayerMask mObjectLayers = cAllObjectLayers; ///< Only bodies in these object layers
};

/// Receives a body found by an overlap query.
using BodyVisitor = FunctionRef<void(BodyID)>;
/// Receives a body whose AABB the ray enters at inFraction; returns the new maximum fraction (return the
/// current maximum to keep going, a smaller one to prune farther bodies, a negative one to stop).
using RayBodyVisitor = FunctionRef<float(BodyID inBody, float inFraction)>;
/// Receives a potentially colliding pair; inActive is the active body whose AABB was queried.
using BodyPairVisitor = FunctionRef<void(BodyID inActive, BodyID inOther)>;
/// Runs inBody over [0, inCount) split into ranges, possibly several at once on different threads, and
/// returns when every range is done (the physics step passes its job system's ParallelFor).
using ParallelRanges =
    FunctionRef<void(uint32_t inCount, FunctionRef<void(uint32_t inBegin, uint32_t inEnd)> inBody)>;

/// Whether a cast is made of finite numbers. A NaN in a slab test reads as "inside", so a NaN ray or sweep
/// would report every body at fraction 0: the broad phases ignore such casts, as they ignore NaN boxes.
inline bool IsFiniteCast(const Vec3& inStart, const Vec3& inDisplacement)
{
    return IsFinite(inStart) && IsFinite(inDisplacement);
}
inline bool IsFiniteCast(const AABB& inBox, const Vec3& inDisplacement)
{
    return inBox.IsFinite() && IsFinite(inDisplacement);
}

class BroadPhase
{
public:
    /// Opaque result of AddBodiesPrepare, owned by the broad phase until finalized or aborted.
    using AddState = void*;

    virtual ~BroadPhase() = default;

    /// Builds whatever a batch needs without touching the live structure: safe on a loading thread while
    /// physics runs. inBodies is read during the call only. Returns nullptr when the broad phase has no room
    /// for the batch (a fixed-capacity pool is full): nothing was added.
    virtual AddState AddBodiesPrepare(std::span<const BroadPhaseBody> inBodies) = 0;
    /// Makes a prepared batch visible to queries.
    virtual void AddBodiesFinalize(AddState inState) = 0;
    /// Throws a prepared batch away.
    virtual void AddBodiesAbort(AddState inState) = 0;

    /// Removes added bodies.
    virtual void RemoveBodies(std::span<const BodyID> inBodies) = 0;

    /// New world AABBs for added bodies (after a move). A new object layer is taken too, but a query running
    /// meanwhile may miss a body that it moves to another broad-phase layer: ChangeBodyLayer does not.
    virtual void NotifyBodiesAABBChanged(std::span<const BroadPhaseBody> inBodies) = 0;

    /// Moves an added body to object layer inLayer (another broad-phase layer's structure, perhaps) without a
    /// moment where a query could miss it: from the start of the call to its end, a query whose filter takes
    /// either layer reports the body exactly once (as the filter of a query that starts after the call sees
    /// it, only in the new layer). inWhileInBoth runs in the middle, while the body is found under both
    /// layers: the body interface publishes the new layer there, so a query that reads the body's published
    /// layer finds the body under it at every moment. It must not call the broad phase (it may run under its
    /// lock). Returns false, with nothing changed and inWhileInBoth not run, for a body that is not present,
    /// an object layer the broad phase does not know, or no room for the body in the new structure. Any
    /// thread, not from inside a visitor; the caller serialises it with the body's other operations. It may
    /// wait for the queries running when it starts to finish (microseconds, unless one lost its core).
    virtual bool ChangeBodyLayer(BodyID inBody, ObjectLayer inLayer, FunctionRef<void()> inWhileInBoth) = 0;

    /// Optimises the structure after moves, adds and removes (re-sort, rebuild). Physics step only.
    virtual void Update() = 0;
    /// True when FindCollidingPairs may run on one thread while Update runs on another, with the same pairs
    /// as after it (the step then overlaps the two). False by default: a re-sort under a sweep races.
    virtual bool CanFindPairsDuringUpdate() const { return false; }

    /// Bodies whose AABB overlaps inBox.
    virtual void CollideAABox(const AABB& inBox, const BroadPhaseQueryFilter& inFilter,
                              BodyVisitor inVisitor) const = 0;
    /// Bodies whose AABB overlaps the sphere.
    virtual void CollideSphere(const Vec3& inCenter, float inRadius, const BroadPhaseQueryFilter& inFilter,
                               BodyVisitor inVisitor) const = 0;
    /// Bodies whose AABB contains inPoint.
    virtual void CollidePoint(const Vec3& inPoint, const BroadPhaseQueryFilter& inFilter,
                              BodyVisitor inVisitor) const = 0;
    /// Bodies whose AABB the segment enters before the visitor's current maximum fraction (starting at 1),
    /// in no particular order. None for a ray that is not IsFiniteCast.
    virtual void CastRay(const RayCast& inRay, const BroadPhaseQueryFilter& inFilter,
                         RayBodyVisitor inVisitor) const = 0;
    /// Bodies whose AABB the box swept along inDisplacement touches; the fraction is where contact starts.
    /// None for a sweep that is not IsFiniteCast.
    virtual void CastAABox(const AABB& inBox, const Vec3& inDisplacement,
                           const BroadPhaseQueryFilter& inFilter, RayBodyVisitor inVisitor) const = 0;

    /// Every pair (active body, other body) whose AABBs overlap and whose object layers collide according to
    /// inLayers; a pair of two active bodies is reported once. Physics step only. With inParallel, the active
    /// bodies may be split into ranges run at once on several threads: inVisitor is then called concurrently,
    /// all pairs of one active body from the same thread (a broad phase may also ignore inParallel).
    virtual void FindCollidingPairs(std::span<const BodyID> inActiveBodies, const LayerSetup& inLayers,
                                    BodyPairVisitor inVisitor,
                                    const ParallelRanges* inParallel = nullptr) const = 0;

    /// Number of bodies currently added (for statistics and tests).
    virtual size_t GetBodyCount() const = 0;
};

} // namespace cairn::physics
