#pragma once

// ReplaceFile: writes a file so that a reader (or a crash) never sees half of it: the contents go to a
// temporary file next to it, which is renamed over the target only when every byte was written. On any
// failure the temporary is removed and the target is left as it was. Any thread; two writers of one path at
// once are not supported.

#include "cairn/physics/math/Result.h"

#include <functional>
#include <ostream>
#include <string>

namespace cairn::navmesh
{

/// inWrite streams the contents (binary); an error it returns abandons the file and is returned. Errors:
/// IOError naming the file, or inWrite's.
Status ReplaceFile(const std::string& inPath, const std::function<Status(std::ostream&)>& inWrite);

/// ReplaceFile with a ready string.
Status ReplaceFileWithText(const std::string& inPath, const std::string& inContents);

} // namespace cairn::navmesh
