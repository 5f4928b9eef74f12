// atmos io: `bake --layout rgba`: the tables as 4-channel float16 and float32
// textures, in raw blobs and KTX2 files (issue 35 item 2; docs/engine.md,
// "RGBA tables and KTX2").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace atmos {

// From a bake in `dir` (NAME.json's "raw", tables.f32, tables.f16), writes
// DIR/tables_rgba.f32 and DIR/tables_rgba.f16 (each table padded to 4 channels,
// alpha 1 where the table has 3; each table at a multiple of 256 bytes),
// DIR/ktx2/TABLE_rgba32f.ktx2 and TABLE_rgba16f.ktx2, and DIR/tables_rgba.json
// describing them. The float16 values are the bake's own (tables.f16), so the
// RGBA16F texels are bit-identical to the 3-channel blob's.
void WriteRgbaTables(const std::string& dir, const std::string& model_name);

// A KTX 2.0 file (Khronos, "KTX File Format Specification" 2.0) of one
// uncompressed level: VK_FORMAT_R16G16B16A16_SFLOAT (bytes_per_channel 2) or
// VK_FORMAT_R32G32B32A32_SFLOAT (4), 2D (depth 0 or 1) or 3D, with its basic
// data format descriptor (linear, BT.709 primaries) and the KTXorientation and
// KTXwriter metadata. `texels` is width x height x max(depth, 1) x 4 channels,
// little-endian, in the raw blobs' order.
std::string Ktx2File(int width, int height, int depth, int bytes_per_channel,
                     const std::string& texels);

}  // namespace atmos
