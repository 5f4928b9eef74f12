// atmos io: `bake --layout rgba` (bake_rgba.h): RGBA16F/RGBA32F raw blobs and
// KTX2 files. A small KTX2 writer of our own: Debian bookworm has no libktx.
#include "io/rgba_tables.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "atmos/error.h"
#include "io/output_path.h"
#include "io/text_files.h"

namespace atmos {

namespace rgba_tables {

namespace fs = std::filesystem;

void PutU32(std::string* out, uint32_t v) {
    for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}
void PutU64(std::string* out, uint64_t v) {
    for (int i = 0; i < 8; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}
void PadTo(std::string* out, size_t alignment) {
    while (out->size() % alignment != 0) out->push_back('\0');
}

// One key/value pair of the KTX2 metadata: u32 length, "key\0value\0", padded to 4.
void PutKeyValue(std::string* kvd, const std::string& key, const std::string& value) {
    const uint32_t length = static_cast<uint32_t>(key.size() + 1 + value.size() + 1);
    PutU32(kvd, length);
    *kvd += key;
    kvd->push_back('\0');
    *kvd += value;
    kvd->push_back('\0');
    PadTo(kvd, 4);
}

// A table of the bake's blob padded to 4 channels; `one` is 1.0 in the blob's
// element type (the alpha of a 3-channel table).
std::string PadToRgba(const std::string& blob, size_t offset, size_t texels, int channels,
                      size_t element, const std::string& one) {
    if (channels != 3 && channels != 4)
        Fail("bake --layout rgba: a table has ", channels, " channels");
    if (offset + texels * channels * element > blob.size())
        Fail("bake --layout rgba: a table lies outside its blob");
    std::string out;
    out.reserve(texels * 4 * element);
    for (size_t t = 0; t < texels; ++t) {
        out.append(blob, offset + t * channels * element, channels * element);
        if (channels == 3) out += one;
    }
    return out;
}

}  // namespace rgba_tables

std::string Ktx2File(int width, int height, int depth, int bytes_per_channel,
                     const std::string& texels) {
    using namespace rgba_tables;
    const bool half = bytes_per_channel == 2;
    const uint32_t vk_format = half ? 97u : 109u;  // VK_FORMAT_R16G16B16A16_SFLOAT / R32G32B32A32
    const uint32_t texel_bytes = 4u * static_cast<uint32_t>(bytes_per_channel);
    const bool is_3d = depth > 1;

    // Data format descriptor (Khronos Data Format Specification 1.3, basic block).
    std::string dfd_block;
    PutU32(&dfd_block, 0u);  // vendorId 0 (Khronos) | descriptorType 0 (basic) << 17
    const uint32_t block_size = 24u + 16u * 4u;
    PutU32(&dfd_block, 2u | (block_size << 16));  // versionNumber 2 | descriptorBlockSize
    // colorModel 1 (RGBSDA), colorPrimaries 1 (BT.709), transferFunction 1 (linear), flags 0.
    dfd_block += std::string("\x01\x01\x01\x00", 4);
    PutU32(&dfd_block, 0u);  // texelBlockDimension 0..3 (1x1x1x1, stored minus one)
    dfd_block.push_back(static_cast<char>(texel_bytes));  // bytesPlane0
    dfd_block += std::string(7, '\0');                    // bytesPlane1..7
    const uint8_t channel_ids[4] = {0, 1, 2, 15};         // R, G, B, A
    for (int c = 0; c < 4; ++c) {
        const uint32_t bit_offset = static_cast<uint32_t>(c * bytes_per_channel * 8);
        const uint32_t bit_length = static_cast<uint32_t>(bytes_per_channel * 8 - 1);
        const uint32_t channel_type = 0xC0u | channel_ids[c];  // FLOAT | SIGNED | id
        PutU32(&dfd_block, bit_offset | (bit_length << 16) | (channel_type << 24));
        PutU32(&dfd_block, 0u);                            // samplePosition 0..3
        PutU32(&dfd_block, half ? 0xBC00u : 0xBF800000u);  // sampleLower: -1.0
        PutU32(&dfd_block, half ? 0x3C00u : 0x3F800000u);  // sampleUpper: 1.0
    }
    std::string dfd;
    PutU32(&dfd, static_cast<uint32_t>(4 + dfd_block.size()));  // dfdTotalSize
    dfd += dfd_block;

    std::string kvd;
    // Row 0 is v = 0 (the GL upload order of the raw blobs): right, up (and in).
    PutKeyValue(&kvd, "KTXorientation", is_3d ? "rui" : "ru");
    PutKeyValue(&kvd, "KTXwriter", "atmos bake --layout rgba");

    const size_t header_bytes = 12 + 9 * 4 + 4 * 4 + 2 * 8;  // identifier, header, index
    const size_t level_index_bytes = 3 * 8;                  // one level
    const size_t dfd_offset = header_bytes + level_index_bytes;
    const size_t kvd_offset = dfd_offset + dfd.size();
    size_t data_offset = kvd_offset + kvd.size();
    const size_t alignment = texel_bytes;  // lcm(texel block size, 4)
    data_offset = (data_offset + alignment - 1) / alignment * alignment;
    const size_t expected = static_cast<size_t>(width) * height * (is_3d ? depth : 1) * texel_bytes;
    if (texels.size() != expected)
        Fail("KTX2: ", texels.size(), " bytes of texels, expected ", expected);

    std::string out;
    out += std::string("\xABKTX 20\xBB\r\n\x1A\n", 12);
    PutU32(&out, vk_format);
    PutU32(&out, static_cast<uint32_t>(bytes_per_channel));  // typeSize
    PutU32(&out, static_cast<uint32_t>(width));
    PutU32(&out, static_cast<uint32_t>(height));
    PutU32(&out, is_3d ? static_cast<uint32_t>(depth) : 0u);  // pixelDepth (0: 2D)
    PutU32(&out, 0u);                                         // layerCount (not an array)
    PutU32(&out, 1u);                                         // faceCount
    PutU32(&out, 1u);                                         // levelCount
    PutU32(&out, 0u);                                         // supercompressionScheme: none
    PutU32(&out, static_cast<uint32_t>(dfd_offset));
    PutU32(&out, static_cast<uint32_t>(dfd.size()));
    PutU32(&out, static_cast<uint32_t>(kvd_offset));
    PutU32(&out, static_cast<uint32_t>(kvd.size()));
    PutU64(&out, 0u);             // sgdByteOffset
    PutU64(&out, 0u);             // sgdByteLength
    PutU64(&out, data_offset);    // level 0: byteOffset
    PutU64(&out, texels.size());  // byteLength
    PutU64(&out, texels.size());  // uncompressedByteLength
    out += dfd;
    out += kvd;
    out.resize(data_offset, '\0');
    out += texels;
    return out;
}

void WriteRgbaTables(const std::string& dir_text, const std::string& model_name) {
    using namespace rgba_tables;
    const fs::path dir(dir_text);
    const nlohmann::json bake = nlohmann::json::parse(ReadWholeFile(dir / (model_name + ".json")));
    const nlohmann::json& raw = bake.at("raw");
    const std::string f32 = ReadWholeFile(dir / raw.at("float32").at("file").get<std::string>());
    const std::string f16 = ReadWholeFile(dir / raw.at("float16").at("file").get<std::string>());
    float one_f = 1.0f;
    std::string one32(4, '\0');
    std::memcpy(one32.data(), &one_f, 4);  // little-endian hosts (as the blobs)
    const std::string one16("\x00\x3C", 2);

    std::string blob32, blob16;
    nlohmann::json tables = nlohmann::json::object();
    fs::create_directories(dir / "ktx2");
    for (const auto& [name, t] : raw.at("tables").items()) {
        const int width = t.at("width").get<int>(), height = t.at("height").get<int>();
        const int depth = t.at("depth").get<int>(), channels = t.at("channels").get<int>();
        const size_t texels = static_cast<size_t>(width) * height * std::max(depth, 1);
        const std::string rgba32 =
            PadToRgba(f32, t.at("float32_offset").get<size_t>(), texels, channels, 4, one32);
        const std::string rgba16 =
            PadToRgba(f16, t.at("float16_offset").get<size_t>(), texels, channels, 2, one16);
        blob32.resize((blob32.size() + 255) / 256 * 256, '\0');
        blob16.resize((blob16.size() + 255) / 256 * 256, '\0');
        const std::string k32 = "ktx2/" + name + "_rgba32f.ktx2";
        const std::string k16 = "ktx2/" + name + "_rgba16f.ktx2";
        tables[name] = {{"width", width},
                        {"height", height},
                        {"depth", depth},
                        {"channels", 4},
                        {"source_channels", channels},
                        {"values", texels * 4},
                        {"float32_offset", blob32.size()},
                        {"float16_offset", blob16.size()},
                        {"ktx2_rgba32f", k32},
                        {"ktx2_rgba16f", k16}};
        blob32 += rgba32;
        blob16 += rgba16;
        WriteFileAtomically((dir / k32).string(), Ktx2File(width, height, depth, 4, rgba32));
        WriteFileAtomically((dir / k16).string(), Ktx2File(width, height, depth, 2, rgba16));
    }
    WriteFileAtomically((dir / "tables_rgba.f32").string(), blob32);
    WriteFileAtomically((dir / "tables_rgba.f16").string(), blob16);
    nlohmann::json doc = {
        {"description",
         "the tables of " + model_name +
             ".json's \"raw\" as 4-channel textures (RGBA32F, RGBA16F): "
             "alpha 1 where the table has 3 channels; the float16 values are tables.f16's; layout "
             "and "
             "256-byte alignment as there; offsets in bytes; one KTX2 file per table and format"},
        {"float32", {{"file", "tables_rgba.f32"}, {"bytes", blob32.size()}}},
        {"float16", {{"file", "tables_rgba.f16"}, {"bytes", blob16.size()}}},
        {"tables", tables}};
    WriteFileAtomically((dir / "tables_rgba.json").string(), doc.dump(2) + "\n");
}

}  // namespace atmos
