// atmos: sky and ground apart in `atmos compare` (compare_regions.h).
#include "harness/compare_regions.h"

#include <cmath>

namespace atmos {

namespace {

// Sums of `value(i)` over each region, divided by the region's count (NaN when empty).
template <typename F>
RegionValues Means(const std::vector<uint8_t>& mask, F value) {
    double sum[2] = {0.0, 0.0};
    int64_t n[2] = {0, 0};
    for (size_t i = 0; i < mask.size(); ++i) {
        if (mask[i] > 1) continue;
        sum[mask[i]] += value(i);
        ++n[mask[i]];
    }
    RegionValues r;
    r.sky = n[0] > 0 ? sum[0] / static_cast<double>(n[0]) : std::nan("");
    r.ground = n[1] > 0 ? sum[1] / static_cast<double>(n[1]) : std::nan("");
    return r;
}

double Luminance(const Image& image, size_t pixel) {
    const float* p = image.data() + 3 * pixel;
    return 0.2126 * static_cast<double>(p[0]) + 0.7152 * static_cast<double>(p[1]) +
           0.0722 * static_cast<double>(p[2]);
}

}  // namespace

std::vector<uint8_t> RegionMask(const View& view, int width, int height, double bottom_radius) {
    std::vector<uint8_t> mask(static_cast<size_t>(width) * static_cast<size_t>(height));
    const Vec3d p = view.camera.position;
    const double c = Dot(p, p) - bottom_radius * bottom_radius;
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            const Vec3d d = view.camera.RayDirection(x, y, width, height);
            uint8_t region = static_cast<uint8_t>(PixelRegion::kNone);
            if (Dot(d, d) > 0.0) {
                // |p + t d| = R for some t > 0: the ray points down (b < 0) and,
                // from outside the sphere, comes within R of the centre.
                const double b = Dot(p, d);
                const bool ground = b < 0.0 && (c <= 0.0 || b * b - c >= 0.0);
                region = static_cast<uint8_t>(ground ? PixelRegion::kGround : PixelRegion::kSky);
            }
            mask[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)] =
                region;
        }
    }
    return mask;
}

RegionCounts CountRegions(const std::vector<uint8_t>& mask) {
    RegionCounts n;
    for (uint8_t m : mask) {
        if (m == static_cast<uint8_t>(PixelRegion::kSky)) ++n.sky;
        if (m == static_cast<uint8_t>(PixelRegion::kGround)) ++n.ground;
    }
    return n;
}

RegionValues RegionMean(const std::vector<float>& map, const std::vector<uint8_t>& mask) {
    if (map.size() != mask.size()) return {std::nan(""), std::nan("")};
    return Means(mask, [&](size_t i) { return static_cast<double>(map[i]); });
}

RegionValues RegionRmse(const Image& reference, const Image& test,
                        const std::vector<uint8_t>& mask) {
    if (reference.size() != test.size() || reference.size() != 3 * mask.size()) {
        return {std::nan(""), std::nan("")};
    }
    RegionValues r = Means(mask, [&](size_t i) {
        double s = 0.0;
        for (size_t c = 0; c < 3; ++c) {
            const double d = static_cast<double>(test.data()[3 * i + c]) -
                             static_cast<double>(reference.data()[3 * i + c]);
            s += d * d;
        }
        return s / 3.0;
    });
    r.sky = std::sqrt(r.sky);
    r.ground = std::sqrt(r.ground);
    return r;
}

RegionValues RegionRmseNoise(const Image& variance, const std::vector<uint8_t>& mask) {
    if (variance.size() != 3 * mask.size()) return {-1.0, -1.0};
    RegionValues r = Means(mask, [&](size_t i) {
        const float* v = variance.data() + 3 * i;
        return (static_cast<double>(v[0]) + static_cast<double>(v[1]) + static_cast<double>(v[2])) /
               3.0;
    });
    r.sky = std::isfinite(r.sky) ? 2.0 * std::sqrt(r.sky) : -1.0;
    r.ground = std::isfinite(r.ground) ? 2.0 * std::sqrt(r.ground) : -1.0;
    return r;
}

RegionLuminance MeanLuminance(const Image& image, const std::vector<uint8_t>& mask) {
    RegionLuminance out;
    if (image.size() != 3 * mask.size() || mask.empty()) {
        out.all = out.sky = out.ground = std::nan("");
        return out;
    }
    double sum = 0.0;
    for (size_t i = 0; i < mask.size(); ++i) sum += Luminance(image, i);
    out.all = sum / static_cast<double>(mask.size());
    const RegionValues r = Means(mask, [&](size_t i) { return Luminance(image, i); });
    out.sky = r.sky;
    out.ground = r.ground;
    return out;
}

}  // namespace atmos
