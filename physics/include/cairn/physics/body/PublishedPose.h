#pragma once

// Published poses: what queries read of a body, with no lock that the physics step holds.
//
// Every body slot has a record of 64 bytes (one cache line) that holds the body's id, shape, transform,
// motion type, layer, navmesh area and whether it is in the world and awake. Its writers:
//  - the physics step, for every active body, at the end of each collision step (when that step's positions
//    are final), after the broad phase got the body's new bounds;
//  - BodyInterface (create, destroy, add, remove, moves by hand, activation), under the body's write lock;
// so one writer at a time per record. Readers are any thread, at any time, also while the step runs: a
// PoseReader never takes a lock. Each record is a sequence lock: a writer makes its version odd, stores the
// fields, makes it even; a reader that meets an odd or changed version reads again (a write is a few dozen
// nanoseconds of stores, never a wait for the step).
//
// What a reader may see: a body's last published pose, whole (never a position of one step with the rotation
// of another). A body removed meanwhile is reported with its last pose or not at all; a stale id never (the
// record names the id it holds). The shape stays alive while the PoseReader lives: a destroyed body's shape
// is freed only once no reader that could have read it is left (the broad phase's epoch scheme).
//
// The broad phase's bounds of a body always contain the bounds of its published pose: the step gives the
// broad phase the box of both the pose it is about to replace and the new one before it publishes, and a move
// by hand grows the body's box over both poses, publishes, then shrinks it. So a query that finds its
// candidates in the broad phase and tests them against published poses misses no body.

#include "cairn/physics/body/BodyID.h"
#include "cairn/physics/body/Layers.h"
#include "cairn/physics/body/MotionType.h"
#include "cairn/physics/math/Transform.h"

#include <atomic>
#include <cstdint>

namespace cairn::physics
{

class BodyManager;
class PublishedPoseStore;
class Shape;

/// One body as last published.
struct PublishedPose
{
    BodyID mID;
    const Shape* mShape = nullptr; ///< Alive while the PoseReader that read it lives
    Transform mTransform;          ///< Shape origin and rotation, world space
    MotionType mMotionType = MotionType::Static;
    ObjectLayer mLayer = 0;
    uint8_t mNavMeshArea = 0;
    bool mActive = false; ///< Awake (in the active list) when published
    /// Even, and different for every publication of this body slot: a reader that reads a pose twice and
    /// finds the same version knows it did not change in between
    uint32_t mVersion = 0;
};

/// A read section over a world's published poses: reads never wait for the step, and every shape read stays
/// alive until the reader is destroyed. Any thread, any time; keep one for the length of a query, not longer
/// (a reader held for seconds keeps destroyed bodies' shapes in memory that long). Not movable.
class PoseReader
{
public:
    explicit PoseReader(const BodyManager& inBodies);
    ~PoseReader();
    PoseReader(const PoseReader&) = delete;
    PoseReader& operator=(const PoseReader&) = delete;

    /// The last published pose of a body in the world; false for an invalid or stale id, or a body that is
    /// not in the world.
    bool Read(const BodyID& inID, PublishedPose& outPose) const;

private:
    const PublishedPoseStore& mStore;
    /// The epoch read section this reader holds open, entered by the constructor and left by the destructor:
    /// an EpochReclaimer::ReadScope's counter, kept here so that the reclaimer stays out of installed headers
    std::atomic<uint32_t>& mEpochReaders;
};

} // namespace cairn::physics
