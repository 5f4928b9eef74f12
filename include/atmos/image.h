// atmos: float RGB images.
//
// Image owns its pixels (host memory, row-major, top row first, RGB float32
// interleaved). ImageView is a trivially copyable, non-owning window that
// per-pixel code (ATMOS_HD) writes through, on the host or on a device.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "atmos/math.h"

namespace atmos {

struct ImageView {
    float* data = nullptr;  // width * height * 3 floats, row-major, top row first
    int width = 0;
    int height = 0;

    ATMOS_HD Rgb Get(int x, int y) const {
        const float* p = data + (static_cast<size_t>(y) * width + x) * 3;
        return {p[0], p[1], p[2]};
    }
    ATMOS_HD void Set(int x, int y, const Rgb& c) const {
        float* p = data + (static_cast<size_t>(y) * width + x) * 3;
        p[0] = c.x;
        p[1] = c.y;
        p[2] = c.z;
    }
};

class Image {
  public:
    Image() = default;
    Image(int width, int height) { Resize(width, height); }

    // Negative sizes are clamped to 0 (callers validate sizes; see ParseSize).
    void Resize(int width, int height) {
        width = width > 0 ? width : 0;
        height = height > 0 ? height : 0;
        width_ = width;
        height_ = height;
        pixels_.assign(static_cast<size_t>(width) * height * 3, 0.0f);
    }
    int width() const { return width_; }
    int height() const { return height_; }
    bool empty() const { return pixels_.empty(); }
    float* data() { return pixels_.data(); }
    const float* data() const { return pixels_.data(); }
    size_t size() const { return pixels_.size(); }  // number of floats

    Rgb Get(int x, int y) const { return View().Get(x, y); }
    void Set(int x, int y, const Rgb& c) { View().Set(x, y, c); }

    ImageView View() const {
        return ImageView{const_cast<float*>(pixels_.data()), width_, height_};
    }

  private:
    int width_ = 0;
    int height_ = 0;
    std::vector<float> pixels_;
};

// Display transform of DESIGN.md / Leenman's 2025 thesis section 11.5 for PNG output:
// multiply by `exposure`, tone map t(x) = 1 - exp(-x) per channel, then encode
// with the sRGB transfer curve. Returns 8-bit values in [0, 255].
unsigned char EncodeDisplayValue(float linear, float exposure);

// The image format chosen from a file name's extension: .exr, .png, .npy, .pfm.
enum class ImageFormat { kExr, kPng, kNpy, kPfm };
ImageFormat ImageFormatFromPath(const std::string& path);  // throws atmos::Error

// Writes an image; the format follows the extension. `exposure` applies to PNG
// only (float formats store linear values untouched). Throws atmos::Error.
void WriteImage(const Image& image, const std::string& path, float exposure = 1.0f);

// Reads EXR (half or float R, G, B; Y alone as grey), NPY (float32 or float64;
// H x W x 3, H x W x 4 with alpha dropped, H x W x 1 or H x W as grey) and PFM
// (colour or grey) into linear RGB. PNG reads always decode the sRGB curve to
// [0, 1] (gAMA/iCCP chunks ignored, alpha dropped, no inverse tone map).
// Throws atmos::Error on anything malformed.
Image ReadImage(const std::string& path);

}  // namespace atmos
