#pragma once

// Which slow frames the host accounts for: given each frame's wall time and the share of it the host took
// the measuring thread's vCPU (ThreadCpuClock.h's HostTakenMs, NaN when it can not be told), count the frames
// over a multiple of the mean and those that are within it once the host's share is left out. Used by the
// demo's summary and by cairn-bench-host.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace cairn::tools
{

/// The spike bound: no frame over this times the mean.
inline constexpr double cSpikeRatio = 3.0;

/// The frames over a bound (a multiple of their mean), and how many of them the host's time accounts for.
struct SpikeAttribution
{
    size_t mSpikes = 0;       ///< Frames over the bound
    size_t mSpikesByHost = 0; ///< Of those, the frames that are within it once the host's time is left out
    /// Of those, the frames whose host share can not be told (the thread was switched out, or no share was
    /// measured): counted as not the host's, so a frame here may still be one the host slowed
    size_t mSpikesUnknown = 0;
    double mHostTakenMinMs = NAN; ///< The host's time in those frames: the least
    double mHostTakenMaxMs = NAN; ///< ... and the most
    double mMaxLessHostMs = NAN;  ///< The slowest frame once the host's time is left out of every frame
};

namespace spike_detail
{
inline bool IsShareKnown(const std::vector<double>& inHostTakenMs, size_t inIndex)
{
    return inIndex < inHostTakenMs.size() && std::isfinite(inHostTakenMs[inIndex]);
}

/// The host's share of frame inIndex, within [0, inWallMs]: an unknown (NaN) or missing one counts as 0.
inline double HostShare(const std::vector<double>& inHostTakenMs, size_t inIndex, double inWallMs)
{
    return IsShareKnown(inHostTakenMs, inIndex) ? std::clamp(inHostTakenMs[inIndex], 0.0, inWallMs) : 0.0;
}
} // namespace spike_detail

/// The largest of inWallMs[i] less inHostTakenMs[i] (an unknown or missing share counts as 0); NaN for none.
inline double MaxLessHost(const std::vector<double>& inWallMs, const std::vector<double>& inHostTakenMs)
{
    double largest = std::nan("");
    for (size_t i = 0; i < inWallMs.size(); ++i)
        if (std::isfinite(inWallMs[i]))
            largest = std::fmax(largest, inWallMs[i] - spike_detail::HostShare(
                                                           inHostTakenMs, i, inWallMs[i])); // fmax skips NaN
    return largest;
}

/// Frames of inWallMs over inRatio times their mean (of the finite ones): how many, and which the host
/// accounts for.
inline SpikeAttribution AttributeSpikes(const std::vector<double>& inWallMs,
                                        const std::vector<double>& inHostTakenMs, double inRatio)
{
    SpikeAttribution attribution;
    double sum = 0.0;
    size_t count = 0;
    for (double wall : inWallMs)
        if (std::isfinite(wall))
        {
            sum += wall;
            ++count;
        }
    if (count == 0) return attribution;
    attribution.mMaxLessHostMs = MaxLessHost(inWallMs, inHostTakenMs);
    const double bound = inRatio * sum / double(count);
    for (size_t i = 0; i < inWallMs.size(); ++i)
    {
        const double wall = inWallMs[i];
        if (!std::isfinite(wall) || wall <= bound) continue;
        ++attribution.mSpikes;
        if (!spike_detail::IsShareKnown(inHostTakenMs, i)) ++attribution.mSpikesUnknown;
        const double host = spike_detail::HostShare(inHostTakenMs, i, wall);
        if (wall - host > bound) continue;
        ++attribution.mSpikesByHost;
        attribution.mHostTakenMinMs =
            std::fmin(attribution.mHostTakenMinMs, host); // fmin skips the NaN start
        attribution.mHostTakenMaxMs = std::fmax(attribution.mHostTakenMaxMs, host);
    }
    return attribution;
}

} // namespace cairn::tools
