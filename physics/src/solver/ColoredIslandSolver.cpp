// IslandSolver's colored islands: a color's constraints and joints share no dynamic body, so every thread
// solves a part of each color at once, the colors in turn (StepScheduler::RunStages); with the wide solver,
// four manifolds at a time in SIMD lanes, packed straight from the narrow phase's buffers.

#include "body/Integration.h"
#include "constraints/JointStage.h"
#include "solver/IslandSolver.h"
#include "step/StepContext.h"
#include "step/StepCosts.h"

#include <algorithm>

namespace cairn::physics
{

void IslandSolver::SolveColoredIsland(uint32_t inIsland, bool inAlone)
{
    StepScheduler& scheduler = mContext->mScheduler;
    const uint32_t firstColor = mPlan->mIslandFirstColor[inIsland];
    // The island's colors are the ranges [mPlan->mColorStart[k], mPlan->mColorStart[k + 1]) up to its end
    uint32_t lastColor = firstColor;
    while (mPlan->mColorStart[lastColor + 1] != mPlan->mConstraintStart[inIsland + 1])
        ++lastColor;
    // inPasses passes over the colors in turn, each color a stage: inSolve(pass, constraints). Within a color
    // no two constraints share a dynamic body, so its parts may run at once (one per thread, the same region
    // for the same thread in every color); the range of constraints that found no color shares bodies and
    // runs as one part
    // inItems: per entry of mPlan->mIslandConstraints (the constraints or their position constraints). A
    // color's joints are cut into the same parts and solved first in each (inSolveJoints(pass, joints)), as
    // an island solved whole solves its joints before its contacts
    const uint32_t numColors = lastColor - firstColor + 1;
    auto colorPasses = [&](int inPasses, auto inItems, const auto& inSolve, const auto& inSolveJoints)
    {
        scheduler.RunStages(
            inAlone, uint32_t(std::max(inPasses, 0)) * numColors,
            [&](uint32_t inStage, uint32_t inThreads)
            {
                const uint32_t color = firstColor + inStage % numColors;
                return mPlan->mColorIsSerial[color] != 0
                           ? 1u
                           : StepScheduler::PartsFor(uint32_t(mPlan->ColorConstraints(color).size() +
                                                              mPlan->ColorJoints(color).size()),
                                                     StepCosts::cMinConstraintsPerPart, inThreads);
            },
            [&](uint32_t inStage, uint32_t inPart, uint32_t inParts)
            {
                const uint32_t color = firstColor + inStage % numColors;
                const int pass = int(inStage / numColors);
                inSolveJoints(pass, StepScheduler::PartOf(mPlan->ColorJoints(color), inPart, inParts));
                inSolve(pass, StepScheduler::PartOf(
                                  inItems.subspan(mPlan->mColorStart[color],
                                                  mPlan->mColorStart[color + 1] - mPlan->mColorStart[color]),
                                  inPart, inParts));
            });
    };
    const std::span<ContactConstraint* const> constraints(mPlan->mIslandConstraints);
    const SolverSettings& solver = mContext->mSettings.mSolver;
    const std::span<SolverBody> solverBodies(mSolverBodies);
    // Without a restitution pass the impulses go from the wide solver's batches to the cache directly
    const bool bounces = mPlan->mIslandBounces[inIsland] != 0;
    const bool wide = CAIRN_WIDE_SOLVER && solver.mWideColoredIslands;
    if (wide)
        SolveColoredVelocitiesWide(firstColor, lastColor, !bounces, inAlone); // The warm start too
    else
        colorPasses(
            1 + solver.mVelocityIterations, constraints,
            [&](int inPass, std::span<ContactConstraint* const> inC)
            {
                if (inPass == 0)
                    SequentialImpulseSolver::WarmStart(inC, solverBodies);
                else
                    SequentialImpulseSolver::SolveVelocities(inC, solverBodies, inPass - 1);
            },
            [&](int inPass, std::span<const uint32_t> inJ)
            {
                if (inPass == 0)
                    mJoints->WarmStart(inJ, solverBodies);
                else
                    mJoints->SolveVelocities(inJ, solverBodies);
            });
    // Only where something bounces: the pass costs a stage per color
    if (bounces)
        colorPasses(
            1, constraints,
            [&](int, std::span<ContactConstraint* const> inC)
            { SequentialImpulseSolver::ApplyRestitution(inC, solverBodies); },
            [](int, std::span<const uint32_t>) {});

    const std::vector<uint32_t>& active = mContext->mActive;
    const std::span<const uint32_t> bodies = mContext->mIslands.GetBodies(inIsland);
    scheduler.ParallelForUnlessAlone(inAlone, uint32_t(bodies.size()), StepCosts::cColoredIslandGrain,
                                     [&](uint32_t inBegin, uint32_t inEnd)
                                     {
                                         for (uint32_t i = inBegin; i < inEnd; ++i)
                                             StoreVelocitiesAndIntegrate(mContext->BodyAt(active[bodies[i]]));
                                     });
    colorPasses(
        solver.mPositionIterations, std::span<const PositionConstraint>(mPositionConstraints),
        [&](int, std::span<const PositionConstraint> inC)
        { SequentialImpulseSolver::SolvePositions(inC, solver); },
        [&](int, std::span<const uint32_t> inJ) { mJoints->SolvePositions(inJ, solver); });

    if (wide && !bounces) return; // Stored already
    const std::span<ContactConstraint* const> all = mPlan->ConstraintsOf(inIsland);
    scheduler.ParallelForUnlessAlone(inAlone, uint32_t(all.size()), StepCosts::cColoredIslandGrain,
                                     [&](uint32_t inBegin, uint32_t inEnd)
                                     { StoreImpulses(all.subspan(inBegin, inEnd - inBegin)); });
}

void IslandSolver::SolveColoredVelocitiesWide([[maybe_unused]] uint32_t inFirstColor,
                                              [[maybe_unused]] uint32_t inLastColor,
                                              [[maybe_unused]] bool inStoreImpulses,
                                              [[maybe_unused]] bool inAlone)
{
#if CAIRN_WIDE_SOLVER
    StepScheduler& scheduler = mContext->mScheduler;
    // Each color's constraints in batches of four, in order; the last batch of a color may be partial. The
    // island's batches are its own slice of the step's (mPlan->mColorFirstBatch): islands solved alone run at
    // once. Each batch is set up where it is packed (below), by the thread that packs it: set up in a serial
    // pass, a settled pyramid's 2,000 batches were each a line written on this thread and read next on
    // another
    auto setUp = [&](uint32_t inColor, WideContactBatch& ioBatch)
    {
        const uint32_t indexInColor =
            uint32_t(&ioBatch - (mWideBatches.data() + mPlan->mColorFirstBatch[inColor]));
        ioBatch.mFirst = mPlan->mColorStart[inColor] + 4 * indexInColor;
        ioBatch.mCount = std::min(4u, mPlan->mColorStart[inColor + 1] - ioBatch.mFirst);
        ioBatch.mPaddingFirst = mPaddingBlocksFirst + WideContactSolver::cPaddingBlocks * inColor;
    };
    const std::span<SolverBody> solverBodies(mSolverBodies);
    auto constraintsOf = [&](const WideContactBatch& inBatch)
    {
        return std::span<ContactConstraint* const>(mPlan->mIslandConstraints.data() + inBatch.mFirst,
                                                   inBatch.mCount);
    };
    // The batches of a color (they share no dynamic body) are solved in one contiguous part per thread, as
    // in SolveColoredIsland (8 batches are the 32 constraints a part needs). Packed and stored in the same
    // parts, part p by the thread that runs the loop's part p, which is normally the one that runs the
    // stages' part p too (each thread takes its own part first): a batch is 2 KB, and one packed on the other
    // core (a loop over all the batches in chunks gave half of them to it) crossed between the cores twice a
    // step
    auto batchesOf = [&](uint32_t inColor)
    {
        return std::span<WideContactBatch>(mWideBatches.data() + mPlan->mColorFirstBatch[inColor],
                                           mWideBatches.data() + mPlan->mColorFirstBatch[inColor + 1]);
    };
    auto partsOfColor = [&](uint32_t inColor, uint32_t inThreads)
    {
        return StepScheduler::PartsFor(uint32_t(batchesOf(inColor).size()), StepCosts::cMinBatchesPerPart,
                                       inThreads);
    };
    auto forEachPartOfThreads = [&](const auto& inRunBatches)
    {
        const uint32_t threads = inAlone ? 1 : scheduler.GetNumThreads();
        if (threads == 1)
        {
            scheduler.RunWhole(inAlone,
                               [&]
                               {
                                   for (uint32_t color = inFirstColor; color <= inLastColor; ++color)
                                       inRunBatches(color, batchesOf(color));
                               });
            return;
        }
        scheduler.ParallelForUnlessAlone(
            false, threads, 1,
            [&](uint32_t inBegin, uint32_t inEnd)
            {
                for (uint32_t part = inBegin; part < inEnd; ++part)
                    for (uint32_t color = inFirstColor; color <= inLastColor; ++color)
                        if (const uint32_t parts = partsOfColor(color, threads); part < parts)
                            inRunBatches(color, StepScheduler::PartOf(batchesOf(color), part, parts));
            });
    };

    // The constraints are where the narrow phase made them (not copied: see Solve), scattered over its
    // chunks: each batch's are fetched a batch ahead, and bound and given position constraints as they are
    // packed, while their cache lines are at hand. The range that found no color is prepared here
    const uint32_t numActive = uint32_t(mContext->mActive.size());
    for (uint32_t color = inFirstColor; color <= inLastColor; ++color)
        if (mPlan->mColorIsSerial[color] != 0)
            for (uint32_t i = mPlan->mColorStart[color]; i < mPlan->mColorStart[color + 1]; ++i)
                PrepareForSolve(i, numActive);
    forEachPartOfThreads(
        [&](uint32_t inColor, std::span<WideContactBatch> inBatches)
        {
            if (!inBatches.empty()) setUp(inColor, inBatches[0]);
            for (size_t i = 0; i < inBatches.size(); ++i)
            {
                if (i + 1 < inBatches.size())
                {
                    setUp(inColor, inBatches[i + 1]);
                    for (ContactConstraint* next : constraintsOf(inBatches[i + 1]))
                        PrefetchConstraint(next);
                }
                WideContactBatch& batch = inBatches[i];
                for (uint32_t lane = 0; lane < batch.mCount; ++lane)
                    PrepareForSolve(batch.mFirst + lane, numActive);
                WideContactSolver::Pack(constraintsOf(batch), solverBodies, batch);
            }
        });

    // The warm start, then the iterations: each a pass over the colors in turn, each color a stage. The
    // serial range by the scalar solver in one part; the batches of a color in their parts
    const uint32_t numColors = inLastColor - inFirstColor + 1;
    scheduler.RunStages(
        inAlone, (1 + uint32_t(mContext->mSettings.mSolver.mVelocityIterations)) * numColors,
        [&](uint32_t inStage, uint32_t inThreads)
        {
            const uint32_t color = inFirstColor + inStage % numColors;
            return mPlan->mColorIsSerial[color] != 0
                       ? 1u
                       : std::max(partsOfColor(color, inThreads),
                                  StepScheduler::PartsFor(uint32_t(mPlan->ColorJoints(color).size()),
                                                          StepCosts::cMinConstraintsPerPart, inThreads));
        },
        [&](uint32_t inStage, uint32_t inPart, uint32_t inParts)
        {
            const uint32_t color = inFirstColor + inStage % numColors;
            const int pass = int(inStage / numColors); // 0: the warm start; then iteration pass - 1
            // The color's joints first, cut into the same parts (see SolveColoredIsland)
            const std::span<const uint32_t> joints =
                StepScheduler::PartOf(mPlan->ColorJoints(color), inPart, inParts);
            if (pass == 0)
                mJoints->WarmStart(joints, solverBodies);
            else
                mJoints->SolveVelocities(joints, solverBodies);
            if (mPlan->mColorIsSerial[color] != 0)
            {
                const std::span<ContactConstraint* const> constraints = mPlan->ColorConstraints(color);
                if (pass == 0)
                    SequentialImpulseSolver::WarmStart(constraints, solverBodies);
                else
                    SequentialImpulseSolver::SolveVelocities(constraints, solverBodies, pass - 1);
                return;
            }
            const std::span<WideContactBatch> part = StepScheduler::PartOf(batchesOf(color), inPart, inParts);
            if (pass == 0)
                WideContactSolver::WarmStart(part, solverBodies);
            else
                WideContactSolver::SolveVelocities(part, solverBodies, pass - 1);
        });

    forEachPartOfThreads(
        [&](uint32_t, std::span<WideContactBatch> inBatches)
        {
            for (WideContactBatch& batch : inBatches)
                if (inStoreImpulses)
                    WideContactSolver::StoreImpulses(batch, mContext->mContactCache);
                else
                    WideContactSolver::Unpack(batch, constraintsOf(batch));
        });
    if (inStoreImpulses)
        for (uint32_t color = inFirstColor; color <= inLastColor; ++color)
            if (mPlan->mColorIsSerial[color] != 0) StoreImpulses(mPlan->ColorConstraints(color));
#endif
}

} // namespace cairn::physics
