// atmos: NumPy .npy reading and writing (format versions 1.0, 2.0 and 3.0).
//
// File layout: the magic "\x93NUMPY", a major and a minor version byte, the
// header length (little-endian uint16 in 1.0, uint32 in 2.0 / 3.0), then the
// header: a Python dict literal with 'descr', 'fortran_order' and 'shape',
// padded with spaces and a final '\n' so the data starts on a 64-byte boundary.
#include <cctype>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "io/image_formats.h"

namespace atmos::detail {

namespace {

constexpr char kMagic[] = "\x93NUMPY";
constexpr size_t kMagicSize = 6;
constexpr size_t kAlignment = 64;

// What the header dict says.
struct NpyHeader {
    std::string descr;
    bool has_descr = false;
    bool fortran_order = false;
    bool has_fortran_order = false;
    std::vector<std::uint64_t> shape;
    bool has_shape = false;
};

// A strict little parser for the Python dict literal NumPy writes.
class HeaderParser {
  public:
    HeaderParser(const std::string& text, const std::string& path) : text_(text), path_(path) {}

    NpyHeader Parse() {
        NpyHeader header;
        Expect('{');
        for (;;) {
            SkipSpace();
            if (Peek() == '}') break;
            const std::string key = ParseString();
            Expect(':');
            if (key == "descr") {
                header.descr = ParseString();
                header.has_descr = true;
            } else if (key == "fortran_order") {
                header.fortran_order = ParseBool();
                header.has_fortran_order = true;
            } else if (key == "shape") {
                header.shape = ParseShape();
                header.has_shape = true;
            } else {
                Bad("unexpected key '" + key + "'");
            }
            SkipSpace();
            if (Peek() == ',') {
                ++pos_;
                continue;
            }
            if (Peek() != '}') Bad("expected ',' or '}'");
        }
        ++pos_;  // '}'
        SkipSpace();
        if (pos_ != text_.size()) Bad("trailing characters after the dict");
        if (!header.has_descr || !header.has_fortran_order || !header.has_shape) {
            Bad("missing 'descr', 'fortran_order' or 'shape'");
        }
        return header;
    }

  private:
    [[noreturn]] void Bad(const std::string& what) const {
        Fail("cannot read NPY '", path_, "': malformed header (", what, ") in: ", text_);
    }
    char Peek() const { return pos_ < text_.size() ? text_[pos_] : '\0'; }
    void SkipSpace() {
        while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) {
            ++pos_;
        }
    }
    void Expect(char c) {
        SkipSpace();
        if (Peek() != c) Bad(std::string("expected '") + c + "'");
        ++pos_;
    }
    std::string ParseString() {
        SkipSpace();
        const char quote = Peek();
        if (quote != '\'' && quote != '"') Bad("expected a quoted string");
        const size_t end = text_.find(quote, pos_ + 1);
        if (end == std::string::npos) Bad("unterminated string");
        std::string s = text_.substr(pos_ + 1, end - pos_ - 1);
        pos_ = end + 1;
        return s;
    }
    bool ParseBool() {
        SkipSpace();
        if (text_.compare(pos_, 4, "True") == 0) {
            pos_ += 4;
            return true;
        }
        if (text_.compare(pos_, 5, "False") == 0) {
            pos_ += 5;
            return false;
        }
        Bad("expected True or False");
    }
    std::vector<std::uint64_t> ParseShape() {
        Expect('(');
        std::vector<std::uint64_t> shape;
        for (;;) {
            SkipSpace();
            if (Peek() == ')') break;
            if (!std::isdigit(static_cast<unsigned char>(Peek()))) Bad("expected a dimension");
            std::uint64_t value = 0;
            while (std::isdigit(static_cast<unsigned char>(Peek()))) {
                value = value * 10 + static_cast<std::uint64_t>(Peek() - '0');
                if (value > (std::uint64_t{1} << 40)) Bad("dimension too large");
                ++pos_;
            }
            shape.push_back(value);
            SkipSpace();
            if (Peek() == 'L') ++pos_;  // Python 2 long suffix
            SkipSpace();
            if (Peek() == ',') {
                ++pos_;
                continue;
            }
            if (Peek() != ')') Bad("expected ',' or ')' in shape");
        }
        ++pos_;  // ')'
        return shape;
    }

    const std::string& text_;
    const std::string& path_;
    size_t pos_ = 0;
};

std::string ShapeString(const std::vector<std::uint64_t>& shape) {
    std::string s = "(";
    for (size_t i = 0; i < shape.size(); ++i) {
        s += std::to_string(shape[i]);
        if (i + 1 < shape.size() || shape.size() == 1) s += ",";
        if (i + 1 < shape.size()) s += " ";
    }
    return s + ")";
}

}  // namespace

void WriteNpyArray(const std::string& path, const std::vector<std::uint64_t>& shape,
                   const float* data) {
    std::string dict =
        "{'descr': '<f4', 'fortran_order': False, 'shape': " + ShapeString(shape) + ", }";
    // Version 1.0 unless the header would not fit its 16-bit length field.
    size_t prefix = kMagicSize + 2 + 2;
    size_t total = prefix + dict.size() + 1;  // + '\n'
    total = (total + kAlignment - 1) / kAlignment * kAlignment;
    bool version2 = total - prefix > 0xffff;
    if (version2) {
        prefix = kMagicSize + 2 + 4;
        total = (prefix + dict.size() + 1 + kAlignment - 1) / kAlignment * kAlignment;
    }
    const size_t header_len = total - prefix;
    dict.append(header_len - dict.size() - 1, ' ');
    dict.push_back('\n');

    std::string prelude(kMagic, kMagicSize);
    prelude.push_back(static_cast<char>(version2 ? 2 : 1));
    prelude.push_back(0);
    const int len_bytes = version2 ? 4 : 2;
    for (int i = 0; i < len_bytes; ++i) {
        prelude.push_back(static_cast<char>((header_len >> (8 * i)) & 0xffu));
    }
    prelude += dict;

    size_t count = 1;
    for (const std::uint64_t d : shape) count *= static_cast<size_t>(d);
    const size_t data_start = prelude.size();
    std::vector<std::uint8_t> bytes(data_start + count * 4);
    std::memcpy(bytes.data(), prelude.data(), data_start);
    for (size_t i = 0; i < count; ++i) StoreF32Le(data[i], &bytes[data_start + 4 * i]);
    WriteFileBytes(path, bytes);
}

