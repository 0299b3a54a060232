#include "JsonFile.h"

#include <filesystem>
#include <fstream>

namespace cairn::tools
{
using namespace cairn::physics;

Result<nlohmann::json> ReadJsonFile(const std::string& inPath)
{
    std::error_code error;
    if (!std::filesystem::is_regular_file(inPath, error))
        return MakeError(ErrorCode::IOError, inPath + ": not a readable file");
    std::ifstream in(inPath, std::ios::binary);
    if (!in) return MakeError(ErrorCode::IOError, inPath + ": cannot be read");
    try
    {
        return nlohmann::json::parse(in);
    }
    catch (const nlohmann::json::exception& exception)
    {
        // "parse error at line 1, column 6: ... number overflow parsing '1e400'"
        return MakeError(ErrorCode::ParseError, inPath + ": " + exception.what());
    }
    catch (const std::exception& exception)
    {
        return MakeError(ErrorCode::IOError, inPath + ": " + exception.what());
    }
}

bool GetWholeNumber(const nlohmann::json& inValue, int64_t inMin, int64_t inMax, int64_t& outNumber)
{
    if (inValue.is_number_unsigned())
    {
        const uint64_t value = inValue.get<uint64_t>();
        if (inMax < 0 || value > uint64_t(inMax) || (inMin > 0 && value < uint64_t(inMin))) return false;
        outNumber = int64_t(value);
        return true;
    }
    if (!inValue.is_number_integer()) return false;
    const int64_t value = inValue.get<int64_t>();
    if (value < inMin || value > inMax) return false;
    outNumber = value;
    return true;
}

} // namespace cairn::tools
