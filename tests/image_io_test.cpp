// Tests of image I/O: EXR, PNG, NPY and PFM round trips, the display transform
// and error reporting.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "atmos/image.h"

namespace {

namespace fs = std::filesystem;
using atmos::Image;

fs::path TestDir() {
    const char* env = std::getenv("ATMOS_TEST_TMP");
    fs::path dir =
        (env != nullptr && *env != '\0') ? fs::path(env) : fs::temp_directory_path() / "atmos_test";
    fs::create_directories(dir);
    return dir;
}

// A file name unique to the running test.
std::string TempPath(const std::string& suffix) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    const std::string name =
        std::string("image_io_") + info->test_suite_name() + "_" + info->name() + suffix;
    return (TestDir() / name).string();
}

std::vector<std::uint8_t> ReadBytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), {});
}

void WriteBytes(const std::string& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// 7 x 5 with zeros, tiny, denormal, negative and large values, distinct per
// pixel and channel.
Image MakeTestImage(int width = 7, int height = 5) {
    Image image(width, height);
    float* p = image.data();
    for (size_t i = 0; i < image.size(); ++i) {
        p[i] = 0.001f * static_cast<float>(i * i) + 0.37f * static_cast<float>(i % 7);
    }
    const float special[] = {0.0f,        1e-30f, 1e6f,   std::numeric_limits<float>::denorm_min(),
                             123456.789f, -2.5f,  3.0e-8f};
    for (size_t i = 0; i < std::size(special) && i < image.size(); ++i) p[i] = special[i];
    p[image.size() - 1] = 1e6f;
    return image;
}

void ExpectBitExact(const Image& expected, const Image& actual) {
    ASSERT_EQ(expected.width(), actual.width());
    ASSERT_EQ(expected.height(), actual.height());
    ASSERT_EQ(expected.size(), actual.size());
    for (size_t i = 0; i < expected.size(); ++i) {
        std::uint32_t a;
        std::uint32_t b;
        std::memcpy(&a, expected.data() + i, 4);
        std::memcpy(&b, actual.data() + i, 4);
        ASSERT_EQ(a, b) << "float " << i << ": " << expected.data()[i] << " vs "
                        << actual.data()[i];
    }
}

void ExpectRoundTrip(const std::string& suffix) {
    const Image image = MakeTestImage();
    const std::string path = TempPath(suffix);
    atmos::WriteImage(image, path);
    ExpectBitExact(image, atmos::ReadImage(path));
}

// Inverse of the exact sRGB transfer function.
double SrgbDecode(double v) {
    return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}
double SrgbEncode(double t) {
    return t < 0.0031308 ? 12.92 * t : 1.055 * std::pow(t, 1.0 / 2.4) - 0.055;
}

// A minimal NPY v1.0 file with the given header dict and payload.
std::string MakeNpy(const std::string& dict, const std::string& payload) {
    std::string header = dict;
    const size_t total = (10 + header.size() + 1 + 63) / 64 * 64;
    header.append(total - 10 - header.size() - 1, ' ');
    header.push_back('\n');
    std::string bytes = "\x93NUMPY";
    bytes.push_back('\x01');
    bytes.push_back('\x00');
    bytes.push_back(static_cast<char>(header.size() & 0xff));
    bytes.push_back(static_cast<char>(header.size() >> 8));
    return bytes + header + payload;
}

std::string FloatBytesLe(const std::vector<float>& values) {
    std::string s;
    for (float v : values) {
        std::uint32_t u;
        std::memcpy(&u, &v, 4);
        for (int i = 0; i < 4; ++i) s.push_back(static_cast<char>((u >> (8 * i)) & 0xff));
    }
    return s;
}

std::string FloatBytesBe(const std::vector<float>& values) {
    std::string s;
    for (float v : values) {
        std::uint32_t u;
        std::memcpy(&u, &v, 4);
        for (int i = 3; i >= 0; --i) s.push_back(static_cast<char>((u >> (8 * i)) & 0xff));
    }
    return s;
}

TEST(ImageIoTest, FormatFromPathIsCaseInsensitive) {
    EXPECT_EQ(atmos::ImageFormatFromPath("a/b.exr"), atmos::ImageFormat::kExr);
    EXPECT_EQ(atmos::ImageFormatFromPath("x.PNG"), atmos::ImageFormat::kPng);
    EXPECT_EQ(atmos::ImageFormatFromPath("dir.png/x.Npy"), atmos::ImageFormat::kNpy);
    EXPECT_EQ(atmos::ImageFormatFromPath("out.pFm"), atmos::ImageFormat::kPfm);
}

TEST(ImageIoTest, UnknownExtensionThrowsNamingPathAndAllowedExtensions) {
    try {
        atmos::ImageFormatFromPath("render.tiff");
        FAIL() << "expected atmos::Error";
    } catch (const atmos::Error& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("render.tiff"), std::string::npos) << message;
        for (const char* ext : {".exr", ".png", ".npy", ".pfm"}) {
            EXPECT_NE(message.find(ext), std::string::npos) << message;
        }
    }
    EXPECT_THROW(atmos::ImageFormatFromPath("noextension"), atmos::Error);
    EXPECT_THROW(atmos::WriteImage(MakeTestImage(), TempPath(".jpg")), atmos::Error);
    EXPECT_THROW(atmos::ReadImage(TempPath(".bmp")), atmos::Error);
}

