// atmos: inputs read with bounds (see bounded_read.h).
#include "io/bounded_read.h"

#include <cerrno>
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
    std::unique_ptr<std::FILE, decltype(&std::fclose)> file(std::fopen(path.c_str(), "rb"),
                                                            &std::fclose);
    if (!file) Fail("cannot open '", path, "' for reading: ", std::strerror(errno));
    return ReadBounded(file.get(), "'" + path + "'", max_bytes, max_line);
}

void CheckImageDimensions(int64_t width, int64_t height, const std::string& what) {
    if (width <= 0 || height <= 0 || width > kMaxImageSide || height > kMaxImageSide ||
        width * height > kMaxImagePixels) {
        Fail(what, " claims ", width, "x", height, " pixels: atmos reads images of 1 to ",
             kMaxImageSide, " pixels a side and at most ", kMaxImagePixels, " pixels");
    }
}

}  // namespace atmos
