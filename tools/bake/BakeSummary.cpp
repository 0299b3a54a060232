#include "BakeSummary.h"

#include "cairn/navmesh/PendingFile.h"
#include "common/JsonFile.h"
#include "common/ParseWholeNumber.h"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

namespace cairn::bake
{
using namespace cairn::physics;

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

std::string BakeSummaryToJson(const BakeSummary& inSummary)
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
    return json.dump(1) + "\n";
}

Status SaveBakeSummary(const std::string& inPath, const BakeSummary& inSummary)
{
    return navmesh::ReplaceFileWithText(inPath, BakeSummaryToJson(inSummary));
}

Result<BakeSummary> LoadBakeSummary(const std::string& inPath)
{
    Result<nlohmann::json> read = tools::ReadJsonFile(inPath);
    if (!read) return read.GetError();
    const nlohmann::json& json = read.Value();
    auto parseError = [&](const std::string& inWhat)
    { return MakeError(ErrorCode::ParseError, inPath + ": " + inWhat); };
    // Fields are looked up by type, never converted: nlohmann's value() and get() throw on a wrong type
    auto member = [&](const nlohmann::json& inObject, const char* inKey) -> const nlohmann::json*
    {
        auto it = inObject.find(inKey);
        return it != inObject.end() ? &*it : nullptr;
    };
    if (!json.is_object()) return parseError("not a cairn-bake summary of version 1");
    const nlohmann::json* format = member(json, "format");
    const nlohmann::json* version = member(json, "version");
    if (format == nullptr || !format->is_string() || *format != "cairn-bake-summary" || version == nullptr ||
        !version->is_number_integer() || *version != 1)
        return parseError("not a cairn-bake summary of version 1");
    BakeSummary summary;
    const nlohmann::json* tiles = member(json, "tiles");
    if (tiles == nullptr || !tiles->is_array()) return parseError("'tiles' is not an array");
    for (size_t i = 0; i < tiles->size(); ++i)
    {
        const nlohmann::json& tile = (*tiles)[i];
        TileRecord record;
        const std::string where = "tiles[" + std::to_string(i) + "]";
        if (!tile.is_object()) return parseError(where + ": not an object");
        const nlohmann::json* x = member(tile, "x");
        const nlohmann::json* z = member(tile, "z");
        const nlohmann::json* inputHash = member(tile, "input_hash");
        const nlohmann::json* outputHash = member(tile, "output_hash");
        int64_t tileX = 0, tileZ = 0;
        if (x == nullptr || z == nullptr || !tools::GetWholeNumber(*x, INT32_MIN, INT32_MAX, tileX) ||
            !tools::GetWholeNumber(*z, INT32_MIN, INT32_MAX, tileZ) || inputHash == nullptr ||
            !inputHash->is_string() || outputHash == nullptr || !outputHash->is_string())
            return parseError(where + ": needs integer x, z (32 bits) and hex input_hash, output_hash");
        record.mTile = {int32_t(tileX), int32_t(tileZ)};
        if (!FromHex(inputHash->get<std::string>(), record.mInputHash) ||
            !FromHex(outputHash->get<std::string>(), record.mOutputHash))
            return parseError(where + ": a hash is not 16 hex digits");
        int64_t polygons = 0, bytes = 0;
        const nlohmann::json* polygonsValue = member(tile, "polygons");
        const nlohmann::json* bytesValue = member(tile, "bytes");
        if ((polygonsValue != nullptr && !tools::GetWholeNumber(*polygonsValue, 0, INT32_MAX, polygons)) ||
            (bytesValue != nullptr && !tools::GetWholeNumber(*bytesValue, 0, UINT32_MAX, bytes)))
            return parseError(where + ": 'polygons' and 'bytes' must be whole numbers from 0");
        record.mPolygons = int(polygons);
        record.mBytes = uint32_t(bytes);
        summary.mTiles.push_back(record);
    }
    std::sort(summary.mTiles.begin(), summary.mTiles.end(),
              [](const TileRecord& inL, const TileRecord& inR) { return inL.mTile < inR.mTile; });
    for (size_t i = 1; i < summary.mTiles.size(); ++i)
        if (summary.mTiles[i - 1].mTile == summary.mTiles[i].mTile)
            return parseError("tile (" + std::to_string(summary.mTiles[i].mTile.mX) + ", " +
                              std::to_string(summary.mTiles[i].mTile.mZ) + ") is listed twice");
    int64_t tilesInWorld = 0;
    if (const nlohmann::json* value = member(json, "tiles_in_world");
        value != nullptr && !tools::GetWholeNumber(*value, 0, UINT32_MAX, tilesInWorld))
        return parseError("'tiles_in_world' must be a whole number from 0");
    summary.mTilesInWorld = uint32_t(tilesInWorld);
    if (const nlohmann::json* shard = member(json, "shard"); shard != nullptr)
        if (!shard->is_string() ||
            !ParseShard(shard->get<std::string>(), summary.mShard, summary.mShardCount))
            return parseError("'shard' must be \"K/N\" with 0 <= K < N");
    return summary;
}

