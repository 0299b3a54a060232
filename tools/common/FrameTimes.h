#pragma once

// Times and summarises per-frame timings (mean, percentiles, max) for the tools' reports.

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <numeric>
#include <vector>

namespace cairn::tools
{

/// Wall time since inStart, in milliseconds.
inline double MillisecondsSince(std::chrono::steady_clock::time_point inStart)
{
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - inStart).count();
}

/// The middle value of inValues (the upper of the two middle ones for an even count), 0 when empty: the
/// benchmarks' figure over their repetitions.
inline double Median(std::vector<double> inValues)
{
    if (inValues.empty()) return 0.0;
    std::sort(inValues.begin(), inValues.end());
    return inValues[inValues.size() / 2];
}

struct TimingSummary
{
    double mMean = 0.0;
    double mP50 = 0.0;
    double mP99 = 0.0;
    double mMax = 0.0;
};

/// Percentiles by nearest rank over a copy of the samples.
inline TimingSummary Summarize(std::vector<double> inSamples)
{
    TimingSummary summary;
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
    return summary;
}

} // namespace cairn::tools
