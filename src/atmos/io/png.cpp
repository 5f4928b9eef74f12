// atmos: PNG reading (libpng, exact sRGB decode) and writing (display transform).
#include <png.h>

#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "io/bounded_read.h"
#include "io/image_formats.h"

namespace atmos::detail {

namespace {

// Exact inverse of the sRGB transfer function, encoded [0, 1] -> linear [0, 1].
float SrgbDecode(double v) {
    const double linear = v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
    return static_cast<float>(linear);
}

struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

// Where libpng's error callback leaves its message before it longjmps.
struct PngErrorState {
    char message[256];
};

void OnPngError(png_structp png, png_const_charp message) {
    auto* state = static_cast<PngErrorState*>(png_get_error_ptr(png));
    if (state != nullptr) {
        std::snprintf(state->message, sizeof(state->message), "%s",
                      message != nullptr ? message : "libpng error");
    }
    png_longjmp(png, 1);
}

void OnPngWarning(png_structp, png_const_charp) {}

// The decoded samples: `channels` (1 or 3) samples per pixel, 8- or 16-bit
// (16-bit big-endian as stored), rows top first.
struct PngPixels {
    std::uint32_t width = 0;
    std::uint32_t height = 0;
    int channels = 0;
    int bit_depth = 0;
    size_t row_bytes = 0;
    std::vector<std::uint8_t> data;
    std::vector<png_bytep> rows;
};

constexpr std::uint64_t kMaxPngBytes = std::uint64_t{1} << 32;

// Decodes the rest of a PNG file (its 8-byte signature already read) into
// `out`. Returns false with `error->message` set on failure. libpng reports
// errors by longjmp to the setjmp below, so this function keeps no automatic
// objects with non-trivial destructors; everything it fills lives in `out`.
bool DecodePng(std::FILE* file, PngPixels* out, PngErrorState* error) {
    png_structp png =
        png_create_read_struct(PNG_LIBPNG_VER_STRING, error, OnPngError, OnPngWarning);
    if (png == nullptr) {
        std::snprintf(error->message, sizeof(error->message), "%s", "out of memory");
        return false;
    }
    png_infop info = png_create_info_struct(png);
    if (info == nullptr) {
        png_destroy_read_struct(&png, nullptr, nullptr);
        std::snprintf(error->message, sizeof(error->message), "%s", "out of memory");
        return false;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_read_struct(&png, &info, nullptr);
        return false;
    }

    png_init_io(png, file);
    png_set_sig_bytes(png, 8);
    png_read_info(png, info);

    const int color_type = png_get_color_type(png, info);
    const int file_bit_depth = png_get_bit_depth(png, info);
    if (color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
    if (color_type == PNG_COLOR_TYPE_GRAY && file_bit_depth < 8) {
        png_set_expand_gray_1_2_4_to_8(png);
    }
    if ((color_type & PNG_COLOR_MASK_ALPHA) != 0) png_set_strip_alpha(png);
    png_set_interlace_handling(png);
    png_read_update_info(png, info);

    out->width = png_get_image_width(png, info);
    out->height = png_get_image_height(png, info);
    out->channels = png_get_channels(png, info);
    out->bit_depth = png_get_bit_depth(png, info);
    out->row_bytes = png_get_rowbytes(png, info);
    if ((out->channels != 1 && out->channels != 3) ||
        (out->bit_depth != 8 && out->bit_depth != 16)) {
        png_error(png, "unsupported PNG pixel layout after conversion");
    }
    if (out->width == 0 || out->height == 0 ||
        static_cast<std::uint64_t>(out->row_bytes) * out->height > kMaxPngBytes) {
        png_error(png, "PNG image size is out of range");
    }

    bool allocated = true;
    try {
        out->data.resize(out->row_bytes * out->height);
        out->rows.resize(out->height);
    } catch (const std::bad_alloc&) {
        allocated = false;
    }
    if (!allocated) png_error(png, "out of memory");
    for (std::uint32_t y = 0; y < out->height; ++y) {
        out->rows[y] = out->data.data() + static_cast<size_t>(y) * out->row_bytes;
    }
    png_read_image(png, out->rows.data());
    png_read_end(png, nullptr);
    png_destroy_read_struct(&png, &info, nullptr);
    return true;
}

}  // namespace

void WritePng(const Image& image, const std::string& path, float exposure) {
    std::vector<std::uint8_t> bytes(image.size());
    const float* src = image.data();
    for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = EncodeDisplayValue(src[i], exposure);
    WritePngBytes(bytes, image.width(), image.height(), path);
}

void WritePngBytes(const std::vector<std::uint8_t>& bytes, int width, int height,
                   const std::string& path) {
    if (bytes.size() != static_cast<size_t>(width) * height * 3) {
        Fail("cannot write PNG '", path, "': wrong number of bytes");
    }
    png_image png;
    std::memset(&png, 0, sizeof(png));
    png.version = PNG_IMAGE_VERSION;
    png.width = static_cast<png_uint_32>(width);
    png.height = static_cast<png_uint_32>(height);
    png.format = PNG_FORMAT_RGB;  // 8-bit sRGB-encoded RGB
    // Encoded in memory and written by WriteFileBytes (each write and the
    // close checked): a failure names its reason (a full disk), not libpng's
    // "Write Error".
    png_alloc_size_t size = 0;
    int ok = png_image_write_get_memory_size(png, size, 0, bytes.data(), 0, nullptr);
    std::vector<std::uint8_t> encoded(ok != 0 ? size : 0);
    if (ok != 0)
        ok = png_image_write_to_memory(&png, encoded.data(), &size, 0, bytes.data(), 0, nullptr);
    const std::string message = png.message;
    png_image_free(&png);
    if (ok == 0) Fail("cannot write PNG '", path, "': ", message);
    encoded.resize(size);
    WriteFileBytes(path, encoded);
}

Image ReadPng(const std::string& path) {
    RequireRegularInput(path, "PNG");  // a FIFO no one writes would block the open
    errno = 0;
    FilePtr file(std::fopen(path.c_str(), "rb"));
    if (!file) Fail("cannot open '", path, "' for reading: ", std::strerror(errno));
    png_byte signature[8] = {};
    if (std::fread(signature, 1, sizeof(signature), file.get()) != sizeof(signature) ||
        png_sig_cmp(signature, 0, sizeof(signature)) != 0) {
        Fail("cannot read PNG '", path, "': not a PNG file (bad signature)");
    }
    // The size its header (IHDR, the first chunk) claims, before anything is
    // read or allocated for it (io/bounded_read.h: a 33-byte file claiming
    // 20000x20000 cost 6 GB).
    {
        png_byte ihdr[16] = {};
        if (std::fread(ihdr, 1, sizeof ihdr, file.get()) != sizeof ihdr ||
            std::memcmp(ihdr + 4, "IHDR", 4) != 0) {
            Fail("cannot read PNG '", path, "': no IHDR chunk first");
        }
        CheckImageDimensions(png_get_uint_32(ihdr + 8), png_get_uint_32(ihdr + 12),
                             "PNG '" + path + "'");
        if (std::fseek(file.get(), sizeof(signature), SEEK_SET) != 0) {
            Fail("cannot read PNG '", path, "': ", std::strerror(errno));
        }
    }

    PngPixels pixels;
    PngErrorState error = {};
    if (!DecodePng(file.get(), &pixels, &error)) {
        Fail("cannot read PNG '", path, "': ", error.message);
    }
    if (pixels.width > 0x7fffffffu || pixels.height > 0x7fffffffu) {
        Fail("cannot read PNG '", path, "': image too large");
    }

    Image image(static_cast<int>(pixels.width), static_cast<int>(pixels.height));
    float table[256];
    for (int i = 0; i < 256; ++i) table[i] = SrgbDecode(i / 255.0);
    float* out = image.data();
    const int channels = pixels.channels;
    for (std::uint32_t y = 0; y < pixels.height; ++y) {
        const std::uint8_t* row = pixels.rows[y];
        for (std::uint32_t x = 0; x < pixels.width; ++x) {
            float rgb[3] = {0.0f, 0.0f, 0.0f};
            for (int c = 0; c < channels; ++c) {
                const size_t i = static_cast<size_t>(x) * channels + c;
                if (pixels.bit_depth == 8) {
                    rgb[c] = table[row[i]];
                } else {
                    const unsigned v = (unsigned{row[2 * i]} << 8) | row[2 * i + 1];
                    rgb[c] = SrgbDecode(v / 65535.0);
                }
            }
            if (channels == 1) rgb[1] = rgb[2] = rgb[0];
            *out++ = rgb[0];
            *out++ = rgb[1];
            *out++ = rgb[2];
        }
    }
    return image;
}

}  // namespace atmos::detail
