#pragma once

// GeometryCollector: stages 1 and 2 of a tile job. Asks the broad phase for the bodies whose bounds overlap a
// tile's bordered box (lock-free, any thread), then copies each body's triangles in that box, in world space,
// from the body's published pose (PublishedPose.h): static, dynamic (asleep or awake) and kinematic bodies
// alike, with no lock, also while the physics step runs. So a tile job never waits for a step and never has
// to try again: it reads the world as the last collision step (or move by hand) published it.
// Threads: any thread; the collector holds no state of its own (const methods).

#include "cairn/navmesh/TileGeometry.h"
#include "cairn/physics/body/BodyManager.h"
#include "cairn/physics/broadphase/BroadPhase.h"

#include <span>
#include <vector>

namespace cairn::navmesh
{
using namespace cairn::physics;

/// Which bodies make the navmesh.
struct NavMeshInclusion
{
    /// Bodies in other layers are ignored; by default every layer but the default setup's debris and triggers
    /// (small things that get kicked around, and sensors that nobody stands on)
    ObjectLayerMask mObjectLayers = cAllObjectLayers & ~(ObjectLayerMask(1) << Layers::cDebris) &
                                    ~(ObjectLayerMask(1) << Layers::cTrigger);
    bool mSleepingDynamic = true; ///< Sleeping dynamic bodies are obstacles
    /// Awake dynamic bodies are obstacles too, where their last published pose has them (off by default: they
    /// move, and a tile job marks the tile dirty again when one falls asleep)
    bool mAwakeDynamic = false;
    bool mKinematic = false; ///< Kinematic bodies (moving platforms, doors) are obstacles
};

struct CollectStats
{
    uint32_t mBodies = 0; ///< Bodies whose triangles were collected
    uint32_t mTriangles = 0;
    double mCollectMs = 0.0; ///< Wall time of the query and the copies
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

    /// Stage 2: appends the triangles in inBox of each body in inBodies that inInclusion takes, at its
    /// published pose, in the order of inBodies. Adds its figures to ioStats.
    void CollectTriangles(const AABB& inBox, const NavMeshInclusion& inInclusion,
                          std::span<const BodyID> inBodies, TileGeometry& ioGeometry,
                          CollectStats& ioStats) const;

private:
    const BodyManager& mBodies;
    const BroadPhase& mBroadPhase;
};

} // namespace cairn::navmesh