TEST(ImageIoTest, MissingFileThrows) {
    for (const char* ext : {".exr", ".png", ".npy", ".pfm"}) {
        const std::string path = TempPath(std::string("_does_not_exist") + ext);
        fs::remove(path);
        EXPECT_THROW(atmos::ReadImage(path), atmos::Error) << ext;
    }
}

TEST(ImageIoTest, WriteToUnwritablePathThrows) {
    const std::string dir = TempPath("_no_such_dir");
    fs::remove_all(dir);
    for (const char* ext : {".exr", ".png", ".npy", ".pfm"}) {
        EXPECT_THROW(atmos::WriteImage(MakeTestImage(), dir + "/x" + ext), atmos::Error) << ext;
    }
}

TEST(ImageIoTest, WriteEmptyImageThrows) {
    EXPECT_THROW(atmos::WriteImage(Image(), TempPath(".npy")), atmos::Error);
}

TEST(ImageIoTest, ExrRoundTripIsBitExact) { ExpectRoundTrip(".exr"); }
TEST(ImageIoTest, NpyRoundTripIsBitExact) { ExpectRoundTrip(".npy"); }
TEST(ImageIoTest, PfmRoundTripIsBitExact) { ExpectRoundTrip(".pfm"); }

TEST(ImageIoTest, RoundTripsOneByOneAndWideImages) {
    for (const char* ext : {".exr", ".npy", ".pfm"}) {
        for (const auto& size : {std::pair<int, int>{1, 1}, {13, 2}, {2, 11}}) {
            const Image image = MakeTestImage(size.first, size.second);
            const std::string path = TempPath(std::to_string(size.first) + ext);
            atmos::WriteImage(image, path);
            ExpectBitExact(image, atmos::ReadImage(path));
        }
    }
}

TEST(ImageIoTest, UppercaseExtensionRoundTrips) { ExpectRoundTrip(".NPY"); }

TEST(ImageIoTest, PngRoundTripMatchesToneMappedValues) {
    Image image(7, 5);
    for (int y = 0; y < 5; ++y) {
        for (int x = 0; x < 7; ++x) {
            image.Set(x, y,
                      {0.05f * static_cast<float>(x * 5 + y), 0.3f * static_cast<float>(y),
                       x == 0 ? 0.0f : 1e6f / static_cast<float>(x)});
        }
    }
    const float exposure = 1.5f;
    const std::string path = TempPath(".png");
    atmos::WriteImage(image, path, exposure);
    const Image back = atmos::ReadImage(path);
    ASSERT_EQ(back.width(), 7);
    ASSERT_EQ(back.height(), 5);
    for (size_t i = 0; i < image.size(); ++i) {
        const double x = static_cast<double>(image.data()[i]) * static_cast<double>(exposure);
        const double encoded = SrgbEncode(1.0 - std::exp(-x));
        const double decoded_back = SrgbEncode(static_cast<double>(back.data()[i]));
        EXPECT_NEAR(decoded_back, encoded, 1.0 / 255.0) << i;
        // The decoded value is the exact sRGB decode of the stored byte.
        const double byte = atmos::EncodeDisplayValue(image.data()[i], exposure);
        EXPECT_NEAR(static_cast<double>(back.data()[i]), SrgbDecode(byte / 255.0), 1e-6) << i;
    }
    EXPECT_EQ(back.data()[2 * 0 + 2], 0.0f);  // pixel (0, 0) blue is 0 -> 0
    EXPECT_EQ(back.data()[2 + 3], 1.0f);      // pixel (1, 0) blue is huge -> 255 -> 1
}

