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
    bool stochastic = false;   // Monte Carlo: output depends on --seed / --spp
};

struct ModelInfo {
    std::string name;      // registry name, e.g. "naive"
    std::string title;     // e.g. "Naive single scattering (Nishita 93)"
    std::string citation;  // paper + seed section
    std::string summary;   // one line
    ModelCapabilities capabilities;
    std::vector<ModelOptionSpec> options;  // from the model's OptionTable (atmos/options.h)
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
// Creates a model by name with options given as name -> text (validated by its
// option table; throws atmos::Error naming the option and its range).
std::unique_ptr<Model> CreateModel(const std::string& name,
                                   const std::map<std::string, std::string>& options = {});
std::unique_ptr<Model> CreateModel(const ModelSpec& spec);
// Every option of the model with `given` applied: (name, canonical text), in
// its table's order (defaults included). Throws like CreateModel.
std::vector<std::pair<std::string, std::string>> ResolveModelOptions(
    const std::string& name, const std::map<std::string, std::string>& given);

}  // namespace atmos
