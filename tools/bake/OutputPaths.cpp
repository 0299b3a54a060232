#include "OutputPaths.h"

#include "cairn/navmesh/PendingFile.h"

#include <filesystem>
#include <unistd.h>

namespace cairn::bake
{
using namespace cairn::physics;

namespace
{
/// Whether two paths name one file: the same path once links and `..` are resolved, or (both existing) one
/// file under two names.
bool SameFile(const std::string& inA, const std::string& inB)
{
    std::error_code error;
    const std::filesystem::path a = std::filesystem::weakly_canonical(inA, error);
    if (error) return false;
    const std::filesystem::path b = std::filesystem::weakly_canonical(inB, error);
    if (error) return false;
    if (a == b) return true;
    const bool equivalent = std::filesystem::equivalent(inA, inB, error);
    return !error && equivalent;
}

Error InvalidArgumentError(const NamedPath& inPath, const std::string& inWhat)
{
    return MakeError(ErrorCode::InvalidArgument, inPath.mFlag + " " + inPath.mPath + ": " + inWhat);
}
} // namespace

Status CheckOutputPaths(const std::vector<NamedPath>& inOutputs, const std::vector<NamedPath>& inInputs)
{
    for (size_t i = 0; i < inOutputs.size(); ++i)
    {
        const NamedPath& output = inOutputs[i];
        if (output.mPath.empty())
            return MakeError(ErrorCode::InvalidArgument, output.mFlag + ": an empty path names no file");
        if (const std::string problem = navmesh::CheckReplaceable(output.mPath); !problem.empty())
            return InvalidArgumentError(output, problem);
        std::filesystem::path folder = std::filesystem::path(output.mPath).parent_path();
        if (folder.empty()) folder = ".";
        std::error_code error;
        if (!std::filesystem::is_directory(folder, error))
            return InvalidArgumentError(output, "its folder " + folder.string() + " does not exist");
        if (::access(folder.c_str(), W_OK) != 0)
            return InvalidArgumentError(output, "its folder " + folder.string() + " cannot be written");
        for (const NamedPath& input : inInputs)
            if (!input.mPath.empty() && SameFile(output.mPath, input.mPath))
                return InvalidArgumentError(output, "is the input " + input.mFlag + " " + input.mPath +
                                                        ": an output never replaces an input");
        for (size_t j = 0; j < i; ++j)
            if (SameFile(output.mPath, inOutputs[j].mPath))
                return InvalidArgumentError(output, "is also " + inOutputs[j].mFlag +
                                                        ": each output needs a file of its own");
    }
    return Status::Ok();
}

} // namespace cairn::bake
