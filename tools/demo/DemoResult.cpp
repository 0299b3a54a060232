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

namespace
{
/// The host's share of frame inIndex, within [0, inWallMs]: an unknown (NaN) or missing one counts as 0.
double HostShare(const std::vector<double>& inHostTakenMs, size_t inIndex, double inWallMs)
{
    if (inIndex >= inHostTakenMs.size() || !std::isfinite(inHostTakenMs[inIndex])) return 0.0;
    return std::clamp(inHostTakenMs[inIndex], 0.0, inWallMs);
}
} // namespace

double MaxLessHost(const std::vector<double>& inWallMs, const std::vector<double>& inHostTakenMs)
{
    double largest = std::nan("");
    for (size_t i = 0; i < inWallMs.size(); ++i)
        if (std::isfinite(inWallMs[i]))
            largest =
                std::fmax(largest, inWallMs[i] - HostShare(inHostTakenMs, i, inWallMs[i])); // fmax skips NaN
    return largest;
}

SpikeAttribution AttributeSpikes(const DemoRunResult& inRun, double inRatio)
{
    SpikeAttribution attribution;
    const SampleSummary physics = Summarize(inRun.mPhysicsMs);
    if (physics.mCount == 0) return attribution;
    attribution.mMaxLessHostMs = MaxLessHost(inRun.mPhysicsMs, inRun.mPhysicsHostTakenMs);
    const double bound = inRatio * physics.mMean;
    for (size_t i = 0; i < inRun.mPhysicsMs.size(); ++i)
    {
        const double wall = inRun.mPhysicsMs[i];
        if (!std::isfinite(wall) || wall <= bound) continue;
        ++attribution.mSpikes;
        const double host = HostShare(inRun.mPhysicsHostTakenMs, i, wall);
        if (wall - host > bound) continue;
        ++attribution.mSpikesByHost;
        attribution.mHostTakenMinMs =
            std::fmin(attribution.mHostTakenMinMs, host); // fmin skips the NaN start
        attribution.mHostTakenMaxMs = std::fmax(attribution.mHostTakenMaxMs, host);
    }
    return attribution;
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
