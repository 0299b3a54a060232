#include "WorldFile.h"

#include "common/JsonFile.h"

#include <cmath>
#include <functional>
#include <map>

namespace cairn::demo
{
using namespace cairn::physics;

uint64_t EstimateMaxBodies(const DemoSettings& inSettings)
{
    // The tiles TileStreamer wants around one point, twice (the player and the point ahead may not overlap)
    const int reach = int(std::ceil(inSettings.mCollisionRadius));
    uint64_t tiles = 0;
    for (int dz = -reach; dz <= reach; ++dz)
        for (int dx = -reach; dx <= reach; ++dx)
            if (float(dx * dx + dz * dz) <= inSettings.mCollisionRadius * inSettings.mCollisionRadius)
                ++tiles;
    // A hut is five walls and a door
    const uint64_t perTile = 1 + uint64_t(inSettings.mPropsPerTile) + uint64_t(inSettings.mDynamicPerTile) +
                             6 * uint64_t(inSettings.mBuildingsPerTile);
    return 2 * tiles * perTile + inSettings.mGameObjects;
}

Status LoadDemoWorld(const std::string& inPath, DemoSettings& ioSettings)
{
    Result<nlohmann::json> read = tools::ReadJsonFile(inPath);
    if (!read) return read.GetError();
    const nlohmann::json& json = read.Value();
    if (!json.is_object()) return MakeError(ErrorCode::ParseError, inPath + ": expected a JSON object");
    DemoSettings settings = ioSettings;
    std::string error;
    auto whole = [&](int64_t inMin, int64_t inMax, auto& outField)
    {
        return [&outField, inMin, inMax](const nlohmann::json& inValue, std::string& outExpected)
        {
            int64_t number = 0;
            if (!tools::GetWholeNumber(inValue, inMin, inMax, number))
            {
                outExpected = "a whole number from " + std::to_string(inMin) + " to " + std::to_string(inMax);
                return false;
            }
            outField = static_cast<std::remove_reference_t<decltype(outField)>>(number);
            return true;
        };
    };
    auto real = [&](float inMin, float inMax, float& outField)
    {
        return [&outField, inMin, inMax](const nlohmann::json& inValue, std::string& outExpected)
        {
            const double value = inValue.is_number() ? inValue.get<double>() : NAN;
            if (!(value >= inMin && value <= inMax))
            {
                outExpected = "a number from " + std::to_string(inMin) + " to " + std::to_string(inMax);
                return false;
            }
            outField = float(value);
            return true;
        };
    };
    using Reader = std::function<bool(const nlohmann::json&, std::string&)>;
    const std::map<std::string, Reader> readers = {
        {"seed",
         [&](const nlohmann::json& inValue, std::string& outExpected)
         {
             // The seed's whole range: JSON's unsigned integers reach 2^64 - 1
             if (!inValue.is_number_unsigned())
             {
                 outExpected = "a whole number from 0 to 2^64 - 1";
                 return false;
             }
             settings.mSeed = inValue.get<uint64_t>();
             return true;
         }},
        {"props_per_tile", whole(0, 5000, settings.mPropsPerTile)},
        {"dynamic_per_tile", whole(0, 1000, settings.mDynamicPerTile)},
        {"buildings_per_tile", whole(0, 16, settings.mBuildingsPerTile)},
        {"collision_radius", real(1.0f, 6.0f, settings.mCollisionRadius)},
        {"player_speed", real(0.0f, 100.0f, settings.mPlayerSpeed)},
        {"throw_balls",
         [&](const nlohmann::json& inValue, std::string& outExpected)
         {
             if (!inValue.is_boolean())
             {
                 outExpected = "true or false";
                 return false;
             }
             settings.mThrowBalls = inValue.get<bool>();
             return true;
         }},
        {"agents", whole(0, cDemoMaxAgents, settings.mAgents)},
        {"game_objects", whole(0, cDemoMaxGameObjects, settings.mGameObjects)},
        {"game_object_jobs", whole(1, 64, settings.mGameObjectJobs)},
        {"collision_steps", whole(1, cDemoMaxCollisionSteps, settings.mCollisionSteps)},
        {"candidate_margin", real(0.0f, cDemoMaxCandidateMargin, settings.mCandidateMargin)},
    };
    for (const auto& [key, value] : json.items())
    {
        const auto reader = readers.find(key);
        if (reader == readers.end())
            return MakeError(ErrorCode::ParseError, inPath + ": unknown key \"" + key + "\"");
        std::string expected;
        if (!reader->second(value, expected))
            return MakeError(ErrorCode::ParseError, inPath + ": \"" + key + "\": expected " + expected);
    }
    if (const uint64_t bodies = EstimateMaxBodies(settings); bodies > cDemoMaxBodies - cDemoSpareBodies)
        return MakeError(ErrorCode::InvalidArgument,
                         inPath + ": the world would hold up to " + std::to_string(bodies) +
                             " bodies at once (tiles within collision_radius of the player and of the point "
                             "ahead, each with its terrain, props_per_tile, dynamic_per_tile and "
                             "buildings_per_tile huts; and the "
                             "game_objects), over the demo's " +
                             std::to_string(cDemoMaxBodies - cDemoSpareBodies));
    ioSettings = settings;
    return Status::Ok();
}

} // namespace cairn::demo
