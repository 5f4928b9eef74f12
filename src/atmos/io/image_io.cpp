// atmos: image format dispatch, the PNG display transform and shared file helpers.
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>

#include "atmos/error.h"
#include "atmos/image.h"
#include "io/bounded_read.h"
#include "io/image_formats.h"
#include "io/output_path.h"

namespace atmos {

namespace {

// Exact sRGB transfer function (IEC 61966-2-1) from linear [0, 1] to encoded [0, 1].
double SrgbEncode(double t) {
    if (t < 0.0031308) return 12.92 * t;
    return 1.055 * std::pow(t, 1.0 / 2.4) - 0.055;
}

struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

}  // namespace

unsigned char EncodeDisplayValue(float linear, float exposure) {
    const double x = static_cast<double>(linear) * static_cast<double>(exposure);
    if (!(x > 0.0)) return 0;  // zero, negative and NaN
    // t(x) = 1 - exp(-x), computed as -expm1(-x) to keep precision for small x;
    // x = +inf gives exactly 1.
    const double t = -std::expm1(-x);
    const double encoded = SrgbEncode(t) * 255.0 + 0.5;
    if (!(encoded > 0.0)) return 0;
    if (encoded >= 255.0) return 255;
    return static_cast<unsigned char>(encoded);
}

ImageFormat ImageFormatFromPath(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".exr") return ImageFormat::kExr;
    if (ext == ".png") return ImageFormat::kPng;
    if (ext == ".npy") return ImageFormat::kNpy;
    if (ext == ".pfm") return ImageFormat::kPfm;
    if (ext.empty()) {
        Fail("cannot tell the image format of '", path,
             "': no file extension (allowed: .exr .png .npy .pfm)");
    }
    Fail("cannot tell the image format of '", path, "': unknown extension '",
         std::filesystem::path(path).extension().string(), "' (allowed: .exr .png .npy .pfm)");
}

void WriteImage(const Image& image, const std::string& path, float exposure) {
    const ImageFormat format = ImageFormatFromPath(path);
    if (image.empty() || image.width() <= 0 || image.height() <= 0) {
        Fail("cannot write '", path, "': the image is empty (", image.width(), "x", image.height(),
             ")");
    }
    if (image.size() != static_cast<size_t>(image.width()) * image.height() * 3) {
        Fail("cannot write '", path, "': the image holds ", image.size(), " floats, expected ",
             image.width(), "x", image.height(), "x3");
    }
    // Every format through a temporary file beside the target and one rename:
    // a failed write (a full disk) leaves no truncated file under `path`.
    WriteThroughTemporary(path, [&](const std::string& temporary) {
        switch (format) {
            case ImageFormat::kExr:
                detail::WriteExr(image, temporary);
                break;
            case ImageFormat::kPng:
                detail::WritePng(image, temporary, exposure);
                break;
            case ImageFormat::kNpy:
                detail::WriteNpy(image, temporary);
                break;
            case ImageFormat::kPfm:
                detail::WritePfm(image, temporary);
                break;
        }
    });
}

Image ReadImage(const std::string& path) {
    switch (ImageFormatFromPath(path)) {
        case ImageFormat::kExr:
            return detail::ReadExr(path);
        case ImageFormat::kPng:
            return detail::ReadPng(path);
        case ImageFormat::kNpy:
            return detail::ReadNpy(path);
        case ImageFormat::kPfm:
            return detail::ReadPfm(path);
    }
    Fail("cannot read '", path, "': unsupported image format");
}

namespace detail {

std::vector<std::uint8_t> ReadFileBytes(const std::string& path) {
    // Bounded (io/bounded_read.h): /dev/zero or an endless FIFO is one error.
    const std::string text = ReadFileBounded(path, kMaxImageFileBytes);
    return std::vector<std::uint8_t>(text.begin(), text.end());
}

void WriteFileBytes(const std::string& path, const std::vector<std::uint8_t>& bytes) {
    errno = 0;
    FilePtr file(std::fopen(path.c_str(), "wb"));
    if (!file) Fail("cannot open '", path, "' for writing: ", std::strerror(errno));
    if (!bytes.empty() && std::fwrite(bytes.data(), 1, bytes.size(), file.get()) != bytes.size()) {
        Fail("cannot write '", path, "': ", errno != 0 ? std::strerror(errno) : "write error");
    }
    std::FILE* raw = file.release();
    errno = 0;
    if (std::fclose(raw) != 0) {
        Fail("cannot write '", path, "': ", errno != 0 ? std::strerror(errno) : "close error");
    }
}

float LoadF32(const std::uint8_t* p, bool little_endian) {
    std::uint32_t u = 0;
    for (int i = 0; i < 4; ++i) {
        const std::uint32_t b = p[little_endian ? i : 3 - i];
        u |= b << (8 * i);
    }
    float value;
    std::memcpy(&value, &u, sizeof(value));
    return value;
}

double LoadF64(const std::uint8_t* p, bool little_endian) {
    std::uint64_t u = 0;
    for (int i = 0; i < 8; ++i) {
        const std::uint64_t b = p[little_endian ? i : 7 - i];
        u |= b << (8 * i);
    }
    double value;
    std::memcpy(&value, &u, sizeof(value));
    return value;
}

void StoreF32Le(float value, std::uint8_t* p) {
    std::uint32_t u;
    std::memcpy(&u, &value, sizeof(u));
    for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>((u >> (8 * i)) & 0xffu);
}

}  // namespace detail

}  // namespace atmos
