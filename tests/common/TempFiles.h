#pragma once

// TempFiles: files a test writes (level meshes, JSON, navmesh files) in a folder of its own under the
// system's temporary directory, named by process and instance, so that test processes run in parallel by
// ctest (and the Release and ThreadSanitizer builds' tests) never share a file; the folder goes with the
// object.

#include <atomic>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <unistd.h>
#include <vector>

namespace cairn::test
{
using namespace cairn::physics;

class TempFiles
{
public:
    TempFiles()
    {
        static std::atomic<int> sInstances{0};
        // Relaxed: only distinct numbers are needed
        const int instance = sInstances.fetch_add(1, std::memory_order_relaxed);
        mFolder = std::filesystem::temp_directory_path() /
                  ("cairn-test-" + std::to_string(::getpid()) + "-" + std::to_string(instance));
        std::filesystem::create_directories(mFolder);
    }
    ~TempFiles()
    {
        std::error_code ignored;
        std::filesystem::remove_all(mFolder, ignored);
    }
    TempFiles(const TempFiles&) = delete;
    TempFiles& operator=(const TempFiles&) = delete;

    /// Where a file of this name goes (not created).
    std::string Path(const std::string& inName) const { return (mFolder / inName).string(); }

    /// Writes inText (bytes as given) to a file of this name, replacing one written before; returns its path.
    std::string Write(const std::string& inName, const std::string& inText) const
    {
        const std::string path = Path(inName);
        std::ofstream(path, std::ios::binary | std::ios::trunc) << inText;
        return path;
    }

private:
    std::filesystem::path mFolder;
};

/// A whole file's bytes (empty when it cannot be read): to compare outputs byte for byte.
inline std::vector<unsigned char> ReadBytes(const std::string& inPath)
{
    std::ifstream in(inPath, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

} // namespace cairn::test
