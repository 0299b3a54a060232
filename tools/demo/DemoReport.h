#pragma once

// Turns the demo's measurements (DemoRunResult) into a console summary, a lock-free vs global-mutex
// comparison, SVG charts, and a Markdown report folder.

#include "demo/DemoResult.h"

#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace cairn::demo
{
using namespace cairn::physics;

/// Compact human summary of one run (one locking mode) written to inOut.
void PrintSummary(std::FILE* inOut, const DemoRunResult& inRun);

/// Side-by-side table of the two modes with the global/lock-free ratios, ending with the game-object jobs'
/// lock waits per thread and frame (queries and moves). The 10x query-cost target is judged on both the
/// queries' µs and those waits.
void PrintComparison(std::FILE* inOut, const DemoRunResult& inLockFree, const DemoRunResult& inGlobal);

/// Self-contained 800x300 SVG plotting each (name, samples) series against its sample index. Non-finite
/// samples are skipped (they break the line), empty series only appear in the legend.
std::string SvgLineChart(const std::string& inTitle, const std::string& inYLabel,
                         const std::vector<std::pair<std::string, std::vector<double>>>& inSeries);

/// Self-contained 800x300 SVG histogram of inValues with one bar per integer value 0..max, merged into at
/// most 40 equal-width buckets when the range is larger.
std::string SvgHistogram(const std::string& inTitle, const std::string& inXLabel,
                         const std::vector<uint32_t>& inValues);

/// Per-frame figures of every run, one row per frame: mode, frame, the main thread's frame, its physics step
/// and streaming work (ms), the step's phases (ms), its active bodies, pairs, contact points and lock waits
/// (ms), the game-object jobs' lock waits (µs, all threads), the host's share of the step and of the
/// streaming call, and the navigation's work on the main thread and on the job threads (ms).
std::string FramesCsv(const std::vector<DemoRunResult>& inRuns);

/// Writes report.md, frames.csv, frame_times.svg, tile_latency.svg, nav_ms.svg and nav_map.svg to inFolder
/// (created if missing). With two runs the one whose mode name contains "global" is compared against the
/// other. On failure returns false with the path and reason in outError, and removes the files it had
/// started; never throws.
bool WriteReport(const std::string& inFolder, const std::vector<DemoRunResult>& inRuns,
                 const std::string& inCommandLine, std::string& outError);

} // namespace cairn::demo
