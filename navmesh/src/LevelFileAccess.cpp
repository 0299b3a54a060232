#include "LevelFileAccess.h"

#include <algorithm>
#include <cctype>
#include <fstream>

namespace cairn::navmesh
{
using namespace cairn::physics;

Result<std::vector<unsigned char>> ReadLevelFile(const std::string& inPath, uint64_t inMaxBytes)
{
    std::error_code error;
    // Not a directory, device or FIFO: reading those hangs, or gives a size that is not the bytes'
    if (!std::filesystem::is_regular_file(inPath, error))
        return MakeError(ErrorCode::IOError, inPath + ": not a readable file");
    const uintmax_t size = std::filesystem::file_size(inPath, error);
    if (error) return MakeError(ErrorCode::IOError, inPath + ": not a readable file");
    if (size > inMaxBytes)
        return MakeError(ErrorCode::ParseError,
                         inPath + ": " + std::to_string(size) + " bytes, over the limit of " +
                             std::to_string(inMaxBytes) + " (LevelLoadLimits::mMaxFileBytes)");
    std::ifstream file(inPath, std::ios::binary);
    std::vector<unsigned char> bytes(static_cast<size_t>(size));
    if (!file || !file.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(size)))
        return MakeError(ErrorCode::IOError, inPath + ": cannot be read");
    return bytes;
}

bool IsInsideFolder(const std::filesystem::path& inFile, const std::filesystem::path& inFolder)
{
    std::error_code error;
    const std::filesystem::path file = std::filesystem::weakly_canonical(inFile, error);
    if (error) return false;
    const std::filesystem::path folder = std::filesystem::weakly_canonical(inFolder, error);
    if (error) return false;
    // Component by component: /level2 is not inside /level
    auto [folderEnd, fileAt] = std::mismatch(folder.begin(), folder.end(), file.begin(), file.end());
    (void)fileAt;
    return folderEnd == folder.end() || (std::next(folderEnd) == folder.end() && folderEnd->empty());
}

uint32_t JsonNestingDepth(std::string_view inText, uint32_t inStopAt)
{
    uint32_t depth = 0, deepest = 0;
    bool inString = false;
    for (size_t i = 0; i < inText.size() && deepest <= inStopAt; ++i)
    {
        const char c = inText[i];
        if (inString)
        {
            if (c == '\\')
                ++i; // The escaped character, a quote included, does not end the string
            else if (c == '"')
                inString = false;
            continue;
        }
        if (c == '"')
            inString = true;
        else if (c == '[' || c == '{')
            deepest = std::max(deepest, ++depth);
        else if ((c == ']' || c == '}') && depth > 0)
            --depth;
    }
    return deepest;
}

std::string LowerCaseExtension(const std::string& inPath)
{
    std::string extension = std::filesystem::path(inPath).extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char inC) { return char(std::tolower(inC)); });
    return extension;
}

} // namespace cairn::navmesh
