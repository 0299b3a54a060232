#include "OffMeshLinksFile.h"

#include "common/JsonFile.h"

#include <cmath>
#include <nlohmann/json.hpp>

namespace cairn::bake
{
using namespace cairn::physics;

namespace
{

/// inValue as a position: three numbers, finite as floats (1e39 is a JSON number but no float).
bool GetPosition(const nlohmann::json& inValue, Vec3& outPosition)
{
    if (!inValue.is_array() || inValue.size() != 3) return false;
    for (int axis = 0; axis < 3; ++axis)
    {
        if (!inValue[size_t(axis)].is_number()) return false;
        outPosition[axis] = inValue[size_t(axis)].get<float>();
        if (!std::isfinite(outPosition[axis])) return false;
    }
    return IsValidWorldPosition(outPosition);
}

/// One link of the file; inWhere names it in errors.
Result<navmesh::OffMeshLink> ReadLink(const nlohmann::json& inJson, const std::string& inWhere)
{
    if (!inJson.is_object()) return MakeError(ErrorCode::ParseError, inWhere + ": not a JSON object");
    navmesh::OffMeshLink link;
    bool hasStart = false, hasEnd = false;
    for (const auto& [key, value] : inJson.items())
    {
        const std::string where = inWhere + ": '" + key + "'";
        if (key == "start" || key == "end")
        {
            if (!GetPosition(value, key == "start" ? link.mStart : link.mEnd))
                return MakeError(ErrorCode::ParseError,
                                 where + " must be three numbers [x, y, z] within the world's range");
            (key == "start" ? hasStart : hasEnd) = true;
        }
        else if (key == "radius")
        {
            link.mRadius = value.is_number() ? value.get<float>() : 0.0f;
            if (!(link.mRadius > 0.0f && link.mRadius <= 1000.0f))
                return MakeError(ErrorCode::ParseError, where + " must be a number in (0, 1000] m");
        }
        else if (key == "bidirectional")
        {
            if (!value.is_boolean())
                return MakeError(ErrorCode::ParseError, where + " must be true or false");
            link.mBidirectional = value.get<bool>();
        }
        else if (key == "area")
        {
            int64_t area = 0;
            if (!tools::GetWholeNumber(value, 0, navmesh::cMaxAreaId, area))
                return MakeError(ErrorCode::ParseError, where + " must be a whole number from 0 to " +
                                                            std::to_string(navmesh::cMaxAreaId));
            link.mArea = uint8_t(area);
        }
        else if (key == "user_id")
        {
            int64_t id = 0;
            if (!tools::GetWholeNumber(value, 0, int64_t(UINT32_MAX), id))
                return MakeError(ErrorCode::ParseError,
                                 where + " must be a whole number from 0 to 4294967295");
            link.mUserID = uint32_t(id);
        }
        else
            return MakeError(ErrorCode::ParseError, inWhere + ": unknown key '" + key + "'");
    }
    if (!hasStart || !hasEnd) return MakeError(ErrorCode::ParseError, inWhere + ": needs 'start' and 'end'");
    return link;
}

} // namespace

Result<std::vector<navmesh::OffMeshLink>> LoadOffMeshLinks(const std::string& inPath)
{
    Result<nlohmann::json> read = tools::ReadJsonFile(inPath);
    if (!read) return read.GetError();
    const nlohmann::json& json = read.Value();
    if (!json.is_object()) return MakeError(ErrorCode::ParseError, inPath + ": not a JSON object");
    std::vector<navmesh::OffMeshLink> links;
    for (const auto& [key, value] : json.items())
    {
        if (key != "links") return MakeError(ErrorCode::ParseError, inPath + ": unknown key '" + key + "'");
        if (!value.is_array())
            return MakeError(ErrorCode::ParseError, inPath + ": 'links' must be an array of links");
        if (value.size() > cMaxOffMeshLinks)
            return MakeError(ErrorCode::OutOfCapacity, inPath + ": " + std::to_string(value.size()) +
                                                           " links, more than " +
                                                           std::to_string(cMaxOffMeshLinks));
        links.reserve(value.size());
        for (size_t i = 0; i < value.size(); ++i)
        {
            Result<navmesh::OffMeshLink> link = ReadLink(value[i], inPath + ": link " + std::to_string(i));
            if (!link) return link.GetError();
            links.push_back(link.Value());
        }
    }
    return links;
}

} // namespace cairn::bake
