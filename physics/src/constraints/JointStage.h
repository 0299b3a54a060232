#pragma once

// JointStage: the step's part of the joints (ConstraintManager). At the step's start it takes the enabled
// joints whose bodies are in the world and wakes a sleeping dynamic body jointed to an active one (through
// chains of joints, in slot order); after the narrow phase it links the islands of the joints' two active
// dynamic bodies; after the islands are numbered it groups the joints by island (slot order within one). The
// solver then runs each island's joints in the island's passes: warm start and velocity rows before the
// contacts', and position rows before the contacts' after integration; in a large island colored for every
// thread, a color's joints before its contacts, the colors in turn (IslandStage::ColorIsland).
//
// Threads: BeginStep, LinkIslands and GroupByIsland on the updating thread, while Update holds the joints'
// mutex (LinkIslands' loop on the step's jobs, each joint by one of them); the solve calls from the thread
// that solves the island, which writes only that island's joints and its bodies; or, in a colored island,
// from the threads that solve a color's parts, each writing only its part's joints and their bodies (a
// color's joints and contacts share no dynamic body).

#include "constraints/ConstraintManager.h"
#include "math/UninitializedAllocator.h"
#include "solver/SolverBody.h"

#include <span>
#include <vector>

namespace cairn::physics
{

struct SolverSettings;
struct StepContext;
class Body;
class Integration;

class JointStage
{
public:
    /// Before the islands are reset for this step (active bodies may be added). inIntegration: the step's,
    /// whose world inverse inertias, kept from the velocity half, the velocity passes' rows read (the bodies
    /// have not turned since).
    void BeginStep(const StepContext& inContext, ConstraintManager& ioManager,
                   const Integration& inIntegration);
    /// After the narrow phase's last merge, before the islands are finalized.
    void LinkIslands(const StepContext& inContext);
    /// After the islands are finalized.
    void GroupByIsland(const StepContext& inContext);

    uint32_t GetNumStepJoints() const { return uint32_t(mStepJoints.size()); }

    /// The island's joints: indices of this step's joints, in slot order (none without the table: a step
    /// without joints does not build it).
    std::span<const uint32_t> GetIslandJoints(uint32_t inIsland) const
    {
        if (mStepJoints.empty()) return {};
        return {mIslandJoints.data() + mJointStart[inIsland],
                mIslandJoints.data() + mJointStart[inIsland + 1]};
    }
    /// The active indices of step joint inJoint's two bodies, UINT32_MAX for a side that is not an active
    /// dynamic body (the world, static, kinematic): what a coloring keeps apart.
    void GetActiveIndices(uint32_t inJoint, uint32_t& outA, uint32_t& outB) const;

    // The solve of step joints inJoints (an island's, or a color's part of a colored island's), by the thread
    // that solves them; ioBodies: the solver's velocity blocks by active index. Joints solved at once on
    // other threads must share no dynamic body with these
    /// Sets the rows from the poses at the step's start and applies the last step's impulses.
    void WarmStart(std::span<const uint32_t> inJoints, std::span<SolverBody> ioBodies);
    void SolveVelocities(std::span<const uint32_t> inJoints, std::span<SolverBody> ioBodies);
    /// One position iteration, on the integrated poses.
    void SolvePositions(std::span<const uint32_t> inJoints, const SolverSettings& inSettings);

    /// After the solve, on the updating thread: the joints whose force or torque this step was above their
    /// thresholds are disabled and reported, in slot order.
    void BreakOverloaded();

private:
    struct StepJoint
    {
        Joint* mJoint;
        Body* mA; ///< Null: the world
        Body* mB;
        SolverBody mBlockA; ///< The velocity block of a side that is not dynamic (static, kinematic, world)
        SolverBody mBlockB;
        // As the last Prepare found them
        Vec3 mAnchorA = Vec3::Zero(); ///< World space
        Vec3 mAnchorB = Vec3::Zero();
        bool mRowActive = false; ///< A distance joint out of its limits (or a rod), a slider past a limit
        float mError = 0.0f;     ///< Its length (a slider's place) less the limit it is at
    };
    /// Which rows a Prepare sets: all of them (the velocity passes), or only those with a position to take
    /// out (a position iteration: no motor or friction row, whose next use is after the next step's
    /// Prepare).
    enum class Rows
    {
        All,
        WithPosition
    };
    /// The joint's rows at its bodies' current poses (arms, anchors, masses; a distance joint's axis, error
    /// and limit).
    void Prepare(StepJoint& ioJoint, Rows inRows = Rows::All);
    /// A joint side's arm (centre of mass to anchor, world space), anchor and masses at its pose now; the
    /// world's side: its point, no arm, nothing that moves. inRows All: the body has not turned since the
    /// velocity half, whose inverse inertia is read instead of computed again.
    void SideOf(const Body* inBody, const Vec3& inLocal, Rows inRows, Vec3& outArm, Vec3& outAnchor,
                JointBodyMass& outMass) const;
    /// Only the point's rows (and the anchors) of a joint that has them: after a position iteration turned
    /// its bodies.
    void PreparePoint(StepJoint& ioJoint);
    /// inVisit(part) for each of the joint's velocity rows now in play, in solve order.
    template <class Visit> static void VisitVelocityRows(StepJoint& ioJoint, const Visit& inVisit);
    /// Moves the joint's dynamic bodies by a position iteration's correction.
    static void ApplyCorrection(StepJoint& ioJoint, const PointJointPart::PoseCorrection& inCorrection);
    SolverBody& BlockA(StepJoint& ioJoint, std::span<SolverBody> ioBodies) const;
    SolverBody& BlockB(StepJoint& ioJoint, std::span<SolverBody> ioBodies) const;

    /// What a joint is this step (BeginStep): none of the step's, one of them, or one with a sleeping dynamic
    /// body to wake first; outA and outB its bodies (null: the world). Reads the joint and its bodies only:
    /// any of the step's threads.
    enum class Verdict : uint8_t
    {
        Skip,
        Take,
        Wake
    };
    Verdict VerdictOf(const Joint& inJoint, Body*& outA, Body*& outB) const;
    /// The step's joints, found on all the step's threads, when no joint has a body to wake; else false and
    /// nothing taken (BeginStep's serial pass then wakes them in slot order).
    bool TakeJointsOnAllThreads(std::vector<Joint>& ioJoints);

    const StepContext* mContext = nullptr;
    const Integration* mIntegration = nullptr; ///< This step's (BeginStep's)
    ConstraintManager* mManager = nullptr;     ///< This step's (BeginStep's)
    /// This step's joints, in slot order. Grown unwritten (UninitializedAllocator): the chunks that take the
    /// joints on all threads write every entry
    std::vector<StepJoint, UninitializedAllocator<StepJoint>> mStepJoints;
    std::vector<uint32_t> mBreakableJoints; ///< Indices into mStepJoints of those with a threshold
    std::vector<uint32_t> mJointStart;      ///< Per island, offsets into mIslandJoints
    std::vector<uint32_t> mIslandJoints;    ///< Indices into mStepJoints, by island
    std::vector<uint32_t> mJointIsland;     ///< Scratch: per step joint
    std::vector<uint32_t> mCursor;      ///< Scratch of GroupByIsland (kept: a warm step allocates nothing)
    std::vector<uint32_t> mChunkCounts; ///< Scratch of TakeJointsOnAllThreads (kept, as above)
};

} // namespace cairn::physics
