// atmos: output paths checked before the work and written safely (see output_path.h).
#include "io/output_path.h"

#include <fcntl.h>
#include <stdio.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <mutex>
#include <random>

#include "atmos/error.h"

namespace atmos {

namespace {

enum class TargetKind { kFile, kStdout, kStderr, kStream };

// What an output path is (output_path.h): `path` is the file written for
// kFile (a symbolic link's target) and the stream opened for kStream.
struct Target {
    TargetKind kind = TargetKind::kFile;
    std::string path;
};

bool SameCharDevice(const struct stat& st, const struct stat& other) {
    return S_ISCHR(other.st_mode) && other.st_rdev == st.st_rdev;
}

Target ResolveOutput(const std::string& path) {
    if (path.empty()) Fail("the output path is empty");
    if (path == "-" || path == "/dev/stdout" || path == "/dev/fd/1" || path == "/proc/self/fd/1") {
        return {TargetKind::kStdout, path};
    }
    if (path == "/dev/stderr" || path == "/dev/fd/2" || path == "/proc/self/fd/2") {
        return {TargetKind::kStderr, path};
    }
    struct stat st {};
    if (::lstat(path.c_str(), &st) != 0) return {TargetKind::kFile, path};  // not there yet
    std::string resolved = path;
    if (S_ISLNK(st.st_mode)) {
        // Written through to its target, which must exist.
        errno = 0;
        std::unique_ptr<char, decltype(&std::free)> real(::realpath(path.c_str(), nullptr),
                                                         &std::free);
        if (!real || ::stat(real.get(), &st) != 0) {
            Fail("cannot write '", path, "': it is a symbolic link to a missing file (",
                 std::strerror(errno != 0 ? errno : ENOENT),
                 "); atmos writes through a link to its target, which must exist");
        }
        resolved = real.get();
    }
    if (S_ISREG(st.st_mode)) return {TargetKind::kFile, resolved};
    if (S_ISDIR(st.st_mode)) Fail("cannot write '", path, "': it is a directory");
    if (S_ISFIFO(st.st_mode)) return {TargetKind::kStream, resolved};
    if (S_ISCHR(st.st_mode)) {
        struct stat other {};
        if ((::stat("/dev/null", &other) == 0 && SameCharDevice(st, other)) ||
            (::fstat(1, &other) == 0 && SameCharDevice(st, other)) ||
            (::fstat(2, &other) == 0 && SameCharDevice(st, other))) {
            return {TargetKind::kStream, resolved};
        }
        Fail("cannot write '", path,
             "': it is a device (atmos writes only to /dev/null, /dev/stdout, /dev/stderr, "
             "'-' and FIFOs directly)");
    }
    Fail("cannot write '", path, "': it is not a regular file (a ",
         S_ISSOCK(st.st_mode) ? "socket" : "block device", ")");
}

std::string DirectoryOf(const std::string& path) {
    const std::filesystem::path p(path);
    return p.has_parent_path() ? p.parent_path().string() : ".";
}

std::string RandomSuffix() {
    static std::mutex mutex;
    static std::mt19937_64 engine = [] {
        std::random_device device;
        std::seed_seq seq{device(), device(), device(), device(),
                          static_cast<unsigned>(::getpid())};
        return std::mt19937_64(seq);
    }();
    uint64_t bits;
    {
        const std::lock_guard<std::mutex> lock(mutex);
        bits = engine();
    }
    static const char kDigits[] = "0123456789abcdefghijklmnopqrstuvwxyz";
    std::string s;
    for (int i = 0; i < 12; ++i, bits /= 36) s.push_back(kDigits[bits % 36]);
    return s;
}

// Creates the exclusive file; errno and -1 when it cannot.
int TryCreateExclusive(const std::string& directory, const std::string& prefix, std::string* name) {
    for (int attempt = 0; attempt < 64; ++attempt) {
        *name =
            (std::filesystem::path(directory) / ("." + prefix + ".tmp-" + RandomSuffix())).string();
        const int fd =
            ::open(name->c_str(), O_RDWR | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
        if (fd >= 0 || errno != EEXIST) return fd;
    }
    errno = EEXIST;
    return -1;
}

// The errno text when no file can be created in `directory` (a probe created
// exclusively and removed), else "".
std::string ProbeWritable(const std::string& directory) {
    std::string name;
    errno = 0;
    const int fd = TryCreateExclusive(directory, "atmos-write-probe", &name);
    if (fd < 0) return std::strerror(errno);
    ::close(fd);
    ::unlink(name.c_str());
    return "";
}

// The path a writer opens for descriptor `fd`: /proc/self/fd/N reopens the
// very file created (a name swapped in meanwhile cannot redirect it); `name`
// where /proc is not mounted.
std::string WriterPath(int fd, const std::string& name) {
    static const bool have_proc = ::access("/proc/self/fd", X_OK) == 0;
    return have_proc ? "/proc/self/fd/" + std::to_string(fd) : name;
}

void WriteAllTo(int fd, const char* data, size_t size, const std::string& path) {
    size_t done = 0;
    while (done < size) {
        const ssize_t w = ::write(fd, data + done, size - done);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) Fail("cannot write '", path, "': ", std::strerror(errno));
        done += static_cast<size_t>(w);
    }
}

// Copies the file behind `from` to the stream `target` (an output_path.h stream).
void CopyToStream(int from, const Target& target, const std::string& path) {
    int to = -1;
    bool close_to = false;
    if (target.kind == TargetKind::kStdout) {
        std::fflush(stdout);
        to = 1;
    } else if (target.kind == TargetKind::kStderr) {
        std::fflush(stderr);
        to = 2;
    } else {
        to = ::open(target.path.c_str(), O_WRONLY | O_CLOEXEC | O_NOCTTY);
        if (to < 0) Fail("cannot write '", path, "': ", std::strerror(errno));
        close_to = true;
    }
    try {
        if (::lseek(from, 0, SEEK_SET) != 0)
            Fail("cannot write '", path, "': ", std::strerror(errno));
        char chunk[1 << 16];
        for (;;) {
            const ssize_t n = ::read(from, chunk, sizeof chunk);
            if (n < 0 && errno == EINTR) continue;
            if (n < 0) Fail("cannot write '", path, "': ", std::strerror(errno));
            if (n == 0) break;
            WriteAllTo(to, chunk, static_cast<size_t>(n), path);
        }
    } catch (...) {
        if (close_to) ::close(to);
        throw;
    }
    if (close_to && ::close(to) != 0) Fail("cannot write '", path, "': ", std::strerror(errno));
}

// The writers name the file they were given: name the target instead.
Error RenameInMessage(const Error& e, const std::string& temporary, const std::string& path) {
    std::string message = e.what();
    for (size_t at = message.find(temporary); at != std::string::npos;
         at = message.find(temporary, at + path.size())) {
        message.replace(at, temporary.size(), path);
    }
    return Error(message);
}

// The first entry under `dir` that is not a table, JSON, shader or viewer
// page (what bake and viewer write), else "".
std::string ForeignEntry(const std::filesystem::path& dir, int depth) {
    // Tables, JSON, GLSL, viewer pages, raw blobs; the engine stages and their
    // translations (shaders/{vulkan,spirv,hlsl,msl}/) and KTX2 files (ktx2/).
    static const char* const kWritten[] = {".exr",  ".json", ".glsl", ".js",    ".html",
                                           ".f32",  ".f16",  ".bin",  ".vert",  ".frag",
                                           ".comp", ".spv",  ".hlsl", ".metal", ".ktx2"};
    std::error_code ec;
    for (const std::filesystem::directory_entry& e : std::filesystem::directory_iterator(dir, ec)) {
        const std::filesystem::file_status st = e.symlink_status(ec);
        if (std::filesystem::is_directory(st)) {
            if (depth >= 3) return e.path().string();  // viewer/MODEL/shaders/vulkan
            const std::string inner = ForeignEntry(e.path(), depth + 1);
            if (!inner.empty()) return inner;
            continue;
        }
        bool known = false;
        const std::string ext = e.path().extension().string();
        for (const char* w : kWritten) known |= std::filesystem::is_regular_file(st) && ext == w;
        if (!known) return e.path().string();
    }
    if (ec) return dir.string();
    return "";
}

}  // namespace

int CreateExclusiveFile(const std::string& directory, const std::string& prefix, std::string* name,
                        const std::string& what) {
    errno = 0;
    const int fd = TryCreateExclusive(directory, prefix, name);
    if (fd < 0) {
        Fail("cannot write ", what, ": no temporary file can be created in '", directory,
             "': ", std::strerror(errno));
    }
    return fd;
}

bool IsStreamOutput(const std::string& path) {
    try {
        return ResolveOutput(path).kind != TargetKind::kFile;
    } catch (const Error&) {
        return false;
    }
}

void WriteThroughTemporary(const std::string& path,
                           const std::function<void(const std::string& temporary)>& write) {
    const Target target = ResolveOutput(path);
    const bool stream = target.kind != TargetKind::kFile;
    // A stream's bytes are built in an unnamed file in the temporary directory
    // (named only between its creation and the unlink below).
    std::string directory;
    if (stream) {
        std::error_code ec;
        directory = std::filesystem::temp_directory_path(ec).string();
        if (ec) directory = "/tmp";
    } else {
        directory = DirectoryOf(target.path);
    }
    std::string name;
    const int fd = CreateExclusiveFile(
        directory, stream ? "atmos-output" : std::filesystem::path(target.path).filename().string(),
        &name, "'" + path + "'");
    const std::string writer_path = WriterPath(fd, name);
    const bool unlinked = stream && writer_path != name && ::unlink(name.c_str()) == 0;
    auto discard = [&]() {
        ::close(fd);
        if (!unlinked) ::unlink(name.c_str());
    };
    try {
        write(writer_path);
        if (stream) {
            CopyToStream(fd, target, path);
            discard();
            return;
        }
        if (::close(fd) != 0) {
            const int err = errno;
            ::unlink(name.c_str());
            Fail("cannot write '", path, "': ", std::strerror(err));
        }
    } catch (const Error& e) {
        discard();
        throw RenameInMessage(RenameInMessage(e, writer_path, path), name, path);
    } catch (...) {
        discard();
        throw;
    }
    if (::rename(name.c_str(), target.path.c_str()) != 0) {
        const int err = errno;
        ::unlink(name.c_str());
        Fail("cannot write '", path, "': ", std::strerror(err));
    }
}

void WriteFileAtomically(const std::string& path, const std::string& bytes) {
    WriteThroughTemporary(path, [&](const std::string& temporary) {
        std::unique_ptr<std::FILE, decltype(&std::fclose)> f(std::fopen(temporary.c_str(), "wb"),
                                                             &std::fclose);
        if (!f) Fail("cannot write '", temporary, "': ", std::strerror(errno));
        const bool written = std::fwrite(bytes.data(), 1, bytes.size(), f.get()) == bytes.size() &&
                             std::fflush(f.get()) == 0;
        const int err = errno;
        if (std::fclose(f.release()) != 0 || !written) {
            Fail("cannot write '", temporary, "': ", std::strerror(written ? errno : err));
        }
    });
}

void CheckOutputFile(const std::string& path) {
    const Target target = ResolveOutput(path);  // refuses directories and devices
    if (target.kind != TargetKind::kFile) return;
    const std::string dir = DirectoryOf(target.path);
    std::error_code ec;
    if (!std::filesystem::exists(dir, ec)) {
        Fail("cannot write '", path, "': the directory '", dir, "' does not exist");
    }
    if (!std::filesystem::is_directory(dir, ec)) {
        Fail("cannot write '", path, "': '", dir, "' is not a directory");
    }
    const std::string why = ProbeWritable(dir);
    if (!why.empty()) Fail("cannot write '", path, "': ", why);
}

void CheckCheckpointFile(const std::string& path) {
    std::error_code ec;
    const std::filesystem::file_status status = std::filesystem::status(path, ec);
    if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
        Fail("checkpoint '", path,
             "' exists and is not a regular file (a directory, a FIFO or a device); remove it "
             "or give another --checkpoint");
    }
    CheckOutputFile(path);
}