NpyArray ReadNpyArray(const std::string& path) {
    const std::vector<std::uint8_t> bytes = ReadFileBytes(path);
    if (bytes.size() < kMagicSize + 4 || std::memcmp(bytes.data(), kMagic, kMagicSize) != 0) {
        Fail("cannot read NPY '", path, "': not a NumPy .npy file (bad magic)");
    }
    const int major = bytes[6];
    const int minor = bytes[7];
    size_t header_len = 0;
    size_t prefix = 0;
    if (major == 1) {
        header_len = size_t{bytes[8]} | (size_t{bytes[9]} << 8);
        prefix = 10;
    } else if (major == 2 || major == 3) {
        if (bytes.size() < 12) Fail("cannot read NPY '", path, "': truncated header");
        header_len = size_t{bytes[8]} | (size_t{bytes[9]} << 8) | (size_t{bytes[10]} << 16) |
                     (size_t{bytes[11]} << 24);
        prefix = 12;
    } else {
        Fail("cannot read NPY '", path, "': unsupported format version ", major, ".", minor);
    }
    if (header_len > bytes.size() - prefix) {
        Fail("cannot read NPY '", path, "': truncated header (", header_len, " bytes announced, ",
             bytes.size() - prefix, " present)");
    }
    const std::string text(reinterpret_cast<const char*>(bytes.data()) + prefix, header_len);
    const NpyHeader header = HeaderParser(text, path).Parse();

    size_t item_size = 0;
    if (header.descr == "<f4") {
        item_size = 4;
    } else if (header.descr == "<f8") {
        item_size = 8;
    } else {
        Fail("cannot read NPY '", path, "': unsupported dtype '", header.descr,
             "' (expected little-endian float32 '<f4' or float64 '<f8')");
    }
    if (header.fortran_order) {
        Fail("cannot read NPY '", path, "': Fortran-order arrays are not supported");
    }
    std::uint64_t count = 1;
    for (const std::uint64_t d : header.shape) {
        if (d > 0 && count > (std::uint64_t{1} << 36) / d) {
            Fail("cannot read NPY '", path, "': unsupported size ", ShapeString(header.shape));
        }
        count *= d;
    }
    const std::uint64_t data_bytes = count * item_size;
    const std::uint64_t available = bytes.size() - prefix - header_len;
    if (available < data_bytes) {
        Fail("cannot read NPY '", path, "': truncated data (", available, " bytes of ", data_bytes,
             " for shape ", ShapeString(header.shape), ")");
    }
    if (available > data_bytes) {
        Fail("cannot read NPY '", path, "': ", available - data_bytes,
             " unexpected bytes after the array data");
    }
    NpyArray array;
    array.shape = header.shape;
    array.values.resize(static_cast<size_t>(count));
    const std::uint8_t* src = bytes.data() + prefix + header_len;
    for (size_t i = 0; i < array.values.size(); ++i) {
        const std::uint8_t* q = src + i * item_size;
        array.values[i] = item_size == 4 ? static_cast<double>(LoadF32(q, true)) : LoadF64(q, true);
    }
    return array;
}

std::string NpyShapeString(const std::vector<std::uint64_t>& shape) { return ShapeString(shape); }

void WriteNpy(const Image& image, const std::string& path) {
    WriteNpyArray(
        path,
        {static_cast<std::uint64_t>(image.height()), static_cast<std::uint64_t>(image.width()), 3},
        image.data());
}

Image ReadNpy(const std::string& path) {
    const NpyArray array = ReadNpyArray(path);
    const std::vector<std::uint64_t>& shape = array.shape;
    std::uint64_t channels = 0;
    if (shape.size() == 2) {
        channels = 1;
    } else if (shape.size() == 3 && (shape[2] == 1 || shape[2] == 3 || shape[2] == 4)) {
        channels = shape[2];
    } else {
        Fail("cannot read NPY '", path, "': unsupported shape ", ShapeString(shape),
             " (expected (H, W, 3), (H, W, 4), (H, W, 1) or (H, W))");
    }
    const std::uint64_t height = shape[0];
    const std::uint64_t width = shape[1];
    if (height == 0 || width == 0 || height > 0x7fffffff || width > 0x7fffffff ||
        height * width > (std::uint64_t{1} << 34)) {
        Fail("cannot read NPY '", path, "': unsupported image size ", ShapeString(shape));
    }
    Image image(static_cast<int>(width), static_cast<int>(height));
    float* out = image.data();
    const size_t pixels = static_cast<size_t>(width * height);
    for (size_t p = 0; p < pixels; ++p) {
        for (size_t c = 0; c < 3; ++c) {
            const size_t k = c < channels ? c : 0;  // grey: replicate channel 0
            out[3 * p + c] = static_cast<float>(array.values[p * channels + k]);
        }
    }
    return image;
}

}  // namespace atmos::detail
