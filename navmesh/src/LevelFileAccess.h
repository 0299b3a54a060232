#pragma once

// Reading a level's files within LevelLoadLimits: whole files up to the byte limit, the folders they may come
// from, and the JSON nesting a recursive parser can take. Plain functions, any thread.

#include "cairn/navmesh/LevelMesh.h"

#include <filesystem>
#include <string_view>
#include <vector>

namespace cairn::navmesh
{
using namespace cairn::physics;

/// The bytes of the regular file inPath. Errors: IOError when it is not a readable regular file, ParseError
/// when it is over inMaxBytes (named with the limit).
Result<std::vector<unsigned char>> ReadLevelFile(const std::string& inPath, uint64_t inMaxBytes);

/// True when inFile, with symbolic links and `..` resolved, lies in inFolder or below it.
bool IsInsideFolder(const std::filesystem::path& inFile, const std::filesystem::path& inFolder);

/// How deep arrays and objects nest in the JSON text inText (strings and their escapes skipped); stops
/// counting, and returns, once past inStopAt. Malformed text gives some depth: the parser reports it.
uint32_t JsonNestingDepth(std::string_view inText, uint32_t inStopAt);

/// The extension of inPath in lower case (".OBJ" and ".Obj" are ".obj").
std::string LowerCaseExtension(const std::string& inPath);

} // namespace cairn::navmesh
