#include "demo/NavMapSvg.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace cairn::demo
{
namespace
{
constexpr double cWidth = 800.0;
constexpr double cMargin = 20.0;
constexpr double cTitleHeight = 40.0;
constexpr double cLegendHeight = 40.0;
constexpr const char* cTrailColours[] = {"#1f77b4", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#000000"};

std::string Number(double inValue)
{
    char buffer[32];
    std::snprintf(buffer, sizeof(buffer), "%.1f", inValue);
    return buffer;
}

/// Green (built at once) through yellow to red (inWorst frames or more); grey when not known.
std::string LatencyColour(int inFrames, int inWorst)
{
    if (inFrames < 0) return "#c8c8c8";
    const double t = inWorst <= 0 ? 0.0 : std::clamp(double(inFrames) / double(inWorst), 0.0, 1.0);
    const int red = int(std::lround(t < 0.5 ? 510.0 * t : 255.0));
    const int green = int(std::lround(t < 0.5 ? 200.0 : 200.0 * (2.0 - 2.0 * t)));
    char buffer[8];
    std::snprintf(buffer, sizeof(buffer), "#%02x%02x40", std::clamp(red, 0, 255), std::clamp(green, 0, 255));
    return buffer;
}
} // namespace

std::string SvgNavMap(const DemoRunResult& inRun)
{
    // The world area the picture shows: every polygon and trail point (finite ones)
    double minX = std::numeric_limits<double>::max(), minZ = minX;
    double maxX = std::numeric_limits<double>::lowest(), maxZ = maxX;
    auto include = [&](double inX, double inZ)
    {
        if (!std::isfinite(inX) || !std::isfinite(inZ)) return;
        minX = std::min(minX, inX);
        maxX = std::max(maxX, inX);
        minZ = std::min(minZ, inZ);
        maxZ = std::max(maxZ, inZ);
    };
    for (const DemoRunResult::MapPolygon& polygon : inRun.mNavMap)
        for (const auto& [x, z] : polygon.mOutline)
            include(x, z);
    for (const std::vector<Vec3>& trail : inRun.mAgentStats.mTrails)
        for (const Vec3& point : trail)
            include(point.x(), point.z());
    const bool empty = !(maxX > minX) || !(maxZ > minZ);
    const double scale = empty ? 1.0 : (cWidth - 2.0 * cMargin) / std::max(maxX - minX, maxZ - minZ);
    const double plotHeight = empty ? 200.0 : (maxZ - minZ) * scale;
    const double height = cTitleHeight + plotHeight + cLegendHeight + cMargin;
    auto px = [&](double inX) { return cMargin + (inX - minX) * scale; };
    auto py = [&](double inZ) { return cTitleHeight + (maxZ - inZ) * scale; }; // +z up

    std::string svg = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + Number(cWidth) + "\" height=\"" +
                      Number(height) + "\" viewBox=\"0 0 " + Number(cWidth) + " " + Number(height) +
                      "\" font-family=\"sans-serif\" font-size=\"11\">\n<rect width=\"100%\" height=\"100%\" "
                      "fill=\"white\"/>\n";
    svg += "<text x=\"" + Number(cWidth / 2.0) +
           "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\" font-weight=\"bold\">Final navmesh (human "
           "profile) by tile build latency, and agents' trails</text>\n";
    if (empty)
        return svg + "<text x=\"" + Number(cWidth / 2.0) + "\" y=\"" + Number(cTitleHeight + 100.0) +
               "\" text-anchor=\"middle\" fill=\"#888888\">no data</text>\n</svg>\n";

    // The colour scale ends at the run's p99 latency, so one slow tile does not wash the rest out
    std::vector<int> latencies;
    for (const DemoRunResult::MapPolygon& polygon : inRun.mNavMap)
        if (polygon.mLatencyFrames >= 0) latencies.push_back(polygon.mLatencyFrames);
    std::sort(latencies.begin(), latencies.end());
    const int worst =
        latencies.empty() ? 0 : latencies[std::min(latencies.size() - 1, latencies.size() * 99 / 100)];

    for (const DemoRunResult::MapPolygon& polygon : inRun.mNavMap)
    {
        std::string points;
        for (const auto& [x, z] : polygon.mOutline)
            if (std::isfinite(x) && std::isfinite(z)) points += Number(px(x)) + "," + Number(py(z)) + " ";
        if (points.empty()) continue;
        svg += "<polygon points=\"" + points + "\" fill=\"" + LatencyColour(polygon.mLatencyFrames, worst) +
               "\" stroke=\"#ffffff\" stroke-width=\"0.3\"/>\n";
    }
    const std::vector<std::vector<Vec3>>& trails = inRun.mAgentStats.mTrails;
    for (size_t t = 0; t < trails.size(); ++t)
    {
        // A large agent's trail is drawn wider; a non-finite point (the agent put back) breaks the line
        const float radius =
            t < inRun.mAgentStats.mTrailRadii.size() ? inRun.mAgentStats.mTrailRadii[t] : 0.6f;
        auto draw = [&](const std::string& inPoints)
        {
            if (inPoints.empty()) return;
            svg += "<polyline points=\"" + inPoints + "\" fill=\"none\" stroke=\"" +
                   cTrailColours[t % std::size(cTrailColours)] + "\" stroke-width=\"" +
                   Number(std::max(1.0, 1.5 * radius)) + "\" stroke-opacity=\"0.8\"/>\n";
        };
        std::string points;
        for (const Vec3& point : trails[t])
        {
            if (std::isfinite(point.x()) && std::isfinite(point.z()))
                points += Number(px(point.x())) + "," + Number(py(point.z())) + " ";
            else
            {
                draw(points);
                points.clear();
            }
        }
        draw(points);
    }

    // Legend: the colour scale, the map's scale
    const double legendY = cTitleHeight + plotHeight + 16.0;
    for (int i = 0; i <= 10; ++i)
        svg += "<rect x=\"" + Number(cMargin + 20.0 * i) + "\" y=\"" + Number(legendY) +
               "\" width=\"20\" height=\"10\" fill=\"" + LatencyColour(worst * i / 10, worst) + "\"/>\n";
    svg += "<text x=\"" + Number(cMargin + 230.0) + "\" y=\"" + Number(legendY + 9.0) +
           "\">tile latency 0 to " + std::to_string(worst) +
           " frames (p99) and more; grey: built before the run. Lines: agents' trails (wide: large "
           "agents). Width " +
           Number(maxX - minX) + " m</text>\n";
    return svg + "</svg>\n";
}

} // namespace cairn::demo
