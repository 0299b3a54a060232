// Summarize for the demo's results: the tools' frame-time summary (mean and nearest-rank percentiles), over
// the finite samples only.

#include "demo/DemoResult.h"

#include "common/FrameTimes.h"

#include <algorithm>
#include <cmath>

namespace cairn::demo
{
using namespace cairn::physics;

SampleSummary Summarize(std::vector<double> inSamples)
{
    // A NaN or infinity is a broken measurement, not a slow frame: it would break the strict weak ordering
    // std::sort relies on or turn the mean into inf, so it counts as missing (and not in mCount).
    inSamples.erase(std::remove_if(inSamples.begin(), inSamples.end(),
                                   [](double inValue) { return !std::isfinite(inValue); }),
                    inSamples.end());
    const size_t count = inSamples.size();
    const tools::TimingSummary timing = tools::Summarize(std::move(inSamples));
    return {timing.mMean, timing.mP50, timing.mP99, timing.mMax, count};
}

PhaseSummaries SummarizePhases(const std::vector<StepStatistics>& inSteps)
{
    auto phase = [&](double StepStatistics::*inPhase)
    {
        std::vector<double> samples;
        samples.reserve(inSteps.size());
        for (const StepStatistics& step : inSteps)
            samples.push_back(step.*inPhase);
        return Summarize(std::move(samples));
    };
    return {phase(&StepStatistics::mBroadPhaseUpdateMs), phase(&StepStatistics::mNarrowPhaseMs),
            phase(&StepStatistics::mIslandsMs),          phase(&StepStatistics::mSolveMs),
            phase(&StepStatistics::mFinishMs),           phase(&StepStatistics::mLockWaitMs)};
}

tools::SpikeAttribution AttributePhysicsSpikes(const DemoRunResult& inRun, double inRatio)
{
    return tools::AttributeSpikes(inRun.mPhysicsMs, inRun.mPhysicsHostTakenMs, inRatio);
}

std::vector<double> LockWaitMicrosPerThreadFrame(const DemoRunResult& inRun)
{
    std::vector<double> total = inRun.mBroadPhaseLockWaitMicrosPerThreadFrame;
    total.resize(std::max(total.size(), inRun.mBodyLockWaitMicrosPerThreadFrame.size()), 0.0);
    for (size_t i = 0; i < inRun.mBodyLockWaitMicrosPerThreadFrame.size(); ++i)
        total[i] += inRun.mBodyLockWaitMicrosPerThreadFrame[i];
    return total;
}

double QueryLockWaitMicrosPerQuery(const DemoRunResult& inRun)
{
    if (inRun.mQueries == 0) return std::nan("");
    double totalMicros = 0.0;
    for (double frameMicros : inRun.mGameObjectLockWaitUs)
        totalMicros += frameMicros;
    return totalMicros / double(inRun.mQueries);
}

} // namespace cairn::demo
