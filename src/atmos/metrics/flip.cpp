// atmos: FLIP, written from /work/shared/specs/flip.md (section numbers below).
#include "metrics/flip.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "atmos/error.h"
#include "base/parallel.h"
#include "io/image_formats.h"
#include "io/output_path.h"

namespace atmos {

namespace {

constexpr float kFlipPi = 3.14159265358979f;  // spec 0: pi as float32

// Spec 2.1: D65 reference white and its reciprocal, as stored constants.
constexpr float kWhite[3] = {0.950428545f, 1.0f, 1.088900371f};
constexpr float kInvWhite[3] = {1.052156925f, 1.0f, 0.918357670f};

// Spec 5: the FLIP constants.
constexpr float kQc = 0.7f;    // colour compression exponent q_c
constexpr float kPc = 0.4f;    // p_c
constexpr float kPt = 0.95f;   // p_t
constexpr float kGw = 0.082f;  // feature width w in degrees
constexpr float kQf = 0.5f;    // feature exponent q_f
constexpr float kHunt = 0.01f;

struct Col {
    float x, y, z;
};

// Spec 2.1: linear RGB -> XYZ with exact rational rows.
Col LinearRgbToXyz(Col c) {
    constexpr float kXr = 10135552.0f / 24577794.0f, kXg = 8788810.0f / 24577794.0f,
                    kXb = 4435075.0f / 24577794.0f;
    constexpr float kYr = 2613072.0f / 12288897.0f, kYg = 8788810.0f / 12288897.0f,
                    kYb = 887015.0f / 12288897.0f;
    constexpr float kZr = 1425312.0f / 73733382.0f, kZg = 8788810.0f / 73733382.0f,
                    kZb = 70074185.0f / 73733382.0f;
    return {kXr * c.x + kXg * c.y + kXb * c.z, kYr * c.x + kYg * c.y + kYb * c.z,
            kZr * c.x + kZg * c.y + kZb * c.z};
}

// Spec 2.1: XYZ -> linear RGB.
Col XyzToLinearRgb(Col c) {
    return {3.241003275f * c.x - 1.537398934f * c.y - 0.498615861f * c.z,
            -0.969224334f * c.x + 1.875930071f * c.y + 0.041554224f * c.z,
            0.055639423f * c.x - 0.204011202f * c.y + 1.057148933f * c.z};
}

// Spec 2.1: XYZ -> YCxCz and back.
Col XyzToYcxcz(Col c) {
    const float x = c.x * kInvWhite[0], y = c.y * kInvWhite[1], z = c.z * kInvWhite[2];
    return {116.0f * y - 16.0f, 500.0f * (x - y), 200.0f * (y - z)};
}
Col YcxczToXyz(Col c) {
    const float y = (c.x + 16.0f) / 116.0f;
    const float x = y + c.y / 500.0f;
    const float z = y - c.z / 200.0f;
    return {x * kWhite[0], y * kWhite[1], z * kWhite[2]};
}

// Spec 2.1: XYZ -> CIELAB with delta = 6/29.
Col XyzToLab(Col c) {
    constexpr float kDelta = 6.0f / 29.0f;
    constexpr float kDelta3 = kDelta * kDelta * kDelta;
    auto f = [](float t) {
        return t > kDelta3 ? std::cbrt(t) : t / (3.0f * kDelta * kDelta) + 4.0f / 29.0f;
    };
    const float fx = f(c.x * kInvWhite[0]), fy = f(c.y * kInvWhite[1]), fz = f(c.z * kInvWhite[2]);
    return {116.0f * fy - 16.0f, 500.0f * (fx - fy), 200.0f * (fy - fz)};
}

float Clamp01(float v) { return std::min(std::max(v, 0.0f), 1.0f); }
Col Clamp01(Col c) { return {Clamp01(c.x), Clamp01(c.y), Clamp01(c.z)}; }

// Spec 2.2 steps 4-5: Hunt adjustment then HyAB distance.
Col Hunt(Col lab) { return {lab.x, kHunt * lab.x * lab.y, kHunt * lab.x * lab.z}; }
float HyAb(Col a, Col b) {
    const float da = a.y - b.y, db = a.z - b.z;
    return std::fabs(a.x - b.x) + std::sqrt(da * da + db * db);
}

// A W x H float plane.
struct Plane {
    int w = 0, h = 0;
    std::vector<float> v;
    Plane() = default;
    Plane(int width, int height) : w(width), h(height), v(static_cast<size_t>(width) * height) {}
    float* Row(int y) { return v.data() + static_cast<size_t>(y) * w; }
    const float* Row(int y) const { return v.data() + static_cast<size_t>(y) * w; }
};

// Horizontal correlation out(x) = sum_k k[k] in(clamp(x + k - r)), clamp-to-edge.
void FilterRows(const Plane& in, const std::vector<float>& kernel, Plane* out) {
    const int r = static_cast<int>(kernel.size() / 2);
    *out = Plane(in.w, in.h);
    ParallelFor(in.h, 8, [&](int64_t yy) {
        const int y = static_cast<int>(yy);
        std::vector<float> padded(static_cast<size_t>(in.w + 2 * r));
        const float* src = in.Row(y);
        for (int i = 0; i < in.w + 2 * r; ++i)
            padded[i] = src[std::min(std::max(i - r, 0), in.w - 1)];
        // Accumulate tap by tap (the same summation order per pixel as a
        // per-pixel loop over k, but vectorizable over x without fast-math).
        float* dst = out->Row(y);
        std::fill(dst, dst + in.w, 0.0f);
        for (int k = 0; k <= 2 * r; ++k) {
            const float wk = kernel[k];
            const float* src_k = padded.data() + k;
            for (int x = 0; x < in.w; ++x) dst[x] += wk * src_k[x];
        }
    });
}

// Vertical correlation, clamp-to-edge.
void FilterColumns(const Plane& in, const std::vector<float>& kernel, Plane* out) {
    const int r = static_cast<int>(kernel.size() / 2);
    *out = Plane(in.w, in.h);
    ParallelFor(in.h, 8, [&](int64_t yy) {
        const int y = static_cast<int>(yy);
        float* dst = out->Row(y);
        std::fill(dst, dst + in.w, 0.0f);
        for (int k = 0; k <= 2 * r; ++k) {
            const float* src = in.Row(std::min(std::max(y + k - r, 0), in.h - 1));
            const float wk = kernel[k];
            for (int x = 0; x < in.w; ++x) dst[x] += wk * src[x];
        }
    });
}

void Separable(const Plane& in, const std::vector<float>& horizontal,
               const std::vector<float>& vertical, Plane* out) {
    Plane tmp;
    FilterRows(in, horizontal, &tmp);
    FilterColumns(tmp, vertical, out);
}

// One image's YCxCz planes (spec 2.2 step 1) from linear RGB clamped to [0, 1].
struct Ycxcz {
    Plane y, cx, cz;
};
Ycxcz ToYcxcz(const Image& image) {
    const int w = image.width(), h = image.height();
    Ycxcz out{Plane(w, h), Plane(w, h), Plane(w, h)};
    const float* p = image.data();
    ParallelFor(static_cast<int64_t>(w) * h, 4096, [&](int64_t i) {
        const Col rgb = Clamp01(Col{p[3 * i], p[3 * i + 1], p[3 * i + 2]});
        const Col c = XyzToYcxcz(LinearRgbToXyz(rgb));
        out.y.v[i] = c.x;
        out.cx.v[i] = c.y;
        out.cz.v[i] = c.z;
    });
    return out;
}

// Spec 2.2 step 2: the CSF-filtered YCxCz planes.
Ycxcz FilterCsf(const Ycxcz& in, const FlipCsfKernels& k) {
    Ycxcz out;
    Separable(in.y, k.yy, k.yy, &out.y);
    Separable(in.cx, k.cx, k.cx, &out.cx);
    Plane a, b;
    Separable(in.cz, k.cz1, k.cz1, &a);
    Separable(in.cz, k.cz2, k.cz2, &b);
    for (size_t i = 0; i < a.v.size(); ++i) a.v[i] += b.v[i];
    out.cz = std::move(a);
    return out;
}

// Spec 2.3: edge and point magnitudes of the normalized luminance yn.
void FeatureMagnitudes(const Plane& yy, const FlipFeatureKernels& k, Plane* edges, Plane* points) {
    Plane yn(yy.w, yy.h);
    for (size_t i = 0; i < yn.v.size(); ++i) yn.v[i] = (yy.v[i] + 16.0f) / 116.0f;
    Plane hg, hd1, hd2;
    FilterRows(yn, k.gauss, &hg);
    FilterRows(yn, k.d1, &hd1);
    FilterRows(yn, k.d2, &hd2);
    Plane ex, ey, px, py;
    FilterColumns(hd1, k.gauss, &ex);  // D1(i) G(j)
    FilterColumns(hg, k.d1, &ey);      // G(i) D1(j)
    FilterColumns(hd2, k.gauss, &px);  // D2(i) G(j)
    FilterColumns(hg, k.d2, &py);      // G(i) D2(j)
    *edges = Plane(yy.w, yy.h);
    *points = Plane(yy.w, yy.h);
    for (size_t i = 0; i < yn.v.size(); ++i) {
        edges->v[i] = std::sqrt(ex.v[i] * ex.v[i] + ey.v[i] * ey.v[i]);
        points->v[i] = std::sqrt(px.v[i] * px.v[i] + py.v[i] * py.v[i]);
    }
}

void CheckPair(const Image& a, const Image& b) {
    if (a.empty() || b.empty()) Fail("FLIP needs two non-empty images");
    if (a.width() != b.width() || a.height() != b.height()) {
        Fail("FLIP needs images of the same size (reference ", a.width(), "x", a.height(),
             ", test ", b.width(), "x", b.height(), ")");
    }
    for (const Image* img : {&a, &b}) {
        for (size_t i = 0; i < img->size(); ++i) {
            if (!std::isfinite(img->data()[i])) {
                Fail("FLIP: the ", img == &a ? "reference" : "test",
                     " image holds a NaN or infinite value");
            }
        }
    }
}

double Ppd(const FlipOptions& o) {
    CheckFlipPpd(o.ppd);
    return o.ppd > 0.0 ? o.ppd : FlipDefaultPpd();
}

// Spec 2: the LDR-FLIP map of two linear RGB images (clamped here).
std::vector<float> LdrFlipMap(const Image& ref, const Image& test, double ppd) {
    const FlipCsfKernels csf = MakeFlipCsfKernels(ppd);
    const FlipFeatureKernels feat = MakeFlipFeatureKernels(ppd);
    const Ycxcz ref_c = ToYcxcz(ref), test_c = ToYcxcz(test);
    const Ycxcz ref_f = FilterCsf(ref_c, csf), test_f = FilterCsf(test_c, csf);
    Plane ref_e, ref_p, test_e, test_p;
    FeatureMagnitudes(ref_c.y, feat, &ref_e, &ref_p);
    FeatureMagnitudes(test_c.y, feat, &test_e, &test_p);

    const float cmax = FlipMaxColorDistance();
    const float pccmax = kPc * cmax;
    const float inv_sqrt2 = 1.0f / std::sqrt(2.0f);
    const size_t n = ref_c.y.v.size();
    std::vector<float> map(n);
    ParallelFor(static_cast<int64_t>(n), 4096, [&](int64_t i) {
        // Spec 2.2 step 3: back to linear RGB, clamp, then CIELAB; steps 4-8.
        auto lab = [&](const Ycxcz& f) {
            const Col rgb = Clamp01(XyzToLinearRgb(YcxczToXyz({f.y.v[i], f.cx.v[i], f.cz.v[i]})));
            return Hunt(XyzToLab(LinearRgbToXyz(rgb)));
        };
        const float e = std::pow(HyAb(lab(ref_f), lab(test_f)), kQc);
        const float dec =
            e < pccmax ? e * kPt / pccmax : kPt + (e - pccmax) / (cmax - pccmax) * (1.0f - kPt);
        // Spec 2.3 step 5.
        const float de = std::fabs(ref_e.v[i] - test_e.v[i]);
        const float dp = std::fabs(ref_p.v[i] - test_p.v[i]);
        const float def = std::pow(inv_sqrt2 * std::max(de, dp), kQf);
        // Spec 2.4.
        map[i] = std::pow(dec, 1.0f - def);
    });
    return map;
}

double MeanOf(const std::vector<float>& map) {
    // Spec 4: summed in float32, raster order.
    float sum = 0.0f;
    for (float v : map) sum += v;
    return static_cast<double>(sum) / static_cast<double>(map.size());
}

// Tone-mapper coefficients k0..k5 of spec 3.1.
struct Coefficients {
    float k[6];
};
Coefficients CoefficientsOf(FlipToneMapper t) {
    switch (t) {
        case FlipToneMapper::kAces:
            return {{0.6f * 0.6f * 2.51f, 0.6f * 0.03f, 0.0f, 0.6f * 0.6f * 2.43f, 0.6f * 0.59f,
                     0.14f}};
        case FlipToneMapper::kHable:
            return {{0.231683f, 0.013791f, 0.0f, 0.18f, 0.3f, 0.018f}};
        case FlipToneMapper::kReinhard:
            break;
    }
    return {{0.0f, 1.0f, 0.0f, 0.0f, 1.0f, 1.0f}};
}

float Luminance(const Rgb& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

}  // namespace

FlipToneMapper ParseFlipToneMapper(const std::string& name) {
    if (name == "aces" || name == "ACES") return FlipToneMapper::kAces;
    if (name == "hable" || name == "Hable") return FlipToneMapper::kHable;
    if (name == "reinhard" || name == "Reinhard") return FlipToneMapper::kReinhard;
    Fail("unknown tone mapper '", name, "' (tone mappers: aces, hable, reinhard)");
}

const char* FlipToneMapperName(FlipToneMapper t) {
    switch (t) {
        case FlipToneMapper::kAces:
            return "aces";
        case FlipToneMapper::kHable:
            return "hable";
        case FlipToneMapper::kReinhard:
            return "reinhard";
    }
    return "aces";
}

double FlipPixelsPerDegree(double distance_m, double monitor_width_m, double resolution_px) {
    return distance_m * (resolution_px / monitor_width_m) * (static_cast<double>(kFlipPi) / 180.0);
}

void CheckFlipPpd(double ppd) {
    if (!(ppd >= 0.0 && ppd <= kFlipMaxPpd)) {
        Fail("--ppd must be in (0, ", kFlipMaxPpd, "] pixels per degree (0 or absent: the default ",
             FlipDefaultPpd(), "), got ", ppd);
    }
}

double FlipDefaultPpd() {
    // Spec 0, evaluated in float32 as the reference tool: 67.0206451.
    return static_cast<double>(0.7f * (3840.0f / 0.7f) * (kFlipPi / 180.0f));
}

FlipCsfKernels MakeFlipCsfKernels(double ppd_in) {
    const float ppd = static_cast<float>(ppd_in);
    // Spec 2.2 step 2 table: (a1, b1, a2, b2) per channel.
    const float yy[4] = {1.0f, 0.0047f, 0.0f, 1e-5f};
    const float cx[4] = {1.0f, 0.0053f, 0.0f, 1e-5f};
    const float cz[4] = {34.1f, 0.04f, 13.5f, 0.025f};
    const float bmax = 0.04f;
    FlipCsfKernels k;
    k.radius =
        static_cast<int>(std::ceil(3.0f * std::sqrt(bmax / (2.0f * kFlipPi * kFlipPi)) * ppd));
    const int r = k.radius;
    auto gauss = [&](float a, float b, bool sqrt_amplitude) {
        std::vector<float> g(static_cast<size_t>(2 * r + 1));
        const float amp = a * std::sqrt(kFlipPi / b);
        for (int i = -r; i <= r; ++i) {
            const float x = static_cast<float>(i) / ppd;
            g[i + r] =
                (sqrt_amplitude ? std::sqrt(amp) : amp) * std::exp(-kFlipPi * kFlipPi * x * x / b);
        }
        return g;
    };
    auto normalize = [](std::vector<float> g) {
        float s = 0.0f;
        for (float v : g) s += v;
        for (float& v : g) v /= s;
        return g;
    };
    k.yy = normalize(gauss(yy[0], yy[1], false));
    k.cx = normalize(gauss(cx[0], cx[1], false));
    // Cz: two Gaussian terms; each 1-D piece carries sqrt of its amplitude, and
    // both are divided by sqrt(S1^2 + S2^2) so the 2-D sum h1h1 + h2h2 is 1.
    k.cz1 = gauss(cz[0], cz[1], true);
    k.cz2 = gauss(cz[2], cz[3], true);
    float s1 = 0.0f, s2 = 0.0f;
    for (float v : k.cz1) s1 += v;
    for (float v : k.cz2) s2 += v;
    const float norm = std::sqrt(s1 * s1 + s2 * s2);
    for (float& v : k.cz1) v /= norm;
    for (float& v : k.cz2) v /= norm;
    return k;
}

FlipFeatureKernels MakeFlipFeatureKernels(double ppd_in) {
    const float ppd = static_cast<float>(ppd_in);
    const float sigma = 0.5f * kGw * ppd;  // spec 2.3 step 2
    FlipFeatureKernels k;
    k.radius = static_cast<int>(std::ceil(3.0f * sigma));
    const int r = k.radius;
    const size_t n = static_cast<size_t>(2 * r + 1);
    k.gauss.resize(n);
    k.d1.resize(n);
    k.d2.resize(n);
    for (int i = -r; i <= r; ++i) {
        const float x = static_cast<float>(i);
        const float g = std::exp(-x * x / (2.0f * sigma * sigma));
        k.gauss[i + r] = g;
        k.d1[i + r] = -x * g;
        k.d2[i + r] = (x * x / (sigma * sigma) - 1.0f) * g;
    }
    float sg = 0.0f;
    for (float v : k.gauss) sg += v;
    for (float& v : k.gauss) v /= sg;
    // Positive taps sum to +1, negative taps to -1.
    auto split_normalize = [](std::vector<float>* d) {
        float pos = 0.0f, neg = 0.0f;
        for (float v : *d) (v > 0.0f ? pos : neg) += v;
        for (float& v : *d) {
            if (v > 0.0f)
                v /= pos;
            else if (v < 0.0f)
                v /= -neg;
        }
    };
    split_normalize(&k.d1);
    split_normalize(&k.d2);
    return k;
}

float FlipMaxColorDistance() {
    const Col green = Hunt(XyzToLab(LinearRgbToXyz({0.0f, 1.0f, 0.0f})));
    const Col blue = Hunt(XyzToLab(LinearRgbToXyz({0.0f, 0.0f, 1.0f})));
    return std::pow(HyAb(green, blue), kQc);
}

FlipResult LdrFlip(const Image& reference, const Image& test, const FlipOptions& options) {
    CheckPair(reference, test);
    FlipResult r;
    r.width = reference.width();
    r.height = reference.height();
    r.map = LdrFlipMap(reference, test, Ppd(options));
    r.mean = MeanOf(r.map);
    return r;
}

double FlipToneMapperThreshold(FlipToneMapper t) {
    // Spec 3.2: the larger root of (k0 - t k3) x^2 + (k1 - t k4) x + (k2 - t k5) = 0, t = 0.85.
    const Coefficients c = CoefficientsOf(t);
    const double th = 0.85;
    const double a = static_cast<double>(c.k[0]) - th * static_cast<double>(c.k[3]);
    const double b = static_cast<double>(c.k[1]) - th * static_cast<double>(c.k[4]);
    const double cc = static_cast<double>(c.k[2]) - th * static_cast<double>(c.k[5]);
    if (a == 0.0) return -cc / b;
    const double d1 = -b / (2.0 * a);
    return d1 + std::sqrt(d1 * d1 - cc / a);
}

Rgb FlipToneMap(FlipToneMapper t, const Rgb& c) {
    if (t == FlipToneMapper::kReinhard) {
        // Spec 3.1 caveat: luminance-based, C' = C / (1 + L(C)).
        return c / (1.0f + Luminance(c));
    }
    const Coefficients k = CoefficientsOf(t);
    auto curve = [&](float x) {
        return (k.k[0] * x * x + k.k[1] * x + k.k[2]) / (k.k[3] * x * x + k.k[4] * x + k.k[5]);
    };
    return {curve(c.x), curve(c.y), curve(c.z)};
}

FlipExposureRange FlipComputeExposureRange(const Image& reference, const FlipOptions& options) {
    const double xt = FlipToneMapperThreshold(options.tone_mapper);
    const size_t n = static_cast<size_t>(reference.width()) * reference.height();
    std::vector<float> lum(n);
    const float* p = reference.data();
    float y_max = 0.0f;
    for (size_t i = 0; i < n; ++i) {
        lum[i] = Luminance({p[3 * i], p[3 * i + 1], p[3 * i + 2]});
        y_max = i == 0 ? lum[i] : std::max(y_max, lum[i]);
    }
    // Spec 3.2: the element at floor(N/2) in sorted order, zeros included.
    float y_median = 0.0f;
    if (n > 0) {
        std::vector<float> sorted = lum;
        std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(n / 2),
                         sorted.end());
        y_median = sorted[n / 2];
    }
    if (!(y_median > 0.0f)) {
        // Deviation (see flip.h): the median of the positive luminances.
        std::vector<float> positive;
        for (float v : lum) {
            if (v > 0.0f) positive.push_back(v);
        }
        if (!positive.empty()) {
            const size_t m = positive.size() / 2;
            std::nth_element(positive.begin(), positive.begin() + static_cast<std::ptrdiff_t>(m),
                             positive.end());
            y_median = positive[m];
        }
    }
    FlipExposureRange r;
    if (y_max > 0.0f && y_median > 0.0f) {
        r.start = std::log2(xt / static_cast<double>(y_max));
        r.stop = std::log2(xt / static_cast<double>(y_median));
    }
    if (options.has_start_exposure) r.start = options.start_exposure;
    if (options.has_stop_exposure) r.stop = options.stop_exposure;
    if (!std::isfinite(r.start) || !std::isfinite(r.stop)) {
        Fail("FLIP: the exposure range is not finite (start ", r.start, ", stop ", r.stop, ")");
    }
    if (r.start > r.stop) {
        Fail("FLIP: start exposure ", r.start, " is greater than stop exposure ", r.stop);
    }
    r.count = options.num_exposures > 0
                  ? options.num_exposures
                  : std::max(2, static_cast<int>(std::ceil(r.stop - r.start)));
    if (r.count > 1000) Fail("FLIP: too many exposures (", r.count, ")");
    return r;
}

FlipExposureSetup ParseFlipExposureSetup(const std::string& name) {
    if (name == "atmos") return FlipExposureSetup::kAtmos;
    if (name == "thesis") return FlipExposureSetup::kThesis;
    Fail("--exposure must be atmos or thesis, got '", name, "'");
}
const char* FlipExposureSetupName(FlipExposureSetup s) {
    return s == FlipExposureSetup::kThesis ? "thesis" : "atmos";
}

FlipResult HdrFlip(const Image& reference, const Image& test, const FlipOptions& options) {
    CheckPair(reference, test);
    if (options.exposure_setup == FlipExposureSetup::kThesis) {
        // Leenman's 2025 thesis section 11.5: 1e-9 added to every channel of every pixel.
        auto offset = [](const Image& in) {
            Image out = in;
            float* d = out.data();
            const size_t n = static_cast<size_t>(out.width()) * out.height() * 3;
            for (size_t i = 0; i < n; ++i) d[i] += kFlipThesisOffset;
            return out;
        };
        FlipOptions plain = options;
        plain.exposure_setup = FlipExposureSetup::kAtmos;
        return HdrFlip(offset(reference), offset(test), plain);
    }
    FlipResult r;
    r.hdr = true;
    r.width = reference.width();
    r.height = reference.height();
    r.exposures = FlipComputeExposureRange(reference, options);
    const double ppd = Ppd(options);
    const int count = r.exposures.count;
    const double step = count > 1 ? (r.exposures.stop - r.exposures.start) / (count - 1) : 0.0;
    r.map.assign(static_cast<size_t>(r.width) * r.height, 0.0f);
    Image ref_i(r.width, r.height), test_i(r.width, r.height);
    for (int e = 0; e < count; ++e) {
        // Spec 3.3: ref_i = clamp01(T(ref * 2^c_i)), straight into LDR-FLIP.
        const float scale = static_cast<float>(std::exp2(r.exposures.start + e * step));
        auto expose = [&](const Image& in, Image* out) {
            const float* src = in.data();
            float* dst = out->data();
            const int64_t n = static_cast<int64_t>(r.width) * r.height;
            ParallelFor(n, 4096, [&](int64_t i) {
                const Rgb c = FlipToneMap(options.tone_mapper,
                                          Rgb(src[3 * i], src[3 * i + 1], src[3 * i + 2]) * scale);
                dst[3 * i] = Clamp01(c.x);
                dst[3 * i + 1] = Clamp01(c.y);
                dst[3 * i + 2] = Clamp01(c.z);
            });
        };
        expose(reference, &ref_i);
        expose(test, &test_i);
        const std::vector<float> ldr = LdrFlipMap(ref_i, test_i, ppd);
        for (size_t i = 0; i < ldr.size(); ++i) {
            if (ldr[i] > r.map[i]) r.map[i] = ldr[i];
        }
    }
    r.mean = MeanOf(r.map);
    return r;
}

void FlipMagma(float value, unsigned char rgb[3]) {
    // Anchor colours of matplotlib's magma at 0, 1/8, ..., 1 (sRGB, [0, 1]).
    static const float kAnchors[9][3] = {
        {0.001462f, 0.000466f, 0.013866f}, {0.078815f, 0.054184f, 0.211667f},
        {0.232077f, 0.059889f, 0.437695f}, {0.390384f, 0.100379f, 0.501864f},
        {0.550287f, 0.161158f, 0.505719f}, {0.716387f, 0.214982f, 0.475290f},
        {0.868793f, 0.287728f, 0.409303f}, {0.967671f, 0.439703f, 0.359810f},
        {0.987053f, 0.991438f, 0.749504f}};
    float v = std::isfinite(value) ? Clamp01(value) : 0.0f;
    const float t = v * 8.0f;
    const int i = std::min(static_cast<int>(t), 7);
    const float f = t - static_cast<float>(i);
    for (int c = 0; c < 3; ++c) {
        const float s = kAnchors[i][c] + f * (kAnchors[i + 1][c] - kAnchors[i][c]);
        rgb[c] = static_cast<unsigned char>(std::lround(Clamp01(s) * 255.0f));
    }
}

void WriteColorMappedPng(const std::vector<float>& map, int width, int height,
                         const std::string& path) {
    if (map.size() != static_cast<size_t>(width) * height || map.empty()) {
        Fail("cannot write '", path, "': the map does not match its size");
    }
    std::vector<std::uint8_t> bytes(map.size() * 3);
    for (size_t i = 0; i < map.size(); ++i) FlipMagma(map[i], &bytes[3 * i]);
    WriteThroughTemporary(path, [&](const std::string& temporary) {
        detail::WritePngBytes(bytes, width, height, temporary);
    });
}

}  // namespace atmos
