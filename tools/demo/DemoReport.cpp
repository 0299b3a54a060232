// Renders the demo's measurements for people: the console summary, the lock-free vs global-mutex comparison,
// SVG charts and the Markdown report folder. Standard library only, so the demo needs no extra dependency.

#include "demo/DemoReport.h"

#include "demo/NavMapSvg.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstring>
#include <exception>
#include <filesystem>
#include <iterator>
#include <limits>
#include <optional>
#include <system_error>

namespace cairn::demo
{
using namespace cairn::physics;
namespace
{

namespace fs = std::filesystem;

/// The lock-free mode's game-object query cost must be this much lower. The issue does not say whether that
/// cost is the queries' whole time or, as in the talk, the locks' cost per thread, so both are judged.
constexpr double cQueryTargetRatio = 10.0;
constexpr double cP99TargetRatio = 2.0; ///< A physics frame's p99 at most this times its average
constexpr double cSpikeTargetRatio = tools::cSpikeRatio; ///< No physics frame over this times the average
constexpr double cMainThreadStreamTargetMs = 0.5;  ///< Streaming work on the main thread per frame, at most
constexpr double cNavMainThreadTargetMs = 0.5;     ///< Navigation work on the main thread per frame, p99
constexpr double cNavJobThreadsTargetMs = 2.0;     ///< ... and on the job threads (1,000 agents)
constexpr double cNavJobThreads10kTargetMs = 12.0; ///< ... (more than 1,000 agents: 10,000's target)
constexpr double cPathWaitTargetFrames = 10.0;     ///< A path request's wait, p99
constexpr size_t cMaxHistogramBuckets = 40;
constexpr int cSummaryTitleWidth = 23; ///< Column of the first metric in the console summary

// Chart geometry, shared by the line chart and the histogram so the report's images line up.
constexpr double cSvgWidth = 800.0;
constexpr double cSvgHeight = 300.0;
constexpr double cPlotLeft = 70.0;
constexpr double cPlotRight = 780.0;
constexpr double cPlotTop = 54.0;
constexpr double cPlotBottom = 250.0;
constexpr double cCharWidth = 6.5; ///< Rough advance of an 11 px sans-serif glyph, for layout only
constexpr double cLegendRowHeight = 16.0;
constexpr const char* cPalette[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e",
                                    "#9467bd", "#8c564b", "#e377c2", "#17becf"};

[[gnu::format(printf, 1, 2)]] std::string Format(const char* inFormat, ...)
{
    char buffer[256];
    va_list args;
    va_start(args, inFormat);
    const int length = std::vsnprintf(buffer, sizeof(buffer), inFormat, args);
    va_end(args);
    if (length < 0) return {};
    if (size_t(length) < sizeof(buffer)) return std::string(buffer, size_t(length));
    std::string result(size_t(length), '\0');
    va_start(args, inFormat);
    std::vsnprintf(result.data(), result.size() + 1, inFormat, args);
    va_end(args);
    return result;
}

std::string Fixed(double inValue, int inDecimals)
{
    if (std::isnan(inValue)) return "n/a";
    return Format("%.*f", inDecimals, inValue);
}

std::string Ms(double inValue)
{
    return Fixed(inValue, 3);
}

/// "0.500-1.250", or one figure when both ends are the same.
std::string MsRange(double inLeast, double inMost)
{
    return inLeast == inMost ? Ms(inLeast) : Ms(inLeast) + "-" + Ms(inMost);
}

std::string Micros(double inValue)
{
    return Fixed(inValue, 2);
}

/// "1.25, 2.50" (per thread), or "n/a" for none.
std::string MicrosList(const std::vector<double>& inValues)
{
    std::string text;
    for (size_t i = 0; i < inValues.size(); ++i)
        text += (i == 0 ? "" : ", ") + Micros(inValues[i]);
    return text.empty() ? "n/a" : text;
}

/// A statistic of a series that was never sampled shows "n/a": a 0 would read as "free".
std::string Ms(const SampleSummary& inSummary, double inValue)
{
    return inSummary.mCount == 0 ? std::string("n/a") : Ms(inValue);
}

std::string Count(uint64_t inValue)
{
    return Format("%llu", static_cast<unsigned long long>(inValue));
}

/// "n/a" rather than a misleading 0 or inf when the denominator was never measured.
std::string Ratio(double inNumerator, double inDenominator)
{
    if (!(inDenominator > 0.0) || !std::isfinite(inNumerator) || !std::isfinite(inDenominator)) return "n/a";
    return Format("%.2fx", inNumerator / inDenominator);
}

/// " (target <= 2x: met)": inValue against the bound inBound (smaller is better).
std::string AtMost(double inValue, double inBound, const char* inUnit)
{
    if (!std::isfinite(inValue)) return "";
    return Format(" (target <= %g%s: %s)", inBound, inUnit, inValue <= inBound ? "met" : "NOT met");
}

/// "<inReading>: met": the global/lock-free ratio against cQueryTargetRatio. A global mode that waited
/// against a lock-free mode that never did meets it.
std::string QueryTarget(double inGlobal, double inLockFree, const char* inReading)
{
    const char* verdict = "unknown";
    if (std::isfinite(inGlobal) && std::isfinite(inLockFree) && inLockFree >= 0.0)
        verdict = inLockFree == 0.0                            ? (inGlobal > 0.0 ? "met" : "unknown")
                  : inGlobal / inLockFree >= cQueryTargetRatio ? "met"
                                                               : "NOT met";
    return Format("%s: %s", inReading, verdict);
}

/// A ratio of two waits, where the lock-free side may be exactly 0.
std::string WaitRatio(double inNumerator, double inDenominator)
{
    if (std::isfinite(inNumerator) && inNumerator > 0.0 && inDenominator == 0.0) return "no waits lock-free";
    return Ratio(inNumerator, inDenominator);
}

/// The mean of a series, NaN when empty.
double MeanOf(const std::vector<double>& inValues)
{
    if (inValues.empty()) return std::nan("");
    double sum = 0.0;
    for (double value : inValues)
        sum += value;
    return sum / double(inValues.size());
}

/// Display width in columns, counting UTF-8 code points (the reports use "µ").
size_t TextWidth(const std::string& inText)
{
    return size_t(std::count_if(inText.begin(), inText.end(),
                                [](char inChar)
                                { return (static_cast<unsigned char>(inChar) & 0xC0) != 0x80; }));
}

std::string PadRight(const std::string& inText, size_t inWidth)
{
    const size_t width = TextWidth(inText);
    return width >= inWidth ? inText : inText + std::string(inWidth - width, ' ');
}

std::string PadLeft(const std::string& inText, size_t inWidth)
{
    const size_t width = TextWidth(inText);
    return width >= inWidth ? inText : std::string(inWidth - width, ' ') + inText;
}

std::string OneLine(const std::string& inText)
{
    std::string result = inText;
    std::replace(result.begin(), result.end(), '\n', ' ');
    std::replace(result.begin(), result.end(), '\r', ' ');
    return result;
}

/// One line of Markdown text in which a caller's "<" cannot open an HTML tag.
std::string EscapeMarkdown(const std::string& inText)
{
    std::string result;
    for (char c : OneLine(inText))
        if (c == '<')
            result += "&lt;";
        else
            result += c;
    return result;
}

/// Also keeps a cell inside its Markdown table column.
std::string EscapeMarkdownCell(const std::string& inText)
{
    std::string result;
    for (char c : EscapeMarkdown(inText))
    {
        if (c == '|') result += '\\';
        result += c;
    }
    return result;
}

/// Escapes the XML specials and replaces what would make the SVG ill-formed (control characters, invalid
/// UTF-8), since mode names and titles come from callers we do not control.
std::string EscapeXml(const std::string& inText)
{
    std::string result;
    size_t i = 0;
    while (i < inText.size())
    {
        const unsigned char lead = static_cast<unsigned char>(inText[i]);
        if (lead < 0x80)
        {
            switch (lead)
            {
            case '&':
                result += "&amp;";
                break;
            case '<':
                result += "&lt;";
                break;
            case '>':
                result += "&gt;";
                break;
            case '"':
                result += "&quot;";
                break;
            case '\'':
                result += "&apos;";
                break;
            default:
                result += (lead < 0x20 && lead != '\t' && lead != '\n' && lead != '\r') ? '?' : char(lead);
            }
            ++i;
            continue;
        }
        const size_t length = lead >= 0xF8 ? 0 : lead >= 0xF0 ? 4 : lead >= 0xE0 ? 3 : lead >= 0xC0 ? 2 : 0;
        bool valid = length != 0 && i + length <= inText.size();
        uint32_t codePoint = lead & (0xFFu >> (length + 1));
        for (size_t k = 1; valid && k < length; ++k)
        {
            const unsigned char next = static_cast<unsigned char>(inText[i + k]);
            valid = (next & 0xC0) == 0x80;
            codePoint = (codePoint << 6) | (next & 0x3Fu);
        }
        static constexpr uint32_t cMinimumForLength[] = {0, 0, 0x80, 0x800, 0x10000};
        valid = valid && codePoint >= cMinimumForLength[length] && codePoint <= 0x10FFFF &&
                !(codePoint >= 0xD800 && codePoint <= 0xDFFF) && codePoint != 0xFFFE && codePoint != 0xFFFF;
        if (valid)
        {
            result.append(inText, i, length);
            i += length;
        }
        else
        {
            result += '?';
            ++i;
        }
    }
    return result;
}

std::string ModeName(const DemoRunResult& inRun, const char* inFallback)
{
    return inRun.mModeName.empty() ? std::string(inFallback) : OneLine(inRun.mModeName);
}

// ---------------------------------------------------------------------------------------------------------
// Summary and comparison content, built once and rendered both to the console and to Markdown so the two
// never disagree.

struct Row
{
    std::string mLabel;
    std::string mValue;
};

struct Section
{
    std::string mTitle;
    std::vector<Row> mRows;
    /// For a phase of the physics step, its name (the title adds the unit): report.md puts these in a table
    /// of their own
    std::string mStepPhase = {};
};

struct Table
{
    std::vector<std::string> mHeader;
    std::vector<std::vector<std::string>> mRows;
    /// Right-aligned columns after the first (all unless set); the columns after them are left-aligned text
    size_t mNumNumberColumns = std::numeric_limits<size_t>::max();
};

/// Whether column inColumn of inTable is left-aligned (the row names, and text after the numbers).
bool IsTextColumn(const Table& inTable, size_t inColumn)
{
    return inColumn == 0 || inColumn > inTable.mNumNumberColumns;
}

SampleSummary SummarizeFrames(const std::vector<uint32_t>& inFrames)
{
    return Summarize(std::vector<double>(inFrames.begin(), inFrames.end()));
}

/// Doorway checks the navmesh failed: a path through a door at rest closed, or none through an open one.
uint64_t DoorwaysNotAsTheirDoor(const DoorStats& inDoors)
{
    return (inDoors.mClosedChecks - inDoors.mClosedBlocked) + (inDoors.mOpenChecks - inDoors.mOpenPassable);
}

bool InvariantsHold(const DemoRunResult& inRun)
{
    return inRun.mLostOrDuplicatedBodies == 0 && inRun.mTilesRequestedNeverBuilt == 0 &&
           inRun.mAgentStats.mInsideStatic == 0 && inRun.mAgentStats.mOffNavMeshOverOneSecond == 0 &&
           inRun.mAgentStats.mCorridorsThroughGone == 0 && DoorwaysNotAsTheirDoor(inRun.mDoorStats) == 0 &&
           inRun.mAgentStats.mNonClimberLadderFrames == 0 && inRun.mLaddersDead == 0 && inRun.mErrors.empty();
}

std::vector<Section> BuildSummary(const DemoRunResult& inRun)
{
    const SampleSummary physics = Summarize(inRun.mPhysicsMs);
    const SampleSummary frame = Summarize(inRun.mFrameMs);
    const SampleSummary streamIn = Summarize(inRun.mStreamInMs);
    const SampleSummary link = Summarize(inRun.mStreamLinkMs);
    const SampleSummary streamOut = Summarize(inRun.mStreamOutMs);
    const SampleSummary mainThreadStream = Summarize(inRun.mMainThreadStreamMs);
    const SampleSummary latency = SummarizeFrames(inRun.mNavTileLatencyFrames);

    auto frames = [&](double inValue)
    { return latency.mCount == 0 ? std::string("n/a") : Fixed(inValue, 0); };

    const AgentStats& agents = inRun.mAgentStats;
    const SampleSummary navMain = Summarize(agents.mMainThreadMs);
    const SampleSummary navJobs = Summarize(agents.mJobThreadsMs);
    // The frames in which no other task took a navigation thread's core, apart: what the rest's tail holds
    std::vector<double> navJobsAlone;
    uint64_t navInterrupted = 0, navWatched = 0;
    for (size_t i = 0; i < agents.mJobThreadsMs.size() && i < agents.mOtherTaskSwitches.size(); ++i)
    {
        if (agents.mOtherTaskSwitches[i] < 0) continue;
        ++navWatched;
        if (agents.mOtherTaskSwitches[i] > 0)
            ++navInterrupted;
        else
            navJobsAlone.push_back(agents.mJobThreadsMs[i]);
    }
    const SampleSummary navJobsUninterrupted = Summarize(navJobsAlone);
    auto percentOf = [](uint64_t inCount, uint64_t inOf) {
        return Count(inCount) + Format(" (%.2f%%)", inOf == 0 ? 0.0 : 100.0 * double(inCount) / double(inOf));
    };

    std::vector<Section> sections;
    sections.push_back({"physics ms/frame",
                        {{"avg", Ms(physics, physics.mMean)},
                         {"p50", Ms(physics, physics.mP50)},
                         {"p99", Ms(physics, physics.mP99)},
                         {"max spike", Ms(physics, physics.mMax)},
                         {"p99/avg", Ratio(physics.mP99, physics.mMean) +
                                         AtMost(physics.mP99 / physics.mMean, cP99TargetRatio, "x")},
                         {"max/avg", Ratio(physics.mMax, physics.mMean) +
                                         AtMost(physics.mMax / physics.mMean, cSpikeTargetRatio, "x")}}});
    const tools::SpikeAttribution spikes = AttributePhysicsSpikes(inRun, cSpikeTargetRatio);
    sections.push_back(
        {"physics spikes",
         {{Format("frames over %gx avg", cSpikeTargetRatio), Count(spikes.mSpikes)},
          {"of which the host's", spikes.mSpikes == 0 ? std::string("n/a")
                                  : spikes.mSpikesByHost == 0
                                      ? std::string("none")
                                      : Count(spikes.mSpikesByHost) +
                                            " (it took the updating thread's core for " +
                                            MsRange(spikes.mHostTakenMinMs, spikes.mHostTakenMaxMs) + " ms)"},
          {"share unknown", spikes.mSpikes == 0 ? std::string("n/a") : Count(spikes.mSpikesUnknown)},
          {"max/avg less the host's time", Ratio(spikes.mMaxLessHostMs, physics.mMean)},
          {"guest steal ms", Fixed(inRun.mGuestStealMs, 0)}}});
    sections.push_back({"frame ms",
                        {{"avg", Ms(frame, frame.mMean)},
                         {"p50", Ms(frame, frame.mP50)},
                         {"p99", Ms(frame, frame.mP99)},
                         {"max", Ms(frame, frame.mMax)}}});
    // Each phase as the whole step: where the step's average and its spikes come from
    const PhaseSummaries phases = SummarizePhases(inRun.mSteps);
    auto phaseSection = [&](const char* inPhase, const SampleSummary& inSummary)
    {
        sections.push_back({std::string(inPhase) + " ms",
                            {{"avg", Ms(inSummary, inSummary.mMean)},
                             {"p50", Ms(inSummary, inSummary.mP50)},
                             {"p99", Ms(inSummary, inSummary.mP99)},
                             {"max", Ms(inSummary, inSummary.mMax)}},
                            inPhase});
    };
    phaseSection("broad-phase update", phases.mBroadPhaseUpdate);
    phaseSection("narrow phase+pairs", phases.mNarrowPhase);
    phaseSection("islands", phases.mIslands);
    phaseSection("solve", phases.mSolve);
    phaseSection("finish", phases.mFinish);
    phaseSection("step lock waits", phases.mLockWait);
    sections.push_back(
        {"game-object queries",
         {{"queries (beside the step)", Count(inRun.mQueries)},
          {"character walks", Count(inRun.mCharacterWalks)},
          {"put back 3 m behind", Count(inRun.mCharacterPutBack)},
          {"mean µs/query", Micros(inRun.mQueryMicrosMean)},
          {"µs/query per thread", MicrosList(inRun.mQueryMicrosPerThread)},
          {"lock waits µs/query", Micros(QueryLockWaitMicrosPerQuery(inRun))},
          {"lock waits µs/frame per thread", MicrosList(LockWaitMicrosPerThreadFrame(inRun))},
          {"broad-phase / body locks", Micros(MeanOf(inRun.mBroadPhaseLockWaitMicrosPerThreadFrame)) + " / " +
                                           Micros(MeanOf(inRun.mBodyLockWaitMicrosPerThreadFrame))},
          {"moves' lock waits µs/frame per thread (after the step)",
           MicrosList(inRun.mMoveLockWaitMicrosPerThreadFrame)}}});
    sections.push_back(
        {"streaming",
         {{"tiles in", Count(inRun.mTilesStreamedIn)},
          {"tiles out", Count(inRun.mTilesStreamedOut)},
          {"tile in ms p50", Ms(streamIn, streamIn.mP50)},
          {"tile in ms max", Ms(streamIn, streamIn.mMax)},
          {"link ms p50", Ms(link, link.mP50)},
          {"link ms max", Ms(link, link.mMax)},
          {"tile out ms p50", Ms(streamOut, streamOut.mP50)},
          {"tile out ms max", Ms(streamOut, streamOut.mMax)},
          {"main-thread ms/frame max",
           Ms(mainThreadStream, mainThreadStream.mMax) +
               (mainThreadStream.mCount == 0
                    ? std::string()
                    : AtMost(mainThreadStream.mMax, cMainThreadStreamTargetMs, " ms"))},
          {"less the host's time",
           Ms(tools::MaxLessHost(inRun.mMainThreadStreamMs, inRun.mMainThreadStreamHostTakenMs))}}});
    sections.push_back(
        {"bodies peak",
         {{"static", Count(inRun.mStaticBodiesPeak)}, {"dynamic", Count(inRun.mDynamicBodiesPeak)}}});
    sections.push_back({"navmesh",
                        {{"tiles built", Count(inRun.mNavTilesBuilt)},
                         {"latency frames p50", frames(latency.mP50)},
                         {"p99", frames(latency.mP99)},
                         {"max", frames(latency.mMax)}}});
    const DoorStats& doors = inRun.mDoorStats;
    const SampleSummary doorLatency = SummarizeFrames(doors.mLatencyFrames);
    auto doorFrames = [&](double inValue)
    { return doorLatency.mCount == 0 ? std::string("n/a") : Fixed(inValue, 0); };
    sections.push_back(
        {"doors",
         {{"doors", Count(doors.mDoorsSeen)},
          {"opened or closed", Count(doors.mCommands)},
          {"came to rest", Count(doors.mRests)},
          {"tiles rebuilt", Count(doors.mRebuilds)},
          {"latency frames p50", doorFrames(doorLatency.mP50)},
          {"p99", doorFrames(doorLatency.mP99)},
          {"max", doorFrames(doorLatency.mMax)},
          {"closed blocked the path", Count(doors.mClosedBlocked) + " of " + Count(doors.mClosedChecks)},
          {"open let it through", Count(doors.mOpenPassable) + " of " + Count(doors.mOpenChecks)},
          {"checks skipped", Count(doors.mChecksSkipped)}}});
    const GuardStats& guards = inRun.mGuardStats;
    const SampleSummary make = Summarize(guards.mMakeMs);
    const SampleSummary toRest = Summarize(guards.mSecondsToRest);
    sections.push_back({"ragdolls",
                        {{"guards stood", Count(guards.mPlaced)},
                         {"shots", Count(guards.mShots)},
                         {"hit, gone limp", Count(guards.mHits)},
                         {"came to rest", Count(guards.mAtRest)},
                         {"taken away moving", Count(guards.mRemovedBeforeRest)},
                         {"make ms p50", Ms(make, make.mP50)},
                         {"max", Ms(make, make.mMax)},
                         {"s to rest p50", toRest.mCount == 0 ? std::string("n/a") : Fixed(toRest.mP50, 2)},
                         {"max", toRest.mCount == 0 ? std::string("n/a") : Fixed(toRest.mMax, 2)}}});
    sections.push_back(
        {"navigation ms/frame",
         {{"main thread p50", Ms(navMain, navMain.mP50)},
          {"p99",
           Ms(navMain, navMain.mP99) +
               (navMain.mCount == 0 ? std::string() : AtMost(navMain.mP99, cNavMainThreadTargetMs, " ms"))},
          {"max", Ms(navMain, navMain.mMax)},
          {"job threads p50", Ms(navJobs, navJobs.mP50)},
          {"p99", Ms(navJobs, navJobs.mP99) +
                      (navJobs.mCount == 0
                           ? std::string()
                           : AtMost(navJobs.mP99,
                                    inRun.mAgents > 1000 ? cNavJobThreads10kTargetMs : cNavJobThreadsTargetMs,
                                    " ms"))},
          {"max", Ms(navJobs, navJobs.mMax)},
          {"of which goal picking p99", Ms(Summarize(agents.mGoalPickingMs).mP99)},
          {"frames another task took a navigation thread's core",
           navWatched == 0 ? std::string("n/a") : percentOf(navInterrupted, navWatched)},
          {"job threads p99 in the other frames", Ms(navJobsUninterrupted, navJobsUninterrupted.mP99)}}});
    sections.push_back(
        {"paths",
         {{"requested", Count(agents.mPathsRequested)},
          {"served", Count(agents.mPathsServed)},
          {"failed", Count(agents.mPathsFailed)},
          {"queue wait frames p99", Count(agents.mPathWaitP99Frames) +
                                        AtMost(double(agents.mPathWaitP99Frames), cPathWaitTargetFrames, "")},
          {"max", Count(agents.mPathWaitMaxFrames)},
          {"replans (tile changes)", Count(agents.mReplans)}}});
    sections.push_back(
        {"agents",
         {{"agents", Format("%d", inRun.mAgents)},
          {"goals", Count(agents.mGoalsSet)},
          {"arrivals", Count(agents.mArrivals)},
          {"goals given up after 15 s", Count(agents.mGoalTimeouts)},
          {"stuck 5 s", Count(agents.mStuck)},
          {"no goal found", Count(agents.mGoalsNotFound)},
          {"walked m", Fixed(agents.mDistance, 0)},
          {"put back by the player", Count(agents.mCatchUps)},
          {"ladders climbed", Count(agents.mLinksTaken) + " of " + Count(inRun.mLaddersMost) + " at most"},
          {"ladders at the end, joined / waiting for tiles",
           Count(inRun.mLaddersJoined) + " / " + Count(inRun.mLaddersWaiting)},
          {"agents that may not climb", Count(agents.mNonClimbers)}}});
    sections.push_back(
        {"agent checks",
         {{"overlapping > 10 % of a radius",
           percentOf(agents.mOverlapping, agents.mOverlapChecks) +
               (agents.mOverlapChecks == 0
                    ? std::string()
                    : AtMost(100.0 * double(agents.mOverlapping) / double(agents.mOverlapChecks), 1.0,
                             " %"))},
          {"off navmesh agent-frames", percentOf(agents.mOffNavMeshFrames, agents.mAgentFrames)},
          {"longest off navmesh frames", Count(agents.mLongestOffNavMeshFrames)}}});
    sections.push_back(
        {"invariants",
         {{"lost/duplicated bodies", Count(inRun.mLostOrDuplicatedBodies)},
          {"tiles never built", Count(inRun.mTilesRequestedNeverBuilt)},
          {"agents inside static bodies",
           Count(agents.mInsideStatic) + " of " + Count(agents.mInsideStaticChecks) + " checks"},
          {"off navmesh over 1 s", Count(agents.mOffNavMeshOverOneSecond)},
          {"corridors through gone polygons", Count(agents.mCorridorsThroughGone)},
          {"doorways not as their door", Count(DoorwaysNotAsTheirDoor(inRun.mDoorStats))},
          {"ladders no agent can take", Count(inRun.mLaddersDead)},
          {"frames on a ladder by agents that may not climb", Count(agents.mNonClimberLadderFrames)},
          {"status", InvariantsHold(inRun) ? "OK" : "FAILED"}}});
    return sections;
}

std::string RunHeading(const DemoRunResult& inRun)
{
    return Format("%d frames, %u job-system threads", inRun.mFrames, inRun.mThreads);
}

std::string SummaryText(const DemoRunResult& inRun)
{
    std::string text = "== " + ModeName(inRun, "(unnamed mode)") + ": " + RunHeading(inRun) + " ==\n";
    for (const Section& section : BuildSummary(inRun))
    {
        std::string line = PadRight(section.mTitle, cSummaryTitleWidth);
        for (size_t i = 0; i < section.mRows.size(); ++i)
            line += (i == 0 ? "" : "  ") + section.mRows[i].mLabel + " " + section.mRows[i].mValue;
        text += line + "\n";
    }
    if (inRun.mErrors.empty())
        text += PadRight("errors", cSummaryTitleWidth) + "none\n";
    else
    {
        text += Format("errors (%zu):\n", inRun.mErrors.size());
        for (const std::string& error : inRun.mErrors)
            text += "  - " + OneLine(error) + "\n";
    }
    return text;
}

std::string SummaryMarkdown(const DemoRunResult& inRun)
{
    std::string text =
        "## Run: " + EscapeMarkdown(ModeName(inRun, "(unnamed mode)")) + "\n\n" + RunHeading(inRun) + ".\n\n";
    text += "| Area | Metric | Value |\n|---|---|--:|\n";
    const std::vector<Section> sections = BuildSummary(inRun);
    std::string
        phases; // A row a phase, its figures side by side, instead of 4 rows a phase in the table above
    for (const Section& section : sections)
    {
        if (!section.mStepPhase.empty())
        {
            phases += "| " + EscapeMarkdownCell(section.mStepPhase);
            for (const Row& row : section.mRows)
                phases += " | " + EscapeMarkdownCell(row.mValue);
            phases += " |\n";
            continue;
        }
        for (size_t i = 0; i < section.mRows.size(); ++i)
            text += "| " + (i == 0 ? EscapeMarkdownCell(section.mTitle) : std::string()) + " | " +
                    EscapeMarkdownCell(section.mRows[i].mLabel) + " | " +
                    EscapeMarkdownCell(section.mRows[i].mValue) + " |\n";
    }
    if (!phases.empty())
        text +=
            "\nThe physics step's phases, ms per frame. The narrow phase includes the pair search and any "
            "wait for the broad-phase update beside it; the step's lock waits are inside the phases.\n\n"
            "| phase | avg | p50 | p99 | max |\n|---|--:|--:|--:|--:|\n" +
            phases;
    if (inRun.mErrors.empty())
        text += "\n**Errors:** none\n\n";
    else
    {
        text += Format("\n**Errors (%zu):**\n\n", inRun.mErrors.size());
        for (const std::string& error : inRun.mErrors)
            text += "- " + EscapeMarkdown(error) + "\n";
        text += "\n";
    }
    return text;
}

Table BuildComparison(const DemoRunResult& inLockFree, const DemoRunResult& inGlobal)
{
    const SampleSummary lockFree = Summarize(inLockFree.mPhysicsMs);
    const SampleSummary global = Summarize(inGlobal.mPhysicsMs);

    Table table;
    table.mHeader = {"metric", ModeName(inLockFree, "lock-free"), ModeName(inGlobal, "global mutex"),
                     "global/lock-free", Format("%.0fx target, read as", cQueryTargetRatio)};
    table.mNumNumberColumns = 3;
    table.mRows.push_back({"physics avg ms/frame", Ms(lockFree, lockFree.mMean), Ms(global, global.mMean),
                           Ratio(global.mMean, lockFree.mMean)});
    table.mRows.push_back({"physics p99 ms/frame", Ms(lockFree, lockFree.mP99), Ms(global, global.mP99),
                           Ratio(global.mP99, lockFree.mP99)});
    table.mRows.push_back({"physics max ms/frame", Ms(lockFree, lockFree.mMax), Ms(global, global.mMax),
                           Ratio(global.mMax, lockFree.mMax)});
    table.mRows.push_back({"game-object queries", Count(inLockFree.mQueries), Count(inGlobal.mQueries), ""});

    // A mode that made no queries has no mean (GameObjects reports 0): no verdict from it
    auto queryMean = [](const DemoRunResult& inRun)
    { return inRun.mQueries == 0 ? std::nan("") : inRun.mQueryMicrosMean; };
    table.mRows.push_back({"query µs/query mean", Micros(inLockFree.mQueryMicrosMean),
                           Micros(inGlobal.mQueryMicrosMean),
                           Ratio(inGlobal.mQueryMicrosMean, inLockFree.mQueryMicrosMean),
                           QueryTarget(queryMean(inGlobal), queryMean(inLockFree), "µs per query")});

    const size_t threads =
        std::max(inLockFree.mQueryMicrosPerThread.size(), inGlobal.mQueryMicrosPerThread.size());
    auto threadValue = [](const DemoRunResult& inRun, size_t inThread)
    {
        return inThread < inRun.mQueryMicrosPerThread.size() ? inRun.mQueryMicrosPerThread[inThread]
                                                             : std::nan("");
    };
    for (size_t i = 0; i < threads; ++i)
    {
        const double lockFreeValue = threadValue(inLockFree, i);
        const double globalValue = threadValue(inGlobal, i);
        table.mRows.push_back({Format("query µs/query thread %zu", i), Micros(lockFreeValue),
                               Micros(globalValue), Ratio(globalValue, lockFreeValue)});
    }
    table.mRows.push_back(
        {"query lock waits µs/query", Micros(QueryLockWaitMicrosPerQuery(inLockFree)),
         Micros(QueryLockWaitMicrosPerQuery(inGlobal)),
         WaitRatio(QueryLockWaitMicrosPerQuery(inGlobal), QueryLockWaitMicrosPerQuery(inLockFree))});
    const double lockFreeWaits = MeanOf(LockWaitMicrosPerThreadFrame(inLockFree));
    const double globalWaits = MeanOf(LockWaitMicrosPerThreadFrame(inGlobal));
    table.mRows.push_back({"lock waits µs/frame per thread", Micros(lockFreeWaits), Micros(globalWaits),
                           WaitRatio(globalWaits, lockFreeWaits),
                           QueryTarget(globalWaits, lockFreeWaits, "lock cost per thread")});
    auto kindRow = [&](const char* inName, const std::vector<double> DemoRunResult::*inSeries)
    {
        const double lockFree = MeanOf(inLockFree.*inSeries);
        const double global = MeanOf(inGlobal.*inSeries);
        table.mRows.push_back({inName, Micros(lockFree), Micros(global), WaitRatio(global, lockFree)});
    };
    kindRow("  of which broad-phase locks", &DemoRunResult::mBroadPhaseLockWaitMicrosPerThreadFrame);
    kindRow("  of which body locks", &DemoRunResult::mBodyLockWaitMicrosPerThreadFrame);
    kindRow("moves' lock waits µs/frame per thread", &DemoRunResult::mMoveLockWaitMicrosPerThreadFrame);
    return table;
}

std::string TableText(const Table& inTable)
{
    std::vector<size_t> widths(inTable.mHeader.size(), 0);
    auto measure = [&](const std::vector<std::string>& inCells)
    {
        for (size_t c = 0; c < inCells.size() && c < widths.size(); ++c)
            widths[c] = std::max(widths[c], TextWidth(inCells[c]));
    };
    measure(inTable.mHeader);
    for (const std::vector<std::string>& row : inTable.mRows)
        measure(row);

    // Names and text left-aligned, numbers right-aligned so their decimal points line up.
    auto line = [&](const std::vector<std::string>& inCells)
    {
        std::string text;
        for (size_t c = 0; c < inCells.size() && c < widths.size(); ++c)
            text += (c == 0                     ? PadRight(inCells[c], widths[c])
                     : IsTextColumn(inTable, c) ? "  " + PadRight(inCells[c], widths[c])
                                                : "  " + PadLeft(inCells[c], widths[c]));
        while (!text.empty() && text.back() == ' ')
            text.pop_back();
        return text + "\n";
    };
    std::string text = line(inTable.mHeader);
    size_t total = 0;
    for (size_t width : widths)
        total += width + 2;
    text += std::string(total > 2 ? total - 2 : 0, '-') + "\n";
    for (const std::vector<std::string>& row : inTable.mRows)
        text += line(row);
    return text;
}

std::string TableMarkdown(const Table& inTable)
{
    auto line = [&](const std::vector<std::string>& inCells)
    {
        // Appended piece by piece: g++ 12 warns (wrongly, -Wrestrict) about " " + std::string temporaries
        // here. A short row gets empty cells: GitHub fills them in itself, other renderers may not.
        std::string text = "|";
        for (size_t c = 0; c < std::max(inCells.size(), inTable.mHeader.size()); ++c)
        {
            text += ' ';
            if (c < inCells.size()) text += EscapeMarkdownCell(inCells[c]);
            text += " |";
        }
        text += '\n';
        return text;
    };
    std::string text = line(inTable.mHeader) + "|---|";
    for (size_t c = 1; c < inTable.mHeader.size(); ++c)
        text += IsTextColumn(inTable, c) ? "---|" : "--:|";
    text += "\n";
    for (const std::vector<std::string>& row : inTable.mRows)
        text += line(row);
    return text;
}

// ---------------------------------------------------------------------------------------------------------
// SVG helpers.

struct Axis
{
    double mLow = 0.0;
    double mHigh = 1.0;
    std::vector<double> mTicks;
};

/// An axis from a "nice" multiple of 1, 2 or 5 x 10^k below inMin (or 0) to one above inMax, with about five
/// ticks. Falls back to the raw bounds when the range overflows a double.
Axis MakeAxis(double inMin, double inMax, bool inIntegerTicks)
{
    Axis axis;
    double low = std::min(0.0, inMin);
    double high = std::max(0.0, inMax);
    if (!(high > low)) high = low + 1.0;
    axis.mLow = low;
    axis.mHigh = high;
    axis.mTicks = {low, high};

    const double range = high - low;
    if (!std::isfinite(range)) return axis;
    const double rough = range / 5.0;
    const double magnitude = std::pow(10.0, std::floor(std::log10(rough)));
    const double normalized = rough / magnitude;
    double step = (normalized <= 1.0   ? 1.0
                   : normalized <= 2.0 ? 2.0
                   : normalized <= 5.0 ? 5.0
                                       : 10.0) *
                  magnitude;
    if (inIntegerTicks) step = std::max(1.0, std::ceil(step));
    const double niceLow = std::floor(low / step) * step;
    const double niceHigh = std::ceil(high / step) * step;
    if (!(step > 0.0) || !std::isfinite(step) || !std::isfinite(niceLow) || !std::isfinite(niceHigh) ||
        !(niceHigh > niceLow) || (niceHigh - niceLow) / step > 20.0)
        return axis;

    axis.mLow = niceLow;
    axis.mHigh = niceHigh;
    axis.mTicks.clear();
    for (int i = 0; i <= 20; ++i)
    {
        double value = niceLow + step * double(i);
        if (value > niceHigh + step * 1e-6) break;
        if (std::abs(value) < step * 1e-9) value = 0.0; // No "-1.1e-17" labels from rounding
        axis.mTicks.push_back(value);
    }
    return axis;
}

/// Position of inValue along inAxis in [0, 1]; halves first so that low/high near the double limits do not
/// overflow.
double AxisFraction(const Axis& inAxis, double inValue)
{
    const double fraction = (inValue * 0.5 - inAxis.mLow * 0.5) / (inAxis.mHigh * 0.5 - inAxis.mLow * 0.5);
    return std::isfinite(fraction) ? std::clamp(fraction, 0.0, 1.0) : 0.0;
}

std::string SvgOpen()
{
    return Format(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" viewBox=\"0 0 %.0f "
        "%.0f\" font-family=\"sans-serif\" font-size=\"11\">\n"
        "<rect width=\"%.0f\" height=\"%.0f\" fill=\"white\"/>\n",
        cSvgWidth, cSvgHeight, cSvgWidth, cSvgHeight, cSvgWidth, cSvgHeight);
}

std::string SvgText(double inX, double inY, const char* inAnchor, const std::string& inText,
                    const char* inExtra = "")
{
    return Format("<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"%s\"%s>", inX, inY, inAnchor, inExtra) +
           EscapeXml(inText) + "</text>\n";
}

/// A label under the x axis, nudged left when the last one would run off the image.
std::string SvgXLabel(double inX, const std::string& inText)
{
    const double halfWidth = cCharWidth * double(TextWidth(inText)) / 2.0;
    return SvgText(std::min(inX, cSvgWidth - 2.0 - halfWidth), cPlotBottom + 16.0, "middle", inText);
}

/// Title, y-axis ticks with grid lines, both axis lines and both axis labels.
std::string SvgFrame(const std::string& inTitle, const std::string& inXLabel, const std::string& inYLabel,
                     const Axis& inYAxis, double inPlotTop)
{
    std::string svg =
        SvgText(cSvgWidth / 2.0, 22.0, "middle", inTitle, " font-size=\"15\" font-weight=\"bold\"");
    for (double tick : inYAxis.mTicks)
    {
        const double y = cPlotBottom - AxisFraction(inYAxis, tick) * (cPlotBottom - inPlotTop);
        svg += Format("<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#dddddd\"/>\n",
                      cPlotLeft, y, cPlotRight, y);
        svg += SvgText(cPlotLeft - 6.0, y + 4.0, "end", Format("%.10g", tick));
    }
    svg += Format("<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\"/>\n", cPlotLeft,
                  inPlotTop, cPlotLeft, cPlotBottom);
    svg += Format("<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\"/>\n", cPlotLeft,
                  cPlotBottom, cPlotRight, cPlotBottom);
    svg += SvgText((cPlotLeft + cPlotRight) / 2.0, cSvgHeight - 10.0, "middle", inXLabel);
    const double middle = (inPlotTop + cPlotBottom) / 2.0;
    svg += SvgText(16.0, middle, "middle", inYLabel,
                   Format(" transform=\"rotate(-90 16 %.1f)\"", middle).c_str());
    return svg;
}

std::string SvgNoData(double inPlotTop)
{
    return SvgText((cPlotLeft + cPlotRight) / 2.0, (inPlotTop + cPlotBottom) / 2.0, "middle", "no data",
                   " fill=\"#888888\"");
}

/// The points of one series to draw, in index order; nullopt breaks the line. Long series keep the minimum
/// and maximum of each pixel column, so spikes survive while the file stays small.
std::vector<std::optional<std::pair<size_t, double>>> PlotPoints(const std::vector<double>& inSamples)
{
    std::vector<std::optional<std::pair<size_t, double>>> points;
    const size_t columns = size_t(cPlotRight - cPlotLeft);
    if (inSamples.size() <= 2 * columns)
    {
        for (size_t i = 0; i < inSamples.size(); ++i)
            if (std::isfinite(inSamples[i]))
                points.push_back(std::pair(i, inSamples[i]));
            else
                points.push_back(std::nullopt);
        return points;
    }
    for (size_t column = 0; column < columns; ++column)
    {
        const size_t begin = column * inSamples.size() / columns;
        const size_t end = (column + 1) * inSamples.size() / columns;
        std::optional<size_t> lowest, highest;
        for (size_t i = begin; i < end; ++i)
        {
            if (!std::isfinite(inSamples[i])) continue;
            if (!lowest || inSamples[i] < inSamples[*lowest]) lowest = i;
            if (!highest || inSamples[i] > inSamples[*highest]) highest = i;
        }
        if (!lowest)
        {
            points.push_back(std::nullopt);
            continue;
        }
        const size_t first = std::min(*lowest, *highest), second = std::max(*lowest, *highest);
        points.push_back(std::pair(first, inSamples[first]));
        if (second != first) points.push_back(std::pair(second, inSamples[second]));
    }
    return points;
}

} // namespace

void PrintSummary(std::FILE* inOut, const DemoRunResult& inRun)
{
    if (inOut == nullptr) return;
    std::fputs(SummaryText(inRun).c_str(), inOut);
}

void PrintComparison(std::FILE* inOut, const DemoRunResult& inLockFree, const DemoRunResult& inGlobal)
{
    if (inOut == nullptr) return;
    std::fputs(TableText(BuildComparison(inLockFree, inGlobal)).c_str(), inOut);
}

std::string SvgLineChart(const std::string& inTitle, const std::string& inYLabel,
                         const std::vector<std::pair<std::string, std::vector<double>>>& inSeries)
{
    size_t sampleCount = 0;
    double minValue = std::numeric_limits<double>::infinity();
    double maxValue = -std::numeric_limits<double>::infinity();
    for (const auto& [name, samples] : inSeries)
    {
        sampleCount = std::max(sampleCount, samples.size());
        for (double value : samples)
            if (std::isfinite(value))
            {
                minValue = std::min(minValue, value);
                maxValue = std::max(maxValue, value);
            }
    }
    const bool hasData = minValue <= maxValue;
    const Axis yAxis = hasData ? MakeAxis(minValue, maxValue, false) : MakeAxis(0.0, 1.0, false);
    const Axis xAxis = MakeAxis(0.0, sampleCount > 0 ? double(sampleCount - 1) : 0.0, true);

    // Lay the legend out first: its rows push the plot down.
    std::vector<std::pair<double, double>> legendPositions;
    double legendX = cPlotLeft, legendY = 40.0;
    for (const auto& [name, samples] : inSeries)
    {
        const std::string label = samples.empty() ? name + " (no data)" : name;
        const double width = 28.0 + cCharWidth * double(TextWidth(label));
        if (legendX + width > cPlotRight && legendX > cPlotLeft)
        {
            legendX = cPlotLeft;
            legendY += cLegendRowHeight;
        }
        legendPositions.emplace_back(legendX, legendY);
        legendX += width + 12.0;
    }
    const double plotTop = std::min(cPlotTop + (legendY - 40.0), cPlotBottom - 60.0);

    std::string svg = SvgOpen() + SvgFrame(inTitle, "sample", inYLabel, yAxis, plotTop);
    auto mapX = [&](double inIndex)
    { return cPlotLeft + AxisFraction(xAxis, inIndex) * (cPlotRight - cPlotLeft); };
    auto mapY = [&](double inValue)
    { return cPlotBottom - AxisFraction(yAxis, inValue) * (cPlotBottom - plotTop); };
    for (double tick : xAxis.mTicks)
    {
        const double x = mapX(tick);
        svg += Format("<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\"/>\n", x,
                      cPlotBottom, x, cPlotBottom + 4.0);
        svg += SvgXLabel(x, Format("%.10g", tick));
    }
    if (!hasData) svg += SvgNoData(plotTop);

    for (size_t s = 0; s < inSeries.size(); ++s)
    {
        const auto& [name, samples] = inSeries[s];
        const char* colour = cPalette[s % std::size(cPalette)];
        std::string segment;
        size_t segmentPoints = 0;
        std::pair<double, double> lastPoint;
        auto flush = [&]()
        {
            // A lone point between gaps would be an invisible one-vertex polyline.
            if (segmentPoints == 1)
                svg += Format("<circle cx=\"%.1f\" cy=\"%.1f\" r=\"1.5\" fill=\"%s\"/>\n", lastPoint.first,
                              lastPoint.second, colour);
            else if (segmentPoints > 1)
                svg += Format("<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"1.2\" "
                              "stroke-linejoin=\"round\" points=\"",
                              colour) +
                       segment + "\"/>\n";
            segment.clear();
            segmentPoints = 0;
        };
        for (const auto& point : PlotPoints(samples))
        {
            if (!point)
            {
                flush();
                continue;
            }
            lastPoint = {mapX(double(point->first)), mapY(point->second)};
            segment +=
                Format("%s%.1f,%.1f", segmentPoints == 0 ? "" : " ", lastPoint.first, lastPoint.second);
            ++segmentPoints;
        }
        flush();

        const auto [x, y] = legendPositions[s];
        svg += Format(
            "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\" stroke-width=\"3\"/>\n", x,
            y - 4.0, x + 20.0, y - 4.0, colour);
        svg += SvgText(x + 26.0, y, "start", samples.empty() ? name + " (no data)" : name);
    }
    return svg + "</svg>\n";
}

std::string SvgHistogram(const std::string& inTitle, const std::string& inXLabel,
                         const std::vector<uint32_t>& inValues)
{
    // 64-bit so that a value of UINT32_MAX cannot overflow the bucket arithmetic.
    const uint64_t maxValue = inValues.empty() ? 0 : *std::max_element(inValues.begin(), inValues.end());
    const uint64_t bucketWidth = (maxValue + 1 + cMaxHistogramBuckets - 1) / cMaxHistogramBuckets;
    const size_t bucketCount = inValues.empty() ? 0 : size_t((maxValue + 1 + bucketWidth - 1) / bucketWidth);
    std::vector<uint64_t> counts(bucketCount, 0);
    for (uint32_t value : inValues)
        ++counts[size_t(value / bucketWidth)];
    const uint64_t maxCount = counts.empty() ? 0 : *std::max_element(counts.begin(), counts.end());

    const double plotHeight = cPlotBottom - cPlotTop;
    const double slot = bucketCount == 0 ? 0.0 : (cPlotRight - cPlotLeft) / double(bucketCount);
    // Counts wider than their bar are drawn vertically; the y axis gets headroom so they stay in the plot.
    const double countLabelWidth = cCharWidth * double(Count(maxCount).size());
    const bool verticalCounts = countLabelWidth > slot;
    const double labelHeight = verticalCounts ? countLabelWidth + 4.0 : 14.0;
    const Axis yAxis =
        MakeAxis(0.0, maxCount == 0 ? 1.0 : double(maxCount) * plotHeight / (plotHeight - labelHeight), true);

    const std::string title = inValues.empty() ? inTitle : inTitle + " (n = " + Count(inValues.size()) + ")";
    std::string svg = SvgOpen() + SvgFrame(title, inXLabel, "count", yAxis, cPlotTop);
    if (bucketCount == 0) return svg + SvgNoData(cPlotTop) + "</svg>\n";

    auto bucketLabel = [&](size_t inBucket)
    {
        const uint64_t low = inBucket * bucketWidth;
        return bucketWidth == 1 ? Count(low) : Count(low) + "-" + Count(low + bucketWidth - 1);
    };
    // Label every n-th bucket so that the x labels never overlap.
    const double xLabelWidth = cCharWidth * double(bucketLabel(bucketCount - 1).size()) + 8.0;
    const size_t labelEvery = std::max<size_t>(1, size_t(std::ceil(xLabelWidth / slot)));

    for (size_t i = 0; i < bucketCount; ++i)
    {
        const double centre = cPlotLeft + slot * (double(i) + 0.5);
        const double top = cPlotBottom - AxisFraction(yAxis, double(counts[i])) * plotHeight;
        if (counts[i] > 0)
        {
            svg += Format("<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"%s\"/>\n",
                          centre - slot * 0.4, top, slot * 0.8, cPlotBottom - top, cPalette[0]);
            if (verticalCounts)
                svg += SvgText(
                    centre + 4.0, top - 3.0, "start", Count(counts[i]),
                    Format(" font-size=\"10\" transform=\"rotate(-90 %.1f %.1f)\"", centre + 4.0, top - 3.0)
                        .c_str());
            else
                svg += SvgText(centre, top - 3.0, "middle", Count(counts[i]), " font-size=\"10\"");
        }
        if (i % labelEvery == 0)
        {
            svg += Format("<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\"/>\n",
                          centre, cPlotBottom, centre, cPlotBottom + 4.0);
            svg += SvgXLabel(centre, bucketLabel(i));
        }
    }
    return svg + "</svg>\n";
}

namespace
{

/// Writes the whole file or reports why not; fopen/fclose rather than streams because they set errno, which
/// gives the reason.
bool WriteFile(const fs::path& inPath, const std::string& inContents, std::string& outError)
{
    errno = 0;
    std::FILE* file = std::fopen(inPath.string().c_str(), "wb");
    if (file == nullptr)
    {
        outError = "cannot open '" + inPath.string() +
                   "' for writing: " + (errno != 0 ? std::strerror(errno) : "unknown error");
        return false;
    }
    const size_t written = std::fwrite(inContents.data(), 1, inContents.size(), file);
    const int writeErrno = errno;
    // fclose flushes, so a full disk may only show up here.
    const bool closed = std::fclose(file) == 0;
    if (written != inContents.size() || !closed)
    {
        const int error = writeErrno != 0 ? writeErrno : errno;
        outError = "cannot write '" + inPath.string() +
                   "': " + (error != 0 ? std::strerror(error) : "unknown error");
        return false;
    }
    return true;
}

/// A fence longer than any run of backticks in inText, so a command line cannot close its code block.
std::string CodeFence(const std::string& inText)
{
    size_t longest = 0, current = 0;
    for (char c : inText)
    {
        current = c == '`' ? current + 1 : 0;
        longest = std::max(longest, current);
    }
    return std::string(std::max<size_t>(3, longest + 1), '`');
}

std::string ReportMarkdown(const std::vector<DemoRunResult>& inRuns, const std::string& inCommandLine)
{
    std::string text = "# Cairn demo report\n\nCommand line:\n\n";
    const std::string fence = CodeFence(inCommandLine);
    text += fence + "text\n" + inCommandLine + "\n" + fence + "\n\n";
    if (inRuns.empty()) text += "No runs were recorded.\n\n";
    for (const DemoRunResult& run : inRuns)
        text += SummaryMarkdown(run);
    if (inRuns.size() == 2)
    {
        // The comparison's ratios are global/lock-free whatever order the runner used.
        const bool firstIsGlobal = inRuns[0].mModeName.find("global") != std::string::npos &&
                                   inRuns[1].mModeName.find("global") == std::string::npos;
        const DemoRunResult& lockFree = firstIsGlobal ? inRuns[1] : inRuns[0];
        const DemoRunResult& global = firstIsGlobal ? inRuns[0] : inRuns[1];
        text += "## Comparison\n\n" + TableMarkdown(BuildComparison(lockFree, global)) + "\n";
        text +=
            "The game objects' queries run while the physics step runs on another thread, as in a game with "
            "a "
            "frame pipeline; their moves follow the step. The modes are the reference talk's before and "
            "after as a whole: one mutex around the broad phase and one for all bodies, under which a query "
            "reads each body and so waits for the step that holds it, against the lock-free trees and "
            "queries that read the bodies' published poses with no lock (the talk's slide: 500 against 10 µs "
            "a thread). The query lock waits are the time the query jobs spent blocked on the engine's "
            "locks, per query and per thread and frame; the two rows below split them between the broad "
            "phase's locks and the body locks. The moves' waits, after the step, are apart.\n\n"
            "The 10x query-cost target is judged two ways. Read as the talk's figure, which follows its "
            "\"Overhead locks 10-20 %\" of the game-object update, it is the locks' cost per thread: the "
            "lock-waits row. Read as the queries' whole time, it is the µs/query row, which holds the waits "
            "for the step in the global-mutex mode.\n\n";
    }
    if (!inRuns.empty())
        text +=
            "A physics spike is a frame over " + Format("%g", cSpikeTargetRatio) +
            "x its run's average. The host's share of one is the time the updating thread was off its core "
            "while the guest never switched it out (its CPU clock stood still while the wall clock ran): "
            "the hypervisor had taken its vCPU. Only the updating thread is watched, so a job thread that "
            "lost its core while the updating thread waited for it is not counted. The main thread's "
            "streaming time is split the same way. Guest steal is the same kind of time from all vCPUs over "
            "the run, as the guest counts it (10 ms ticks). A vCPU that runs slowly while it counts as "
            "running is seen by neither measure: "
            "`cairn-bench-host` times the same work every frame, without the engine, to show how steady the "
            "machine itself is.\n\n";
    text += "## Charts\n\n![Physics ms per frame](frame_times.svg)\n\n";
    text += "![Navmesh tile latency in frames](tile_latency.svg)\n\n";
    text += "![Navigation ms per frame: main thread and job threads](nav_ms.svg)\n\n";
    text += "![The final navmesh by tile build latency, and agents' trails](nav_map.svg)\n\n";
    text += "Every frame's figures, with the physics step's phases: [frames.csv](frames.csv).\n";
    return text;
}

/// A CSV field: the mode names are plain words, but a comma or quote in one must not shift the columns.
std::string CsvField(const std::string& inText)
{
    if (inText.find_first_of(",\"\r\n") == std::string::npos) return inText;
    std::string quoted = "\"";
    for (char c : inText)
        quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
    return quoted + "\"";
}

/// Removes the temporary files it holds when the report is abandoned half-way, however that happens.
struct TemporaryFiles
{
    std::vector<fs::path> mPaths;

