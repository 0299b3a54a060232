#pragma once

// Ragdolls (issue 33): a description of parts (each a body and the swing-twist joint that hangs it from its
// parent) made into bodies and joints in one call, the bodies added to the world as one broad-phase batch (a
// character going limp adds its 20-odd bodies at once, not one by one into the live tree). The parts are one
// collision group; by default a part does not collide with its parent (they overlap at the joint), nor with
// the parts it touches in the description's pose, while other pairs do (an arm still hits a leg).
//
// Threads: Create and Destroy from any thread outside the step and while holding no body lock (as
// BodyInterface's and ConstraintInterface's calls; WrongThread otherwise). A Ragdoll is a plain handle: one
// thread at a time.

#include "cairn/physics/body/BodyCreationSettings.h"
#include "cairn/physics/body/BodyInterface.h"
#include "cairn/physics/constraints/ConstraintInterface.h"

#include <span>
#include <utility>
#include <vector>

namespace cairn::physics
{

class PhysicsSystem;

/// One part: its body, posed in the ragdoll's own space, and the joint to its parent (in that space too).
struct RagdollPart
{
    BodyCreationSettings mBody;          ///< Its mCollisionGroup is the ragdoll's, set by Create
    int32_t mParent = -1;                ///< An earlier part's index; -1 only for the first part, the root
    SwingTwistConstraintSettings mJoint; ///< Its bodies are set by Create; unused for the root
};

struct RagdollSettings
{
    /// At most this many parts: a bad count gets a clear error, not a world of bodies
    static constexpr size_t cMaxParts = 256;
    std::vector<RagdollPart> mParts;
    /// A part and its parent do not collide (other pairs of parts do, but those in mNoCollisionPairs)
    bool mDisableParentChildCollisions = true;
    /// Pairs of parts (indices) that do not collide either
    std::vector<std::pair<uint32_t, uint32_t>> mNoCollisionPairs;

    /// Adds to mNoCollisionPairs every pair of parts whose shapes, as posed here, are within inMinSeparation
    /// (m) of each other: parts that overlap at rest (a spine's spheres, the shoulders at the chest) would
    /// push the ragdoll apart the moment it is made. Call once per description, not per ragdoll (it collides
    /// every pair of parts).
    void DisableCollisionsOfTouchingParts(float inMinSeparation);
};

class Ragdoll
{
public:
    /// Makes the ragdoll's bodies at inPosition and inRotation (ragdoll space to world), adds them to the
    /// world in one batch, then joins them; all or nothing (whatever was made is taken back on an error).
    /// inGroupID: its collision group, one per ragdoll (not CollisionGroup::cNoGroup). Errors: no parts or
    /// more than cMaxParts, a parent that is not an earlier part (or a second root), a pose that is NaN or
    /// beyond the world (InvalidArgument); and whatever creating a body, adding the batch or a joint refuses.
    static Result<Ragdoll> Create(PhysicsSystem& ioSystem, const RagdollSettings& inSettings,
                                  const Vec3& inPosition, const Quat& inRotation, uint32_t inGroupID,
                                  Activation inActivation);

    /// Removes its joints, takes its bodies out of the world and destroys them; the handle is empty after.
    Status Destroy(PhysicsSystem& ioSystem);

    /// By part index
    std::span<const BodyID> GetBodies() const { return mBodies; }
    /// By part index less one (the root has none)
    std::span<const ConstraintID> GetConstraints() const { return mJoints; }

private:
    std::vector<BodyID> mBodies;
    std::vector<ConstraintID> mJoints;
};

} // namespace cairn::physics
