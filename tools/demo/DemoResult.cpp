// Summarize for the demo's results: mean and nearest-rank percentiles of a series of samples.

#include "demo/DemoResult.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace cairn::demo
{

SampleSummary Summarize(std::vector<double> inSamples)
{
    // A NaN or infinity is a broken measurement, not a slow frame: it would break the strict weak ordering
    // std::sort relies on or turn the mean into inf, so it counts as missing (and not in mCount).
    inSamples.erase(std::remove_if(inSamples.begin(), inSamples.end(),
                                   [](double inValue) { return !std::isfinite(inValue); }),
                    inSamples.end());
    SampleSummary summary;
    if (inSamples.empty()) return summary;
    std::sort(inSamples.begin(), inSamples.end());
    auto rank = [&](double inFraction)
    {
        const size_t index = size_t(inFraction * double(inSamples.size() - 1) + 0.5);
        return inSamples[std::min(index, inSamples.size() - 1)];
    };
    summary.mMean = std::accumulate(inSamples.begin(), inSamples.end(), 0.0) / double(inSamples.size());
    summary.mP50 = rank(0.50);
    summary.mP99 = rank(0.99);
    summary.mMax = inSamples.back();
    summary.mCount = inSamples.size();
    return summary;
}

} // namespace cairn::demo
