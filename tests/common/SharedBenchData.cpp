#include "common/SharedBenchData.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <fstream>

namespace cairn
{
using namespace cairn::physics;

namespace
{

/// Rows of a CSV file with a known header, each split into numbers.
Result<std::vector<std::vector<double>>> ReadCsv(const std::string& inPath, const std::string& inHeader)
{
    std::ifstream file(inPath);
    if (!file) return MakeError(ErrorCode::IOError, "cannot open " + inPath);

    std::string line;
    if (!std::getline(file, line)) return MakeError(ErrorCode::ParseError, inPath + ": empty file");
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line != inHeader)
        return MakeError(ErrorCode::ParseError,
                         inPath + ": header '" + line + "', expected '" + inHeader + "'");
    const size_t columns = size_t(std::count(inHeader.begin(), inHeader.end(), ',')) + 1;

    std::vector<std::vector<double>> rows;
    for (size_t lineNumber = 2; std::getline(file, line); ++lineNumber)
    {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty()) continue;
        std::vector<double> row;
        const char* cursor = line.data();
        const char* end = line.data() + line.size();
        while (true)
        {
            double value = 0.0;
            const auto [next, error] = std::from_chars(cursor, end, value);
            if (error != std::errc() || !std::isfinite(value))
                return MakeError(ErrorCode::ParseError,
                                 inPath + ":" + std::to_string(lineNumber) + ": bad number");
            row.push_back(value);
            if (next == end) break;
            if (*next != ',')
                return MakeError(ErrorCode::ParseError,
                                 inPath + ":" + std::to_string(lineNumber) + ": expected ','");
            cursor = next + 1;
        }
        if (row.size() != columns)
            return MakeError(ErrorCode::ParseError, inPath + ":" + std::to_string(lineNumber) + ": " +
                                                        std::to_string(row.size()) + " columns, expected " +
                                                        std::to_string(columns));
        rows.push_back(std::move(row));
    }
    if (rows.empty()) return MakeError(ErrorCode::ParseError, inPath + ": no data rows");
    return rows;
}

Vec3 ToVec3(const std::vector<double>& inRow, size_t inFirst)
{
    return Vec3(float(inRow[inFirst]), float(inRow[inFirst + 1]), float(inRow[inFirst + 2]));
}

} // namespace

AABB BenchBox::GetWorldBounds() const
{
    const float c = std::abs(std::cos(mYaw));
    const float s = std::abs(std::sin(mYaw));
    const Vec3 extent(c * mHalfExtent.x() + s * mHalfExtent.z(), mHalfExtent.y(),
                      s * mHalfExtent.x() + c * mHalfExtent.z());
    return {mCenter - extent, mCenter + extent};
}

std::string GetSharedBenchDir()
{
    if (const char* dir = std::getenv("CAIRN_SHARED_DIR"); dir != nullptr && dir[0] != '\0')
        return std::string(dir) + "/bench";
#ifdef CAIRN_SHARED_DIR
    return std::string(CAIRN_SHARED_DIR) + "/bench";
#else
    return "/work/shared/bench";
#endif
}

std::string GetSharedDataDir()
{
    const std::string bench = GetSharedBenchDir();
    return bench.substr(0, bench.size() - std::string("/bench").size()) + "/data";
}

Result<std::vector<BenchBox>> LoadBenchBoxes(const std::string& inPath, bool inWithTile)
{
    auto rows = ReadCsv(inPath, inWithTile ? "tile,cx,cy,cz,hx,hy,hz,yaw" : "cx,cy,cz,hx,hy,hz,yaw");
    if (!rows) return rows.GetError();
    std::vector<BenchBox> boxes;
    boxes.reserve(rows.Value().size());
    const size_t first = inWithTile ? 1 : 0;
    for (const std::vector<double>& row : rows.Value())
    {
        BenchBox box;
        box.mTile = inWithTile ? int(row[0]) : -1;
        box.mCenter = ToVec3(row, first);
        box.mHalfExtent = ToVec3(row, first + 3);
        box.mYaw = float(row[first + 6]);
        if ((box.mHalfExtent.array() <= 0.0f).any())
            return MakeError(ErrorCode::ParseError, inPath + ": non-positive half extent");
        boxes.push_back(box);
    }
    return boxes;
}

Result<std::vector<AABB>> LoadBenchQueryBoxes(const std::string& inPath)
{
    auto rows = ReadCsv(inPath, "minx,miny,minz,maxx,maxy,maxz");
    if (!rows) return rows.GetError();
    std::vector<AABB> boxes;
    boxes.reserve(rows.Value().size());
    for (const std::vector<double>& row : rows.Value())
        boxes.emplace_back(ToVec3(row, 0), ToVec3(row, 3));
    return boxes;
}

Result<std::vector<BenchRay>> LoadBenchRays(const std::string& inPath)
{
    auto rows = ReadCsv(inPath, "ox,oy,oz,dx,dy,dz");
    if (!rows) return rows.GetError();
    std::vector<BenchRay> rays;
    rays.reserve(rows.Value().size());
    for (const std::vector<double>& row : rows.Value())
        rays.push_back({ToVec3(row, 0), ToVec3(row, 3)});
    return rays;
}

Result<std::vector<uint32_t>> LoadBenchRemovals(const std::string& inPath)
{
    auto rows = ReadCsv(inPath, "index");
    if (!rows) return rows.GetError();
    std::vector<uint32_t> indices;
    indices.reserve(rows.Value().size());
    for (const std::vector<double>& row : rows.Value())
    {
        if (row[0] < 0.0 || row[0] != std::floor(row[0]))
            return MakeError(ErrorCode::ParseError, inPath + ": not a row index");
        indices.push_back(uint32_t(row[0]));
    }
    return indices;
}

Result<SharedBenchData> LoadSharedBenchData(const std::string& inDir)
{
    SharedBenchData data;
    auto staticBoxes = LoadBenchBoxes(inDir + "/world20k_static.csv", true);
    if (!staticBoxes) return staticBoxes.GetError();
    data.mStatic = std::move(staticBoxes).Value();
    auto dynamicBoxes = LoadBenchBoxes(inDir + "/world20k_dynamic.csv", false);
    if (!dynamicBoxes) return dynamicBoxes.GetError();
    data.mDynamic = std::move(dynamicBoxes).Value();
    auto queries = LoadBenchQueryBoxes(inDir + "/queries10k_box12_8.csv");
    if (!queries) return queries.GetError();
    data.mQueryBoxes = std::move(queries).Value();
    auto rays = LoadBenchRays(inDir + "/rays10k_50m.csv");
    if (!rays) return rays.GetError();
    data.mRays = std::move(rays).Value();
    auto removals = LoadBenchRemovals(inDir + "/remove1k.csv");
    if (!removals) return removals.GetError();
    data.mRemovals = std::move(removals).Value();
    for (uint32_t index : data.mRemovals)
        if (index >= data.mStatic.size())
            return MakeError(ErrorCode::ParseError, inDir + "/remove1k.csv: index " + std::to_string(index) +
                                                        " beyond the static world");
    return data;
}

} // namespace cairn