TEST(ImageIoTest, EncodeDisplayValue) {
    EXPECT_EQ(atmos::EncodeDisplayValue(0.0f, 1.0f), 0);
    EXPECT_EQ(atmos::EncodeDisplayValue(-1.0f, 1.0f), 0);
    EXPECT_EQ(atmos::EncodeDisplayValue(std::nanf(""), 1.0f), 0);
    EXPECT_EQ(atmos::EncodeDisplayValue(1e30f, 1.0f), 255);
    EXPECT_EQ(atmos::EncodeDisplayValue(std::numeric_limits<float>::infinity(), 1.0f), 255);
    EXPECT_EQ(atmos::EncodeDisplayValue(100.0f, 1.0f), 255);
    // x = ln 2 -> t = 0.5 -> sRGB(0.5) = 0.73536 -> 187.52 -> 188.
    EXPECT_EQ(atmos::EncodeDisplayValue(std::log(2.0f), 1.0f), 188);
    EXPECT_EQ(atmos::EncodeDisplayValue(0.5f * std::log(2.0f), 2.0f), 188);
    EXPECT_EQ(atmos::EncodeDisplayValue(1.0f, 0.0f), 0);
    // Monotonic over a wide range.
    int previous = 0;
    for (int i = 0; i <= 4000; ++i) {
        const float x = std::pow(10.0f, -6.0f + 0.0025f * static_cast<float>(i));
        const int v = atmos::EncodeDisplayValue(x, 1.0f);
        EXPECT_GE(v, previous) << x;
        previous = v;
    }
    EXPECT_EQ(previous, 255);
    // Matches the formula everywhere in a sweep.
    for (int i = 0; i <= 1000; ++i) {
        const float x = 0.005f * static_cast<float>(i);
        const double expected = SrgbEncode(1.0 - std::exp(-static_cast<double>(x))) * 255.0;
        EXPECT_EQ(atmos::EncodeDisplayValue(x, 1.0f), static_cast<int>(std::lround(expected))) << x;
    }
}

TEST(ImageIoTest, NpyHeaderIsPaddedTo64Bytes) {
    const std::string path = TempPath(".npy");
    atmos::WriteImage(MakeTestImage(), path);
    const std::vector<std::uint8_t> bytes = ReadBytes(path);
    ASSERT_GE(bytes.size(), 10u);
    EXPECT_EQ(std::string(bytes.begin(), bytes.begin() + 6), "\x93NUMPY");
    EXPECT_EQ(bytes[6], 1);
    EXPECT_EQ(bytes[7], 0);
    const size_t header_len = bytes[8] | (size_t{bytes[9]} << 8);
    const size_t data_start = 10 + header_len;
    EXPECT_EQ(data_start % 64, 0u);
    EXPECT_EQ(bytes.size(), data_start + 7 * 5 * 3 * 4);
    const std::string header(bytes.begin() + 10, bytes.begin() + static_cast<long>(data_start));
    EXPECT_EQ(header.back(), '\n');
    EXPECT_NE(header.find("'descr': '<f4'"), std::string::npos) << header;
    EXPECT_NE(header.find("'fortran_order': False"), std::string::npos) << header;
    EXPECT_NE(header.find("'shape': (5, 7, 3)"), std::string::npos) << header;
    EXPECT_EQ(header.find_first_not_of(' ', header.find('}') + 1), header.size() - 1);
}

