// atmos: output paths checked before the work (issue 18 item 6).
//
// Commands call these before any precomputation or rendering, so that a path
// that cannot be written fails in one clear line at once rather than after
// minutes of work. WriteImage (atmos/image.h) then writes every format through
// a temporary file in the same directory and one rename, so a failed write
// (a full disk) never leaves a truncated file under the final name.
#pragma once

#include <functional>
#include <sstream>
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

// Writes `path` through a temporary file beside it (".NAME.tmp-PID.EXT") and
// one rename: `write` writes the file it is given and throws on failure; a
// failure removes the temporary and throws atmos::Error naming `path`, and
// leaves any previous file at `path` as it was. Every output of the CLI goes
// through it (images: WriteImage; text: WriteFileAtomically, TextOutput).
void WriteThroughTemporary(const std::string& path,
                           const std::function<void(const std::string& temporary)>& write);
// `bytes` to `path` that way (each write and the close checked).
void WriteFileAtomically(const std::string& path, const std::string& bytes);

// A text output (CSV, HTML, JSON) built in memory and written by Commit()
// through WriteFileAtomically: a failure never leaves a truncated file.
class TextOutput : public std::ostringstream {
  public:
    explicit TextOutput(std::string path) : path_(std::move(path)) {}
    const std::string& path() const { return path_; }
    void Commit() const { WriteFileAtomically(path_, str()); }

  private:
    std::string path_;
};

}  // namespace atmos
