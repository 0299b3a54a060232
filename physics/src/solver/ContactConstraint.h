#pragma once

// One contact manifold prepared for the sequential impulse solver. Built, solved and discarded inside the
// physics step, by the thread that solves its island: no locking.

#include "cairn/physics/math/Math.h"
#include "cairn/physics/narrowphase/ContactManifold.h"

#include <cstdint>

namespace cairn::physics
{

class Body;

/// The impulse along one axis at one contact point, with its precomputed effective mass.
struct AxisImpulse
{
    Vec3 mRAxAxis;       ///< rA x axis
    Vec3 mRBxAxis;       ///< rB x axis
    Vec3 mInvIA_RAxAxis; ///< World inverse inertia of A times rA x axis
    Vec3 mInvIB_RBxAxis;
    float mEffectiveMass; ///< 1 / (J M^-1 J^T)
    float mAccumulated;   ///< Total impulse this step (warm-started from the cache)
};

struct ContactConstraintPoint
{
    Vec3 mLocalOnA; ///< Contact point in A's centre-of-mass frame, for position correction
    Vec3 mLocalOnB;
    AxisImpulse mNormal;
    float mSeparation;       ///< Gap at the start of the step (negative: penetration)
    float mVelocityBias;     ///< Minimum normal relative velocity (negative: a speculative gap may close)
    float mApproachVelocity; ///< Normal relative velocity before solving, after this step's forces
    float mMaxNormalImpulse; ///< Largest normal impulse applied this step: > 0 means the point really touched
    float
        mBounceVelocity; ///< The restitution pass's target normal velocity (> 0), 0: no bounce (InitBounces)
};

/// Friction for a whole manifold ("patch friction"): a 2D impulse at the centroid of the contact points and a
/// twist impulse about the normal, limited by mu times the manifold's total normal impulse. Solving friction
/// once per manifold instead of per point keeps the result independent of the order the points are solved in,
/// which is what lets tall stacks stand.
struct PatchFriction
{
    AxisImpulse mTangent[2];   ///< At the centroid, along ContactConstraint::mTangent
    float mTwistEffectiveMass; ///< 1 / (n . (IA^-1 + IB^-1) n)
    float mTwistAccumulated;   ///< Angular impulse about the normal
    float mTwistRadius;        ///< Mean distance of the points from the centroid: torsional lever arm
};

struct ContactConstraint
{
    /// Leaves the fields unset on purpose: InitConstraint sets every one the solver reads, and the step sets
    /// the rest (cache index, island, solver bodies, order key). Zeroing the whole struct first, which
    /// emplace_back's value-initialisation did, took half of the time AddConstraint spent outside
    /// InitConstraint.
    ContactConstraint() {}

    Body* mBodyA;
    Body* mBodyB;
    Vec3 mNormal;     ///< World, from A to B
    Vec3 mTangent[2]; ///< World, perpendicular to mNormal and each other
    PatchFriction mPatch;
    Vec3 mInvIA_Normal; ///< World inverse inertia of A times the normal (twist)
    Vec3 mInvIB_Normal;
    float mFriction;       ///< Combined: sqrt(frictionA * frictionB)
    float mRestitution;    ///< Combined: max(restitutionA, restitutionB)
    uint32_t mCacheIndex;  ///< Where this manifold's impulses are stored for next step's warm start
    uint32_t mSolverBodyA; ///< A's velocities in the step's SolverBody array, set before solving
    uint32_t mSolverBodyB;
    uint64_t mOrderKey; ///< Hash of bodies and sub-shapes: the solve order within the island
    int mNumPoints;
    ContactConstraintPoint mPoints[ContactManifold::cMaxPoints];
};

/// What the position iterations read of a contact constraint, apart: 128 bytes (two cache lines) where the
/// whole constraint is 640 (ten), over which they went twice a step per constraint. Made from the constraint
/// before the position iterations (MakePositionConstraint); the points are fixed on the bodies.
struct alignas(64) PositionConstraint
{
    Body* mBodyA;
    Body* mBodyB;
    Vec3 mNormal; ///< World, from A to B, as at the start of the step
    int mNumPoints;
    Vec3 mLocalOnA[ContactManifold::cMaxPoints]; ///< In A's centre-of-mass frame
    Vec3 mLocalOnB[ContactManifold::cMaxPoints]; ///< In B's centre-of-mass frame
};
static_assert(sizeof(PositionConstraint) == 128, "two cache lines");

} // namespace cairn::physics
