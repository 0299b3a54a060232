#pragma once

// Solver tuning, shared by every island of a step. Plain value type.

namespace cairn::physics
{

struct SolverSettings
{
    int mVelocityIterations = 10;    ///< Sequential impulse iterations on velocities
    int mPositionIterations = 2;     ///< Non-linear Gauss-Seidel iterations on positions
    float mPenetrationSlop = 0.005f; ///< m of penetration left alone, so resting contacts stay touching
    float mBaumgarte = 0.2f;         ///< Fraction of the remaining penetration removed per position iteration
    float mMaxPenetrationCorrection = 0.2f; ///< m per position iteration, so deep overlaps do not explode
    float mRestitutionThreshold = 1.0f;     ///< m/s of approach below which contacts do not bounce
    /// Velocity iterations of large (colored) islands four manifolds at a time with SSE, where available.
    /// Same results bit for bit as the scalar solver (false), which is kept for comparison
    bool mWideColoredIslands = true;
    /// An island whose constraints join the same bodies in the same solve order as an island colored in the
    /// previous step takes that coloring over (the coloring depends on nothing else: same results bit for
    /// bit); likewise a step whose constraints come with the same keys in the same order as the previous
    /// step's takes its solve order over. False colors every island and sorts every step anew, for comparison
    bool mReuseColorings = true;
};

} // namespace cairn::physics
