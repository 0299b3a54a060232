#pragma once

// BroadPhaseSortAndSweep: the engine's default broad phase until the lock-free quad tree replaces it.
//
// Structure, per broad-phase layer:
//  - mEntries: the truth. Unordered array of the stored bodies; swap-remove; mLocation maps a body index to
//    (layer, position) so every modification is O(1) with no allocation.
//  - A snapshot built by Update(): the narrow entries split into strips along z (by min z), each strip sorted
//    by an x key, in SoA arrays; plus a small linear list of wide entries. A query scans, in each strip its z
//    range reaches, only the keys in [query min x - reach, query max x]. Strips (a 2D sort rather than a
//    plain 1D sweep) cut the candidates of a small box in the 448 m x 256 m shared world from ~300 to ~20: a
//    1D sweep sees every body of a 6 m wide column of the world. Within a strip, a table of x cells (about
//    one reach wide) gives the first slot to look at in O(1): binary searches over ~1,000 keys dominated the
//    step's pair search.
//  - Wide entries (x width or z depth above max(4 x median, 99th percentile)) would inflate the reach of
//    every query (a 64 m ground slab would make each query scan a 64 m column), so they live in the wide
//    list, which the percentile bounds to ~2% of the layer.
//  - Modifications between two Update() calls are visible at once: a removed or moved body's snapshot slot is
//    marked dead (invalid id); a moved body whose new bounds still satisfy its slot's invariants (below) is
//    updated in place; added bodies and bodies that left their slot go to a dirty list that queries scan
//    linearly. Update() rebuilds a layer when it has dirty or dead entries.
//  - Slot invariants, which make the scan exact: key <= min x, max x - key <= mReachX, strip(min z) == the
//    slot's strip, max z - min z <= mMaxDepthZ. Query windows are padded by a relative epsilon that covers
//    float rounding, and every candidate gets the exact test of BroadPhaseOverlap.h, so results equal brute
//    force's.
//  - A layer whose bodies moved gets x keys min x - headroom (headroom = a quarter of the median width) so
//    that small moves in both directions stay in place.
//
// Threads: as BroadPhase: any thread, except Update/FindCollidingPairs (physics step only, one at a time) and
// AddBodiesFinalize/Abort (once per batch).
// Locking: one reader-writer lock, mMutex, guards every member except the immutable mMaxBodies/mLayerSetup
// and the per-batch AddState (owned by its caller). It is a std::shared_mutex behind a turnstile
// (WriterFairSharedMutex): the plain glibc one let two query threads starve the mover and the step's
// Update(). Queries and FindCollidingPairs hold it shared; AddBodiesFinalize, RemoveBodies,
// NotifyBodiesAABBChanged and Update hold it exclusive; AddBodiesPrepare/Abort take no lock. mActiveScratch
// is written under the shared lock: safe because only the physics step calls FindCollidingPairs. Lock order:
// the broad-phase lock is innermost. Callers may hold body locks when they call any method; the broad phase
// calls nothing that locks while holding mMutex, except the visitors. Visitors run under the shared lock:
// they must not call any method of the broad phase (a modifying one self-deadlocks; a recursive shared lock
// can deadlock behind a waiting writer) and must not wait for a lock (e.g. a body write lock) that a thread
// calling a modifying broad-phase method may hold: collect the ids, then lock after the query returns.
//
// Bad input (the BodyInterface validates before calling; these are caller bugs) is ignored, never stored:
//  - non-finite or inverted bounds, an invalid id, an index >= inMaxBodies, an object layer the LayerSetup
//    does not know: assert in debug, ignored in release (for NotifyBodiesAABBChanged: the old bounds stay);
//  - adding a body index that is already present (whatever its sequence): ignored, the first add stays;
//  - removing or moving a body that is not present (index and sequence must match): ignored.

#include "cairn/physics/broadphase/BroadPhase.h"
#include "cairn/physics/broadphase/WriterFairSharedMutex.h"

#include <vector>

namespace cairn
{

class BroadPhaseSortAndSweep final : public BroadPhase
{
public:
    /// inMaxBodies: body indices are < inMaxBodies (sizes the index map once). inLayers is copied.
    BroadPhaseSortAndSweep(uint32_t inMaxBodies, const LayerSetup& inLayers);
    ~BroadPhaseSortAndSweep() override;
    BroadPhaseSortAndSweep(const BroadPhaseSortAndSweep&) = delete;
    BroadPhaseSortAndSweep& operator=(const BroadPhaseSortAndSweep&) = delete;

    /// Copies and validates the batch; no lock.
    AddState AddBodiesPrepare(std::span<const BroadPhaseBody> inBodies) override;
    /// Appends the batch to the dirty lists under the exclusive lock and frees it.
    void AddBodiesFinalize(AddState inState) override;
    /// Frees the batch.
    void AddBodiesAbort(AddState inState) override;
    /// Swap-removes each present body and kills its snapshot slot.
    void RemoveBodies(std::span<const BodyID> inBodies) override;
    /// Stores the new bounds; in place in the snapshot when the slot invariants allow, else via the dirty
    /// list.
    void NotifyBodiesAABBChanged(std::span<const BroadPhaseBody> inBodies) override;
    /// Rebuilds the snapshot of every layer with dirty or dead entries. Physics step only.
    void Update() override;

