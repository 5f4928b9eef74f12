// atmos: the model interface, its description, options and the registry.
//
// A model is a pure function (view ray, sun direction) -> (radiance,
// transmittance) plus an optional Prepare() that precomputes (DESIGN.md). On the
// host it is a small virtual interface, dispatched once per image; inside, each
// model owns a trivially copyable evaluator whose ATMOS_HD Evaluate() the one
// per-pixel loop (src/atmos/render/render.h) calls.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/image.h"
#include "atmos/math.h"
#include "atmos/options.h"
#include "atmos/view.h"

namespace atmos {

enum class Quantity { kRadiance, kTransmittance };
Quantity ParseQuantity(const std::string& text);  // "radiance" | "transmittance"
const char* QuantityName(Quantity q);

// What a model can do; the harness flags views outside a model's validity.
struct ModelCapabilities {
    bool radiance = true;           // produces sky radiance
    bool transmittance = true;      // produces the view ray's transmittance
    bool space_views = true;        // valid for cameras above the ground / in space
    bool sun_below_horizon = true;  // valid with the sun below the horizon
    bool multiple_scattering = false;
    bool precomputed = false;  // Prepare() builds tables or fits
    // Monte Carlo: the output depends on MonteCarloSettings (spp, seed); the
    // model renders passes and the progressive driver (src/atmos/render/
    // progressive.h) runs them, with checkpoints, resume and the variance.
    bool stochastic = false;
    // Has a per-wavelength form (harness/spectral_run.h): its inputs are an
    // atmosphere's coefficients (the physical models) or it builds a spectral
    // form of its own (preetham). false: compare/bench skip it in spectral
    // runs and --wavelengths refuses it.
    bool spectral = true;
    // Monte Carlo models whose paths carry any number of wavelengths at once
    // (hero-wavelength sampling): a spectral run gives them all its wavelengths
    // in one set of paths (Model::SetSpectralPaths) instead of batches of three.
    bool spectral_paths = false;
    // `atmos fit` trains its weights against a reference model.
    bool trainable = false;
    // Wide channel batches (docs/performance.md "Wide channel batches"): one
    // model takes up to kMaxWideChannels channels (PrepareWide, RenderWide,
    // SampleWide), sharing each ray's geometry and table coordinates across
    // them; a spectral run then prepares one model for all its batches of
    // three instead of one per batch. Channel 3b + c of a wide run equals
    // channel c of batch b's three-channel run, bit for bit.
    bool wide_channels = false;
    // A baseline that models nothing (`empty`): compare leaves it out of the
    // Pareto front and of the verdict per regime.
    bool baseline = false;
    // The WebGL2 shader (shaders/NAME.glsl, without the directory) that draws
    // its baked tables in `atmos viewer`; empty: none. The models with one are
    // the viewer's default list, in registry order.
    std::string shader;
    // Lines `atmos list` prints under "validity:" (what the tables or the
    // method do outside their range, measured).
    std::vector<std::string> validity_notes;
};

// Where a model's answers are valid for an atmosphere (issues 38 item 3, 39
// item 5), as measured against the reference (docs/models/NAME.md). Each limit
// 0 is none (the default: a model that declares nothing is checked for
// nothing). Prepare() warns on stderr outside it with the model's name and the
// reason (WarnOutsideValidityDomain); `atmos list` prints it.
struct ValidityDomain {
    // Largest top_radius / bottom_radius (the shell's thickness).
    double max_radius_ratio = 0.0;
    std::string radius_ratio_reason;
    // Largest shell thickness (top - bottom) in equivalent heights of the
    // column (ColumnEquivalentHeight): how much empty shell a model's fixed
    // step counts spread over (a giant planet's 10^9 m shell over a few-km air
    // column).
    double max_shell_heights = 0.0;
    std::string shell_heights_reason;
    // Largest planet radius (bottom) in column heights: the curvature a
    // method's fitted constants assume (O'Neil's scale()).
    double max_radius_heights = 0.0;
    std::string radius_heights_reason;
    // Largest vertical optical depth of the column (extinction of all
    // constituents, largest channel: VerticalOpticalDepth).
    double max_optical_depth = 0.0;
    std::string optical_depth_reason;
    // A fitted sky (preetham, hosek-wilkie): the atmosphere its coefficients
    // were fitted to, by name ("earth", a preset or a file). Its sky does not
    // follow another planet's, so the planet must match
    // (AtmosphereShapeDifferences). Null: no check.
    std::string fitted_to;
    std::shared_ptr<const AtmosphereParameters> fitted_atmosphere;
};

struct ModelInfo {
    std::string name;      // registry name, e.g. "naive"
    std::string title;     // e.g. "Naive single scattering (Nishita 93)"
    std::string citation;  // paper + seed section
    std::string summary;   // one line
    ModelCapabilities capabilities;
    ValidityDomain domain;
    std::vector<ModelOptionSpec> options;  // from the model's OptionTable (atmos/options.h)
    // `atmos loc` (harness/loc.h): the stem of its source files under
    // src/atmos/models/ (STEM.h, STEM.cpp, STEM_*.h ...; empty: the name with
    // '-' as '_'), and the thesis's count of the same model (Leenman's 2025 thesis section
    // 12.4: its name there and its significant lines; -1: not in the thesis).
    std::string source_stem;
    std::string thesis_name;
    int thesis_lines = -1;
};

// A model with options, as written everywhere (command line, compare, bench):
// NAME[:OPTION=VALUE[:OPTION=VALUE...]], e.g. "bruneton:orders=2".
struct ModelSpec {
    std::string text;                            // as given
    std::string name;                            // the registered name
    std::map<std::string, std::string> options;  // as given (name -> text)
};
// Parses and validates a spec (unknown model or option, malformed item, value
// out of range, option given twice: atmos::Error naming the model and the range).
ModelSpec ParseModelSpec(const std::string& text);

// One `atmos sample` query (DESIGN.md): camera at (0, 0, bottom + altitude),
// view (sqrt(1 - mu^2), 0, mu), sun (sqrt(1 - mu_s^2) cos az, sqrt(1 - mu_s^2) sin az, mu_s).
struct SampleQuery {
    double altitude_m = 0.0;
    double mu = 1.0;
    double mu_s = 1.0;
    double azimuth_deg = 0.0;
    // `sample --ground`: add the lit ground's reflected radiance, attenuated
    // along the ray, as a render's pixel shows it (the model is then asked as a
    // render asks it, want_ground = true).
    int32_t ground = 0;
    int32_t padding = 0;
};
// Sky radiance per unit solar irradiance (scattered light only: no sun disc;
// no ground unless the query asks for it), and the view ray's transmittance to
// space (0 when it hits the ground). AddSunDisc (render/render.h) adds the
// sun's disc as a render does.
struct SampleAnswer {
    Rgb radiance;
    Rgb transmittance;
};

// How a Monte Carlo model (ModelCapabilities::stochastic) estimates: `spp`
// paths per pixel (per query for sample) from `seed`, rendered in passes of
// `pass_spp` paths (0: spp / 8 in [1, 64]), the granularity of checkpoints and
// of the variance estimate. Other models ignore it.
struct MonteCarloSettings {
    int64_t spp = 64;  // paths per pixel; with a noise target: the cap
    uint64_t seed = 0;
    int64_t pass_spp = 0;
    // > 0: render until the HDR-FLIP between the mean of the even passes and
    // the mean of the odd passes (two independent halves) is at or below this,
    // or spp is reached (render/progressive.h).
    double noise_target = 0.0;
    // Checkpointed renders (RenderRequest::checkpoint): the longest time
    // between two checkpoints, in seconds. Passes are rendered in bands of
    // rows (about a second each; 0: one row) and a checkpoint may follow any
    // band, so it also bounds what a kill loses (issue 18 item 10).
    double checkpoint_seconds = 10.0;
};

// What a Monte Carlo render reached (RenderRequest::report).
struct MonteCarloReport {
    int64_t samples = 0;  // paths per pixel in the image
    double noise = -1.0;  // HDR-FLIP between its two halves; < 0: not measured
    // The per-pixel HDR-FLIP map of the two halves at the measurement that gave
    // `noise` (width x height, row-major, top row first; its mean is `noise`);
    // empty when the noise was not measured.
    std::vector<float> noise_map;
};

// One pass of a Monte Carlo model: the mean of samples [first_sample,
// first_sample + samples) of every pixel or query, random numbers from `seed`.
struct MonteCarloPass {
    uint64_t seed = 0;
    int64_t first_sample = 0;
    int64_t samples = 1;
    // The band of image rows to render: [row_begin, row_begin + rows) (rows 0:
    // every row). Pixels depend on their coordinates only, so a pass rendered
    // in bands is the pass rendered whole.
    int row_begin = 0;
    int rows = 0;
};

class Progress;
struct SpectralAtmosphere;  // atmos/spectral.h

// The most channels one wide model takes (ModelCapabilities::wide_channels):
// 16 batches of three; a spectral run with more wavelengths uses several.
constexpr int kMaxWideChannels = 48;

struct RenderRequest {
    View view;
    int width = 480;
    int height = 270;
    Quantity quantity = Quantity::kRadiance;
    bool sun_disc = false;  // add the sun's disc (radiance E / (pi alpha^2) times T)
    bool show_progress = true;
    // Monte Carlo models (ModelCapabilities::stochastic): the estimate, the
    // checkpoint file stem (empty: no checkpoints), whether to resume from it,
    // and an optional image that receives the per-pixel variance of the
    // estimate (same units squared). Others ignore them.
    MonteCarloSettings monte_carlo;
    std::string checkpoint;
    bool resume = false;
    Image* variance = nullptr;
    // Called on the calling thread after each pass of a Monte Carlo model
    // (passes done, passes in all, counting resumed ones); may throw to stop
    // the render (the checkpoint keeps the passes done). Others ignore it.
    std::function<void(int64_t, int64_t)> on_pass;
    MonteCarloReport* report = nullptr;  // optional: filled by a Monte Carlo render
};

// `sample --sun-disc`: adds the sun's disc to each answer as a free render's
// pixel shows it (per unit irradiance: T / (pi alpha^2) times the limb
// darkening's factor where the ray sees the disc and misses the ground; alpha =
// the atmosphere's sun_angular_radius; limb_darkening as View's, 0: uniform;
// defined in render/render.cpp).
void AddSunDisc(const std::vector<SampleQuery>& queries, const AtmosphereParameters& atmosphere,
                std::vector<SampleAnswer>* answers, double limb_darkening = kSunLimbDarkening);

class Model {
  public:
    virtual ~Model() = default;
    virtual const ModelInfo& Info() const = 0;
    // Precomputation for the given atmosphere (tables, fits). Must be called
    // before Render / Sample; calling it again re-prepares.
    virtual void Prepare(const AtmosphereParameters& atmosphere) = 0;
    // A spectral run (harness/spectral_run.h) calls this before each batch's
    // Prepare(): the wavelengths (nm) its three channels stand for and the whole
    // spectral atmosphere. The physical models take their per-wavelength
    // coefficients from the batch's atmosphere and ignore it; a model with a
    // spectral form of its own (preetham) builds it in the Prepare() that follows.
    virtual void SetSpectralBatch(const SpectralAtmosphere& /*atmosphere*/,
                                  const double /*nm*/[3]) {}
    // Monte Carlo models whose paths carry any number of wavelengths at once
    // (ModelCapabilities::spectral_paths: hero-wavelength sampling): a spectral
    // run (harness/spectral_run.h) gives them all its wavelengths instead of
    // batches of three. SetSpectralPaths(atmosphere, nm) comes before the one
    // Prepare() (given the atmosphere at three of the wavelengths); then
    // RenderSpectralPaths writes the radiance per unit solar irradiance of
    // every pixel at every wavelength,
    // (*values)[(y * width + x) * nm.size() + i], from request.monte_carlo's spp
    // and seed (radiance, no sun disc), and SampleSpectralPaths the radiance per
    // unit irradiance of each query (sky; plus ground where the query asks),
    // [q * nm.size() + i], mc.spp paths from mc.seed. Others throw atmos::Error.
    virtual void SetSpectralPaths(const SpectralAtmosphere& atmosphere,
                                  const std::vector<double>& nm);
    virtual void RenderSpectralPaths(const RenderRequest& request,
                                     std::vector<float>* values) const;
    virtual std::vector<float> SampleSpectralPaths(const std::vector<SampleQuery>& queries,
                                                   const MonteCarloSettings& mc) const;
    // Renders the view's radiance (times the view's irradiance and the
    // atmosphere's solar irradiance) or transmittance into `out` (resized).
    virtual void Render(const RenderRequest& request, Image* out) const = 0;
    virtual std::vector<SampleAnswer> Sample(const std::vector<SampleQuery>& queries) const = 0;

