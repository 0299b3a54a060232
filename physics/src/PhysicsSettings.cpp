#include "cairn/physics/PhysicsSettings.h"

#include <bit>
#include <cmath>
#include <string>

namespace cairn::physics
{

namespace
{
/// Finite and within [inMin, inMax].
bool InRange(float inValue, float inMin, float inMax)
{
    return std::isfinite(inValue) && inValue >= inMin && inValue <= inMax;
}

Status Invalid(const std::string& inWhat)
{
    return MakeError(ErrorCode::InvalidArgument, "physics settings: " + inWhat);
}
} // namespace

Status ValidateSettings(const PhysicsSettings& inSettings)
{
    if (inSettings.mMaxBodies < 1 || inSettings.mMaxBodies > PhysicsSettings::cMaxBodiesLimit)
        return Invalid("mMaxBodies must be in 1.." + std::to_string(PhysicsSettings::cMaxBodiesLimit));
    if (!InRange(inSettings.mGravity.x(), -1e4f, 1e4f) || !InRange(inSettings.mGravity.y(), -1e4f, 1e4f) ||
        !InRange(inSettings.mGravity.z(), -1e4f, 1e4f))
        return Invalid("mGravity must be finite, at most 1e4 m/s^2 on each axis");
    if (!InRange(inSettings.mSpeculativeDistance, 0.0f, 10.0f))
        return Invalid("mSpeculativeDistance must be in [0, 10] m");
    if (!InRange(inSettings.mTimeBeforeSleep, 0.0f, 1e6f))
        return Invalid("mTimeBeforeSleep must be in [0, 1e6] s");
    if (!InRange(inSettings.mSleepVelocity, 0.0f, 1e6f))
        return Invalid("mSleepVelocity must be in [0, 1e6] m/s");
    switch (inSettings.mBroadPhase)
    {
    case BroadPhaseType::BruteForce:
    case BroadPhaseType::QuadTree:
    case BroadPhaseType::QuadTreeGlobalMutex:
        break;
    default:
        return Invalid("mBroadPhase is not a BroadPhaseType");
    }
    if (inSettings.mQueryReads != QueryReads::PublishedPoses &&
        inSettings.mQueryReads != QueryReads::BodyLocks)
        return Invalid("mQueryReads is not a QueryReads");
    if (inSettings.mNumBodyMutexes < 1 || inSettings.mNumBodyMutexes > 32 ||
        !std::has_single_bit(inSettings.mNumBodyMutexes))
        return Invalid("mNumBodyMutexes must be a power of two from 1 to 32");
    if (!InRange(inSettings.mPairCacheMaxDeltaPosition, 0.0f, 1.0f))
        return Invalid("mPairCacheMaxDeltaPosition must be in [0, 1] m");
    if (!InRange(inSettings.mPairCacheMaxDeltaAngle, 0.0f, cPi))
        return Invalid("mPairCacheMaxDeltaAngle must be in [0, pi]");
    if (!InRange(inSettings.mBroadPhaseCandidateMargin, 0.0f, 100.0f))
        return Invalid("mBroadPhaseCandidateMargin must be in [0, 100] m");
    const SolverSettings& solver = inSettings.mSolver;
    // Iteration counts bound the step's work: a typo of 10000 would look like a hang
    if (solver.mVelocityIterations < 1 || solver.mVelocityIterations > 1000)
        return Invalid("mSolver.mVelocityIterations must be in 1..1000");
    if (solver.mPositionIterations < 0 || solver.mPositionIterations > 1000)
        return Invalid("mSolver.mPositionIterations must be in 0..1000");
    if (!InRange(solver.mPenetrationSlop, 0.0f, 1.0f))
        return Invalid("mSolver.mPenetrationSlop must be in [0, 1] m");
    if (!InRange(solver.mBaumgarte, 0.0f, 1.0f)) return Invalid("mSolver.mBaumgarte must be in [0, 1]");
    if (!InRange(solver.mJointBaumgarte, 0.0f, 1.0f))
        return Invalid("mSolver.mJointBaumgarte must be in [0, 1]");
    if (!InRange(solver.mMaxPenetrationCorrection, 0.0f, 10.0f))
        return Invalid("mSolver.mMaxPenetrationCorrection must be in [0, 10] m");
    if (!InRange(solver.mRestitutionThreshold, 0.0f, 1e6f))
        return Invalid("mSolver.mRestitutionThreshold must be in [0, 1e6] m/s");
    return Status::Ok();
}

} // namespace cairn::physics
