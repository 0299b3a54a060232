#pragma once

// The warm start and velocity iterations of a colored island, four manifolds at a time, one in each lane of
// an SSE register. Within one color no two constraints share a dynamic body (and each static or kinematic
// side has a SolverBody block of its own), so four of them can be solved at once without conflict. Each lane
// does the arithmetic of SequentialImpulseSolver::WarmStart and SolveVelocities in the same order, so the
// bodies end with the same velocities bit for bit (PhysicsStep tests compare the two); what changes is speed:
// the scalar solver waits on one long chain of dependent operations per contact row, where here four chains
// run side by side.
//
// A batch is packed from its constraints once per step, solved by one thread per iteration (the thread that
// owns its part of the color), and its impulses are either unpacked back into the constraints (for the
// restitution pass) or stored straight into the contact cache. No locks: the batches of one color are split
// between threads, colors in turn.

#include "solver/ContactCache.h"
#include "solver/ContactConstraint.h"
#include "solver/SolverBody.h"

#include <span>

#if defined(__SSE2__)
#include <emmintrin.h>
#define CAIRN_WIDE_SOLVER 1
#else
#define CAIRN_WIDE_SOLVER 0
#endif

namespace cairn::physics
{

namespace WideContactSolver
{
/// SolverBody blocks a batch needs for its padding lanes (two per lane: A and B), zeroed by Pack.
inline constexpr uint32_t cPaddingBlocks = 8;
/// WideContactBatch::mCacheIndex of a padding lane.
inline constexpr uint32_t cInvalidCacheIndex = 0xffffffffu;
} // namespace WideContactSolver

#if CAIRN_WIDE_SOLVER

/// AxisImpulse for four lanes: component-major (x of the four lanes, then y, then z).
struct WideAxis
{
    __m128 mRAxAxis[3];
    __m128 mRBxAxis[3];
    __m128 mInvIA_RAxAxis[3];
    __m128 mInvIB_RBxAxis[3];
    __m128 mEffectiveMass;
    __m128 mAccumulated;
};

struct WideContactBatch
{
    uint32_t mFirst;        ///< First of its constraints in the step's island order
    uint32_t mCount;        ///< 1 to 4; lanes beyond it are padding with zero mass and zero impulse
    uint32_t mPaddingFirst; ///< First of the cPaddingBlocks SolverBody blocks its padding lanes use
    uint32_t mBodyA[4];     ///< SolverBody blocks of each lane
    uint32_t mBodyB[4];
    uint32_t mCacheIndex[4]; ///< Each lane's ContactConstraint::mCacheIndex (padding: cInvalidCacheIndex)
    __m128 mNormal[3];
    __m128 mTangent[2][3];
    __m128 mInvIA_Normal[3];
    __m128 mInvIB_Normal[3];
    __m128 mFriction;
    __m128 mTwistEffectiveMass;
    __m128 mTwistAccumulated;
    __m128 mTwistRadius;
    WideAxis mTangentAxis[2];
    WideAxis mPoint[ContactManifold::cMaxPoints]; ///< Points beyond a lane's count are zero: they do nothing
    __m128 mVelocityBias[ContactManifold::cMaxPoints];
    __m128 mMaxNormalImpulse[ContactManifold::cMaxPoints];
};

namespace WideContactSolver
{
/// Packs inConstraints (mCount of them, already bound to their SolverBody blocks; a null one is a padding
/// lane) into ioBatch, whose mFirst, mCount and mPaddingFirst are set (and kept). Padding lanes use the
/// blocks from mPaddingFirst on, zeroed here.
void Pack(std::span<ContactConstraint* const> inConstraints, std::span<SolverBody> ioBodies,
          WideContactBatch& ioBatch);
/// Applies the batches' accumulated (warm-start) impulses, as SequentialImpulseSolver::WarmStart does.
void WarmStart(std::span<const WideContactBatch> inBatches, std::span<SolverBody> ioBodies);
/// Velocity iteration inIteration over the batches, in order (points swept as the scalar solver does).
void SolveVelocities(std::span<WideContactBatch> ioBatches, std::span<SolverBody> ioBodies, int inIteration);
/// Copies the batch's impulses back into its constraints (null ones skipped).
void Unpack(const WideContactBatch& inBatch, std::span<ContactConstraint* const> ioConstraints);
/// Stores the batch's impulses in the contact cache for next step's warm start, as PhysicsStep::StoreImpulses
/// does from unpacked constraints whose restitution pass did not run (no deferred bounces): for an island
/// where nothing bounces, the constraints need not be unpacked at all.
void StoreImpulses(const WideContactBatch& inBatch, ContactCache& ioCache);
} // namespace WideContactSolver

#endif

} // namespace cairn::physics