    // Wide channel batches (ModelCapabilities::wide_channels; others throw
    // atmos::Error). PrepareWide prepares for 3 x batches.size() channels at
    // once (at most kMaxWideChannels): batch b's atmosphere gives channels 3b ..
    // 3b + 2; the batches differ only in their per-channel coefficients
    // (AtWavelengths), else it throws naming the field. `prepare_batch`
    // (optional): how one batch is prepared, the spectral run's prepare
    // function (the CLI's: through the table cache, or --load): a model that
    // gathers per-batch tables (bruneton) calls it with each batch's
    // atmosphere and a fresh model of its own kind and options; empty:
    // Prepare(). RenderWide renders as Render, every channel
    // (values[pixel * channels + c], resized); SampleWide answers as Sample's
    // radiance ([query * channels + c]).
    using BatchPrepare = std::function<void(const AtmosphereParameters&, Model*)>;
    virtual void PrepareWide(const std::vector<AtmosphereParameters>& batches,
                             const BatchPrepare& prepare_batch = {});
    virtual void RenderWide(const RenderRequest& request, std::vector<float>* values) const;
    virtual std::vector<float> SampleWide(const std::vector<SampleQuery>& queries) const;

    // Monte Carlo models (ModelCapabilities::stochastic) provide one pass; the
    // progressive driver (src/atmos/render/progressive.h) runs the passes and
    // is their Render and Sample. RenderPass renders the pass's mean over its
    // band of rows into `out` (resized to width x rows), advancing `progress`
    // (may be null) by one per pixel; PassKey
    // is JSON text of everything of the model that determines a pass besides
    // the request (options, atmosphere): a checkpoint resumes only the same.
    // Others throw atmos::Error.
    virtual void RenderPass(const RenderRequest& request, const MonteCarloPass& pass, Image* out,
                            Progress* progress) const;
    virtual std::vector<SampleAnswer> SamplePass(const std::vector<SampleQuery>& queries,
                                                 const MonteCarloPass& pass) const;
    virtual std::string PassKey() const;

