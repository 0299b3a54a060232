#include "cairn/navmesh/ReplaceFile.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace cairn::navmesh
{

Status ReplaceFile(const std::string& inPath, const std::function<Status(std::ostream&)>& inWrite)
{
    const std::string temporary = inPath + ".tmp";
    auto removeTemporary = [&]
    {
        std::error_code ignored;
        std::filesystem::remove(temporary, ignored);
    };
    {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        if (!out)
            return MakeError(ErrorCode::IOError, temporary + ": cannot be written: " + std::strerror(errno));
        if (Status written = inWrite(out); !written)
        {
            out.close();
            removeTemporary();
            return written;
        }
        out.flush();
        if (!out)
        {
            out.close();
            removeTemporary();
            return MakeError(ErrorCode::IOError, temporary + ": write failed");
        }
    }
    std::error_code error;
    std::filesystem::rename(temporary, inPath, error);
    if (error)
    {
        removeTemporary();
        return MakeError(ErrorCode::IOError, inPath + ": cannot be replaced: " + error.message());
    }
    return Status::Ok();
}

Status ReplaceFileWithText(const std::string& inPath, const std::string& inContents)
{
    return ReplaceFile(inPath,
                       [&](std::ostream& ioOut)
                       {
                           ioOut.write(inContents.data(), std::streamsize(inContents.size()));
                           return Status::Ok();
                       });
}

} // namespace cairn::navmesh
