// atmos: output paths checked before the work (issue 18 item 6) and written
// safely (issue 38 items 1 and 5, issue 39 item 2).
//
// Commands call the checks before any precomputation or rendering, so that a
// path that cannot be written fails in one clear line at once rather than
// after minutes of work. WriteImage (atmos/image.h) then writes every format
// through a temporary file in the same directory and one rename, so a failed
// write (a full disk) never leaves a truncated file under the final name.
//
// What an output path may be:
// - a regular file or a name not there yet: written through a temporary file
//   created exclusively (O_CREAT | O_EXCL | O_NOFOLLOW, a random name, the
//   mode 0666 less the umask) in its directory, then renamed over it; a
//   symbolic link planted under any name atmos uses can no longer redirect a
//   write;
// - a symbolic link to one of these: written through to its target (the
//   target is replaced as above; the link stays a link); a dangling link is
//   refused;
// - a stream: "-", /dev/stdout (/dev/fd/1) and /dev/stderr (/dev/fd/2), a
//   FIFO, /dev/null: the bytes are written to it directly (built in an
//   unnamed temporary file first), never replaced by a file;
// - anything else (a directory, another device, a socket): refused, one
//   atmos::Error naming the path and what it is.
#pragma once

#include <functional>
#include <sstream>
#include <string>

#include "base/non_copyable.h"

namespace atmos {

// The file `path` can be created or replaced (or is a stream, above): its
// directory exists and is writable and `path` is not a directory or a device.
// Nothing is created. Throws atmos::Error naming the path and the reason.
void CheckOutputFile(const std::string& path);
// The directory `path` exists and is writable, or can be created (its nearest
// existing ancestor is a writable directory; nothing is created here).
// Throws atmos::Error naming the path and the reason.
void CheckOutputDirectory(const std::string& path);

// A checkpoint file (STEM.bin) can be written: `path` is absent or a regular
// file (a directory, FIFO or device there is refused, never replaced or
// read) and its directory exists and is writable (atmos creates none).
void CheckCheckpointFile(const std::string& path);

// True when `path` names a stream ("-", /dev/stdout, /dev/stderr, a FIFO,
// /dev/null): outputs derived from its name (a checkpoint, a stages CSV, a
// variance image) have no place beside it and are skipped or must be named.
bool IsStreamOutput(const std::string& path);

// Writes `path` through a temporary file (above): `write` writes the file it
// is given and throws on failure; a failure removes the temporary and throws
// atmos::Error naming `path`, and leaves any previous file at `path` as it
// was. Every output of the CLI goes through it (images: WriteImage; text:
// WriteFileAtomically, TextOutput).
void WriteThroughTemporary(const std::string& path,
                           const std::function<void(const std::string& temporary)>& write);
// `bytes` to `path` that way (each write and the close checked).
void WriteFileAtomically(const std::string& path, const std::string& bytes);

// A new file in `directory`, created exclusively (O_CREAT | O_EXCL |
// O_NOFOLLOW | O_CLOEXEC, mode 0666 less the umask) under the name
// ".PREFIX.tmp-RANDOM": its descriptor, and its path in *name. Throws
// atmos::Error (naming `what`) when it cannot be created.
int CreateExclusiveFile(const std::string& directory, const std::string& prefix, std::string* name,
                        const std::string& what);

// An exclusive lock on `path` + ".lock" (flock, non-blocking) held for the
// object's life, so two runs on one checkpoint fail fast: the second throws
// atmos::Error saying another run holds it. The lock file is removed on
// release. An empty path locks nothing.
class FileLock : private NonCopyable {
  public:
    explicit FileLock(const std::string& path);
    ~FileLock();

  private:
    std::string lock_path_;
    int fd_ = -1;
};

// A directory of outputs written as one transaction (issue 38 item 2): its
// new contents go to a fresh sibling, ".NAME.new-RANDOM" (created with mode
// 0777 less the umask; NAME's parent is created if missing), and Commit()
// puts it in place with one atomic exchange (renameat2 RENAME_EXCHANGE) or,
// where NAME is not there yet, one rename; the previous directory is then
// removed. A failure or an interruption before Commit() leaves NAME as it was
// (never a mix of two bakes); the destructor removes an uncommitted sibling.
class StagedDirectory : private NonCopyable {
  public:
    explicit StagedDirectory(const std::string& final_path);
    ~StagedDirectory();
    const std::string& path() const { return staging_; }
    // Runs `write` on path(); an atmos::Error it throws names the final
    // directory in place of the staging one (which is removed).
    void Write(const std::function<void(const std::string& staging)>& write) const;
    void Commit();
    // Before the work: CheckOutputDirectory, and an existing `path` holds only
    // what atmos writes (tables, JSON, shaders, viewer pages; it is replaced
    // as a whole). Throws atmos::Error naming the first other entry.
    static void Check(const std::string& path);

  private:
    std::string final_, staging_;
    bool committed_ = false;
};

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
