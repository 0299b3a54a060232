#pragma once

// Writing a file so that a reader (or a crash) never sees half of it: the contents go to a temporary file
// next to it, which is renamed over the target only when every byte was written. On any failure, or when the
// writer gives up, the temporary is removed and the target is left as it was. Any thread; two writers of one
// path at once are not supported.

#include "cairn/physics/math/Result.h"

#include <fstream>
#include <functional>
#include <ostream>
#include <string>

namespace cairn::navmesh
{
using namespace cairn::physics;

/// A file being written: Stream() goes to "<path>.tmp-<process>-<n>"; Commit renames it to the path.
/// Destroyed uncommitted (an error, an exception, a cancelled bake), it removes the temporary; so does
/// SIGINT or SIGTERM once RemovePendingFilesOnTermination is installed. The path must not be a symbolic
/// link or anything but a regular file (a device, a folder): a rename would replace that entry, so it is
/// refused at creation and again at Commit.
class PendingFile
{
public:
    explicit PendingFile(std::string inPath);
    ~PendingFile();
    PendingFile(const PendingFile&) = delete;
    PendingFile& operator=(const PendingFile&) = delete;

    /// Whether the temporary could be created and the path may be replaced (IOError naming it otherwise).
    Status GetOpenStatus() const { return mOpenStatus; }
    std::ostream& Stream() { return mStream; }
    /// The temporary's name, to read the contents back before Commit.
    const std::string& GetTemporaryPath() const { return mTemporary; }
    /// Flushes and closes the temporary, keeping it for Commit: outputs that go together are all completed
    /// before any is committed. Errors: IOError naming the file (then nothing is left behind).
    Status Complete();
    /// Completes (if not yet) and renames. Errors: IOError naming the file (then nothing is left behind).
    Status Commit();

private:
    void Abandon();

    std::string mPath, mTemporary;
    std::ofstream mStream;
    Status mOpenStatus;
    int mSignalSlot = -1; ///< Where RemovePendingFilesOnTermination finds the temporary's name
    bool mCompleted = false;
    bool mDone = false; ///< Committed or abandoned
};

/// Empty when inPath may be replaced by an output: it does not exist, or is a regular file and not a
/// symbolic link; else why not.
std::string CheckReplaceable(const std::string& inPath);

/// Installs SIGINT and SIGTERM handlers that remove every PendingFile's temporary and then end the process
/// as the signal would have. For programs (the baker): a library does not take its host's signals.
void RemovePendingFilesOnTermination();

/// inWrite streams the contents (binary); an error it returns abandons the file and is returned. Errors:
/// IOError naming the file, or inWrite's.
Status ReplaceFile(const std::string& inPath, const std::function<Status(std::ostream&)>& inWrite);

/// ReplaceFile with a ready string.
Status ReplaceFileWithText(const std::string& inPath, const std::string& inContents);

} // namespace cairn::navmesh
