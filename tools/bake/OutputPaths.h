#pragma once

// The baker's outputs checked before any work: a bake that would overwrite its own level, write two outputs
// to one file, replace a symbolic link's target or a device, or write into a folder that does not exist is
// refused at once, not after an hour of baking. Plain function, any thread.

#include "cairn/physics/math/Result.h"

#include <string>
#include <vector>

namespace cairn::bake
{
using namespace cairn::physics;

struct NamedPath
{
    std::string mFlag; ///< How the user gave it ("-o", "--summary"), for the message
    std::string mPath;
};

/// Ok when every output is a non-empty path that ReplaceFile may replace (CheckReplaceable), in a folder
/// that exists and can be written, no two outputs are the same file, and no output is one of inInputs
/// (the level files, config, previous bake: links and `..` resolved, hard links compared as files).
/// Errors: InvalidArgument naming the flag and the path.
Status CheckOutputPaths(const std::vector<NamedPath>& inOutputs, const std::vector<NamedPath>& inInputs);

} // namespace cairn::bake
