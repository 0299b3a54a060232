#pragma once

// SweptBoxes: the broad-phase box of an active body reaches over where the body can go this step, from the
// step's first velocities on. The finish gives each body its bounds swept over the next step plus the
// speculative distance; a body that no finish has boxed yet (added, moved by hand or woken since), or whose
// velocity outgrew its box (set by hand), would otherwise find its pairs from its bounds alone in its first
// step, and a fast one would pass through a floor it never met. Right after the velocity half, such a body
// gets the box the finish would have given it, so the finish's check of the box it holds stays true.
//
// Threads: the step's jobs, each on a range of active bodies of its own, after their velocity half; the broad
// phase takes moves from any thread.

#include "cairn/physics/math/AABB.h"

#include <cstdint>
#include <span>

namespace cairn::physics
{

struct StepContext;

namespace SweptBoxes
{
/// inBounds swept by inSweep (a step's motion), grown by inSpeculativeDistance: the box the broad phase holds
/// for an active body.
AABB Of(const AABB& inBounds, const Vec3& inSweep, float inSpeculativeDistance);

/// Re-boxes the bodies of inBodies (active-list entries, velocities integrated) whose box does not cover
/// this step's motion.
void CoverThisStep(const StepContext& inContext, std::span<const uint32_t> inBodies);
} // namespace SweptBoxes

} // namespace cairn::physics