    /// Bodies whose AABB overlaps inBox (closed intervals).
    void CollideAABox(const AABB& inBox, const BroadPhaseQueryFilter& inFilter,
                      BodyVisitor inVisitor) const override;
    /// Bodies whose AABB is within inRadius of inCenter.
    void CollideSphere(const Vec3& inCenter, float inRadius, const BroadPhaseQueryFilter& inFilter,
                       BodyVisitor inVisitor) const override;
    /// Bodies whose AABB contains inPoint.
    void CollidePoint(const Vec3& inPoint, const BroadPhaseQueryFilter& inFilter,
                      BodyVisitor inVisitor) const override;
    /// Slab test of every body in the segment's window; the visitor can only shrink the max fraction.
    void CastRay(const RayCast& inRay, const BroadPhaseQueryFilter& inFilter,
                 RayBodyVisitor inVisitor) const override;
    /// Ray cast of the box centre against body boxes grown by the box half extents.
    void CastAABox(const AABB& inBox, const Vec3& inDisplacement, const BroadPhaseQueryFilter& inFilter,
                   RayBodyVisitor inVisitor) const override;
    /// Each active body (listed once each) against the layers it collides with. Call Update() first: dirty
    /// entries are scanned linearly by every active body.
    void FindCollidingPairs(std::span<const BodyID> inActiveBodies, const LayerSetup& inLayers,
                            BodyPairVisitor inVisitor,
                            const ParallelRanges* inParallel = nullptr) const override;

    /// Number of bodies stored.
    size_t GetBodyCount() const override;

    /// Checks every internal invariant (index map, dirty list, slot invariants, sort order); false on the
    /// first violation. For tests; takes the shared lock.
    bool Validate() const;

private:
    struct Layer;
    struct Tier;
    struct Window;

    /// Inserts a validated body. Caller holds mMutex exclusive.
    void InsertBody(const BroadPhaseBody& inBody);
    /// Removes the body at (inLayer, inPosition). Caller holds mMutex exclusive.
    void RemoveAt(uint32_t inLayer, uint32_t inPosition);
    /// Position code (see mLocation) of the body with exactly this id, or cNotPresent. Caller holds mMutex.
    uint32_t FindLocation(BodyID inID) const;
    /// Rebuilds ioLayer's snapshot from its entries. Caller holds mMutex exclusive.
    void Rebuild(Layer& ioLayer);
    /// Calls inTest(bounds) for every candidate of every layer in inMask whose bounds can meet inWindow, then
    /// inVisit(id) for those that pass and are in inMask; stops when inVisit returns false. Caller holds
    /// mMutex.
    template <class Test, class Visit>
    void Query(const Window& inWindow, ObjectLayerMask inMask, Test&& inTest, Visit&& inVisit) const;
    /// Query() under the shared lock for the overlap queries, which visit every body that passes (no early
    /// out).
    template <class Test>
    void VisitOverlapping(const Window& inWindow, ObjectLayerMask inMask, Test&& inTest,
                          BodyVisitor inVisitor) const;
    /// Query() on one layer; returns false when the visitor asked to stop.
    template <class Test, class Visit>
    bool QueryLayer(const Layer& inLayer, const Window& inWindow, ObjectLayerMask inMask, Test& inTest,
                    Visit& inVisit) const;

    static constexpr uint32_t cNotPresent = 0xffffffffu; ///< mLocation value of an absent body
    static constexpr uint32_t cLayerBits = 3;            ///< mLocation = position << cLayerBits | layer
    static_assert((1u << cLayerBits) >= cMaxBroadPhaseLayers);

    const uint32_t mMaxBodies;    ///< Body indices are below this
    const LayerSetup mLayerSetup; ///< Copy of the constructor's setup; immutable
    mutable WriterFairSharedMutex
        mMutex;                      ///< Guards everything below; a shared_mutex that does not starve writers
    std::vector<Layer> mLayers;      ///< One per broad-phase layer of mLayerSetup
    std::vector<uint32_t> mLocation; ///< Body index -> position << cLayerBits | layer, or cNotPresent
    size_t mBodyCount = 0;           ///< Sum of the layers' entry counts
    mutable std::vector<uint8_t>
        mActiveScratch; ///< Body index -> 1 while FindCollidingPairs runs and it is active
    std::vector<float>
        mScratchWidths; ///< Rebuild(): widths for the median/percentile; kept to avoid reallocating
    std::vector<float> mScratchDepths;    ///< Rebuild(): depths, same
    std::vector<uint32_t> mScratchNarrow; ///< Rebuild(): positions of the narrow entries
    std::vector<uint32_t> mScratchWide;   ///< Rebuild(): positions of the wide entries
    std::vector<std::pair<uint64_t, uint32_t>>
        mScratchOrder; ///< Rebuild(): (strip, key) sort key, entry position
};

} // namespace cairn
