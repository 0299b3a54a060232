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

/// A file being written: Stream() goes to "<path>.tmp-<process>-<n>"; Commit renames it to the path.
/// Destroyed uncommitted (an error, an exception, a cancelled bake), it removes the temporary.
class PendingFile
{
public:
    explicit PendingFile(std::string inPath);
    ~PendingFile();
    PendingFile(const PendingFile&) = delete;
    PendingFile& operator=(const PendingFile&) = delete;

    /// Whether the temporary could be created (IOError naming it otherwise).
    Status GetOpenStatus() const { return mOpenStatus; }
    std::ostream& Stream() { return mStream; }
    /// Flushes, closes and renames. Errors: IOError naming the file (then nothing is left behind).
    Status Commit();

private:
    void Abandon();

    std::string mPath, mTemporary;
    std::ofstream mStream;
    Status mOpenStatus;
    bool mDone = false; ///< Committed or abandoned
};

/// inWrite streams the contents (binary); an error it returns abandons the file and is returned. Errors:
/// IOError naming the file, or inWrite's.
Status ReplaceFile(const std::string& inPath, const std::function<Status(std::ostream&)>& inWrite);

/// ReplaceFile with a ready string.
Status ReplaceFileWithText(const std::string& inPath, const std::string& inContents);

} // namespace cairn::navmesh
