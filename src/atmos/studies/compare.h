// atmos studies: the compare study (`atmos compare`, Python atmos.compare):
// every model against the reference at the views (harness/compare.h runs it and
// writes its images; the tables and the report are its writers).
//
// A CompareRequest is what a user asks for; ResolveCompareConfig applies the
// defaults and the policy (the reference and its Monte Carlo estimate, the
// shipped references, the cache directory, the spectral checks) and gives the
// CompareConfig that RunCompare runs. Every default is here or in CompareConfig.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "harness/compare.h"

namespace atmos {

// A Monte Carlo reference's estimate when no flag sets it: a noise target (the
// HDR-FLIP between its two halves) capped at kCompareReferenceCap paths per
// pixel; a fixed count alone is kCompareReferenceSpp unless given.
constexpr int64_t kCompareReferenceSpp = 64;
constexpr double kCompareReferenceNoise = 0.01;
constexpr int64_t kCompareReferenceCap = 512;

// The help of compare's --views and --luminance (the CLI's flags).
constexpr const char* kCompareViewsHelp =
    "views (default: all 12; transmittance: 5): names, and FILE.json files of named custom "
    "views {\"NAME\": {\"camera\": \"KEY=VALUE,...\", \"sun\": \"KEY=VALUE,...\"}} in the "
    "vocabulary of render --camera and --sun (docs/manual.md)";
constexpr const char* kCompareLuminanceHelp =
    "photopic luminance in cd m^-2: luminance.csv (mean over each image, its sky and its "
    "ground) and the report's profiles (docs/manual.md: what it means for RGB models)";

struct CompareRequest {
    std::vector<std::string>
        models;  // specs; empty: every model with the quantity but the reference
    // Views: names of the 12, or views files (NAME.json, studies/compare_views.h)
    // whose entries join in the file's order; empty: DefaultCompareViews(quantity).
    std::vector<std::string> views;
    // Custom views as JSON text (Python's views=dict), after `views`' entries.
    std::string views_json;
    int width = 320, height = 180;
    std::string quantity = "radiance";  // radiance (HDR-FLIP) or transmittance (LDR-FLIP)
    // The reference NAME[:OPTION=VALUE...]; unset: CompareConfig's (the path tracer).
    std::optional<std::string> reference;
    // A Monte Carlo reference's estimate: the noise target alone (default
    // kCompareReferenceNoise, capped at spp or kCompareReferenceCap), or a
    // fixed spp alone (noise off; default kCompareReferenceSpp); 0 noise: fixed.
    std::optional<int64_t> reference_spp, reference_seed;
    std::optional<double> reference_noise;
    std::string atmosphere = "earth";  // preset name or JSON file
    std::vector<std::string> sets;     // FIELD=VALUE overrides
    std::string output_dir;            // empty: out (radiance) or out/transmittance
    // The render cache: unset: out/cache, or OUTPUT/cache when output_dir is
    // given; no_cache: none. CUDA images get their own sub-directory.
    std::optional<std::string> cache_dir;
    bool no_cache = false;
    bool cuda = false;  // the images come from the CUDA backend
    bool write_npy = true;
    bool show_progress = true;
    double ppd = 0.0;                  // FLIP pixels per degree (0: the default 67.0206)
    std::string tone_mapper = "aces";  // HDR-FLIP: aces, hable, reinhard
    std::string exposure = "atmos";    // HDR-FLIP black pixels: atmos or thesis
    // Spectral: every model and the reference at these wavelengths (linear sRGB with `white`).
    std::vector<double> wavelengths;
    std::string colour = "srgb";  // only srgb compares
    std::string white = "d65";
    SpectralBatching batching;
    // What RGB costs: the reference alone at these wavelengths, the models in RGB.
    std::vector<double> reference_wavelengths;
    // Shipped references: unset: data/references/WxH of the source tree when it
    // exists and the reference renders to a noise target; no_shipped: never.
    std::optional<std::string> shipped_references;
    bool no_shipped = false;
    // Photopic luminance in cd m^-2 (luminance.csv, the report's profiles):
    // Rec. 709 Y of the images (for a spectral run the CIE 1931 Y, the images
    // being linear sRGB from XYZ) times a scale, per unit of the view's
    // sun_irradiance. An atmosphere with a tabulated solar spectrum
    // (HasPhysicalSolarSpectrum: W m^-2 nm^-1) makes the images W m^-2 sr^-1
    // nm^-1: 683 lm/W x 106.86 nm. Otherwise the images are radiance per unit
    // solar irradiance: times the Sun's illuminance at the top of the
    // atmosphere at 1 AU computed from the ASTM G173 extraterrestrial spectrum
    // (683 x integral of E y dlambda, about 1.33e5 lx). For RGB models Y takes
    // the three channels as the luminance-weighted samples of the spectrum.
    // Radiance only; not with reference_wavelengths.
    bool luminance = false;
    std::string command_line;  // for the report
};

// The defaults and the policy; throws atmos::Error naming the flag.
CompareConfig ResolveCompareConfig(const CompareRequest& request);

// The Sun's illuminance (lx) at the top of the atmosphere at 1 AU: 683 lm/W
// times the integral of the ASTM G173 extraterrestrial spectrum (W m^-2 nm^-1)
// against the CIE 1931 y function.
double SolarIlluminanceLux();
// The atmosphere's solar spectrum is physical: a spectral file that tabulates
// it (earth-spectral: ASTM G173, W m^-2 nm^-1); else the images are per unit
// solar irradiance.
bool HasPhysicalSolarSpectrum(const SpectralAtmosphere& atmosphere);

}  // namespace atmos
