#pragma once

// The loaders under fuzz take a path (they are the baker's and the runtime's entry points, file checks and
// all): each input is written to a file of this process, named with the extension the loader dispatches on.

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <unistd.h>

namespace cairn::fuzz
{

/// Writes inData to <tmp>/cairn-fuzz-<pid>/input<inExtension> and returns that path (the folder is the
/// level's folder for loaders that read files beside it; it holds nothing else).
inline std::string WriteInputFile(const uint8_t* inData, size_t inSize, const std::string& inExtension)
{
    static const std::filesystem::path folder = []
    {
        std::filesystem::path path =
            std::filesystem::temp_directory_path() / ("cairn-fuzz-" + std::to_string(getpid()));
        std::filesystem::create_directories(path);
        return path;
    }();
    const std::string path = (folder / ("input" + inExtension)).string();
    std::FILE* file = std::fopen(path.c_str(), "wb");
    if (file == nullptr) __builtin_trap(); // The harness's own failure, not the loader's
    if (inSize > 0 && std::fwrite(inData, 1, inSize, file) != inSize) __builtin_trap();
    std::fclose(file);
    return path;
}

} // namespace cairn::fuzz
