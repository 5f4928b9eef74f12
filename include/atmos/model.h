// atmos: the model interface, its description, options and the registry.
//
// A model is a pure function (view ray, sun direction) -> (radiance,
// transmittance) plus an optional Prepare() that precomputes (DESIGN.md). On the
// host it is a small virtual interface, dispatched once per image; inside, each
// model owns a trivially copyable evaluator whose ATMOS_HD Evaluate() the one
// per-pixel loop (src/atmos/render/render.h) calls.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/image.h"
#include "atmos/math.h"
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
    bool stochastic = false;   // Monte Carlo: output depends on --seed / --spp
};

// One option a model accepts on the command line (`--NAME VALUE`), for both
// `render` and `sample`.
struct ModelOptionSpec {
    enum class Type { kInteger, kReal, kChoice, kText };
    std::string name;  // without the leading "--"
    Type type = Type::kInteger;
    std::string default_value;
    std::string help;
    double min = 0.0;  // integer / real: allowed range [min, max]
    double max = 0.0;
    std::vector<std::string> choices;  // kChoice
};

struct ModelInfo {
    std::string name;      // registry name, e.g. "naive"
    std::string title;     // e.g. "Naive single scattering (Nishita 93)"
    std::string citation;  // paper + seed section
    std::string summary;   // one line
    ModelCapabilities capabilities;
    std::vector<ModelOptionSpec> options;
};

// Validated option values of one model: every option of its spec, set or at
// its default. Built by CreateModel from the user's strings.
class ModelOptions {
  public:
    ModelOptions() = default;
    // Validates `given` (name -> text) against `specs`; throws atmos::Error for an
    // unknown option or a value outside its type or range.
    ModelOptions(const std::string& model_name, const std::vector<ModelOptionSpec>& specs,
                 const std::map<std::string, std::string>& given);

    int GetInt(const std::string& name) const;
    double GetReal(const std::string& name) const;
    const std::string& GetText(const std::string& name) const;
    bool WasSet(const std::string& name) const { return set_.count(name) != 0; }
    const std::map<std::string, std::string>& values() const { return values_; }

  private:
    std::map<std::string, std::string> values_;
    std::map<std::string, bool> set_;
};

// One `atmos sample` query (DESIGN.md): camera at (0, 0, bottom + altitude),
// view (sqrt(1 - mu^2), 0, mu), sun (sqrt(1 - mu_s^2) cos az, sqrt(1 - mu_s^2) sin az, mu_s).
struct SampleQuery {
    double altitude_m = 0.0;
    double mu = 1.0;
    double mu_s = 1.0;
    double azimuth_deg = 0.0;
};
// Sky radiance per unit solar irradiance (scattered light only: no sun disc, no
// ground), and the view ray's transmittance to space (0 when it hits the ground).
struct SampleAnswer {
    Rgb radiance;
    Rgb transmittance;
};

struct RenderRequest {
    View view;
    int width = 480;
    int height = 270;
    Quantity quantity = Quantity::kRadiance;
    bool sun_disc = false;  // add the sun's disc (radiance E / (pi alpha^2) times T)
    bool show_progress = true;
    // Monte Carlo models (ModelCapabilities::stochastic): checkpoint file stem
    // (empty: no checkpoints), whether to resume from it, and an optional image
    // that receives the per-pixel variance of the estimate (same units squared).
    std::string checkpoint;
    bool resume = false;
    Image* variance = nullptr;
};

class Model {
  public:
    virtual ~Model() = default;
    virtual const ModelInfo& Info() const = 0;
    // Precomputation for the given atmosphere (tables, fits). Must be called
    // before Render / Sample; calling it again re-prepares.
    virtual void Prepare(const AtmosphereParameters& atmosphere) = 0;
    // Renders the view's radiance (times the view's irradiance and the
    // atmosphere's solar irradiance) or transmittance into `out` (resized).
    virtual void Render(const RenderRequest& request, Image* out) const = 0;
    virtual std::vector<SampleAnswer> Sample(const std::vector<SampleQuery>& queries) const = 0;

    // Precomputed tables as files (`atmos bake`, `--load`): models with tables
    // override all three. Bake writes the tables of the last Prepare() to
    // `directory` (EXR + a JSON describing sizes, mappings and the atmosphere);
    // LoadBaked replaces Prepare() by reading them back (throws atmos::Error if
    // they do not match `atmosphere` or the model's options).
    virtual bool CanBake() const { return false; }
    virtual void Bake(const std::string& directory) const;
    virtual void LoadBaked(const std::string& directory, const AtmosphereParameters& atmosphere);
};

// All registered models, in the registry's order (src/atmos/models/registry.cpp).
std::vector<ModelInfo> ListModels();
const ModelInfo& GetModelInfo(const std::string& name);  // throws for an unknown name
// Creates a model by name with options `--NAME VALUE` given as name -> text.
std::unique_ptr<Model> CreateModel(const std::string& name,
                                   const std::map<std::string, std::string>& options = {});

}  // namespace atmos