    // Precomputed tables as files (`atmos bake`, `--load`): models with tables
    // override all three. Bake writes the tables of the last Prepare() to
    // `directory` (EXR + a JSON describing sizes, mappings and the atmosphere);
    // LoadBaked replaces Prepare() by reading them back (throws atmos::Error if
    // they do not match `atmosphere` or the model's options).
    virtual bool CanBake() const { return false; }
    virtual void Bake(const std::string& directory) const;
    // The bytes of the tables.f32 that Bake() would write for the last
    // Prepare() (every table as float32, 256-byte aligned: io/raw_tables.h);
    // -1 for a model without tables or before Prepare().
    virtual int64_t TableBytes() const { return -1; }
    virtual void LoadBaked(const std::string& directory, const AtmosphereParameters& atmosphere);

    // A model with a precomputed sky-irradiance table (bruneton) answers the
    // sky's diffuse irradiance on a horizontal plane at `altitude_m` for the
    // sun at cosine `mu_s` from it (per unit solar irradiance) and returns
    // true; others return false (harness/irradiance.h integrates their sky).
    virtual bool TableSkyIrradiance(double /*altitude_m*/, double /*mu_s*/, Rgb* /*out*/) const {
        return false;
    }
};

// Output values (NaN, infinity or negative) that the last guard of every render
// and sample (and of the progressive mean) replaced by 0 since the process
// started or the last reset (issue 18 item 3). Non-zero means some answer was
// wrong: the CLI warns on stderr, and fails with --strict.
int64_t OutputGuardCount();
void ResetOutputGuardCount(int64_t value = 0);  // tests: restore a count

// The vertical optical depth of the atmosphere's column from the ground to the
// top (all constituents, the largest channel), by the trapezoid rule on a
// geometric altitude grid (valid for a giant planet's 10^9 m shell too).
double VerticalOpticalDepth(const AtmosphereParameters& atmosphere);
// The column's equivalent height: its vertical optical depth over the
// extinction at the ground (largest channels; Earth: 7.2 km); the shell's
// thickness when the ground has no extinction.
double ColumnEquivalentHeight(const AtmosphereParameters& atmosphere);
// The reasons `atmosphere` is outside `info`'s ValidityDomain, one line each
// ("optical depth 31 above 10: ..."); empty inside it.
std::vector<std::string> ValidityDomainViolations(const ModelInfo& info,
                                                  const AtmosphereParameters& atmosphere);
// Prints "atmos: warning: model NAME: outside its valid domain: REASON" on
// stderr for each violation (models call it at the start of Prepare()).
void WarnOutsideValidityDomain(const ModelInfo& info, const AtmosphereParameters& atmosphere);
// Where `atmosphere` is another planet than `fit`: its bottom_radius more than
// 2 % apart, or its air (rayleigh_density) a profile more than 10 % apart, as
// "FIELD VALUE (fit: VALUE)". Earth's variants (a 60 km shell, no ozone, other
// aerosols: a fitted sky's turbidity stands for those) are the same planet;
// the scattering coefficients are not compared (a spectral run's batches
// change them).
std::vector<std::string> AtmosphereShapeDifferences(const AtmosphereParameters& atmosphere,
                                                    const AtmosphereParameters& fit);

// All registered models, in the registry's order (src/atmos/models/registry.cpp).
std::vector<ModelInfo> ListModels();
const ModelInfo& GetModelInfo(const std::string& name);  // throws for an unknown name
// Creates a model by name with options given as name -> text (validated by its
// option table; throws atmos::Error naming the option and its range).
std::unique_ptr<Model> CreateModel(const std::string& name,
                                   const std::map<std::string, std::string>& options = {});
std::unique_ptr<Model> CreateModel(const ModelSpec& spec);
// Every option of the model with `given` applied: (name, canonical text), in
// its table's order (defaults included). Throws like CreateModel.
std::vector<std::pair<std::string, std::string>> ResolveModelOptions(
    const std::string& name, const std::map<std::string, std::string>& given);

// Run-time registration, for models that are not in THE list
// (models/model_list.h): a test registers a model defined in its own file
// (tests/capabilities_test.cpp). Appends it after the listed models; the
// registration lasts until Unregister (not thread-safe against concurrent
// lookups: register before, unregister after any use).
struct ModelFactory {
    std::function<ModelInfo()> info;
    std::function<std::unique_ptr<Model>(const std::map<std::string, std::string>&)> create;
    std::function<std::vector<std::pair<std::string, std::string>>(
        const std::map<std::string, std::string>&)>
        resolve;
};
void RegisterModel(const ModelFactory& factory);  // throws for a name already registered
void UnregisterModel(const std::string& name);    // run-time registrations only

}  // namespace atmos
