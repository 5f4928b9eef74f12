// atmos: the comparison harness behind `atmos compare` (DESIGN.md; Leenman 2025,
// "A visual and performance comparison of atmospheric scattering models",
// sections 11.5-11.7 and Appendix A-D).
//
// For each view and model: render (or load from the render cache) the
// reference and the model, keep the images and the FLIP error map in the
// result, and collect FLIP and RMSE into tables laid out like the thesis's
// appendices: rows = views, columns = models, the best (lowest) of each row
// named in a last column "best". Radiance uses HDR-FLIP on the linear images;
// transmittance uses LDR-FLIP (values in [0, 1]), as the thesis did. The run
// does no file output (the render cache aside); the writers below write the
// images (PNG, EXR, NPY), the FLIP map (colour-mapped PNG), the error image
// (per-channel |difference|, EXR and PNG), the tables and the report from it.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "atmos/spectral.h"
#include "atmos/view.h"
#include "harness/loc.h"
#include "harness/profiles.h"
#include "harness/spectral_run.h"
#include "metrics/flip.h"

namespace atmos {

struct CompareConfig {
    std::vector<std::string>
        models;  // empty: every registered model with the quantity, but Monte Carlo ones
    std::vector<std::string> views;  // empty: DefaultCompareViews(quantity)
    // Custom views (--views FILE.json, studies/compare_views.h) for
    // `atmosphere`: `views` names them among the 12 named ones.
    std::vector<View> custom_views;
    int width = 320;
    int height = 180;
    Quantity quantity = Quantity::kRadiance;
    std::string reference_model = "reference";  // the path tracer: the one default reference
    std::map<std::string, std::string> reference_options;
    // A Monte Carlo reference's estimate (spp, seed; split into halves, see
    // CompareRow). With reference_monte_carlo.noise_target > 0 each view's
    // reference renders until its halves' HDR-FLIP is at or below the target
    // (spp: the cap).
    MonteCarloSettings reference_monte_carlo;
    std::string reference_note;  // how the reference was chosen (shown in the report)
    // A directory of shipped references (harness/shipped_references.h; ""
    // none): a view whose shipped image matches the run (fingerprint, view, an
    // estimate at least as good as the run's) is read instead of rendered; any
    // other view is rendered and the reason printed. RGB radiance with a Monte
    // Carlo reference only. A damaged set is a warning: every view renders.
    std::string shipped_references;
    std::string atmosphere_name = "earth";
    AtmosphereParameters atmosphere;
    // Spectral comparison (--wavelengths; harness/spectral_run.h): every model and
    // the reference rendered at these wavelengths of `spectral_atmosphere` (each
    // batch prepared once per model for all views, RenderSpectralRequests; no
    // render cache) and compared as linear sRGB with `white`. Empty: the RGB
    // comparison.
    std::vector<double> wavelengths;
    // What RGB costs (--reference-wavelengths): the reference alone rendered at
    // these wavelengths of `spectral_atmosphere` (as linear sRGB with `white`),
    // the models in RGB; each model is also compared with the RGB reference
    // (CompareCell::flip_rgb_reference, rgb_cost.csv). Empty: off.
    std::vector<double> reference_wavelengths;
    SpectralAtmosphere spectral_atmosphere;
    WhitePoint white = WhitePoint::kD65;
    SpectralBatching batching;  // a spectral run's batches (layout, Monte Carlo seeds)
    std::string output_dir = "out";
    std::string cache_dir;  // empty: no cache
    FlipOptions flip;
    bool write_npy = true;
    bool show_progress = true;
    std::string command_line;  // for the report
    // --luminance: each image's mean photopic luminance (luminance.csv, the
    // report) and the profiles in cd m^-2: Rec. 709 Y of the image times
    // luminance_scale / the view's sun_irradiance (studies/compare.h says what
    // the scale is for RGB and spectral runs; luminance_note says it in the report).
    bool luminance = false;
    double luminance_scale = 0.0;
    std::string luminance_note;
    // How the models rendered, for the cost columns: "CPU" or "CUDA GPU".
    std::string machine = "CPU";
};

// Mean luminance over the image and its regions (--luminance: cd m^-2).
struct CompareLuminance {
    double all = -1.0;
    double sky = -1.0;
    double ground = -1.0;
};

struct CompareCell {
    double flip = 0.0;
    double rmse = 0.0;
    double render_seconds = 0.0;
    // --reference-wavelengths: HDR-FLIP against the RGB reference (else < 0).
    double flip_rgb_reference = -1.0;
    bool cached = false;
    // Sky and ground apart (harness/compare_regions.h): FLIP and RMSE over
    // the sky and over the ground pixels (NaN when the view has none).
    double flip_sky = 0.0, flip_ground = 0.0;
    double rmse_sky = 0.0, rmse_ground = 0.0;
    CompareLuminance luminance;  // --luminance
    std::string validity_note;   // non-empty: the view is outside the model's declared validity
    // FLIP at or below the row's reference_noise: the difference to the
    // reference is not resolved by it.
    bool within_noise = false;
    std::string image_png;  // paths relative to the output directory
    std::string flip_png;
    std::string rmse_png;
    // The model's image and its per-pixel FLIP map against the reference
    // (width x height, row-major; WriteCompareImages writes them).
    Image image;
    std::vector<float> flip_map;
};

struct CompareRow {
    std::string view;   // the view's name
    std::string label;  // the table's row label (transmittance: ground, plane, ...)
    std::string description;
    std::string reference_png;
    float exposure = 1.0f;  // the view's PNG exposure (transmittance: 1)
    // The reference's image and, with --reference-wavelengths, the RGB
    // reference's (else empty); WriteCompareImages writes them.
    Image reference_image;
    Image rgb_reference_image;
    double reference_seconds = 0.0;
    bool reference_cached = false;
    // Where the reference came from: "rendered", "cached" or "shipped"
    // (CompareConfig::shipped_references; then reference_provenance names the
    // provenance file and the commit that rendered it).
    std::string reference_source = "rendered";
    std::string reference_provenance;
    // --reference-wavelengths: the RGB reference's render time (else 0).
    double rgb_reference_seconds = 0.0;
    // A Monte Carlo reference is rendered as two independent halves (spp/2
    // each, seeds 2s+1 and 2s+2) and averaged; this is the HDR-FLIP between the
    // halves: the reference's own noise, an upper bound for its error at the full
    // spp. Negative when not measured (deterministic reference, transmittance).
    double reference_noise = -1.0;
    int64_t reference_spp = 0;  // paths per pixel of the (whole) reference
    // Twice the reference's RMS standard error (sqrt of the mean per-pixel
    // variance of its estimate): its noise in RMSE units, the tie tolerance of
    // the RMSE table. Negative when not known.
    double reference_rmse_noise = -1.0;
    // Sky and ground: pixel counts; the reference's noise per region: FLIP
    // between its halves (measured only for a fixed-spp split reference; else
    // < 0) and twice its RMS standard error (< 0 when not known); its mean
    // luminance (Rec. 709 Y, image units) per region.
    int64_t sky_pixels = 0, ground_pixels = 0;
    double reference_noise_sky = -1.0, reference_noise_ground = -1.0;
    double reference_rmse_noise_sky = -1.0, reference_rmse_noise_ground = -1.0;
    double reference_mean_sky = 0.0, reference_mean_ground = 0.0;
    CompareLuminance reference_luminance;  // --luminance
    double luminance_scale = 0.0;          // --luminance: cd m^-2 per unit Y of this view's images
    // The view's regimes (harness/regimes.h): where the camera is, how the sun lights it.
    std::string place, light;
    std::vector<CompareCell> cells;  // one per model, in CompareResult::models order
    // Luminance along the column through the sun and the row above the
    // horizon (profiles.h): the reference, its standard deviation (empty when
    // not known) and each model (CompareResult::models order).
    struct Profile {
        ProfileLine line;
        std::vector<double> reference;
        std::vector<double> reference_sigma;
        std::vector<std::vector<double>> models;
    };
    std::vector<Profile> profiles;
};

struct CompareResult {
    std::vector<std::string> models;       // the specs as given (column names)
    std::vector<std::string> model_names;  // their registered models
    std::vector<std::string> model_titles;
    std::vector<double> prepare_seconds;  // per model; 0 when every image came from the cache
    std::vector<bool> prepared;
    // Bytes of each model's precomputed tables as float32 (the size of the
    // tables.f32 of `atmos bake`); -1 when the model has no bakeable tables or
    // was not prepared in this run or a cached one.
    std::vector<int64_t> table_bytes;
    double reference_prepare_seconds = 0.0;
    std::vector<CompareRow> rows;
    std::vector<ModelLoc> loc;  // per registered model (once), plus the reference model last
    double total_seconds = 0.0;
    int threads = 0;
    // The reference's noise was measured (a split or noise-target Monte Carlo
    // reference, or shipped references): reference_noise.csv is written, with
    // the noise target (0: none).
    bool reference_noise_table = false;
    double reference_noise_target = 0.0;
};

// The default views: all 12 for radiance; for transmittance the thesis's five
// camera positions (Appendix C/D), which do not depend on the sun.
std::vector<std::string> DefaultCompareViews(Quantity quantity);
// The table row label of a view (transmittance: ground-noon -> ground, ...).
std::string CompareRowLabel(const std::string& view, Quantity quantity);
// Why `view` lies outside the model's declared validity, or "" if it does not.
std::string ValidityNote(const ModelCapabilities& caps, const View& view,
                         const AtmosphereParameters& atmosphere);

// Models to compare are ModelSpecs (atmos/model.h): `NAME[:OPTION=VALUE]...`
// (e.g. `hillaire:segment-offset=0.5`), so that variants of one model are
// compared side by side; the spec text names the model's column and files.

// Runs the comparison (studies/compare.h resolves the config) and returns its
// plain data, images included: it writes no file but the render cache's
// (config.cache_dir), and prints progress lines to stderr with
// config.show_progress. The images cost 4 bytes per channel and pixel: at the
// default 320x180, 12 views and 11 models about 12 x (12 x 0.69 + 11 x 0.23)
// MB = 130 MB; at 1920x1080 about 4.7 GB. Throws atmos::Error.
CompareResult RunCompare(const CompareConfig& config);
// Writes each view's images into config.output_dir: images/VIEW/reference,
// reference-rgb (--reference-wavelengths) and each model (.png at the view's
// exposure, .exr, .npy unless !write_npy), errors/VIEW/MODEL-flip.png (the FLIP
// map, magma), MODEL-rmse.exr and .png (|model - reference|). Only reads `result`.
void WriteCompareImages(const CompareConfig& config, const CompareResult& result);
// The writers of a result: flip.csv, rmse.csv, times.csv, reference_noise.csv
// (when measured), rgb_cost.csv (reference_wavelengths), accuracy_cost.csv and
// index.html in config.output_dir. They only read `result`.
void WriteCompareTables(const CompareConfig& config, const CompareResult& result);

// A metric table as CSV (thesis Appendix A/B layout): the header
// "<corner>,<model>...,best", then one row per view with the values (%.8g)
// and the name of the model with the lowest value; with a noise per row
// (ranking.h: BestOfRow), every model within that row's noise of the lowest,
// separated by spaces (a tie).
void WriteMetricCsv(const std::string& path, const std::string& corner,
                    const std::vector<std::string>& row_labels,
                    const std::vector<std::string>& columns,
                    const std::vector<std::vector<double>>& values,
                    const std::vector<double>& row_noise = {});
// Index of the lowest finite value of a row (-1 if none).
int BestIndex(const std::vector<double>& row);

}  // namespace atmos
