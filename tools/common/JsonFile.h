#pragma once

// The tools' JSON files (the baker's config, areas and summaries; the demo's world) read with nlohmann-json,
// whose exceptions end at this boundary: a file is a Status error naming it and the parser's place, never an
// abort. Any thread.

#include "cairn/physics/math/Result.h"

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

namespace cairn::tools
{
using namespace cairn::physics;

/// The JSON value of the regular file inPath. Errors: IOError when it is not a readable regular file (a
/// folder, a device), ParseError with the parser's message (line, column, what) otherwise.
Result<nlohmann::json> ReadJsonFile(const std::string& inPath);

/// inValue as a whole number from inMin to inMax, or false: JSON's integers reach 2^64, and a plain get<int>
/// wraps 4294967299 to 3.
bool GetWholeNumber(const nlohmann::json& inValue, int64_t inMin, int64_t inMax, int64_t& outNumber);

} // namespace cairn::tools