void CheckOutputDirectory(const std::string& path) {
    if (path.empty()) Fail("the output directory is empty");
    std::error_code ec;
    if (std::filesystem::exists(path, ec)) {
        if (!std::filesystem::is_directory(path, ec)) {
            Fail("cannot write to directory '", path, "': it exists and is not a directory");
        }
        const std::string why = ProbeWritable(path);
        if (!why.empty()) Fail("cannot write to directory '", path, "': ", why);
        return;
    }
    // Not there yet (the command creates it after its checks): the nearest
    // existing ancestor must be a writable directory.
    std::filesystem::path ancestor = std::filesystem::absolute(path, ec).parent_path();
    while (!ancestor.empty() && !std::filesystem::exists(ancestor, ec)) {
        if (ancestor == ancestor.parent_path()) break;
        ancestor = ancestor.parent_path();
    }
    if (!std::filesystem::is_directory(ancestor, ec)) {
        Fail("cannot create directory '", path, "': '", ancestor.string(), "' is not a directory");
    }
    const std::string why = ProbeWritable(ancestor.string());
    if (!why.empty()) Fail("cannot create directory '", path, "': ", why);
}

void StagedDirectory::Check(const std::string& path) {
    CheckOutputDirectory(path);
    std::error_code ec;
    // The previous directory is replaced as a whole: only one that holds what
    // atmos writes (tables, their JSON, shaders, viewer pages), so that `-o`
    // naming a directory of other files is refused before any work.
    if (std::filesystem::is_directory(path, ec)) {
        const std::string foreign = ForeignEntry(path, 0);
        if (!foreign.empty()) {
            Fail("cannot write to directory '", path, "': it holds '", foreign,
                 "', which atmos does not write (a bake replaces its whole directory): give a "
                 "new or empty directory, or an earlier bake's");
        }
    }
}

