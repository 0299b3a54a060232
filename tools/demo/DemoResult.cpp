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

} // namespace cairn::demo
