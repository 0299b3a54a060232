#include "cairn/navmesh/ReplaceFile.h"

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <unistd.h>

namespace cairn::navmesh
{

namespace
{
/// "<path>.tmp-<process>-<n>": two writers of one path (two processes, or two threads) never share a
/// temporary; the last rename wins and every file renamed into place is whole.
std::string TemporaryName(const std::string& inPath)
{
    static std::atomic<uint64_t> sCount{0};
    // Relaxed: only distinct numbers are needed
    const uint64_t count = sCount.fetch_add(1, std::memory_order_relaxed);
    return inPath + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(count);
}
} // namespace

PendingFile::PendingFile(std::string inPath)
    : mPath(std::move(inPath)), mTemporary(TemporaryName(mPath)),
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