StagedDirectory::StagedDirectory(const std::string& final_path) : final_(final_path) {
    Check(final_path);
    std::filesystem::path target(final_);
    if (target.filename().empty()) target = target.parent_path();  // "dir/"
    final_ = target.string();
    const std::filesystem::path parent = target.has_parent_path() ? target.parent_path() : ".";
    std::filesystem::create_directories(parent);
    for (int attempt = 0; attempt < 64; ++attempt) {
        staging_ =
            (parent / ("." + target.filename().string() + ".new-" + RandomSuffix())).string();
        if (::mkdir(staging_.c_str(), 0777) == 0) return;
        if (errno != EEXIST) {
            Fail("cannot write to directory '", final_, "': cannot create '", staging_,
                 "': ", std::strerror(errno));
        }
    }
    Fail("cannot write to directory '", final_, "': no staging directory name is free");
}

StagedDirectory::~StagedDirectory() {
    if (committed_) return;
    std::error_code ignored;
    std::filesystem::remove_all(staging_, ignored);
}

void StagedDirectory::Write(const std::function<void(const std::string& staging)>& write) const {
    try {
        write(staging_);
    } catch (const Error& e) {
        throw RenameInMessage(e, staging_, final_);
    }
}

void StagedDirectory::Commit() {
    std::error_code ec;
    if (!std::filesystem::exists(final_, ec)) {
        if (::rename(staging_.c_str(), final_.c_str()) != 0) {
            Fail("cannot write to directory '", final_, "': ", std::strerror(errno));
        }
        committed_ = true;
        return;
    }
    // The new contents and the old swap places in one step; the old then
    // sits under the staging name and is removed.
    if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, final_.c_str(), RENAME_EXCHANGE) != 0) {
        // No exchange on this file system: the old aside, the new in place.
        const std::string aside = staging_ + ".old";
        if (::rename(final_.c_str(), aside.c_str()) != 0 ||
            ::rename(staging_.c_str(), final_.c_str()) != 0) {
            const int err = errno;
            if (!std::filesystem::exists(final_, ec)) ::rename(aside.c_str(), final_.c_str());
            Fail("cannot write to directory '", final_, "': ", std::strerror(err));
        }
        committed_ = true;
        std::filesystem::remove_all(aside, ec);
        return;
    }
    committed_ = true;
    std::filesystem::remove_all(staging_, ec);  // the previous contents
}

