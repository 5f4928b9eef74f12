// atmos: inputs read with bounds (see bounded_read.h).
#include "io/bounded_read.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>

#include "atmos/error.h"

namespace atmos {

namespace {

std::string Size(size_t bytes) {
    if (bytes >= (size_t{1} << 30) && bytes % (size_t{1} << 30) == 0) {
        return std::to_string(bytes >> 30) + " GiB";
    }
    if (bytes >= (size_t{1} << 20) && bytes % (size_t{1} << 20) == 0) {
        return std::to_string(bytes >> 20) + " MiB";
    }
    return std::to_string(bytes) + " bytes";
}

// How long a FIFO input may stay silent: ATMOS_INPUT_WAIT_SECONDS, else 10 s.
double InputWaitSeconds() {
    if (const char* env = std::getenv("ATMOS_INPUT_WAIT_SECONDS")) {
        char* end = nullptr;
        const double v = std::strtod(env, &end);
        if (end != env && *end == '\0' && v >= 0.0 && v <= 86400.0) return v;
    }
    return 10.0;
}

// `path` opened for reading. A FIFO is opened without blocking (a FIFO that no
// one writes would block the open forever) and waited for at most
// InputWaitSeconds(); then it is read as any file.
std::FILE* OpenInput(const std::string& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0 || !S_ISFIFO(st.st_mode)) {
        return std::fopen(path.c_str(), "rb");
    }
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return nullptr;
    const double wait = InputWaitSeconds();
    pollfd p{fd, POLLIN, 0};
    int ready = 0;
    do {
        ready = ::poll(&p, 1, static_cast<int>(wait * 1000.0));
    } while (ready < 0 && errno == EINTR);
    if (ready <= 0) {
        ::close(fd);
        Fail("cannot read '", path, "': it is a FIFO and nothing was written to it within ", wait,
             " s");
    }
    ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
    std::FILE* file = ::fdopen(fd, "rb");
    if (!file) ::close(fd);
    return file;
}

}  // namespace

std::string ReadBounded(std::FILE* file, const std::string& what, size_t max_bytes,
                        size_t max_line) {
    std::string text;
    size_t line_start = 0;
    size_t line_number = 1;
    char chunk[1 << 16];
    for (;;) {
        const size_t n = std::fread(chunk, 1, sizeof chunk, file);
        if (n > 0) {
            if (text.size() + n > max_bytes) {
                Fail(what, " is larger than the ", Size(max_bytes), " atmos reads");
            }
            const size_t before = text.size();
            text.append(chunk, n);
            if (max_line > 0) {
                // Line by line with memchr: a line is too long when more than
                // max_line characters precede its newline (or the end so far).
                size_t at = before;
                for (;;) {
                    const void* nl = std::memchr(text.data() + at, '\n', text.size() - at);
                    const size_t stop =
                        nl ? static_cast<size_t>(static_cast<const char*>(nl) - text.data())
                           : text.size();
                    if (stop - line_start > max_line) {
                        Fail(what, ": line ", line_number, " is longer than ", max_line,
                             " characters");
                    }
                    if (!nl) break;
                    line_start = at = stop + 1;
                    ++line_number;
                }
            }
        }
        if (n < sizeof chunk) break;
    }
    if (std::ferror(file)) {
        Fail("cannot read ", what, ": ", errno != 0 ? std::strerror(errno) : "read error");
    }
    return text;
}

std::string ReadFileBounded(const std::string& path, size_t max_bytes, size_t max_line) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
        Fail("cannot read '", path, "': it is a directory");
    errno = 0;
    std::unique_ptr<std::FILE, decltype(&std::fclose)> file(OpenInput(path), &std::fclose);
    if (!file) Fail("cannot open '", path, "' for reading: ", std::strerror(errno));
    return ReadBounded(file.get(), "'" + path + "'", max_bytes, max_line);
}

void RequireRegularInput(const std::string& path, const std::string& what) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0 || S_ISREG(st.st_mode)) return;
    Fail("cannot read ", what, " '", path, "': it is not a regular file (",
         S_ISDIR(st.st_mode)    ? "a directory"
         : S_ISFIFO(st.st_mode) ? "a FIFO"
         : S_ISCHR(st.st_mode)  ? "a device"
                                : "a socket or a block device",
         ")");
}

void CheckImageDimensions(int64_t width, int64_t height, const std::string& what) {
    if (width <= 0 || height <= 0 || width > kMaxImageSide || height > kMaxImageSide ||
        width * height > kMaxImagePixels) {
        Fail(what, " claims ", width, "x", height, " pixels: atmos reads images of 1 to ",
             kMaxImageSide, " pixels a side and at most ", kMaxImagePixels, " pixels");
    }
}

}  // namespace atmos
