// atmos: portable float map (.pfm) reading and writing.
//
// Layout: "PF" (RGB) or "Pf" (grey), whitespace, width, whitespace, height,
// whitespace, a scale whose sign gives the byte order (negative: little-endian),
// one whitespace character, then float32 samples with rows bottom to top.
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "atmos/number.h"
#include "io/image_formats.h"

namespace atmos::detail {

namespace {

bool IsSpace(std::uint8_t c) { return std::isspace(c) != 0; }

// Reads one whitespace-delimited header token starting at `*pos` (after any
// whitespace), leaving `*pos` on the whitespace that ends it.
std::string NextToken(const std::vector<std::uint8_t>& bytes, size_t* pos,
                      const std::string& path) {
    size_t p = *pos;
    while (p < bytes.size() && IsSpace(bytes[p])) ++p;
    const size_t start = p;
    while (p < bytes.size() && !IsSpace(bytes[p]) && p - start < 64) ++p;
    if (p == start || p >= bytes.size() || !IsSpace(bytes[p])) {
        Fail("cannot read PFM '", path, "': malformed or truncated header");
    }
    *pos = p;
    return std::string(bytes.begin() + static_cast<std::ptrdiff_t>(start),
                       bytes.begin() + static_cast<std::ptrdiff_t>(p));
}

int ParseDimension(const std::string& token, const std::string& path, const char* what) {
    if (token.empty() || token.size() > 9) {
        Fail("cannot read PFM '", path, "': invalid ", what, " '", token, "'");
    }
    int value = 0;
    for (char c : token) {
        if (c < '0' || c > '9')
            Fail("cannot read PFM '", path, "': invalid ", what, " '", token, "'");
        value = value * 10 + (c - '0');
    }
    if (value <= 0) Fail("cannot read PFM '", path, "': invalid ", what, " '", token, "'");
    return value;
}

}  // namespace

void WritePfm(const Image& image, const std::string& path) {
    const int width = image.width();
    const int height = image.height();
    const std::string header =
        "PF\n" + std::to_string(width) + " " + std::to_string(height) + "\n-1.0\n";
    std::vector<std::uint8_t> bytes(header.begin(), header.end());
    const size_t data_start = bytes.size();
    const size_t row_floats = static_cast<size_t>(width) * 3;
    bytes.resize(data_start + image.size() * 4);
    std::uint8_t* dst = bytes.data() + data_start;
    for (int y = height - 1; y >= 0; --y) {  // bottom row first
        const float* row = image.data() + static_cast<size_t>(y) * row_floats;
        for (size_t i = 0; i < row_floats; ++i, dst += 4) StoreF32Le(row[i], dst);
    }
    WriteFileBytes(path, bytes);
}

Image ReadPfm(const std::string& path) {
    const std::vector<std::uint8_t> bytes = ReadFileBytes(path);
    size_t pos = 0;
    const std::string magic = NextToken(bytes, &pos, path);
    int channels = 0;
    if (magic == "PF") {
        channels = 3;
    } else if (magic == "Pf") {
        channels = 1;
    } else {
        Fail("cannot read PFM '", path, "': not a PFM file (expected 'PF' or 'Pf')");
    }
    const int width = ParseDimension(NextToken(bytes, &pos, path), path, "width");
    const int height = ParseDimension(NextToken(bytes, &pos, path), path, "height");
    const std::string scale_token = NextToken(bytes, &pos, path);
    double scale = 0.0;
    if (ParseNumber(scale_token, &scale) != NumberError::kNone || scale == 0.0) {
        Fail("cannot read PFM '", path, "': invalid scale '", scale_token, "'");
    }
    const bool little_endian = scale < 0.0;
    ++pos;  // the single whitespace character that ends the header

    const std::uint64_t samples = std::uint64_t{static_cast<std::uint32_t>(width)} *
                                  static_cast<std::uint32_t>(height) *
                                  static_cast<std::uint32_t>(channels);
    const std::uint64_t available = bytes.size() - pos;
    if (available < samples * 4) {
        Fail("cannot read PFM '", path, "': truncated data (", available, " bytes of ", samples * 4,
             " for ", width, "x", height, ")");
    }

    Image image(width, height);
    const size_t row_samples = static_cast<size_t>(width) * static_cast<size_t>(channels);
    const std::uint8_t* src = bytes.data() + pos;
    for (int file_row = 0; file_row < height; ++file_row) {
        const int y = height - 1 - file_row;  // file rows run bottom to top
        float* out = image.data() + static_cast<size_t>(y) * width * 3;
        for (int x = 0; x < width; ++x) {
            for (int c = 0; c < 3; ++c) {
                const int k = channels == 3 ? c : 0;
                const size_t i = static_cast<size_t>(file_row) * row_samples +
                                 static_cast<size_t>(x) * channels + k;
                out[3 * x + c] = LoadF32(src + 4 * i, little_endian);
            }
        }
    }
    return image;
}

}  // namespace atmos::detail
