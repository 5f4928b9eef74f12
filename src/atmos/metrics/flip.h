// atmos: the FLIP image difference metric, LDR and HDR.
//
// Source: Andersson et al., "FLIP: A Difference Evaluator for Alternating
// Images", HPG 2020 (LDR-FLIP), and Andersson et al., "Visualizing Errors in
// Rendered High Dynamic Range Images", EG 2021 (HDR-FLIP), implemented from
// the project's own specification /work/shared/specs/flip.md (section numbers
// below refer to it). Every constant of that spec is here; borders are
// clamp-to-edge in every convolution; the per-pixel error map is returned.
//
// Deviation (documented, deliberate): the HDR exposure range of spec section
// 3.2 divides by the reference's median luminance, which is 0 when at least
// half of the pixels are black (e.g. the night side of the planet). The
// reference tool then produces an infinite stop exposure and silently returns
// a zero map (Leenman's 2025 thesis section 11.5 had to add 1e-9 to every pixel). Here the
// median is then taken over the pixels with positive luminance, and an image
// with no positive pixel uses start = stop = 0. Images whose median is
// positive are unaffected.
#pragma once

#include <string>
#include <vector>

#include "atmos/image.h"

namespace atmos {

// Spec section 3.1.
enum class FlipToneMapper { kAces, kHable, kReinhard };
FlipToneMapper ParseFlipToneMapper(const std::string& name);  // aces | hable | reinhard
const char* FlipToneMapperName(FlipToneMapper t);

// Spec section 0: ppd = d * (R / w) * (pi / 180).
double FlipPixelsPerDegree(double distance_m, double monitor_width_m, double resolution_px);
// The default viewing condition (0.7 m, 0.7 m, 3840 px): 67.0206451.
double FlipDefaultPpd();
// The largest pixels per degree accepted: the filters' radius grows with ppd
// (about 0.2 ppd pixels), so a larger value only costs time (and overflowed the
// radius at 1e12).
constexpr double kFlipMaxPpd = 1e4;
// Throws atmos::Error unless ppd is 0 (the default) or in (0, kFlipMaxPpd].
void CheckFlipPpd(double ppd);

// HDR-FLIP's handling of black pixels (issue 15). kAtmos: the deviation
// above (median over the positive luminances when the median is 0). kThesis:
// Leenman's 2025 thesis section 11.5, "a value of 1e-9 is added to the color channels of
// every pixel" of both images, then spec 3.2 unchanged (the median over all
// pixels, which is about 1e-9 when half of them were black: many more
// exposures, each brightening the dark part).
enum class FlipExposureSetup { kAtmos, kThesis };
FlipExposureSetup ParseFlipExposureSetup(const std::string& name);  // atmos | thesis
const char* FlipExposureSetupName(FlipExposureSetup s);
constexpr float kFlipThesisOffset = 1e-9f;

struct FlipOptions {
    double ppd = 0.0;                                              // <= 0: FlipDefaultPpd()
    FlipExposureSetup exposure_setup = FlipExposureSetup::kAtmos;  // HDR only
    FlipToneMapper tone_mapper = FlipToneMapper::kAces;
    // HDR only: user-given exposure range (spec 3.2); each replaces the computed value alone.
    bool has_start_exposure = false;
    double start_exposure = 0.0;
    bool has_stop_exposure = false;
    double stop_exposure = 0.0;
    int num_exposures = 0;  // <= 0: max(2, ceil(stop - start))
};

struct FlipExposureRange {
    double start = 0.0;
    double stop = 0.0;
    int count = 0;
};

struct FlipResult {
    int width = 0;
    int height = 0;
    std::vector<float> map;  // per-pixel FLIP in [0, 1], row-major, top row first
    double mean = 0.0;       // float32 sum in raster order / (W*H), as the reference tool
    bool hdr = false;
    FlipExposureRange exposures;  // HDR only
};

// LDR-FLIP (spec section 2) of two linear-RGB images (clamped to [0, 1] first).
// Throws atmos::Error if the sizes differ or an image is empty.
FlipResult LdrFlip(const Image& reference, const Image& test, const FlipOptions& options = {});
// HDR-FLIP (spec section 3) of two linear HDR images.
FlipResult HdrFlip(const Image& reference, const Image& test, const FlipOptions& options = {});

// ---- Pieces, exposed for the tests --------------------------------------------------------

// The larger root x_t of T(x) = 0.85 for a tone mapper (spec 3.2).
double FlipToneMapperThreshold(FlipToneMapper t);
// The tone-mapping curve of spec 3.1 applied to one colour (Reinhard: luminance-based).
Rgb FlipToneMap(FlipToneMapper t, const Rgb& c);
// Spec 3.2: the exposure range computed from the reference image (and options).
FlipExposureRange FlipComputeExposureRange(const Image& reference, const FlipOptions& options);

// Spec 2.2 step 2: CSF kernel radius and the separable 1-D pieces. `yy` and
// `cx` sum to 1; `cz1`, `cz2` are the two Gaussian terms of the blue-yellow
// channel, scaled so that the 2-D kernel they make sums to 1.
struct FlipCsfKernels {
    int radius = 0;
    std::vector<float> yy, cx, cz1, cz2;
};
FlipCsfKernels MakeFlipCsfKernels(double ppd);
// Spec 2.3: the feature kernels (Gaussian sums 1; D1, D2 positive taps sum +1,
// negative taps -1), taps at integer offsets in [-radius, radius].
struct FlipFeatureKernels {
    int radius = 0;
    std::vector<float> gauss, d1, d2;
};
FlipFeatureKernels MakeFlipFeatureKernels(double ppd);
// Spec 2.2 step 7: cmax = HyAB(Hunt(Lab(green)), Hunt(Lab(blue)))^0.7 = 41.2760963.
float FlipMaxColorDistance();

// ---- Error map display ---------------------------------------------------------------------

// The FLIP tool's colour map (magma, approximated by 9 anchor colours of
// matplotlib's magma, linearly interpolated), 8-bit sRGB bytes for a value in [0, 1].
void FlipMagma(float value, unsigned char rgb[3]);
// Writes a per-pixel map of values in [0, 1] as a magma-coloured 8-bit PNG.
void WriteColorMappedPng(const std::vector<float>& map, int width, int height,
                         const std::string& path);

}  // namespace atmos
