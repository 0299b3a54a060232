#include "BakeConfig.h"

#include "common/JsonFile.h"

#include <DetourNavMesh.h>
#include <map>
#include <nlohmann/json.hpp>

namespace cairn::bake
{
using namespace cairn::physics;

Status LoadBakeConfig(const std::string& inPath, navmesh::AgentProfile& ioProfile)
{
    Result<nlohmann::json> read = tools::ReadJsonFile(inPath);
    if (!read) return read.GetError();
    const nlohmann::json& json = read.Value();
    if (!json.is_object()) return MakeError(ErrorCode::ParseError, inPath + ": not a JSON object");
    navmesh::AgentProfile& p = ioProfile;
    const std::map<std::string, float*> numbers = {
        {"agent_height", &p.mHeight},
        {"agent_radius", &p.mRadius},
        {"agent_max_climb", &p.mMaxClimb},
        {"agent_max_slope", &p.mMaxSlopeDegrees},
        {"cell_size", &p.mCellSize},
        {"cell_height", &p.mCellHeight},
        {"tile_size", &p.mTileSize},
        {"region_min_size", &p.mRegionMinSize},
        {"region_merge_size", &p.mRegionMergeSize},
        {"edge_max_length", &p.mEdgeMaxLength},
        {"edge_max_error", &p.mEdgeMaxError},
        {"detail_sample_distance", &p.mDetailSampleDistance},
        {"detail_sample_max_error", &p.mDetailSampleMaxError},
    };
    for (const auto& [key, value] : json.items())
    {
        if (auto number = numbers.find(key); number != numbers.end())
        {
            if (!value.is_number())
                return MakeError(ErrorCode::ParseError, inPath + ": '" + key + "' must be a number");
            *number->second = value.get<float>();
        }
        else if (key == "max_verts_per_poly")
        {
            int64_t number = 0;
            if (!tools::GetWholeNumber(value, 3, DT_VERTS_PER_POLYGON, number))
                return MakeError(ErrorCode::ParseError, inPath + ": '" + key +
                                                            "' must be a whole number from 3 to " +
                                                            std::to_string(DT_VERTS_PER_POLYGON));
            p.mMaxVertsPerPoly = int(number);
        }
        else if (key == "region_partition")
        {
            const std::string name = value.is_string() ? value.get<std::string>() : "";
            if (name == "watershed")
                p.mPartition = navmesh::RegionPartition::Watershed;
            else if (name == "monotone")
                p.mPartition = navmesh::RegionPartition::Monotone;
            else if (name == "layers")
                p.mPartition = navmesh::RegionPartition::Layers;
            else
                return MakeError(
                    ErrorCode::ParseError,
                    inPath + ": 'region_partition' must be \"watershed\", \"monotone\" or \"layers\"");
        }
        else
            return MakeError(ErrorCode::ParseError, inPath + ": unknown key '" + key + "'");
    }
    if (Status valid = p.Validate(); !valid)
        return MakeError(valid.GetError().mCode, inPath + ": " + valid.GetError().mMessage);
    return Status::Ok();
}

Result<navmesh::AreaMapping> LoadAreaMapping(const std::string& inPath)
{
    Result<nlohmann::json> read = tools::ReadJsonFile(inPath);
    if (!read) return read.GetError();
    const nlohmann::json& json = read.Value();
    if (!json.is_object()) return MakeError(ErrorCode::ParseError, inPath + ": not a JSON object");
    auto areaId = [&](const nlohmann::json& inValue, const std::string& inWhat) -> Result<uint8_t>
    {
        int64_t id = 0;
        if (!tools::GetWholeNumber(inValue, 0, navmesh::cMaxAreaId, id))
            return MakeError(ErrorCode::ParseError, inPath + ": " + inWhat +
                                                        " must be a whole number from 0 to " +
                                                        std::to_string(navmesh::cMaxAreaId));
        return uint8_t(id);
    };
    navmesh::AreaMapping mapping;
    for (const auto& [key, value] : json.items())
    {
        if (key == "default")
        {
            Result<uint8_t> area = areaId(value, "'default'");
            if (!area) return area.GetError();
            mapping.mDefaultArea = area.Value();
        }
        else if (key == "materials")
        {
            if (!value.is_object())
                return MakeError(ErrorCode::ParseError,
                                 inPath + ": 'materials' must map material names to area ids");
            for (const auto& [material, id] : value.items())
            {
                Result<uint8_t> area = areaId(id, "material '" + material + "'");
                if (!area) return area.GetError();
                mapping.mMaterialAreas[material] = area.Value();
            }
        }
        else
            return MakeError(ErrorCode::ParseError, inPath + ": unknown key '" + key + "'");
    }
    return mapping;
}

} // namespace cairn::bake
