// atmos: per-format image readers and writers behind WriteImage / ReadImage.
//
// Internal to the library (not installed). Every function throws atmos::Error
// with a message naming the file on any failure. Images are RGB float32, top
// row first, as in atmos/image.h; writers expect a non-empty image.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "atmos/image.h"

namespace atmos::detail {

// OpenEXR: float32 R, G, B channels, ZIP compression (values round-trip
// bit-exactly). Reads half or float R, G, B; a luminance-only file (Y) reads as
// grey, a luminance/chroma file (Y, RY, BY) is converted to RGB.
void WriteExr(const Image& image, const std::string& path);
Image ReadExr(const std::string& path);
// An EXR of `names.size()` float channels, `values` interleaved per pixel (row-major,
// top row first), with string attributes (name, value).
void WriteMultiChannelExr(const std::string& path, int width, int height,
                          const std::vector<std::string>& names, const std::vector<float>& values,
                          const std::vector<std::pair<std::string, std::string>>& attributes);

// PNG: 8-bit RGB through EncodeDisplayValue(value, exposure). Reads 8- or
// 16-bit grey, grey+alpha, RGB, RGBA or palette images (alpha is dropped) and
// decodes the sRGB curve to linear [0, 1].
void WritePng(const Image& image, const std::string& path, float exposure);
Image ReadPng(const std::string& path);
// 8-bit sRGB-encoded RGB bytes (width * height * 3, top row first) as a PNG, untouched.
void WritePngBytes(const std::vector<std::uint8_t>& bytes, int width, int height,
                   const std::string& path);

// NumPy .npy: writes '<f4' of shape (H, W, 3), C order. Reads '<f4' or '<f8',
// C order, shape (H, W, 3), (H, W, 4) (alpha dropped), (H, W, 1) or (H, W)
// (grey).
void WriteNpy(const Image& image, const std::string& path);
Image ReadNpy(const std::string& path);
// Any C-order array: written as '<f4' of `shape` from `data` (row-major), read
// from '<f4' or '<f8' as doubles (the image functions above are these plus
// their shape checks; `atmos sample --input/--output` uses them for tables).
struct NpyArray {
    std::vector<std::uint64_t> shape;
    std::vector<double> values;
};
void WriteNpyArray(const std::string& path, const std::vector<std::uint64_t>& shape,
                   const float* data);
NpyArray ReadNpyArray(const std::string& path);
std::string NpyShapeString(const std::vector<std::uint64_t>& shape);

// Portable float map: writes "PF" (colour), little-endian, rows bottom to top.
// Reads "PF" and "Pf" (grey) of either byte order.
void WritePfm(const Image& image, const std::string& path);
Image ReadPfm(const std::string& path);

// Whole-file helpers shared by the formats above (throw atmos::Error).
std::vector<std::uint8_t> ReadFileBytes(const std::string& path);
void WriteFileBytes(const std::string& path, const std::vector<std::uint8_t>& bytes);

// Little-endian / big-endian float32 and float64 packing, independent of the
// host byte order.
float LoadF32(const std::uint8_t* p, bool little_endian);
double LoadF64(const std::uint8_t* p, bool little_endian);
void StoreF32Le(float value, std::uint8_t* p);

}  // namespace atmos::detail
