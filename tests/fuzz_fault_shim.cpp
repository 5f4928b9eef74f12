// Issue 38 item 5: a test-only LD_PRELOAD library that injects file system
// faults (a full disk, a read-only directory) into the `atmos` executable, so
// that tests/fuzz_faults_test.cpp can check every kind of output under them
// (tests run as root on CI, where chmod makes nothing read-only, and a tmpfs
// mount may not be allowed in a container).
//
// Configured by the environment (nothing happens unless ATMOS_FAULT_PATH is set):
//   ATMOS_FAULT_PATH   where faults apply: a path prefix (a string prefix of the
//                      absolute path; give "DIR/" for everything under DIR);
//                      several separated by ':'.
//   ATMOS_FAULT_ERRNO  the error: ENOSPC (default), EROFS, EACCES, EDQUOT, EIO.
//   ATMOS_FAULT_OPS    which calls fail, comma-separated (default "write"):
//                      write   write, pwrite, writev and stdio writes to a file
//                              opened under the prefix, once ATMOS_FAULT_AFTER
//                              bytes have been written there (a full disk);
//                      fsync   fsync and fdatasync of such a file;
//                      close   close of such a file after a write (as NFS does);
//                      create  opening a file under the prefix for writing,
//                              creating one, mkdir, mkstemp, link, symlink;
//                      rename  rename, renameat, renameat2 from or to the prefix;
//                      remove  unlink, unlinkat, rmdir, remove under the prefix;
//                      all     every one of these.
//   ATMOS_FAULT_AFTER  bytes written under the prefix before `write` fails (0).
//   ATMOS_FAULT_LOG    a file to which one line is appended per fault injected
//                      (so a test can tell that the fault was reached).
//
// Only calls made through the dynamic linker are seen (atmos, libstdc++,
// libpng, OpenEXR calling libc); glibc's stdio writes its buffers internally,
// so the stdio entry points are wrapped too and account the bytes they are
// given. Linux and glibc only (it reads /proc/self/fd and sets a FILE's error
// flag as glibc does).
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/uio.h>
#include <unistd.h>

#include <atomic>

