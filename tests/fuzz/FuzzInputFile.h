#pragma once

// The loaders under fuzz take a path (they are the baker's and the runtime's entry points, file checks and
// all): each input is written to a file of this process, named with the extension the loader dispatches on.

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>
#include <unistd.h>

namespace cairn::fuzz
{

/// <tmp>/cairn-fuzz-<pid>, made on first use and removed when the process exits normally: every harness
/// run (the corpus replays of the test suites, each fuzzing session) would otherwise leave one behind in
/// /tmp. A crash leaves it, and libFuzzer saves the crashing input apart.
class FuzzInputFolder
{
public:
    FuzzInputFolder()
        : mPath(std::filesystem::temp_directory_path() / ("cairn-fuzz-" + std::to_string(getpid())))
    {
        std::filesystem::create_directories(mPath);
    }
    ~FuzzInputFolder()
    {
        std::error_code ignored; // Cleaning up: a folder that cannot be removed is left, not a failure
        std::filesystem::remove_all(mPath, ignored);
    }
    FuzzInputFolder(const FuzzInputFolder&) = delete;
    FuzzInputFolder& operator=(const FuzzInputFolder&) = delete;
    const std::filesystem::path& GetPath() const { return mPath; }

private:
    std::filesystem::path mPath;
};

/// Writes inData to <tmp>/cairn-fuzz-<pid>/input<inExtension> and returns that path (the folder is the
/// level's folder for loaders that read files beside it; it holds nothing else).
inline std::string WriteInputFile(const uint8_t* inData, size_t inSize, const std::string& inExtension)
{
    static const FuzzInputFolder folder;
    const std::string path = (folder.GetPath() / ("input" + inExtension)).string();
    std::FILE* file = std::fopen(path.c_str(), "wb");
    if (file == nullptr) __builtin_trap(); // The harness's own failure, not the loader's
    if (inSize > 0 && std::fwrite(inData, 1, inSize, file) != inSize) __builtin_trap();
    std::fclose(file);
    return path;
}

} // namespace cairn::fuzz
