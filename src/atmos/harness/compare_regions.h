// atmos: sky and ground apart in `atmos compare` (issue 33 item 2).
//
// A pixel is ground when the ray through its centre meets the planet's
// surface (the sphere of bottom_radius) in front of the camera, sky otherwise;
// a pixel without a ray (a fisheye's corners) is neither. Region means are
// over the pixels of the region; NaN when it has none.
#pragma once

#include <cstdint>
#include <vector>

#include "atmos/image.h"
#include "atmos/view.h"

namespace atmos {

enum class PixelRegion : uint8_t { kSky = 0, kGround = 1, kNone = 2 };

// One PixelRegion per pixel, row-major, top row first.
std::vector<uint8_t> RegionMask(const View& view, int width, int height, double bottom_radius);

struct RegionValues {
    double sky = 0.0;
    double ground = 0.0;
};
struct RegionCounts {
    int64_t sky = 0;
    int64_t ground = 0;
};
RegionCounts CountRegions(const std::vector<uint8_t>& mask);
// The mean of a per-pixel map (a FLIP map) over each region.
RegionValues RegionMean(const std::vector<float>& map, const std::vector<uint8_t>& mask);
// The RMSE over each region's pixels and channels (metrics/rmse.h's overall RMSE, per region).
RegionValues RegionRmse(const Image& reference, const Image& test,
                        const std::vector<uint8_t>& mask);
// Twice the RMS standard error over each region (sqrt of the mean per-pixel,
// per-channel variance): the reference's noise in RMSE units, per region.
RegionValues RegionRmseNoise(const Image& variance, const std::vector<uint8_t>& mask);
// The mean Rec. 709 luminance (0.2126 R + 0.7152 G + 0.0722 B) over the whole
// image (`all`, every pixel) and each region.
struct RegionLuminance {
    double all = 0.0;
    double sky = 0.0;
    double ground = 0.0;
};
RegionLuminance MeanLuminance(const Image& image, const std::vector<uint8_t>& mask);

}  // namespace atmos
