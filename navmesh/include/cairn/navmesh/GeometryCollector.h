#pragma once

// GeometryCollector: stages 1 and 2 of a tile job. Asks the broad phase for the bodies whose bounds overlap a
// tile's bordered box (lock-free, any thread), then copies each body's triangles in that box, in world space:
//  - a static body is read under its shard's static mutex only (StaticBodyLockRead), which the physics step
//    never holds, so level geometry is read while the step runs;
//  - a dynamic or kinematic body is read under a read lock that does not wait (TryLock): while the step runs
//    it holds every body lock, and such a body is handed back as busy, for the job's next chunk.
// A lock is held only to copy the shape reference and the transform; the triangles are made after it is
// released (shapes are immutable and the reference keeps them alive). So a tile job never waits for a step.
// Threads: any thread outside the step; the collector holds no state of its own (const methods).

#include "cairn/navmesh/TileGeometry.h"
#include "cairn/physics/body/BodyManager.h"
#include "cairn/physics/broadphase/BroadPhase.h"

#include <span>
#include <vector>

namespace cairn::navmesh
{

/// Which bodies make the navmesh.
struct NavMeshInclusion
{
    /// Bodies in other layers are ignored; by default every layer but the default setup's debris and triggers
    /// (small things that get kicked around, and sensors that nobody stands on)
    ObjectLayerMask mObjectLayers = cAllObjectLayers & ~(ObjectLayerMask(1) << Layers::cDebris) &
                                    ~(ObjectLayerMask(1) << Layers::cTrigger);
    bool mSleepingDynamic = true; ///< Sleeping dynamic bodies are obstacles (awake ones move: never)
    bool mKinematic = false;      ///< Kinematic bodies (moving platforms, doors) are obstacles
};

/// Which of the bodies a collection pass reads. A tile job reads static bodies first (never busy), then the
/// others in one pass that it repeats whole while any is busy, so the triangles always come in the same
/// order.
enum class BodyKinds : uint8_t
{
    All,
    Static,
    NonStatic,
};

struct CollectStats
{
    uint32_t mBodies = 0; ///< Bodies whose triangles were collected
    uint32_t mTriangles = 0;
    uint32_t mBusy = 0;              ///< Bodies handed back because the step held their lock
    double mLongestLockWaitMs = 0.0; ///< Longest time spent taking one lock
    double mCollectMs = 0.0;         ///< Wall time of the query and the copies
};

class GeometryCollector
{
public:
    GeometryCollector(const BodyManager& inBodies, const BroadPhase& inBroadPhase)
        : mBodies(inBodies), mBroadPhase(inBroadPhase)
    {
    }

    /// Stage 1: the bodies whose bounds overlap inBox, in the layers of inInclusion, sorted by id (so the
    /// triangles come in the same order whatever the broad phase's tree looks like).
    void FindBodies(const AABB& inBox, const NavMeshInclusion& inInclusion,
                    std::vector<BodyID>& outBodies) const;

    /// Stage 2: appends the triangles in inBox of each body in inBodies that inInclusion takes. Bodies whose
    /// lock the step holds are appended to outBusy. Adds its figures to ioStats.
    void CollectTriangles(const AABB& inBox, const NavMeshInclusion& inInclusion,
                          std::span<const BodyID> inBodies, TileGeometry& ioGeometry,
                          std::vector<BodyID>& outBusy, CollectStats& ioStats,
                          BodyKinds inKinds = BodyKinds::All) const;

private:
    const BodyManager& mBodies;
    const BroadPhase& mBroadPhase;
};

} // namespace cairn::navmesh
