#pragma once

// Sequential impulse contact solver (Catto, GDC 2009) for one island at a time:
//  - order: the caller sorts each island's constraints by a hash of their bodies (see PhysicsStep), so no
//    geometric order (bottom-up, left-right) biases the result, and the order is the same on every run;
//  - friction per manifold ("patch friction", as PhysX does): see PatchFriction;
//  - warm starting: each point starts from last step's accumulated impulses (matched through the
//  ContactCache);
//  - accumulated-impulse clamping: normal >= 0, friction inside the Coulomb circle |(t1, t2)| <= mu * normal;
//  - restitution: a separate pass after the velocity iterations (as in Box2D v3) gives points that touched
//    and hit faster than the threshold the analytic rebound, from wherever in the step the surface is met
//    (InitBounces);
//  - position correction by split impulses: no Baumgarte term in the velocity solve (it would add energy);
//    after integration, non-linear Gauss-Seidel iterations move the bodies apart by mBaumgarte of the
//    penetration beyond mPenetrationSlop, directly on positions.
// Runs inside the step, by the one thread that owns the island: no locks.

#include "body/Integration.h"
#include "cairn/physics/solver/SolverSettings.h"
#include "solver/ContactConstraint.h"
#include "solver/SolverBody.h"

#include <span>

namespace cairn::physics
{

namespace SequentialImpulseSolver
{
/// Fills a constraint from a manifold between A and B (world space). Impulses start at zero. inInvIA/B: the
/// bodies' world inverse inertia (zero for static and kinematic ones). inLocalOnA/B (optional): the points in
/// A's and B's centre-of-mass frames when they are known (a manifold taken over from the contact cache),
/// which saves turning each world point back into them.
void InitConstraint(Body& ioA, Body& ioB, const Mat3& inInvIA, const Mat3& inInvIB,
                    const ContactManifold& inManifold, float inDeltaTime, ContactConstraint& outConstraint,
                    const Vec3* inLocalOnA = nullptr, const Vec3* inLocalOnB = nullptr);
// The velocity passes work on ioBodies, indexed by each constraint's mSolverBodyA/B; a static or kinematic
// body must have an inverse mass of 0 there (and a zero inverse inertia in the constraint, as InitConstraint
// gives it), so that impulses leave it unchanged.

/// Applies the accumulated (warm-start) impulses.
void WarmStart(std::span<ContactConstraint* const> ioConstraints, std::span<SolverBody> ioBodies);
/// Velocity iteration inIteration over the constraints, in the order given. Each manifold's points are swept
/// forwards on even iterations and backwards on odd ones: a single fixed order biases which corner of a
/// resting face takes the load first, and in a tall stack that bias tilts every joint the same way until the
/// column leans over (a 10-box column leaned 0.5 m in 10 s; sweeping both ways in every iteration, 2 cm).
/// Alternating keeps the column within the same 5 cm test at half the cost of the normal rows. An odd count,
/// where one direction has a sweep more, leans no more than its even neighbours (measured: 3, 5, 9 iterations
/// lean 26, 11, 6.5 cm alternating and 25, 8, < 5 cm sweeping both ways; 7 leaned less when the steps took
/// turns at starting backwards), so nothing evens it out.
void SolveVelocities(std::span<ContactConstraint* const> ioConstraints, std::span<SolverBody> ioBodies,
                     int inIteration);
/// Gives the points of a constraint with restitution their bounce (mBounceVelocity): those that meet the
/// surface this step, faster than the threshold. inA/inB: the bodies' velocity change from this step's
/// gravity and forces (Integration::ForceVelocityChangeOf).
void InitBounces(const VelocityChange& inA, const VelocityChange& inB, float inDeltaTime,
                 const SolverSettings& inSettings, ContactConstraint& ioC);
/// The restitution pass, after the velocity iterations: the points InitBounces chose, that touched, leave at
/// their bounce velocity.
void ApplyRestitution(std::span<ContactConstraint* const> ioConstraints, std::span<SolverBody> ioBodies);
/// The part of inConstraint that the position iterations need.
void MakePositionConstraint(const ContactConstraint& inConstraint, PositionConstraint& outConstraint);
/// One position iteration; returns the largest remaining penetration beyond the slop.
float SolvePositions(std::span<const PositionConstraint> inConstraints, const SolverSettings& inSettings);
} // namespace SequentialImpulseSolver

} // namespace cairn::physics
