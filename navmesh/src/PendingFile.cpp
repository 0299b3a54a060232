#include "cairn/navmesh/PendingFile.h"

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <unistd.h>

namespace cairn::navmesh
{
using namespace cairn::physics;

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

/// The temporaries' names, for the signal handler. Written by the threads that create and finish
/// PendingFiles (a slot is theirs once their compare-exchange took it), read by the handler on whichever
/// thread the signal lands; lock-free atomics, as a handler may touch nothing else. A name's slot is emptied
/// before its string is freed. More PendingFiles at once than slots: the extra ones are not removed on a
/// signal (only on error or destruction).
constexpr int cSignalSlots = 256;
std::atomic<const char*> sPendingNames[cSignalSlots];
static_assert(std::atomic<const char*>::is_always_lock_free);

int RegisterPendingName(const char* inName)
{
    for (int i = 0; i < cSignalSlots; ++i)
    {
        const char* empty = nullptr;
        // Release: the handler that loads the pointer (acquire) reads the whole name
        if (sPendingNames[i].compare_exchange_strong(empty, inName, std::memory_order_release,
                                                     std::memory_order_relaxed))
            return i;
    }
    return -1;
}

void UnregisterPendingName(int inSlot)
{
    // Release: nothing of ours after this is ordered before it, but the slot's next owner pairs with it
    if (inSlot >= 0) sPendingNames[inSlot].store(nullptr, std::memory_order_release);
}

extern "C" void RemovePendingNamesAndReraise(int inSignal)
{
    for (std::atomic<const char*>& slot : sPendingNames)
        // Acquire: pairs with the registering release, so the name's bytes are complete
        if (const char* name = slot.load(std::memory_order_acquire); name != nullptr) ::unlink(name);
    // End as the signal would have (the exit status a shell or build farm sees)
    std::signal(inSignal, SIG_DFL);
    std::raise(inSignal);
}
} // namespace

std::string CheckReplaceable(const std::string& inPath)
{
    if (inPath.empty()) return "an empty path";
    std::error_code error;
    const std::filesystem::file_status status = std::filesystem::symlink_status(inPath, error);
    if (status.type() == std::filesystem::file_type::not_found) return "";
    if (error) return "cannot be examined: " + error.message();
    // rename() replaces the link itself, the device node or the empty folder: never what the user meant
    if (std::filesystem::is_symlink(status)) return "is a symbolic link: outputs replace regular files only";
    if (!std::filesystem::is_regular_file(status))
        return "is not a regular file (a folder, a device or a pipe): outputs replace regular files only";
    return "";
}

void RemovePendingFilesOnTermination()
{
    std::signal(SIGINT, &RemovePendingNamesAndReraise);
    std::signal(SIGTERM, &RemovePendingNamesAndReraise);
}

PendingFile::PendingFile(std::string inPath) : mPath(std::move(inPath)), mTemporary(TemporaryName(mPath))
{
    if (const std::string problem = CheckReplaceable(mPath); !problem.empty())
    {
        mOpenStatus = MakeError(ErrorCode::IOError, mPath + ": " + problem);
        mDone = true; // Nothing was created
        return;
    }
    mSignalSlot = RegisterPendingName(mTemporary.c_str());
    mStream.open(mTemporary, std::ios::binary | std::ios::trunc);
    if (!mStream)
    {
        mOpenStatus =
            MakeError(ErrorCode::IOError, mTemporary + ": cannot be written: " + std::strerror(errno));
        UnregisterPendingName(mSignalSlot);
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
    UnregisterPendingName(mSignalSlot);
    mDone = true;
}

Status PendingFile::Complete()
{
    if (!mOpenStatus) return mOpenStatus;
    if (mDone) return MakeError(ErrorCode::InvalidArgument, mPath + ": already committed");
    if (mCompleted) return Status::Ok();
    mStream.flush();
    const bool written = bool(mStream);
    mStream.close();
    if (!written || mStream.fail())
    {
        Abandon();
        return MakeError(ErrorCode::IOError, mTemporary + ": write failed");
    }
    mCompleted = true;
    return Status::Ok();
}

Status PendingFile::Commit()
{
    if (Status completed = Complete(); !completed) return completed;
    // Again at the last moment: the path may have become a link or a device since the file was opened
    if (const std::string problem = CheckReplaceable(mPath); !problem.empty())
    {
        Abandon();
        return MakeError(ErrorCode::IOError, mPath + ": " + problem);
    }
    std::error_code error;
    std::filesystem::rename(mTemporary, mPath, error);
    if (error)
    {
        Abandon();
        return MakeError(ErrorCode::IOError, mPath + ": cannot be replaced: " + error.message());
    }
    UnregisterPendingName(mSignalSlot);
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
