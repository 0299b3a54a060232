#pragma once

// StepCosts: the step's loops, how they are cut and what an item of each costs, in one table. The costs are
// estimates measured on step_pile2k on one thread (cairn-bench-step); StepScheduler::ParallelFor hands a loop
// to sleeping workers only when its estimate is worth their waking. The grains keep each chunk's work well
// above a hand-off's cost on 2 threads; on more, StepScheduler::GrainFor cuts a loop finer (never coarser) so
// that each thread has several chunks. A change of machine changes the figures, never the results: no cost or
// grain reaches the arithmetic.

#include <cstdint>

namespace cairn::physics::StepCosts
{

/// A loop over items cut into chunks of at most mGrain (StepScheduler::GrainFor), each item costing about
/// mItemNanoseconds.
struct Loop
{
    uint32_t mGrain;
    uint32_t mItemNanoseconds;
};

// Velocities: a body's forces, damping and world inertia (Integration::IntegrateVelocities)
inline constexpr Loop cVelocities{256, 30};
// Pairs: a body's walks of the broad phase's trees
inline constexpr Loop cPairs{64, 300};
// The pairs' gathering and sort, serial, per pair: the narrow phase's loop follows
inline constexpr uint32_t cPairSortNanoseconds = 10;
// Narrow phase: a body pair's shapes collided (pile2k's boxes; a box on a height field takes more)
inline constexpr Loop cNarrowPhase{32, 425};
// The merge's copies, per pair; a task copies whole chunks of the narrow phase
inline constexpr Loop cMergeCopies{128, 38};
// The step's joints taken at its start: a joint's state and its bodies' (JointStage::BeginStep)
inline constexpr Loop cJointsTaken{256, 30};
// The joints' island links: a union per joint
inline constexpr Loop cJointLinks{256, 20};
// Island finalization and the constraints' ordering, serial, per constraint (about 18 ns in a pyramid): the
// solve's loops follow
inline constexpr uint32_t cIslandsNanoseconds = 20;
// The solver's velocity blocks, per active body
inline constexpr Loop cLoadSolverBodies{512, 7};
// Copying constraints into solve order, with their binding; a colored island that every thread solves is
// copied before, in tasks of up to cCopyTask constraints
inline constexpr uint32_t cCopyTask = 512;
inline constexpr uint32_t cCopyNanoseconds = 110;
// A constraint's iterations, integration and position passes in an island or a group of small ones
inline constexpr uint32_t cSolveNanoseconds = 500;
// A body alone in its island: an integration
inline constexpr Loop cUnconstrainedBodies{256, 15};
// The finish: a body's bounds, broad-phase move and publication
inline constexpr Loop cFinish{256, 90};
// A colored island's loops over its bodies and constraints (every thread, awake: no estimate)
inline constexpr uint32_t cColoredIslandGrain = 256;
// A colored island's color is cut into parts of at least this many constraints (scalar) or batches of four
// (wide: the same 32 constraints)
inline constexpr uint32_t cMinConstraintsPerPart = 32;
inline constexpr uint32_t cMinBatchesPerPart = 8;

} // namespace cairn::physics::StepCosts
