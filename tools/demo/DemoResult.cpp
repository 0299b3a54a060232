// Summarize for the demo's results: the tools' frame-time summary (mean and nearest-rank percentiles), over
// the finite samples only.

#include "demo/DemoResult.h"

#include "common/FrameTimes.h"

#include <algorithm>
#include <cmath>

namespace cairn::demo
{

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

PhaseTimes MeanPhases(const std::vector<StepStatistics>& inSteps)
{
    PhaseTimes means;
    for (const StepStatistics& step : inSteps)
    {
        means.mBroadPhaseUpdateMs += step.mBroadPhaseUpdateMs;
        means.mNarrowPhaseMs += step.mNarrowPhaseMs;
        means.mIslandsMs += step.mIslandsMs;
        means.mSolveMs += step.mSolveMs;
        means.mFinishMs += step.mFinishMs;
        means.mLockWaitMs += step.mLockWaitMs;
        means.mLockWaitMaxMs = std::max(means.mLockWaitMaxMs, step.mLockWaitMs);
    }
    const double frames = double(std::max<size_t>(1, inSteps.size()));
    means.mBroadPhaseUpdateMs /= frames;
    means.mNarrowPhaseMs /= frames;
    means.mIslandsMs /= frames;
    means.mSolveMs /= frames;
    means.mFinishMs /= frames;
    means.mLockWaitMs /= frames;
    return means;
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

} // namespace cairn::demo
