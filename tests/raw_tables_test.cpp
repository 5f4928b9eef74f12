// The raw float32/float16 table blobs of `atmos bake` (io/raw_tables.h).
#include "io/raw_tables.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace atmos {
namespace {

TEST(RawTables, HalfConversionMatchesIeeeBinary16) {
    // Exact values and their bit patterns (IEEE 754-2008 binary16).
    EXPECT_EQ(FloatToHalf(0.0f), 0x0000);
    EXPECT_EQ(FloatToHalf(-0.0f), 0x8000);
    EXPECT_EQ(FloatToHalf(1.0f), 0x3c00);
    EXPECT_EQ(FloatToHalf(-2.0f), 0xc000);
    EXPECT_EQ(FloatToHalf(65504.0f), 0x7bff);
    EXPECT_EQ(FloatToHalf(1e9f), 0x7bff);                   // clamped, no infinity
    EXPECT_EQ(FloatToHalf(std::ldexp(1.0f, -14)), 0x0400);  // smallest normal
    EXPECT_EQ(FloatToHalf(std::ldexp(1.0f, -24)), 0x0001);  // smallest subnormal
    EXPECT_EQ(FloatToHalf(std::ldexp(1.0f, -26)), 0x0000);  // below half of it
    // 0.1 = 0x2e66 (nearest), 1 + 2^-11 is a tie: to even (1.0); 1 + 3 * 2^-11 to 1 + 2^-9.
    EXPECT_EQ(FloatToHalf(0.1f), 0x2e66);
    EXPECT_EQ(FloatToHalf(1.0f + std::ldexp(1.0f, -11)), 0x3c00);
    EXPECT_EQ(FloatToHalf(1.0f + 3.0f * std::ldexp(1.0f, -11)), 0x3c02);
    // Round trip within half a unit in the last place over a range of magnitudes.
    for (float x = 1e-7f; x < 6e4f; x *= 1.37f) {
        const float y = HalfToFloat(FloatToHalf(x));
        const float ulp = x < std::ldexp(1.0f, -14) ? std::ldexp(1.0f, -24)
                                                    : std::ldexp(1.0f, std::ilogb(x) - 10);
        EXPECT_LE(std::fabs(y - x), 0.5f * ulp) << x;
    }
}

TEST(RawTables, BlobsHoldEveryTableAtItsOffset) {
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("atmos_raw_" + std::to_string(getpid()));
    std::filesystem::create_directories(dir);
    Table a(3, 2, 1, 3), b(2, 2, 2, 4);
    for (size_t i = 0; i < a.size(); ++i) a.data()[i] = 0.25f * static_cast<float>(i);
    for (size_t i = 0; i < b.size(); ++i) b.data()[i] = -1.0f - static_cast<float>(i);
    const nlohmann::ordered_json j = WriteRawTables(dir.string(), {{"a", &a}, {"b", &b}});
    auto slurp = [&](const char* name) {
        std::ifstream in(dir / name, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    const std::string f32 = slurp("tables.f32"), f16 = slurp("tables.f16");
    EXPECT_EQ(j.at("float32").at("bytes").get<size_t>(), f32.size());
    EXPECT_EQ(j.at("float16").at("bytes").get<size_t>(), f16.size());
    // What compare reports as table memory (Model::TableBytes) without writing.
    EXPECT_EQ(RawTablesFloat32Bytes({{"a", &a}, {"b", &b}}), f32.size());
    const auto& tb = j.at("tables").at("b");
    EXPECT_EQ(tb.at("width"), 2);
    EXPECT_EQ(tb.at("depth"), 2);
    EXPECT_EQ(tb.at("channels"), 4);
    EXPECT_EQ(tb.at("float32_offset").get<size_t>() % 256, 0u);
    for (const auto& [name, table] : {std::pair<const char*, const Table*>{"a", &a}, {"b", &b}}) {
        const auto& t = j.at("tables").at(name);
        const size_t o32 = t.at("float32_offset"), o16 = t.at("float16_offset");
        ASSERT_EQ(t.at("values").get<size_t>(), table->size());
        for (size_t i = 0; i < table->size(); ++i) {
            float x;
            std::memcpy(&x, f32.data() + o32 + 4 * i, 4);
            EXPECT_EQ(x, table->data()[i]) << name << " " << i;
            const uint16_t h =
                static_cast<uint16_t>(static_cast<unsigned char>(f16[o16 + 2 * i]) |
                                      (static_cast<unsigned char>(f16[o16 + 2 * i + 1]) << 8));
            EXPECT_EQ(HalfToFloat(h), table->data()[i]) << name << " " << i;  // exact in half
        }
    }
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace atmos