namespace {

constexpr unsigned kWrite = 1, kFsync = 2, kClose = 4, kCreate = 8, kRename = 16, kRemove = 32;
constexpr int kMaxFd = 65536;
constexpr int kMaxPrefixes = 8;

struct Config {
    bool enabled = false;
    int error = ENOSPC;
    unsigned ops = kWrite;
    long long after = 0;
    char prefixes[kMaxPrefixes][1024] = {};
    int prefix_count = 0;
    char log[1024] = {};
};

Config g_config;
std::atomic<long long> g_written{0};
// Per descriptor: 1 a file under the prefix opened for writing, 2 one written
// to, 3 one that a fault hit.
std::atomic<unsigned char> g_fd_state[kMaxFd];

template <typename F>
F Real(const char* name) {
    return reinterpret_cast<F>(dlsym(RTLD_NEXT, name));
}

#define REAL(name) static const auto real_##name = Real<decltype(&::name)>(#name)

int ErrnoFromName(const char* name) {
    if (name == nullptr || *name == '\0' || strcmp(name, "ENOSPC") == 0) return ENOSPC;
    if (strcmp(name, "EROFS") == 0) return EROFS;
    if (strcmp(name, "EACCES") == 0) return EACCES;
    if (strcmp(name, "EDQUOT") == 0) return EDQUOT;
    if (strcmp(name, "EIO") == 0) return EIO;
    return atoi(name) > 0 ? atoi(name) : ENOSPC;
}

unsigned OpsFromList(const char* list) {
    if (list == nullptr || *list == '\0') return kWrite;
    unsigned ops = 0;
    const char* p = list;
    while (*p != '\0') {
        const char* end = strchr(p, ',');
        const size_t n = end ? static_cast<size_t>(end - p) : strlen(p);
        auto is = [&](const char* word) { return n == strlen(word) && strncmp(p, word, n) == 0; };
        if (is("write")) ops |= kWrite;
        if (is("fsync")) ops |= kFsync;
        if (is("close")) ops |= kClose;
        if (is("create")) ops |= kCreate;
        if (is("rename")) ops |= kRename;
        if (is("remove")) ops |= kRemove;
        if (is("all")) ops |= kWrite | kFsync | kClose | kCreate | kRename | kRemove;
        p += n;
        if (*p == ',') ++p;
    }
    return ops;
}

__attribute__((constructor(101))) void Configure() {
    const char* path = getenv("ATMOS_FAULT_PATH");
    if (path == nullptr || *path == '\0') return;
    const char* p = path;
    while (*p != '\0' && g_config.prefix_count < kMaxPrefixes) {
        const char* end = strchr(p, ':');
        const size_t n = end ? static_cast<size_t>(end - p) : strlen(p);
        if (n > 0 && n < sizeof g_config.prefixes[0]) {
            memcpy(g_config.prefixes[g_config.prefix_count++], p, n);
        }
        p += n;
        if (*p == ':') ++p;
    }
    g_config.error = ErrnoFromName(getenv("ATMOS_FAULT_ERRNO"));
    g_config.ops = OpsFromList(getenv("ATMOS_FAULT_OPS"));
    const char* after = getenv("ATMOS_FAULT_AFTER");
    g_config.after = after ? atoll(after) : 0;
    const char* log = getenv("ATMOS_FAULT_LOG");
    if (log != nullptr && strlen(log) < sizeof g_config.log) strcpy(g_config.log, log);
    g_config.enabled = g_config.prefix_count > 0;
}

bool Enabled(unsigned op) { return g_config.enabled && (g_config.ops & op) != 0; }

// Appends "OP WHAT" to the log; errno is kept.
void Log(const char* op, const char* what) {
    if (g_config.log[0] == '\0') return;
    const int saved = errno;
    REAL(open);
    REAL(write);
    REAL(close);
    const int fd = real_open(g_config.log, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (fd >= 0) {
        char line[1200];
        const int n = snprintf(line, sizeof line, "%s %s\n", op, what ? what : "?");
        if (n > 0) {
            const ssize_t ignored = real_write(fd, line, static_cast<size_t>(n));
            (void)ignored;
        }
        real_close(fd);
    }
    errno = saved;
}

// `path` (relative to `dirfd`) as an absolute path, lexically cleaned; a
// /proc/self/fd/N path is the file it names. False when it cannot be formed.
bool Absolute(int dirfd, const char* path, char* out, size_t size) {
    if (path == nullptr) return false;
    char raw[4096];
    if (path[0] == '/') {
        snprintf(raw, sizeof raw, "%s", path);
    } else {
        char base[4096];
        if (dirfd == AT_FDCWD) {
            if (getcwd(base, sizeof base) == nullptr) return false;
        } else {
            char link[64];
            snprintf(link, sizeof link, "/proc/self/fd/%d", dirfd);
            const ssize_t n = readlink(link, base, sizeof base - 1);
            if (n <= 0) return false;
            base[n] = '\0';
        }
        if (strlen(base) + strlen(path) + 2 > sizeof raw) return false;
        strcpy(raw, base);
        strcat(raw, "/");
        strcat(raw, path);
    }
    if (strncmp(raw, "/proc/self/fd/", 14) == 0 || strncmp(raw, "/dev/fd/", 8) == 0) {
        char target[4096];
        const ssize_t n = readlink(raw, target, sizeof target - 1);
        if (n > 0) {
            target[n] = '\0';
            snprintf(raw, sizeof raw, "%s", target);
        }
    }
    // Drop empty and "." components, resolve "..".
    size_t len = 0;
    out[0] = '\0';
    const char* p = raw;
    while (*p != '\0') {
        while (*p == '/') ++p;
        const char* end = strchr(p, '/');
        const size_t n = end ? static_cast<size_t>(end - p) : strlen(p);
        if (n == 0) break;
        if (n == 1 && p[0] == '.') {
        } else if (n == 2 && p[0] == '.' && p[1] == '.') {
            while (len > 0 && out[len - 1] != '/') --len;
            if (len > 0) --len;
            out[len] = '\0';
        } else {
            if (len + n + 2 >= size) return false;
            out[len++] = '/';
            memcpy(out + len, p, n);
            len += n;
            out[len] = '\0';
        }
        p += n;
    }
    if (len == 0) snprintf(out, size, "/");
    return true;
}

bool Matches(int dirfd, const char* path) {
    if (!g_config.enabled) return false;
    const int saved = errno;
    char abs[4096];
    bool match = false;
    if (Absolute(dirfd, path, abs, sizeof abs)) {
        for (int i = 0; i < g_config.prefix_count && !match; ++i) {
            match = strncmp(abs, g_config.prefixes[i], strlen(g_config.prefixes[i])) == 0;
        }
    }
    errno = saved;
    return match;
}

bool FdMatches(int fd) {
    char link[64];
    snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
    return Matches(AT_FDCWD, link);
}

// After a successful open for writing: remember a descriptor under the prefix.
void Track(int fd, int flags) {
    if (!g_config.enabled || fd < 0 || fd >= kMaxFd) return;
    if ((flags & O_ACCMODE) == O_RDONLY) return;
    g_fd_state[fd].store(FdMatches(fd) ? 1 : 0);
}

bool Tracked(int fd) { return fd >= 0 && fd < kMaxFd && g_fd_state[fd].load() != 0; }

void Untrack(int fd) {
    if (fd >= 0 && fd < kMaxFd) g_fd_state[fd].store(0);
}

bool Faulted(int fd) { return fd >= 0 && fd < kMaxFd && g_fd_state[fd].load() == 3; }

// How many of `n` bytes to descriptor `fd` the disk takes (all of them when
// the fd is not watched); marks the descriptor written to or faulted.
size_t Allow(int fd, size_t n, const char* op) {
    if (!Tracked(fd)) return n;
    if (!Enabled(kWrite)) {
        if (n > 0) g_fd_state[fd].store(2);
        return n;
    }
    const long long before = g_written.fetch_add(static_cast<long long>(n));
    const long long room = g_config.after - before;
    if (room >= static_cast<long long>(n)) {
        if (n > 0) g_fd_state[fd].store(2);
        return n;
    }
    g_written.fetch_sub(static_cast<long long>(n) - (room > 0 ? room : 0));
    g_fd_state[fd].store(3);
    char what[32];
    snprintf(what, sizeof what, "fd %d", fd);
    Log(op, what);
    return room > 0 ? static_cast<size_t>(room) : 0;
}

int FailWith(const char* op, const char* what) {
    Log(op, what);
    errno = g_config.error;
    return -1;
}

bool OpensForWriting(int flags) {
    return (flags & O_ACCMODE) != O_RDONLY || (flags & (O_CREAT | O_TRUNC)) != 0;
}

int FlagsFromMode(const char* mode) {
    if (mode == nullptr) return O_RDONLY;
    if (strchr(mode, '+') != nullptr) return O_RDWR | (mode[0] == 'r' ? 0 : O_CREAT);
    if (mode[0] == 'w' || mode[0] == 'a') return O_WRONLY | O_CREAT;
    return O_RDONLY;
}

// glibc's FILE error flag (_IO_ERR_SEEN), as a failed write of its own sets it.
void SetStreamError(FILE* f) { f->_flags |= 0x0020; }

}  // namespace

extern "C" {

// ---- opening and creating ----

int open(const char* path, int flags, ...) {
    REAL(open);
    mode_t mode = 0;
    if (flags & (O_CREAT | O_TMPFILE)) {
        va_list ap;
        va_start(ap, flags);
        mode = static_cast<mode_t>(va_arg(ap, int));
        va_end(ap);
    }
    if (Enabled(kCreate) && OpensForWriting(flags) && Matches(AT_FDCWD, path)) {
        return FailWith("create", path);
    }
    const int fd = real_open(path, flags, mode);
    Track(fd, flags);
    return fd;
}

int open64(const char* path, int flags, ...) {
    mode_t mode = 0;
    if (flags & (O_CREAT | O_TMPFILE)) {
        va_list ap;
        va_start(ap, flags);
        mode = static_cast<mode_t>(va_arg(ap, int));
        va_end(ap);
    }
    return open(path, flags, mode);
}

int openat(int dirfd, const char* path, int flags, ...) {
    REAL(openat);
    mode_t mode = 0;
    if (flags & (O_CREAT | O_TMPFILE)) {
        va_list ap;
        va_start(ap, flags);
        mode = static_cast<mode_t>(va_arg(ap, int));
        va_end(ap);
    }
    if (Enabled(kCreate) && OpensForWriting(flags) && Matches(dirfd, path)) {
        return FailWith("create", path);
    }
    const int fd = real_openat(dirfd, path, flags, mode);
    Track(fd, flags);
    return fd;
}

int openat64(int dirfd, const char* path, int flags, ...) {
    mode_t mode = 0;
    if (flags & (O_CREAT | O_TMPFILE)) {
        va_list ap;
        va_start(ap, flags);
        mode = static_cast<mode_t>(va_arg(ap, int));
        va_end(ap);
    }
    return openat(dirfd, path, flags, mode);
}

int creat(const char* path, mode_t mode) { return open(path, O_WRONLY | O_CREAT | O_TRUNC, mode); }
int creat64(const char* path, mode_t mode) { return creat(path, mode); }

FILE* fopen(const char* path, const char* mode) {
    REAL(fopen);
    const int flags = FlagsFromMode(mode);
    if (Enabled(kCreate) && OpensForWriting(flags) && Matches(AT_FDCWD, path)) {
        FailWith("create", path);
        return nullptr;
    }
    FILE* f = real_fopen(path, mode);
    if (f != nullptr) Track(fileno(f), flags);
    return f;
}

FILE* fopen64(const char* path, const char* mode) { return fopen(path, mode); }

int mkdir(const char* path, mode_t mode) {
    REAL(mkdir);
    if (Enabled(kCreate) && Matches(AT_FDCWD, path)) return FailWith("create", path);
    return real_mkdir(path, mode);
}

int mkdirat(int dirfd, const char* path, mode_t mode) {
    REAL(mkdirat);
    if (Enabled(kCreate) && Matches(dirfd, path)) return FailWith("create", path);
    return real_mkdirat(dirfd, path, mode);
}

int mkstemp(char* templ) {
    REAL(mkstemp);
    if (Enabled(kCreate) && Matches(AT_FDCWD, templ)) return FailWith("create", templ);
    const int fd = real_mkstemp(templ);
    Track(fd, O_RDWR);
    return fd;
}

int mkostemp(char* templ, int flags) {
    REAL(mkostemp);
    if (Enabled(kCreate) && Matches(AT_FDCWD, templ)) return FailWith("create", templ);
    const int fd = real_mkostemp(templ, flags);
    Track(fd, O_RDWR);
    return fd;
}

int link(const char* from, const char* to) {
    REAL(link);
    if (Enabled(kCreate) && Matches(AT_FDCWD, to)) return FailWith("create", to);
    return real_link(from, to);
}

int symlink(const char* target, const char* path) {
    REAL(symlink);
    if (Enabled(kCreate) && Matches(AT_FDCWD, path)) return FailWith("create", path);
    return real_symlink(target, path);
}

// ---- renaming and removing ----

int rename(const char* from, const char* to) {
    REAL(rename);
    if (Enabled(kRename) && (Matches(AT_FDCWD, from) || Matches(AT_FDCWD, to))) {
        return FailWith("rename", to);
    }
    return real_rename(from, to);
}

int renameat(int fromfd, const char* from, int tofd, const char* to) {
    REAL(renameat);
    if (Enabled(kRename) && (Matches(fromfd, from) || Matches(tofd, to))) {
        return FailWith("rename", to);
    }
    return real_renameat(fromfd, from, tofd, to);
}

int renameat2(int fromfd, const char* from, int tofd, const char* to, unsigned flags) {
    REAL(renameat2);
    if (Enabled(kRename) && (Matches(fromfd, from) || Matches(tofd, to))) {
        return FailWith("rename", to);
    }
    return real_renameat2(fromfd, from, tofd, to, flags);
}

int unlink(const char* path) {
    REAL(unlink);
    if (Enabled(kRemove) && Matches(AT_FDCWD, path)) return FailWith("remove", path);
    return real_unlink(path);
}

int unlinkat(int dirfd, const char* path, int flags) {
    REAL(unlinkat);
    if (Enabled(kRemove) && Matches(dirfd, path)) return FailWith("remove", path);
    return real_unlinkat(dirfd, path, flags);
}

int rmdir(const char* path) {
    REAL(rmdir);
    if (Enabled(kRemove) && Matches(AT_FDCWD, path)) return FailWith("remove", path);
    return real_rmdir(path);
}

int remove(const char* path) {
    REAL(remove);
    if (Enabled(kRemove) && Matches(AT_FDCWD, path)) return FailWith("remove", path);
    return real_remove(path);
}

// ---- descriptors ----

ssize_t write(int fd, const void* data, size_t n) {
    REAL(write);
    const size_t allowed = Allow(fd, n, "write");
    if (allowed == 0 && n > 0) {
        errno = g_config.error;
        return -1;
    }
    return real_write(fd, data, allowed);
}

ssize_t pwrite(int fd, const void* data, size_t n, off_t at) {
    REAL(pwrite);
    const size_t allowed = Allow(fd, n, "pwrite");
    if (allowed == 0 && n > 0) {
        errno = g_config.error;
        return -1;
    }
    return real_pwrite(fd, data, allowed, at);
}

ssize_t pwrite64(int fd, const void* data, size_t n, off64_t at) {
    REAL(pwrite64);
    const size_t allowed = Allow(fd, n, "pwrite");
    if (allowed == 0 && n > 0) {
        errno = g_config.error;
        return -1;
    }
    return real_pwrite64(fd, data, allowed, at);
}

ssize_t writev(int fd, const struct iovec* iov, int count) {
    REAL(writev);
    if (!Tracked(fd)) return real_writev(fd, iov, count);
    size_t n = 0;
    for (int i = 0; i < count; ++i) n += iov[i].iov_len;
    const size_t allowed = Allow(fd, n, "writev");
    if (allowed < n) {
        // The part the disk takes, written plainly.
        if (allowed == 0) {
            errno = g_config.error;
            return -1;
        }
        REAL(write);
        size_t left = allowed;
        ssize_t done = 0;
        for (int i = 0; i < count && left > 0; ++i) {
            const size_t part = iov[i].iov_len < left ? iov[i].iov_len : left;
            const ssize_t w = real_write(fd, iov[i].iov_base, part);
            if (w < 0) return done > 0 ? done : -1;
            done += w;
            left -= static_cast<size_t>(w);
            if (static_cast<size_t>(w) < part) break;
        }
        return done;
    }
    return real_writev(fd, iov, count);
}

int fsync(int fd) {
    REAL(fsync);
    if (Enabled(kFsync) && Tracked(fd)) {
        char what[32];
        snprintf(what, sizeof what, "fd %d", fd);
        return FailWith("fsync", what);
    }
    if (Faulted(fd)) {
        errno = g_config.error;
        return -1;
    }
    return real_fsync(fd);
}

int fdatasync(int fd) {
    REAL(fdatasync);
    if (Enabled(kFsync) && Tracked(fd)) {
        char what[32];
        snprintf(what, sizeof what, "fd %d", fd);
        return FailWith("fsync", what);
    }
    return real_fdatasync(fd);
}

int close(int fd) {
    REAL(close);
    const unsigned char state = fd >= 0 && fd < kMaxFd ? g_fd_state[fd].load() : 0;
    Untrack(fd);
    const int r = real_close(fd);
    if (r == 0 && Enabled(kClose) && state >= 2) {
        char what[32];
        snprintf(what, sizeof what, "fd %d", fd);
        return FailWith("close", what);
    }
    return r;
}

// ---- stdio (glibc writes its buffers internally: the bytes are accounted here) ----

size_t fwrite(const void* data, size_t size, size_t count, FILE* f) {
    REAL(fwrite);
    const int fd = fileno(f);
    if (!Tracked(fd) || size == 0) return real_fwrite(data, size, count, f);
    const size_t allowed = Allow(fd, size * count, "fwrite");
    if (allowed < size * count) {
        const size_t items = allowed / size;
        const size_t done = items > 0 ? real_fwrite(data, size, items, f) : 0;
        SetStreamError(f);
        errno = g_config.error;
        return done;
    }
    return real_fwrite(data, size, count, f);
}

size_t fwrite_unlocked(const void* data, size_t size, size_t count, FILE* f) {
    return fwrite(data, size, count, f);
}

int fputs(const char* s, FILE* f) {
    REAL(fputs);
    const int fd = fileno(f);
    if (Tracked(fd)) {
        const size_t n = strlen(s);
        if (Allow(fd, n, "fputs") < n) {
            SetStreamError(f);
            errno = g_config.error;
            return EOF;
        }
    }
    return real_fputs(s, f);
}

int fputc(int c, FILE* f) {
    REAL(fputc);
    const int fd = fileno(f);
    if (Tracked(fd) && Allow(fd, 1, "fputc") < 1) {
        SetStreamError(f);
        errno = g_config.error;
        return EOF;
    }
    return real_fputc(c, f);
}

int putc(int c, FILE* f) { return fputc(c, f); }

int vfprintf(FILE* f, const char* format, va_list ap) {
    REAL(vfprintf);
    const int fd = fileno(f);
    if (Tracked(fd)) {
        va_list copy;
        va_copy(copy, ap);
        const int n = vsnprintf(nullptr, 0, format, copy);
        va_end(copy);
        if (n > 0 && Allow(fd, static_cast<size_t>(n), "fprintf") < static_cast<size_t>(n)) {
            SetStreamError(f);
            errno = g_config.error;
            return -1;
        }
    }
    return real_vfprintf(f, format, ap);
}

int fprintf(FILE* f, const char* format, ...) {
    va_list ap;
    va_start(ap, format);
    const int r = vfprintf(f, format, ap);
    va_end(ap);
    return r;
}

int fflush(FILE* f) {
    REAL(fflush);
    const int r = real_fflush(f);
    if (f != nullptr && Faulted(fileno(f))) {
        errno = g_config.error;
        return EOF;
    }
    return r;
}

int fclose(FILE* f) {
    REAL(fclose);
    const int fd = fileno(f);
    const unsigned char state = fd >= 0 && fd < kMaxFd ? g_fd_state[fd].load() : 0;
    Untrack(fd);
    const int r = real_fclose(f);
    if (state == 3) {
        errno = g_config.error;
        return EOF;
    }
    if (r == 0 && state == 2 && Enabled(kClose)) {
        // A delayed-allocation file system reports a full disk at the close.
        char what[32];
        snprintf(what, sizeof what, "fd %d", fd);
        FailWith("close", what);
        return EOF;
    }
    return r;
}

}  // extern "C"