FileLock::FileLock(const std::string& path) {
    if (path.empty()) return;
    lock_path_ = path + ".lock";
    // The lock file may be removed by its previous holder between our open
    // and our flock: then the lock is on a file no longer there, so again.
    for (int attempt = 0; attempt < 64; ++attempt) {
        const int fd = ::open(lock_path_.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0666);
        if (fd < 0) Fail("cannot create the lock '", lock_path_, "': ", std::strerror(errno));
        if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
            const int err = errno;
            ::close(fd);
            if (err == EWOULDBLOCK) {
                Fail("another atmos run is using '", path, "' (it holds the lock '", lock_path_,
                     "'): wait for it to finish, or give this run another output or "
                     "--checkpoint");
            }
            Fail("cannot lock '", lock_path_, "': ", std::strerror(err));
        }
        struct stat held {
        }, named{};
        if (::fstat(fd, &held) == 0 && ::stat(lock_path_.c_str(), &named) == 0 &&
            held.st_dev == named.st_dev && held.st_ino == named.st_ino) {
            fd_ = fd;
            return;
        }
        ::close(fd);
    }
    Fail("cannot lock '", lock_path_, "': it keeps being replaced");
}

FileLock::~FileLock() {
    if (fd_ < 0) return;
    ::unlink(lock_path_.c_str());  // while held: the next run creates a new one
    ::close(fd_);
}

}  // namespace atmos
