// StepScheduler::RunStages on several threads: every part of every stage runs exactly once, and a stage sees
// all that the parts of the stage before wrote (plain memory: under ThreadSanitizer, this suite's label, a
// missing order between two stages is a reported race). Part counts change from stage to stage, from one to
// every thread, as a colored island's colors do, so threads that are still a stage behind meet parts that
// others have taken already.

#include "cairn/jobs/JobSystem.h"
#include "step/StepScheduler.h"

#include <gtest/gtest.h>
#include <memory>
#include <vector>

namespace cairn::test
{
using namespace cairn::physics;

namespace
{
void ExpectEveryPartOnceInOrder(uint32_t inThreads)
{
    jobs::JobSystem::Settings settings;
    settings.mNumThreads = inThreads;
    jobs::JobSystem jobSystem(settings);
    StepScheduler scheduler;
    constexpr uint32_t stages = 3000;
    auto partsOf = [](uint32_t inStage, uint32_t inMaxParts)
    { return 1 + (inStage * 7 + inStage / 5) % inMaxParts; };
    // Each stage's parts write their own slot; the next stage reads every slot of the stage before
    std::vector<std::vector<uint32_t>> runs(stages, std::vector<uint32_t>(inThreads, 0));
    std::vector<uint64_t> written[2] = {std::vector<uint64_t>(inThreads, 0),
                                        std::vector<uint64_t>(inThreads, 0)};
    std::vector<uint32_t> misses(inThreads,
                                 0);        // Per part index: a slot of the stage before that was not there
    for (int round = 0; round < 3; ++round) // The parts' progress starts again at each RunStages
    {
        scheduler.BeginStep(&jobSystem);
        for (std::vector<uint32_t>& stage : runs)
            std::fill(stage.begin(), stage.end(), 0u);
        scheduler.RunStages(
            false, stages,
            [&](uint32_t inStage, uint32_t inMaxParts) { return partsOf(inStage, inMaxParts); },
            [&](uint32_t inStage, uint32_t inPart, uint32_t inParts)
            {
                ++runs[inStage][inPart];
                EXPECT_EQ(inParts, partsOf(inStage, scheduler.GetNumThreads()));
                if (inStage > 0)
                    for (uint32_t part = 0; part < partsOf(inStage - 1, scheduler.GetNumThreads()); ++part)
                        if (written[(inStage - 1) % 2][part] != uint64_t(round) * stages + inStage - 1)
                            ++misses[inPart];
                written[inStage % 2][inPart] = uint64_t(round) * stages + inStage;
            });
        for (uint32_t stage = 0; stage < stages; ++stage)
            for (uint32_t part = 0; part < inThreads; ++part)
                ASSERT_EQ(runs[stage][part], part < partsOf(stage, scheduler.GetNumThreads()) ? 1u : 0u)
                    << "round " << round << ", stage " << stage << ", part " << part;
    }
    for (uint32_t part = 0; part < inThreads; ++part)
        EXPECT_EQ(misses[part], 0u) << "part " << part << " read a slot the stage before had not written";
}
} // namespace

TEST(StageMeetingTest, EveryPartOnceAndInStageOrderOnTwoThreads)
{
    ExpectEveryPartOnceInOrder(2);
}

TEST(StageMeetingTest, EveryPartOnceAndInStageOrderOnFourThreads)
{
    ExpectEveryPartOnceInOrder(4);
}

} // namespace cairn::test