TEST(ImageIoTest, NpyReadsGreyAlphaAndFloat64) {
    // (H, W) grey float32, 2 x 3.
    const std::string grey_path = TempPath("_grey.npy");
    WriteBytes(grey_path, MakeNpy("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }",
                                  FloatBytesLe({1, 2, 3, 4, 5, 6})));
    const Image grey = atmos::ReadImage(grey_path);
    ASSERT_EQ(grey.width(), 3);
    ASSERT_EQ(grey.height(), 2);
    EXPECT_EQ(grey.Get(2, 1).x, 6.0f);
    EXPECT_EQ(grey.Get(2, 1).y, 6.0f);
    EXPECT_EQ(grey.Get(2, 1).z, 6.0f);
    EXPECT_EQ(grey.Get(0, 1).x, 4.0f);

    // (H, W, 4): alpha dropped.
    const std::string rgba_path = TempPath("_rgba.npy");
    WriteBytes(rgba_path, MakeNpy("{'descr': '<f4', 'fortran_order': False, 'shape': (1, 2, 4), }",
                                  FloatBytesLe({1, 2, 3, 9, 5, 6, 7, 9})));
    const Image rgba = atmos::ReadImage(rgba_path);
    ASSERT_EQ(rgba.width(), 2);
    ASSERT_EQ(rgba.height(), 1);
    EXPECT_EQ(rgba.Get(1, 0).x, 5.0f);
    EXPECT_EQ(rgba.Get(1, 0).z, 7.0f);

    // '<f8', keys in another order, double quotes.
    std::string payload;
    for (double v : {0.25, 1e6, -3.5}) {
        std::uint64_t u;
        std::memcpy(&u, &v, 8);
        for (int i = 0; i < 8; ++i) payload.push_back(static_cast<char>((u >> (8 * i)) & 0xff));
    }
    const std::string f8_path = TempPath("_f8.npy");
    WriteBytes(f8_path, MakeNpy("{\"shape\": (1, 1, 3), \"fortran_order\": False, \"descr\": "
                                "\"<f8\"}",
                                payload));
    const Image f8 = atmos::ReadImage(f8_path);
    ASSERT_EQ(f8.width(), 1);
    EXPECT_EQ(f8.Get(0, 0).x, 0.25f);
    EXPECT_EQ(f8.Get(0, 0).y, 1e6f);
    EXPECT_EQ(f8.Get(0, 0).z, -3.5f);
}

TEST(ImageIoTest, TruncatedNpyThrows) {
    const std::string good = TempPath("_good.npy");
    atmos::WriteImage(MakeTestImage(), good);
    std::vector<std::uint8_t> bytes = ReadBytes(good);
    const std::string path = TempPath(".npy");
    for (size_t keep : {size_t{5}, size_t{40}, bytes.size() - 1, bytes.size() - 200}) {
        WriteBytes(path, std::string(bytes.begin(), bytes.begin() + static_cast<long>(keep)));
        EXPECT_THROW(atmos::ReadImage(path), atmos::Error) << keep;
    }
}

TEST(ImageIoTest, UnsupportedNpyThrows) {
    const std::string path = TempPath(".npy");
    const std::string payload = FloatBytesLe({1, 2, 3, 4, 5, 6});
    const char* dicts[] = {
        "{'descr': '<i4', 'fortran_order': False, 'shape': (1, 2, 3), }",
        "{'descr': '>f4', 'fortran_order': False, 'shape': (1, 2, 3), }",
        "{'descr': '<f4', 'fortran_order': True, 'shape': (1, 2, 3), }",
        "{'descr': '<f4', 'fortran_order': False, 'shape': (6,), }",
        "{'descr': '<f4', 'fortran_order': False, 'shape': (1, 1, 2, 3), }",
        "{'descr': '<f4', 'fortran_order': False, 'shape': (1, 3, 2), }",
        "{'descr': '<f4', 'fortran_order': False}",
        "{'descr': '<f4', 'fortran_order': False, 'shape': (1, 2, 3)",
        "not a dict",
    };
    for (const char* dict : dicts) {
        WriteBytes(path, MakeNpy(dict, payload));
        EXPECT_THROW(atmos::ReadImage(path), atmos::Error) << dict;
    }
    // The '<i4' message names the dtype.
    WriteBytes(path, MakeNpy(dicts[0], payload));
    try {
        atmos::ReadImage(path);
        FAIL() << "expected atmos::Error";
    } catch (const atmos::Error& e) {
        EXPECT_NE(std::string(e.what()).find("<i4"), std::string::npos) << e.what();
    }
    WriteBytes(path, "garbage that is not npy");
    EXPECT_THROW(atmos::ReadImage(path), atmos::Error);
}

