#include "BakeSummary.h"

#include "cairn/navmesh/ReplaceFile.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

namespace cairn::bake
{

uint64_t Hash64(std::span<const unsigned char> inBytes, uint64_t inHash)
{
    for (unsigned char byte : inBytes)
    {
        inHash ^= byte;
        inHash *= 1099511628211ull;
    }
    return inHash;
}

const TileRecord* BakeSummary::Find(const navmesh::TileCoord& inTile) const
{
    auto it = std::lower_bound(mTiles.begin(), mTiles.end(), inTile,
                               [](const TileRecord& inR, const navmesh::TileCoord& inT)
                               { return inR.mTile < inT; });
    return it != mTiles.end() && it->mTile == inTile ? &*it : nullptr;
}

namespace
{
std::string Hex(uint64_t inValue)
{
    char text[17];
    std::snprintf(text, sizeof(text), "%016llx", (unsigned long long)inValue);
    return text;
}

/// Hex text back to a value; false if it is not 16 hex digits.
bool FromHex(const std::string& inText, uint64_t& outValue)
{
    if (inText.size() != 16) return false;
    outValue = 0;
    for (char c : inText)
    {
        const int digit = c >= '0' && c <= '9' ? c - '0' : (c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1);
        if (digit < 0) return false;
        outValue = outValue << 4 | uint64_t(digit);
    }
    return true;
}
} // namespace

Status SaveBakeSummary(const std::string& inPath, const BakeSummary& inSummary)
{
    nlohmann::json json;
    json["format"] = "cairn-bake-summary";
    json["version"] = 1;
    json["inputs"] = inSummary.mInputs;
    json["shard"] = std::to_string(inSummary.mShard) + "/" + std::to_string(inSummary.mShardCount);
    json["tiles_in_world"] = inSummary.mTilesInWorld;
    json["tiles_rebuilt"] = inSummary.mTilesRebuilt;
    json["polygons"] = inSummary.mPolygons;
    json["bake_ms"] = inSummary.mBakeMs;
    nlohmann::json tiles = nlohmann::json::array();
    for (const TileRecord& tile : inSummary.mTiles)
        tiles.push_back({{"x", tile.mTile.mX},
                         {"z", tile.mTile.mZ},
                         {"input_hash", Hex(tile.mInputHash)},
                         {"output_hash", Hex(tile.mOutputHash)},
                         {"polygons", tile.mPolygons},
                         {"bytes", tile.mBytes}});
    json["tiles"] = tiles;
    return navmesh::ReplaceFileWithText(inPath, json.dump(1) + "\n");
}

Result<BakeSummary> LoadBakeSummary(const std::string& inPath)
{
    std::ifstream in(inPath);
    if (!in) return MakeError(ErrorCode::IOError, inPath + ": cannot be read");
    nlohmann::json json = nlohmann::json::parse(in, nullptr, false);
    if (json.is_discarded()) return MakeError(ErrorCode::ParseError, inPath + ": not valid JSON");
    if (!json.is_object() || json.value("format", "") != "cairn-bake-summary" ||
        json.value("version", 0) != 1)
        return MakeError(ErrorCode::ParseError, inPath + ": not a cairn-bake summary of version 1");
    BakeSummary summary;
    const nlohmann::json& tiles = json["tiles"];
    if (!tiles.is_array()) return MakeError(ErrorCode::ParseError, inPath + ": 'tiles' is not an array");
    for (size_t i = 0; i < tiles.size(); ++i)
    {
        const nlohmann::json& tile = tiles[i];
        TileRecord record;
        const std::string where = inPath + ": tiles[" + std::to_string(i) + "]";
        if (!tile.is_object() || !tile.contains("x") || !tile["x"].is_number_integer() ||
            !tile.contains("z") || !tile["z"].is_number_integer() || !tile.contains("input_hash") ||
            !tile["input_hash"].is_string() || !tile.contains("output_hash") ||
            !tile["output_hash"].is_string())
            return MakeError(ErrorCode::ParseError,
                             where + ": needs integer x, z and hex input_hash, output_hash");
        record.mTile = {tile["x"].get<int32_t>(), tile["z"].get<int32_t>()};
        if (!FromHex(tile["input_hash"].get<std::string>(), record.mInputHash) ||
            !FromHex(tile["output_hash"].get<std::string>(), record.mOutputHash))
            return MakeError(ErrorCode::ParseError, where + ": a hash is not 16 hex digits");
        record.mPolygons = tile.value("polygons", 0);
        record.mBytes = tile.value("bytes", 0u);
        summary.mTiles.push_back(record);
    }
    std::sort(summary.mTiles.begin(), summary.mTiles.end(),
              [](const TileRecord& inL, const TileRecord& inR) { return inL.mTile < inR.mTile; });
    summary.mTilesInWorld = json.value("tiles_in_world", 0u);
    return summary;
}

} // namespace cairn::bake
