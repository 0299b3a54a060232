#pragma once

// SolvePlan: what the islands stage hands the solver. The step's constraints grouped by island, each island's
// in solve order (a colored island's by color, with its joints' colors beside them), which islands are solved
// how (by every thread, alone, or four small ones together in the wide solver's lanes), and the colors.
// Written by IslandStage on the updating thread; read by the solver's jobs, which also rewrite
// mIslandConstraints' entries (each task its own islands') to point at the copies they solve.

#include "solver/ContactConstraint.h"

#include <cstdint>
#include <span>
#include <vector>

namespace cairn::physics
{

struct SolvePlan
{
    /// An island with at most this many constraints is solved in a group of cGroupIslands, one per SSE lane.
    static constexpr uint32_t cGroupMaxConstraints = 4;
    static constexpr uint32_t cGroupIslands = 4;

    /// A unit of the other islands' solve: one island (mGroup = UINT32_MAX) or up to four small ones solved
    /// together (IslandSolver::SolveIslandGroup), mCount islands of mSolvedIslands from mFirst.
    struct SolveItem
    {
        uint32_t mFirst;
        uint32_t mCount;
        uint32_t mGroup; ///< Which group's padding blocks
    };

    std::vector<uint32_t> mConstraintStart; ///< Per island offsets into mIslandConstraints
    std::vector<uint8_t> mIslandBounces;    ///< Per island: 1 if a constraint has restitution
    /// Constraints grouped by island, in solve order: the narrow phase's, until the solver points the ones it
    /// copies at their copies
    std::vector<ContactConstraint*> mIslandConstraints;
    std::vector<uint32_t>
        mColoredIslands; ///< This step's colored islands solved by all threads, largest first
    /// This step's other islands that have constraints: the larger ones largest first, then the small ones
    std::vector<uint32_t> mSolvedIslands;
    std::vector<SolveItem> mSolveItems;
    uint32_t mNumIslandGroups = 0;
    /// The active indices of the bodies alone in an island without any constraint (falling, flying): they
    /// only integrate, many to a chunk
    std::vector<uint32_t> mUnconstrainedBodies;

    std::vector<uint32_t> mIslandFirstColor; ///< Per island: first entry in mColorStart (colored ones)
    std::vector<uint32_t>
        mColorStart; ///< Offsets into mIslandConstraints; a color ends where the next starts
    std::vector<uint8_t> mColorIsSerial; ///< Per mColorStart entry: 1 for the range of uncolored constraints
    /// Per mColorStart entry: its joints' first entry in mColorJoints (a color's joints share no dynamic body
    /// with each other nor with the color's contacts); the end marker: the island's end
    std::vector<uint32_t> mColorJointStart;
    std::vector<uint32_t> mColorJoints; ///< The colored islands' joints (JointStage's step indices) by color
    /// Per mColorStart entry: the color's first batch of four in the wide solver's batches (the end marker:
    /// the island's end). Every colored island has its own slice, so islands solved alone at once never share
    /// batches
    std::vector<uint32_t> mColorFirstBatch;
    uint32_t mNumWideBatches = 0; ///< The step's wide batches, all colored islands together

    /// An island's constraints, in solve order.
    std::span<ContactConstraint* const> ConstraintsOf(uint32_t inIsland) const
    {
        return {mIslandConstraints.data() + mConstraintStart[inIsland],
                mIslandConstraints.data() + mConstraintStart[inIsland + 1]};
    }
    /// The constraints of color inColor (of the colored islands), in solve order.
    std::span<ContactConstraint* const> ColorConstraints(uint32_t inColor) const
    {
        return {mIslandConstraints.data() + mColorStart[inColor],
                mIslandConstraints.data() + mColorStart[inColor + 1]};
    }
    /// The joints of color inColor (of the colored islands).
    std::span<const uint32_t> ColorJoints(uint32_t inColor) const
    {
        return {mColorJoints.data() + mColorJointStart[inColor],
                mColorJoints.data() + mColorJointStart[inColor + 1]};
    }
    bool IsColored(uint32_t inIsland) const { return mIslandFirstColor[inIsland] != UINT32_MAX; }
};

} // namespace cairn::physics