TEST(ImageIoTest, PfmStoresRowsBottomToTop) {
    Image image(4, 3);
    image.Set(1, 0, {7.0f, 8.0f, 9.0f});  // top row distinct
    const std::string path = TempPath(".pfm");
    atmos::WriteImage(image, path);

    const std::vector<std::uint8_t> bytes = ReadBytes(path);
    const std::string header = "PF\n4 3\n-1.0\n";
    ASSERT_EQ(bytes.size(), header.size() + 4 * 3 * 3 * 4);
    EXPECT_EQ(std::string(bytes.begin(), bytes.begin() + static_cast<long>(header.size())), header);
    // The top image row is the last row in the file.
    float r;
    std::memcpy(&r, bytes.data() + header.size() + (2 * 4 + 1) * 12, 4);
    EXPECT_EQ(r, 7.0f);

    const Image back = atmos::ReadImage(path);
    EXPECT_EQ(back.Get(1, 0).x, 7.0f);
    EXPECT_EQ(back.Get(1, 0).y, 8.0f);
    EXPECT_EQ(back.Get(1, 0).z, 9.0f);
    EXPECT_EQ(back.Get(1, 2).x, 0.0f);
}

TEST(ImageIoTest, PfmReadsBigEndianAndGrey) {
    // Big-endian colour, 2 x 2; file rows bottom first.
    const std::string be_path = TempPath("_be.pfm");
    WriteBytes(be_path, "PF\n2 2\n1.0\n" + FloatBytesBe({1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12}));
    const Image be = atmos::ReadImage(be_path);
    ASSERT_EQ(be.width(), 2);
    ASSERT_EQ(be.height(), 2);
    EXPECT_EQ(be.Get(0, 0).x, 7.0f);  // top-left = first pixel of the last file row
    EXPECT_EQ(be.Get(1, 1).z, 6.0f);

    // Little-endian grey with a scale other than 1, 3 x 1.
    const std::string grey_path = TempPath("_grey.pfm");
    WriteBytes(grey_path, "Pf 3 1 -2.5\n" + FloatBytesLe({0.5f, 1.5f, 2.5f}));
    const Image grey = atmos::ReadImage(grey_path);
    ASSERT_EQ(grey.width(), 3);
    ASSERT_EQ(grey.height(), 1);
    EXPECT_EQ(grey.Get(2, 0).x, 2.5f);
    EXPECT_EQ(grey.Get(2, 0).y, 2.5f);
    EXPECT_EQ(grey.Get(1, 0).z, 1.5f);
}

TEST(ImageIoTest, MalformedPfmThrows) {
    const std::string path = TempPath(".pfm");
    const std::string data = FloatBytesLe(std::vector<float>(12, 1.0f));
    for (const std::string& bytes :
         {std::string("P6\n2 2\n255\n") + data, std::string("PF\nx 2\n-1.0\n") + data,
          std::string("PF\n2 -2\n-1.0\n") + data, std::string("PF\n2 2\n0\n") + data,
          std::string("PF\n2 2\nabc\n") + data, std::string("PF\n2 2\n-1.0\n") + data.substr(4),
          std::string("PF\n2"), std::string("hello world, not an image")}) {
        WriteBytes(path, bytes);
        EXPECT_THROW(atmos::ReadImage(path), atmos::Error) << bytes.substr(0, 12);
    }
}

TEST(ImageIoTest, MalformedExrAndPngThrow) {
    for (const char* ext : {".exr", ".png"}) {
        const std::string path = TempPath(ext);
        WriteBytes(path, "definitely not an image file");
        EXPECT_THROW(atmos::ReadImage(path), atmos::Error) << ext;
    }
    // A truncated PNG.
    const std::string good = TempPath("_good.png");
    atmos::WriteImage(MakeTestImage(), good);
    const std::vector<std::uint8_t> bytes = ReadBytes(good);
    const std::string path = TempPath("_truncated.png");
    WriteBytes(path,
               std::string(bytes.begin(), bytes.begin() + static_cast<long>(bytes.size() / 2)));
    EXPECT_THROW(atmos::ReadImage(path), atmos::Error);
    // A truncated EXR.
    const std::string good_exr = TempPath("_good.exr");
    atmos::WriteImage(MakeTestImage(), good_exr);
    const std::vector<std::uint8_t> exr = ReadBytes(good_exr);
    const std::string exr_path = TempPath("_truncated.exr");
    WriteBytes(exr_path, std::string(exr.begin(), exr.begin() + static_cast<long>(exr.size() / 2)));
    EXPECT_THROW(atmos::ReadImage(exr_path), atmos::Error);
}

}  // namespace
