// atmos: output paths checked before the work (issue 18 item 6).
//
// Commands call these before any precomputation or rendering, so that a path
// that cannot be written fails in one clear line at once rather than after
// minutes of work. WriteImage (atmos/image.h) then writes every format through
// a temporary file in the same directory and one rename, so a failed write
// (a full disk) never leaves a truncated file under the final name.
#pragma once

#include <string>

namespace atmos {

// The file `path` can be created or replaced: its directory exists and is
// writable (a probe file is created and removed) and `path` is not a
// directory. Throws atmos::Error naming the path and the reason.
void CheckOutputFile(const std::string& path);
// The directory `path` exists and is writable, or can be created (its nearest
// existing ancestor is a writable directory; nothing is created here).
// Throws atmos::Error naming the path and the reason.
void CheckOutputDirectory(const std::string& path);

}  // namespace atmos
