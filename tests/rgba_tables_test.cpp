// Issue 35 item 2: `bake --layout rgba` writes RGBA32F/RGBA16F blobs and KTX2
// files (apps/atmos/bake_rgba.cpp). Read back here with a reader written from the
// KTX 2.0 specification (header, index, level index, data format descriptor,
// key/value data, level data) and compared texel by texel with the 3-channel blobs.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "test_util.h"

namespace {

namespace fs = std::filesystem;
using atmos_test::Slurp;

fs::path TempDir() { return atmos_test::TestTmpDir("rgba_tables"); }

uint32_t U32(const std::string& b, size_t at) {
    uint32_t v = 0;
    for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(b[at + i]);
    return v;
}
uint64_t U64(const std::string& b, size_t at) {
    return U32(b, at) | (static_cast<uint64_t>(U32(b, at + 4)) << 32);
}

struct Ktx2 {
    uint32_t vk_format, type_size, width, height, depth, layers, faces, levels, scheme;
    std::string orientation;
    uint32_t bytes_plane0 = 0;
    uint32_t channel_ids[4] = {0, 0, 0, 0};
    uint32_t bit_lengths[4] = {0, 0, 0, 0};
    uint32_t color_model = 0, transfer = 0;
    std::string data;  // level 0
};

// Reads a KTX2 file of one level; ADD_FAILUREs on a malformed structure.
Ktx2 ReadKtx2(const std::string& f) {
    Ktx2 k{};
    EXPECT_GE(f.size(), 104u);
    if (f.size() < 104) return k;
    EXPECT_EQ(f.substr(0, 12), std::string("\xABKTX 20\xBB\r\n\x1A\n", 12));
    k.vk_format = U32(f, 12);
    k.type_size = U32(f, 16);
    k.width = U32(f, 20);
    k.height = U32(f, 24);
    k.depth = U32(f, 28);
    k.layers = U32(f, 32);
    k.faces = U32(f, 36);
    k.levels = U32(f, 40);
    k.scheme = U32(f, 44);
    const uint32_t dfd_offset = U32(f, 48), dfd_length = U32(f, 52);
    const uint32_t kvd_offset = U32(f, 56), kvd_length = U32(f, 60);
    EXPECT_EQ(U64(f, 64), 0u);  // no supercompression global data
    EXPECT_EQ(U64(f, 72), 0u);
    const uint64_t level_offset = U64(f, 80), level_length = U64(f, 88);
    EXPECT_EQ(U64(f, 96), level_length);  // uncompressed
    EXPECT_EQ(dfd_offset, 104u);
    // The data format descriptor: total size, then one basic block.
    EXPECT_EQ(U32(f, dfd_offset), dfd_length);
    const size_t b = dfd_offset + 4;
    EXPECT_EQ(U32(f, b), 0u);               // vendor 0, type 0
    EXPECT_EQ(U32(f, b + 4) & 0xFFFF, 2u);  // version 2
    const uint32_t block_size = U32(f, b + 4) >> 16;
    EXPECT_EQ(dfd_length, 4 + block_size);
    k.color_model = static_cast<unsigned char>(f[b + 8]);
    k.transfer = static_cast<unsigned char>(f[b + 10]);
    k.bytes_plane0 = static_cast<unsigned char>(f[b + 16]);
    const uint32_t samples = (block_size - 24) / 16;
    EXPECT_EQ(samples, 4u);
    for (uint32_t s = 0; s < samples && s < 4; ++s) {
        const uint32_t w = U32(f, b + 24 + 16 * s);
        k.bit_lengths[s] = ((w >> 16) & 0xFF) + 1;
        k.channel_ids[s] = (w >> 24) & 0x0F;
        EXPECT_EQ((w >> 24) & 0xC0, 0xC0u);           // float, signed
        EXPECT_EQ(w & 0xFFFF, s * k.bit_lengths[s]);  // bit offset
    }
    // Key/value data: KTXorientation.
    for (size_t at = kvd_offset; at < kvd_offset + kvd_length;) {
        const uint32_t len = U32(f, at);
        const std::string kv = f.substr(at + 4, len);
        const size_t nul = kv.find('\0');
        if (kv.substr(0, nul) == "KTXorientation")
            k.orientation = kv.substr(nul + 1, len - nul - 2);
        at += 4 + (len + 3) / 4 * 4;
    }
    EXPECT_EQ(level_offset % (4 * k.type_size), 0u);
    EXPECT_EQ(level_offset + level_length, f.size());
    k.data = f.substr(level_offset, level_length);
    return k;
}

TEST(RgbaTables, Ktx2AndBlobsReadBack) {
    for (const char* model : {"hillaire", "atmosphere-plus"}) {
        const fs::path dir = TempDir() / model;
        fs::remove_all(dir);
        const std::string cmd = std::string(ATMOS_CLI_PATH) + " bake -q --model " + model +
                                " --layout rgba -o " + dir.string();
        ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
        std::string file = model;
        const nlohmann::json raw = nlohmann::json::parse(Slurp(dir / (file + ".json"))).at("raw");
        const nlohmann::json rgba = nlohmann::json::parse(Slurp(dir / "tables_rgba.json"));
        const std::string f32 = Slurp(dir / "tables.f32"), f16 = Slurp(dir / "tables.f16");
        const std::string r32 = Slurp(dir / "tables_rgba.f32"),
                          r16 = Slurp(dir / "tables_rgba.f16");
        EXPECT_EQ(rgba.at("float32").at("bytes").get<size_t>(), r32.size());
        EXPECT_EQ(rgba.at("float16").at("bytes").get<size_t>(), r16.size());
        ASSERT_EQ(raw.at("tables").size(), rgba.at("tables").size());
        for (const auto& [name, t] : raw.at("tables").items()) {
            const nlohmann::json& q = rgba.at("tables").at(name);
            const uint32_t w = t.at("width"), h = t.at("height"), d = t.at("depth");
            const int channels = t.at("channels");
            const size_t texels = static_cast<size_t>(w) * h * (d > 1 ? d : 1);
            const size_t o32 = q.at("float32_offset"), o16 = q.at("float16_offset");
            EXPECT_EQ(o32 % 256, 0u);
            EXPECT_EQ(o16 % 256, 0u);
            for (int half = 0; half < 2; ++half) {
                const Ktx2 k = ReadKtx2(
                    Slurp(dir / q.at(half ? "ktx2_rgba16f" : "ktx2_rgba32f").get<std::string>()));
                EXPECT_EQ(k.vk_format, half ? 97u : 109u) << name;
                EXPECT_EQ(k.type_size, half ? 2u : 4u);
                EXPECT_EQ(k.width, w);
                EXPECT_EQ(k.height, h);
                EXPECT_EQ(k.depth, d > 1 ? d : 0u);
                EXPECT_EQ(k.layers, 0u);
                EXPECT_EQ(k.faces, 1u);
                EXPECT_EQ(k.levels, 1u);
                EXPECT_EQ(k.scheme, 0u);
                EXPECT_EQ(k.color_model, 1u);  // RGBSDA
                EXPECT_EQ(k.transfer, 1u);     // linear
                EXPECT_EQ(k.bytes_plane0, half ? 8u : 16u);
                EXPECT_EQ(k.channel_ids[0], 0u);
                EXPECT_EQ(k.channel_ids[1], 1u);
                EXPECT_EQ(k.channel_ids[2], 2u);
                EXPECT_EQ(k.channel_ids[3], 15u);
                EXPECT_EQ(k.bit_lengths[0], half ? 16u : 32u);
                EXPECT_EQ(k.orientation, d > 1 ? "rui" : "ru");
                const size_t element = half ? 2 : 4;
                ASSERT_EQ(k.data.size(), texels * 4 * element) << name;
                // The KTX2 level is the RGBA blob's table.
                EXPECT_EQ(k.data, (half ? r16 : r32).substr(half ? o16 : o32, k.data.size()));
                // Texel by texel: RGB(A) of the 3/4-channel blob, alpha 1 added.
                const std::string& src = half ? f16 : f32;
                const size_t src_offset = t.at(half ? "float16_offset" : "float32_offset");
                const std::string one = half ? std::string("\x00\x3C", 2) : [] {
                    float v = 1.0f;
                    std::string s(4, '\0');
                    std::memcpy(s.data(), &v, 4);
                    return s;
                }();
                size_t mismatches = 0;
                for (size_t i = 0; i < texels; ++i) {
                    const std::string texel = k.data.substr(i * 4 * element, 4 * element);
                    const std::string expect =
                        src.substr(src_offset + i * channels * element, channels * element) +
                        (channels == 3 ? one : std::string());
                    mismatches += texel != expect;
                }
                EXPECT_EQ(mismatches, 0u) << model << " " << name << (half ? " f16" : " f32");
            }
        }
    }
}

TEST(RgbaTables, LayoutIsValidated) {
    const std::string cmd = std::string(ATMOS_CLI_PATH) +
                            " bake -q --model hillaire --layout rgb4 -o " +
                            (TempDir() / "bad").string() + " 2>/dev/null";
    EXPECT_NE(std::system(cmd.c_str()), 0);
    EXPECT_FALSE(fs::exists(TempDir() / "bad" / "hillaire.json"));
}

}  // namespace
