#include "solver/IslandSolver.h"

#include "body/Integration.h"
#include "constraints/JointStage.h"
#include "step/StepContext.h"
#include "step/StepCosts.h"

#include <algorithm>
#include <array>

namespace cairn::physics
{

void IslandSolver::Solve(const StepContext& inContext, SolvePlan& ioPlan, uint32_t inNumConstraints,
                         JointStage& ioJoints)
{
    mContext = &inContext;
    mJoints = &ioJoints;
    mPlan = &ioPlan;
    const StepScheduler& scheduler = inContext.mScheduler;
    // The velocity solver works on packed copies of the velocities (SolverBody): one block per active body,
    // at its active index, and after those one private block per constraint side that is static or
    // kinematic. Such a body is shared between islands; with a block of its own per constraint and zero
    // inverse mass, the solver may write to it without a test and without a race
    const std::vector<uint32_t>& active = mContext->mActive;
    const uint32_t numActive = uint32_t(active.size());
    mPaddingBlocksFirst = numActive + 2 * uint32_t(mPlan->mIslandConstraints.size());
    mSolverBodies.resize(mPaddingBlocksFirst + WideContactSolver::cPaddingBlocks *
                                                   (mPlan->mColorStart.size() + mPlan->mNumIslandGroups));
    const uint32_t groupPaddingFirst =
        mPaddingBlocksFirst + WideContactSolver::cPaddingBlocks * uint32_t(mPlan->mColorStart.size());
    // A kinematic body moves by its velocity alone: integrated here, while its lines are at hand, in the loop
    // that reads every active body anyway (a serial pass over them cost every step a miss per body). Nothing
    // before the islands' solve reads a pose
    scheduler.ParallelFor(numActive, StepCosts::cLoadSolverBodies,
                          [&](uint32_t inBegin, uint32_t inEnd)
                          {
                              for (uint32_t i = inBegin; i < inEnd; ++i)
                              {
                                  Body& body = mContext->BodyAt(active[i]);
                                  LoadSolverBody(body, mSolverBodies[i]);
                                  if (body.IsKinematic())
                                      Integration::IntegratePositions(body, mContext->mDeltaTime);
                              }
                          });

    // The scalar solver walks each island's constraints ten times and more: copied into solve order they are
    // read front to back (the hardware prefetcher streams them), where through the pointers they were a cache
    // miss each (a third of the solver's time). Not the colored islands that the wide solver packs: their
    // iterations read the packed batches, which are made straight from the narrow phase's buffers, and the
    // copy (4.7 MB read and written in a pyramid of 8,500 manifolds) was a tenth of that step. An island
    // solved by one thread is copied by that thread as its solve begins, so that its iterations read what
    // its own core just wrote; one that every thread solves is copied before, in a loop of its own
    mSolveOrder.resize(mPlan->mIslandConstraints.size());
    mPositionConstraints.resize(mPlan->mIslandConstraints.size());
    const bool packColored = CAIRN_WIDE_SOLVER && mContext->mSettings.mSolver.mWideColoredIslands;
    mCopyRanges.clear();
    if (!packColored)
        for (uint32_t island : mPlan->mColoredIslands)
            for (uint32_t begin = mPlan->mConstraintStart[island], end = mPlan->mConstraintStart[island + 1];
                 begin < end; begin = std::min(end, begin + StepCosts::cCopyTask))
                mCopyRanges.push_back({begin, std::min(end, begin + StepCosts::cCopyTask)});
    scheduler.ParallelFor(uint32_t(mCopyRanges.size()), 1, StepCosts::cCopyTask * StepCosts::cCopyNanoseconds,
                          [&](uint32_t inBegin, uint32_t inEnd)
                          {
                              for (uint32_t range = inBegin; range < inEnd; ++range)
                                  CopyIntoSolveOrder(mCopyRanges[range].first, mCopyRanges[range].second);
                          });

#if CAIRN_WIDE_SOLVER
    mWideBatches.resize(mPlan->mNumWideBatches); // Each colored island's slice: see IslandStage::ColorIsland
#endif
    // Islands share no dynamic body and no constraint. The colored islands with a quarter of the step first,
    // one at a time with every thread on each; then the others at once, the largest first so that the longest
    // starts early and the small ones fill in around it (colored ones among them by one thread each)
    uint32_t numItemConstraints = inNumConstraints;
    for (uint32_t island : mPlan->mColoredIslands)
    {
        SolveColoredIsland(island, false);
        numItemConstraints -= mPlan->mConstraintStart[island + 1] - mPlan->mConstraintStart[island];
    }
    scheduler.ParallelFor(
        uint32_t(mPlan->mSolveItems.size()), 1,
        StepScheduler::PerItem(uint64_t(StepCosts::cSolveNanoseconds + StepCosts::cCopyNanoseconds) *
                                   numItemConstraints,
                               mPlan->mSolveItems.size()),
        [&](uint32_t inBegin, uint32_t inEnd)
        {
            for (uint32_t i = inBegin; i < inEnd; ++i)
            {
                const SolvePlan::SolveItem& item = mPlan->mSolveItems[i];
                for (uint32_t k = item.mFirst; k < item.mFirst + item.mCount; ++k)
                    if (const uint32_t solved = mPlan->mSolvedIslands[k];
                        !packColored || mPlan->mIslandFirstColor[solved] == UINT32_MAX) // Else packed
                        CopyIntoSolveOrder(mPlan->mConstraintStart[solved],
                                           mPlan->mConstraintStart[solved + 1]);
                const uint32_t island = mPlan->mSolvedIslands[item.mFirst];
                if (item.mGroup == UINT32_MAX && mPlan->mIslandFirstColor[island] != UINT32_MAX)
                    SolveColoredIsland(island, true);
                else if (item.mGroup == UINT32_MAX)
                    SolveIsland(island);
                else
                    SolveIslandGroup(
                        std::span<const uint32_t>(mPlan->mSolvedIslands.data() + item.mFirst, item.mCount),
                        groupPaddingFirst + WideContactSolver::cPaddingBlocks * item.mGroup);
            }
        });
    // A body with nothing to solve keeps the velocity its forces gave it. One chunk per island made the
    // threads fight over the chunk cursor when thousands of bodies fall freely
    scheduler.ParallelFor(uint32_t(mPlan->mUnconstrainedBodies.size()), StepCosts::cUnconstrainedBodies,
                          [&](uint32_t inBegin, uint32_t inEnd)
                          {
                              for (uint32_t i = inBegin; i < inEnd; ++i)
                                  if (Body& body = mContext->BodyAt(active[mPlan->mUnconstrainedBodies[i]]);
                                      body.IsDynamic())
                                      Integration::IntegratePositions(body, mContext->mDeltaTime);
                          });
}

void IslandSolver::LoadSolverBody(const Body& inBody, SolverBody& outBlock)
{
    outBlock.mLinearVelocity = inBody.mLinearVelocity;
    outBlock.mAngularVelocity = inBody.mAngularVelocity;
    outBlock.mInverseMass = inBody.IsDynamic() ? inBody.mInvMass : 0.0f;
    outBlock.mPadding = 0.0f;
}

void IslandSolver::CopyIntoSolveOrder(uint32_t inBegin, uint32_t inEnd)
{
    const uint32_t numActive = uint32_t(mContext->mActive.size());
    // The sources are scattered over the narrow phase's chunks: fetching each one's cache lines a few
    // constraints ahead overlaps the misses that the copy otherwise waits for in turn
    constexpr uint32_t cAhead = 4;
    for (uint32_t i = inBegin; i < std::min(inEnd, inBegin + cAhead); ++i)
        PrefetchConstraint(mPlan->mIslandConstraints[i]);
    for (uint32_t i = inBegin; i < inEnd; ++i)
    {
        if (i + cAhead < inEnd) PrefetchConstraint(mPlan->mIslandConstraints[i + cAhead]);
        mSolveOrder[i] = *mPlan->mIslandConstraints[i];
        mPlan->mIslandConstraints[i] = &mSolveOrder[i];
        PrepareForSolve(i, numActive);
    }
}

void IslandSolver::PrepareForSolve(uint32_t inIndex, uint32_t inNumActive)
{
    ContactConstraint& c = *mPlan->mIslandConstraints[inIndex];
    c.mSolverBodyA = SolverBodyIndex(*c.mBodyA, inNumActive + 2 * inIndex);
    c.mSolverBodyB = SolverBodyIndex(*c.mBodyB, inNumActive + 2 * inIndex + 1);
    SequentialImpulseSolver::MakePositionConstraint(c, mPositionConstraints[inIndex]);
}

uint32_t IslandSolver::SolverBodyIndex(const Body& inBody, uint32_t inPrivateBlock)
{
    if (inBody.IsDynamic()) return inBody.GetActiveIndex();
    LoadSolverBody(inBody, mSolverBodies[inPrivateBlock]);
    return inPrivateBlock;
}

void IslandSolver::StoreVelocitiesAndIntegrate(Body& ioBody) const
{
    if (!ioBody.IsDynamic()) return;
    const SolverBody& block = mSolverBodies[ioBody.GetActiveIndex()];
    ioBody.mLinearVelocity = block.mLinearVelocity;
    ioBody.mAngularVelocity = block.mAngularVelocity;
    Integration::IntegratePositions(ioBody, mContext->mDeltaTime);
}

void IslandSolver::SolveIsland(uint32_t inIsland)
{
    const std::span<ContactConstraint* const> constraints = mPlan->ConstraintsOf(inIsland);
    const SolverSettings& solver = mContext->mSettings.mSolver;
    const std::span<SolverBody> solverBodies(mSolverBodies);
    // Joints before contacts in each pass (as Jolt and Box2D): the contacts, solved last, keep bodies apart
    const std::span<const uint32_t> joints = mJoints->GetIslandJoints(inIsland); // Most islands: none
    mJoints->WarmStart(joints, solverBodies);
    SequentialImpulseSolver::WarmStart(constraints, solverBodies);
    for (int i = 0; i < solver.mVelocityIterations; ++i)
    {
        mJoints->SolveVelocities(joints, solverBodies);
        SequentialImpulseSolver::SolveVelocities(constraints, solverBodies, i);
    }
    FinishIsland(inIsland);
}

void IslandSolver::SolveIslandGroup([[maybe_unused]] std::span<const uint32_t> inIslands,
                                    [[maybe_unused]] uint32_t inPaddingFirst)
{
#if CAIRN_WIDE_SOLVER
    // Row r holds constraint r of each island, one island per lane (null: padding). Each lane then does its
    // island's scalar arithmetic in its order, so the result is SolveIsland's bit for bit
    std::array<std::array<ContactConstraint*, SolvePlan::cGroupIslands>, SolvePlan::cGroupMaxConstraints>
        rows{};
    uint32_t numRows = 0;
    for (uint32_t lane = 0; lane < inIslands.size(); ++lane)
    {
        const std::span<ContactConstraint* const> constraints = mPlan->ConstraintsOf(inIslands[lane]);
        for (uint32_t row = 0; row < constraints.size(); ++row)
            rows[row][lane] = constraints[row];
        numRows = std::max(numRows, uint32_t(constraints.size()));
    }
    const std::span<SolverBody> solverBodies(mSolverBodies);
    WideContactBatch batches[SolvePlan::cGroupMaxConstraints];
    for (uint32_t row = 0; row < numRows; ++row)
    {
        batches[row].mFirst = 0;
        batches[row].mCount = SolvePlan::cGroupIslands;
        batches[row].mPaddingFirst = inPaddingFirst;
        WideContactSolver::Pack(rows[row], solverBodies, batches[row]);
    }
    const std::span<WideContactBatch> all(batches, numRows);
    WideContactSolver::WarmStart(all, solverBodies);
    for (int i = 0; i < mContext->mSettings.mSolver.mVelocityIterations; ++i)
        WideContactSolver::SolveVelocities(all, solverBodies, i);
    for (uint32_t row = 0; row < numRows; ++row)
        WideContactSolver::Unpack(batches[row], rows[row]);
    for (uint32_t island : inIslands)
        FinishIsland(island);
#endif
}

void IslandSolver::FinishIsland(uint32_t inIsland)
{
    const std::span<ContactConstraint* const> constraints = mPlan->ConstraintsOf(inIsland);
    const SolverSettings& solver = mContext->mSettings.mSolver;
    SequentialImpulseSolver::ApplyRestitution(constraints, std::span<SolverBody>(mSolverBodies));

    const std::vector<uint32_t>& active = mContext->mActive;
    for (uint32_t activeIndex : mContext->mIslands.GetBodies(inIsland))
        StoreVelocitiesAndIntegrate(mContext->BodyAt(active[activeIndex]));

    const std::span<const uint32_t> joints = mJoints->GetIslandJoints(inIsland);
    for (int i = 0; i < solver.mPositionIterations; ++i)
    {
        mJoints->SolvePositions(joints, solver);
        SequentialImpulseSolver::SolvePositions(PositionConstraintsOf(inIsland), solver);
    }

    StoreImpulses(constraints);
}

void IslandSolver::StoreImpulses(std::span<ContactConstraint* const> inConstraints) const
{
    for (const ContactConstraint* c : inConstraints)
    {
        CachedManifold& cached = mContext->mContactCache.Get(c->mCacheIndex);
        for (int i = 0; i < c->mNumPoints; ++i)
            cached.mNormalImpulse[i] = c->mPoints[i].mNormal.mAccumulated;
        cached.mFrictionImpulse = c->mPatch.mTangent[0].mAccumulated * c->mTangent[0] +
                                  c->mPatch.mTangent[1].mAccumulated * c->mTangent[1];
        cached.mTwistImpulse = c->mPatch.mTwistAccumulated;
    }
}

} // namespace cairn::physics
