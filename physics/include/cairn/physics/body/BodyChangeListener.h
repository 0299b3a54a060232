#pragma once

// BodyChangeListener: told when a body is added to or removed from the world, moved by hand, or falls asleep
// or wakes, so that systems built on the physics world (a navmesh, say) can follow it without polling.
// Moves made by the simulation itself are not reported: a body that the step moves is awake, and becomes
// news again when it falls asleep.
//
// Threads: called on the thread that made the change, while it holds the body's lock (or inside the step,
// which holds every body lock), so an implementation must be thread-safe, quick, and must not call back into
// the physics system or take a body lock: taking a mutex of its own (a leaf in the lock order) is the way.

#include "cairn/physics/body/BodyID.h"
#include "cairn/physics/body/Layers.h"
#include "cairn/physics/body/MotionType.h"
#include "cairn/physics/math/AABB.h"

#include <cstdint>

namespace cairn::physics
{

enum class BodyChangeKind : uint8_t
{
    Added,      ///< Into the world: mNewBounds
    Removed,    ///< From the world: mOldBounds
    Moved,      ///< Placed by hand (SetPosition and the like): mOldBounds to mNewBounds
    FellAsleep, ///< Deactivated, by the step or by hand: at mNewBounds (= mOldBounds)
    Woke,       ///< Activated: at mNewBounds (= mOldBounds)
};

struct BodyChange
{
    BodyChangeKind mKind;
    BodyID mBody;
    MotionType mMotionType;
    ObjectLayer mObjectLayer;
    bool mActive;    ///< After the change
    AABB mOldBounds; ///< World bounds before the change (empty when the body was not in the world)
    AABB mNewBounds; ///< World bounds after the change (empty when it is not in the world)
};

class BodyChangeListener
{
public:
    virtual ~BodyChangeListener() = default;
    virtual void OnBodyChanged(const BodyChange& inChange) = 0;
};

} // namespace cairn::physics