    ~TemporaryFiles()
    {
        for (const fs::path& path : mPaths)
        {
            std::error_code ignored;
            fs::remove(path, ignored);
        }
    }
};

/// A per-frame figure for frames.csv: empty where the series has none for the frame.
std::string OptionalMsField(const std::vector<double>& inMs, size_t inFrame)
{
    if (inFrame >= inMs.size() || !std::isfinite(inMs[inFrame])) return {};
    return Format("%.4f", inMs[inFrame]);
}

/// A frame's host share for frames.csv: empty where it can not be told (the thread was switched out).
std::string HostTakenField(const std::vector<double>& inHostTakenMs, size_t inFrame)
{
    if (inFrame >= inHostTakenMs.size() || !std::isfinite(inHostTakenMs[inFrame])) return {};
    return Format("%.4f", inHostTakenMs[inFrame]);
}

} // namespace

std::string FramesCsv(const std::vector<DemoRunResult>& inRuns)
{
    std::string csv =
        "mode,frame,frame_ms,physics_ms,streaming_ms,broadphase_update_ms,narrow_phase_ms,"
        "islands_ms,solve_ms,finish_ms,active_bodies,body_pairs,contact_points,step_lock_wait_ms,"
        "game_object_lock_wait_us,physics_host_taken_ms,streaming_host_taken_ms,nav_main_thread_ms,"
        "nav_job_threads_ms,nav_other_task_switches\n";
    for (const DemoRunResult& run : inRuns)
    {
        const std::string mode = CsvField(run.mModeName);
        // The series are filled frame by frame together; a shorter one ends the rows instead of reading past
        const size_t frames =
            std::min({run.mFrameMs.size(), run.mPhysicsMs.size(), run.mMainThreadStreamMs.size(),
                      run.mSteps.size(), run.mGameObjectLockWaitUs.size()});
        for (size_t i = 0; i < frames; ++i)
        {
            const StepStatistics& step = run.mSteps[i];
            const std::vector<int64_t>& switches = run.mAgentStats.mOtherTaskSwitches;
            const std::string switchesField = i < switches.size() && switches[i] >= 0
                                                  ? Format("%lld", (long long)switches[i])
                                                  : std::string();
            csv += Format(
                "%s,%zu,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%u,%u,%u,%.4f,%.2f,%s,%s,%s,%s,%s\n",
                mode.c_str(), i, run.mFrameMs[i], run.mPhysicsMs[i], run.mMainThreadStreamMs[i],
                step.mBroadPhaseUpdateMs, step.mNarrowPhaseMs, step.mIslandsMs, step.mSolveMs, step.mFinishMs,
                step.mNumActiveBodies, step.mNumBodyPairs, step.mNumContactPoints, step.mLockWaitMs,
                run.mGameObjectLockWaitUs[i], HostTakenField(run.mPhysicsHostTakenMs, i).c_str(),
                HostTakenField(run.mMainThreadStreamHostTakenMs, i).c_str(),
                OptionalMsField(run.mAgentStats.mMainThreadMs, i).c_str(),
                OptionalMsField(run.mAgentStats.mJobThreadsMs, i).c_str(), switchesField.c_str());
        }
    }
    return csv;
}

bool WriteReport(const std::string& inFolder, const std::vector<DemoRunResult>& inRuns,
                 const std::string& inCommandLine, std::string& outError)
{
    outError.clear();
    TemporaryFiles temporaries;
    try
    {
        if (inFolder.empty())
        {
            outError = "report folder: the path is empty";
            return false;
        }
        const fs::path folder(inFolder);
        std::error_code error;
        fs::create_directories(folder, error);
        if (error)
        {
            outError = "cannot create report folder '" + inFolder + "': " + error.message();
            return false;
        }
        if (!fs::is_directory(folder, error))
        {
            outError = "report folder '" + inFolder + "' is not a directory";
            return false;
        }

        std::vector<std::pair<std::string, std::vector<double>>> frameSeries;
        for (size_t i = 0; i < inRuns.size(); ++i)
            frameSeries.emplace_back(ModeName(inRuns[i], Format("run %zu", i + 1).c_str()),
                                     inRuns[i].mPhysicsMs);
        const std::string latencyTitle =
            "Navmesh tile latency, request to publication" +
            (inRuns.empty() ? std::string() : " (" + ModeName(inRuns[0], "run 1") + ")");
        const std::vector<std::pair<std::string, std::string>> files = {
            {"report.md", ReportMarkdown(inRuns, inCommandLine)},
            {"frames.csv", FramesCsv(inRuns)},
            {"frame_times.svg", SvgLineChart("Physics ms per frame", "ms", frameSeries)},
            {"nav_map.svg", inRuns.empty() ? SvgNavMap(DemoRunResult()) : SvgNavMap(inRuns[0])},
            {"nav_ms.svg",
             SvgLineChart(
                 "Navigation ms per frame" +
                     (inRuns.empty() ? std::string() : " (" + ModeName(inRuns[0], "run 1") + ")"),
                 "ms",
                 inRuns.empty()
                     ? std::vector<std::pair<std::string, std::vector<double>>>()
                     : std::vector<std::pair<std::string,
                                             std::vector<double>>>{{"main thread",
                                                                    inRuns[0].mAgentStats.mMainThreadMs},
                                                                   {"job threads",
                                                                    inRuns[0].mAgentStats.mJobThreadsMs}})},
            {"tile_latency.svg",
             SvgHistogram(latencyTitle, "frames",
                          inRuns.empty() ? std::vector<uint32_t>() : inRuns[0].mNavTileLatencyFrames)}};

        // Everything is written to temporary names before anything is renamed, so a failed write (a full
        // disk, say) leaves no truncated file and the previous report, if any, as it was. Only a failed
        // rename, which is rare, can leave old and new files side by side.
        for (const auto& [name, contents] : files)
        {
            const fs::path temporary = folder / (name + ".tmp");
            if (!WriteFile(temporary, contents, outError))
            {
                // Only a truncated file of ours goes: whatever blocked the open (a directory, say) is not
                // ours.
                if (fs::is_regular_file(temporary, error)) fs::remove(temporary, error);
                return false;
            }
            temporaries.mPaths.push_back(temporary);
        }
        for (size_t i = 0; i < files.size(); ++i)
        {
            const fs::path target = folder / files[i].first;
            fs::rename(temporaries.mPaths[i], target, error);
            if (error)
            {
                outError = "cannot rename '" + temporaries.mPaths[i].string() + "' to '" + target.string() +
                           "': " + error.message();
                return false;
            }
        }
        temporaries.mPaths.clear();
        return true;
    }
    catch (const std::exception& inException)
    {
        outError = "writing the report to '" + inFolder + "' failed: " + inException.what();
        return false;
    }
    catch (...)
    {
        outError = "writing the report to '" + inFolder + "' failed: unknown exception";
        return false;
    }
}

} // namespace cairn::demo
