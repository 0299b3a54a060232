#include "cairn/navmesh/ReplaceFile.h"

#include <cerrno>
#include <cstring>
#include <filesystem>

namespace cairn::navmesh
{

PendingFile::PendingFile(std::string inPath)
    : mPath(std::move(inPath)), mTemporary(mPath + ".tmp"),
      mStream(mTemporary, std::ios::binary | std::ios::trunc)
{
    if (!mStream)
    {
        mOpenStatus =
            MakeError(ErrorCode::IOError, mTemporary + ": cannot be written: " + std::strerror(errno));
        mDone = true; // Nothing to remove
    }
}

PendingFile::~PendingFile()
{
    if (!mDone) Abandon();
}

void PendingFile::Abandon()
{
    mStream.close();
    std::error_code ignored;
    std::filesystem::remove(mTemporary, ignored);
    mDone = true;
}

Status PendingFile::Commit()
{
    if (!mOpenStatus) return mOpenStatus;
    if (mDone) return MakeError(ErrorCode::InvalidArgument, mPath + ": already committed");
    mStream.flush();
    const bool written = bool(mStream);
    mStream.close();
    if (!written || mStream.fail())
    {
        Abandon();
        return MakeError(ErrorCode::IOError, mTemporary + ": write failed");
    }
    std::error_code error;
    std::filesystem::rename(mTemporary, mPath, error);
    if (error)
    {
        Abandon();
        return MakeError(ErrorCode::IOError, mPath + ": cannot be replaced: " + error.message());
    }
    mDone = true;
    return Status::Ok();
}

Status ReplaceFile(const std::string& inPath, const std::function<Status(std::ostream&)>& inWrite)
{
    PendingFile file(inPath);
    if (Status opened = file.GetOpenStatus(); !opened) return opened;
    if (Status written = inWrite(file.Stream()); !written) return written; // The destructor removes it
    return file.Commit();
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
