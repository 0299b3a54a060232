#pragma once

// ContinuousCollision: the linear cast of MotionQuality::LinearCast bodies, after the solve and before the
// finish. Each such body that moved more than half its smallest half extent is swept from where it started
// the step (its final pose less the step's displacement, at its final rotation) to where the solver put it,
// against everything its layer collides with at their final poses; if it would touch something on the way,
// it is moved back to just before the first touch (conservative advancement: for a translation every point of
// the body moves alike, so a step of separation / (displacement . normal) along the closest contact's normal
// can never pass through). Its velocity is kept: the next step's contacts meet the surface it now touches,
// with the solver's friction, restitution and both bodies' masses, and wake a sleeping body it hit.
//
// Threads: Count on the step's jobs (a relaxed counter); Run on the updating thread alone, the bodies in
// active-list order, so a body cast later meets one cast before where that one was left: the same for any
// thread count.

#include <atomic>
#include <cstdint>
#include <span>

namespace cairn::physics
{

struct StepContext;
class Body;

class ContinuousCollision
{
public:
    void BeginStep() { mNumLinearCast.store(0, std::memory_order_relaxed); } // Relaxed: no job runs yet
    /// Counts the linear-cast bodies among inBodies (active-list entries): Run has nothing to do without any.
    void Count(const StepContext& inContext, std::span<const uint32_t> inBodies);
    /// The casts; returns how many bodies were moved back.
    uint32_t Run(const StepContext& inContext);

private:
    /// Casts one body; true if it was moved back.
    bool Cast(const StepContext& inContext, Body& ioBody) const;

    /// Linear-cast bodies this step. Relaxed: a count, read after the jobs that add to it were waited for
    std::atomic<uint32_t> mNumLinearCast{0};
};

} // namespace cairn::physics