bool ParseShard(const std::string& inText, uint32_t& outShard, uint32_t& outCount)
{
    // Digits only: sscanf's %u took "-1" as 4294967295
    const size_t slash = inText.find('/');
    if (slash == std::string::npos) return false;
    const std::string_view text(inText);
    uint32_t shard = 0, count = 0;
    if (!tools::ParseWholeNumber(text.substr(0, slash), shard) ||
        !tools::ParseWholeNumber(text.substr(slash + 1), count) || count == 0 || shard >= count)
        return false;
    outShard = shard;
    outCount = count;
    return true;
}

Status CheckShardsComplete(const std::vector<BakeSummary>& inSummaries,
                           const std::vector<navmesh::NavMeshFileContents>& inShards)
{
    if (inSummaries.size() != inShards.size())
        return MakeError(ErrorCode::InvalidArgument, "merge: " + std::to_string(inShards.size()) +
                                                         " shards but " + std::to_string(inSummaries.size()) +
                                                         " summaries");
    std::vector<bool> seen(inSummaries.size(), false);
    for (size_t i = 0; i < inSummaries.size(); ++i)
    {
        const BakeSummary& summary = inSummaries[i];
        const std::string which = "merge: shard " + std::to_string(i) + " (" +
                                  std::to_string(summary.mShard) + "/" + std::to_string(summary.mShardCount) +
                                  ")";
        if (summary.mShardCount != inSummaries.size())
            return MakeError(ErrorCode::InvalidArgument,
                             which + ": the bake had " + std::to_string(summary.mShardCount) + " shards, " +
                                 std::to_string(inSummaries.size()) + " are given");
        if (seen[summary.mShard])
            return MakeError(ErrorCode::InvalidArgument, which + ": that shard is given twice");
        seen[summary.mShard] = true;
        if (Status matching = CheckPreviousBake(summary, inShards[i]); !matching)
            return MakeError(ErrorCode::InvalidArgument, which + ": " + matching.GetError().mMessage);
    }
    return Status::Ok();
}

Status CheckPreviousBake(const BakeSummary& inSummary, const navmesh::NavMeshFileContents& inNavMesh)
{
    auto mismatch = [](const navmesh::TileCoord& inTile, const std::string& inWhat)
    {
        return MakeError(ErrorCode::InvalidArgument,
                         "the navmesh and the summary are from different bakes: tile (" +
                             std::to_string(inTile.mX) + ", " + std::to_string(inTile.mZ) + ") " + inWhat);
    };
    size_t withData = 0;
    for (const TileRecord& record : inSummary.mTiles)
        withData += record.mBytes > 0 ? 1 : 0;
    for (const navmesh::NavMeshFileTile& tile : inNavMesh.mTiles)
    {
        const TileRecord* record = inSummary.Find(tile.mTile);
        if (record == nullptr || record->mBytes == 0)
            return mismatch(tile.mTile, "is in the navmesh, not in the summary");
        if (record->mBytes != tile.mData.size() || record->mOutputHash != Hash64(tile.mData))
            return mismatch(tile.mTile, "differs from the output the summary hashed");
    }
    if (withData != inNavMesh.mTiles.size())
        return MakeError(ErrorCode::InvalidArgument,
                         "the navmesh and the summary are from different bakes: the "
                         "summary has " +
                             std::to_string(withData) + " tiles with polygons, the navmesh " +
                             std::to_string(inNavMesh.mTiles.size()));
    return Status::Ok();
}

} // namespace cairn::bake
