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
    /// Fraction of a joint's error removed per position iteration (within Box2D's 0.2 m and 8 degrees an
    /// iteration). All of it, as Box2D's joints: a fast-swinging chain drifts a centimetre a step per joint
    /// (its rows hold the anchors' velocities, not their arcs) and a fifth an iteration lets it stretch by
    /// percents; contacts keep mBaumgarte, which stops them popping apart
    float mJointBaumgarte = 1.0f;
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
