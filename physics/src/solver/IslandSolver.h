#pragma once

// IslandSolver: the solve of one step, island by island, from the islands stage's plan. The velocity solver
// works on packed copies of the velocities (SolverBody); each island's iterations, then its restitution
// pass, the position half of integration (Integration), its position iterations and the impulses stored for
// next step's warm start. Islands share no dynamic body and no constraint: the colored islands that hold a
// quarter of the step are solved one at a time by every thread (a stage per color per pass), the others at
// once, largest first, each by one thread (small ones four to a group in the wide solver's lanes).
//
// Threads: Solve on the updating thread; its loops and islands on the step's jobs. A job writes only its
// islands' constraints, their bodies, their solver blocks, position constraints and cache entries; a colored
// island solved by every thread is written part by part between the stages of StepScheduler::RunStages.

#include "islands/SolvePlan.h"
#include "solver/ContactConstraint.h"
#include "solver/SequentialImpulseSolver.h"
#include "solver/SolverBody.h"
#include "solver/WideContactSolver.h"

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace cairn::physics
{

class JointStage;

struct StepContext;
class Body;

class IslandSolver
{
public:
    /// Solves every island of ioPlan, integrates kinematic bodies and the bodies alone in their islands.
    /// inNumConstraints: the step's.
    /// ioJoints: the step's joints, solved in their islands' passes (a colored island's by color).
    void Solve(const StepContext& inContext, SolvePlan& ioPlan, uint32_t inNumConstraints,
               JointStage& ioJoints);

private:
    void SolveIsland(uint32_t inIsland);
    /// Solves two to four small islands (at most cGroupMaxConstraints constraints each) together, one per
    /// lane of the wide solver, with the same results as SolveIsland on each; inPaddingFirst: the group's
    /// padding blocks.
    void SolveIslandGroup(std::span<const uint32_t> inIslands, uint32_t inPaddingFirst);
    /// An island's restitution pass, integration, position iterations and impulse store, after its
    /// velocities.
    void FinishIsland(uint32_t inIsland);
    /// Solves a colored island with every thread: each color's constraints in parallel, the colors in turn;
    /// or, inAlone, on this thread only (the same results: within a color the order changes nothing).
    void SolveColoredIsland(uint32_t inIsland, bool inAlone);
    /// The velocity iterations of a colored island whose colors are [inFirstColor, inLastColor], four
    /// manifolds at a time (WideContactSolver), on constraints that were not copied (see Solve): this also
    /// gives them their solver blocks and position constraints. inStoreImpulses: store the impulses in the
    /// contact cache straight from the batches (no restitution pass follows); else unpack them.
    void SolveColoredVelocitiesWide(uint32_t inFirstColor, uint32_t inLastColor, bool inStoreImpulses,
                                    bool inAlone);
    /// Binds constraint inIndex of the plan's island constraints to its solver blocks and makes its position
    /// constraint.
    void PrepareForSolve(uint32_t inIndex, uint32_t inNumActive);
    /// Copies the plan's island constraints [inBegin, inEnd) into mSolveOrder, points the plan at the copies
    /// and prepares each (PrepareForSolve).
    void CopyIntoSolveOrder(uint32_t inBegin, uint32_t inEnd);
    /// Stores the constraints' impulses in the contact cache for next step's warm start.
    void StoreImpulses(std::span<ContactConstraint* const> inConstraints) const;
    static void LoadSolverBody(const Body& inBody, SolverBody& outBlock);
    /// Where the solver finds inBody's velocities: its active index if dynamic, else inPrivateBlock (loaded).
    uint32_t SolverBodyIndex(const Body& inBody, uint32_t inPrivateBlock);
    /// Copies a dynamic body's solved velocities back and integrates its position (others: nothing).
    void StoreVelocitiesAndIntegrate(Body& ioBody) const;
    /// Starts fetching every cache line of a constraint (they lie scattered over the narrow phase's chunks).
    static void PrefetchConstraint(const ContactConstraint* inConstraint)
    {
        const char* bytes = reinterpret_cast<const char*>(inConstraint);
        for (size_t offset = 0; offset < sizeof(ContactConstraint); offset += 64)
            __builtin_prefetch(bytes + offset);
    }
    /// An island's position constraints, in solve order.
    std::span<const PositionConstraint> PositionConstraintsOf(uint32_t inIsland) const
    {
        return {mPositionConstraints.data() + mPlan->mConstraintStart[inIsland],
                mPositionConstraints.data() + mPlan->mConstraintStart[inIsland + 1]};
    }

    const StepContext* mContext = nullptr; ///< During Solve only
    SolvePlan* mPlan = nullptr;            ///< During Solve only
    JointStage* mJoints = nullptr;         ///< During Solve only

    std::vector<ContactConstraint> mSolveOrder; ///< The other islands' constraints copied in solve order
    /// Ranges of the plan's island constraints copied into mSolveOrder before the solve, each one task of the
    /// copy: the colored islands that every thread solves, when they are copied (the others are copied by
    /// the thread that solves them)
    std::vector<std::pair<uint32_t, uint32_t>> mCopyRanges;
    std::vector<PositionConstraint> mPositionConstraints; ///< Per entry of the plan's island constraints
    std::vector<SolverBody> mSolverBodies;                ///< Velocities being solved: see Solve
#if CAIRN_WIDE_SOLVER
    /// The colored islands' packed constraints (see SolvePlan::mColorFirstBatch). Each island's slice is
    /// written by the thread that solves it alone, or by all threads in parts of a color between two stages
    std::vector<WideContactBatch> mWideBatches;
#endif
    uint32_t mPaddingBlocksFirst = 0; ///< In mSolverBodies: WideContactSolver::cPaddingBlocks per color
};

} // namespace cairn::physics
