// atmos model `bruneton`: options, Prepare, and the bake (EXR tables + JSON).
#include "models/bruneton.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "atmos/error.h"
#include "base/parallel.h"
#include "io/gpu_passes.h"
#include "io/output_path.h"
#include "io/raw_tables.h"
#include "io/table_io.h"
#include "io/text_files.h"
#include "models/bruneton_wide.h"
#include "models/option_json.h"
#include "render/wide.h"

namespace atmos {

namespace {

constexpr const char* kBakeJson = "bruneton.json";
constexpr int kBakeFormatVersion = 2;  // 2: "options" keyed by option name

}  // namespace

ModelInfo BrunetonModel::StaticInfo() {
    ModelInfo info;
    info.name = "bruneton";
    info.title = "Precomputed atmospheric scattering (Bruneton & Neyret 2008, Bruneton 2017)";
    info.citation =
        "Bruneton & Neyret 2008; Bruneton 2017 (Bruneton's 2017 implementation notes, "
        "functions.glsl); Leenman's 2025 thesis sections "
        "5.2, 11.2.3";
    info.summary =
        "4D scattering tables (packed 3D), transmittance and irradiance tables, N orders";
    info.capabilities.multiple_scattering = true;
    info.capabilities.precomputed = true;
    info.capabilities.wide_channels = true;  // separate Mie storage (the constructor)
    info.options = OptionRows().Specs();
    info.capabilities.shader = "bruneton";
    info.capabilities.validity_notes = {
        "optically thick steps of the view-ray integrals use an energy-conserving rule "
        "(physics/exp_quadrature.h); Prepare still warns on stderr when a precomputed "
        "scattering order stops decreasing, and the radiance is then not valid"};
    info.thesis_name = "Bruneton and Neyret";
    info.thesis_lines = 832;
    // Measured against the reference (docs/models/bruneton.md "Validity domain"):
    // the worst of three ground radiances -7 % at a vertical optical depth of
    // 0.54, -14 % at 0.80, -21 % at 1.07, 14x too dark at 4.2.
    info.domain.max_optical_depth = 0.6;
    info.domain.optical_depth_reason =
        "the sky is too dark in dense air: radiance -14 % at optical depth 0.8, 14x too dark "
        "at 4.2 (against the reference)";
    // The zenith transmittance from the ground against its own at Earth: -0.4 %
    // at a shell of 176 column heights, -2.3 % at 440, -7.4 % on the 2x shell
    // (880), 0 on the giant planet.
    info.domain.max_shell_heights = 300.0;
    info.domain.shell_heights_reason =
        "the tables' r mapping spreads their texels over the whole shell, few in the air near "
        "the ground (zenith transmittance -2.3 % at 440 heights, 0 on a 1e9 m shell)";
    return info;
}

const OptionTable<BrunetonConfig>& BrunetonModel::OptionRows() {
    using C = BrunetonConfig;
    static const auto table =
        OptionTable<C>()
            .Integer("orders", &C::orders, 1, 32, "", "scattering orders (1 = single scattering)")
            .ShapesTables()
            .Integer("scattering-samples", &C::scattering_samples, 1, 1000, "",
                     "intervals along view rays in single and multiple scattering")
            .ShapesTables()
            .Choice("scattering-rule", &C::scattering_rule, {{"simpson", 1}, {"trapezoid", 0}},
                    "quadrature along view rays: Simpson's rule, or the seed's trapezoid "
                    "(scattering-rule=trapezoid reproduces Bruneton's 2017 implementation notes)")
            .ShapesTables()
            .Choice("mie-storage", &C::combined_mie, {{"separate", false}, {"combined", true}},
                    "single Mie scattering in its own table, or combined (red in the scattering "
                    "table's alpha, green and blue extrapolated)")
            .ShapesTables()
            .Choice("low-sun-mie", &C::low_sun_mie,
                    {{"integrate", 0}, {"smoothstep", 1}, {"lookup", 2}},
                    "single Mie on rays to the ground with the sun below mu_s = 0.01: integrated "
                    "along the segment, the seed's smoothstep(0, 0.01, mu_s) fade, or the two "
                    "lookups subtracted (the artefact the fade hides)")
            .Integer("low-sun-mie-steps", &C::low_sun_mie_steps, 1, 4096, "",
                     "midpoint samples of the low-sun single Mie integral")
            .Integer("transmittance-width", &C::transmittance_width, 2, 4096, "",
                     "transmittance table: mu texels")
            .ShapesTables()
            .Integer("transmittance-height", &C::transmittance_height, 2, 4096, "",
                     "transmittance table: r texels")
            .ShapesTables()
            .Integer("irradiance-width", &C::irradiance_width, 2, 4096, "",
                     "irradiance table: mu_s texels")
            .ShapesTables()
            .Integer("irradiance-height", &C::irradiance_height, 2, 4096, "",
                     "irradiance table: r texels")
            .ShapesTables()
            .Integer("scattering-r", &C::scattering_r, 2, 1024, "", "scattering table: r texels")
            .ShapesTables()
            .Integer("scattering-mu", &C::scattering_mu, 4, 4096, "",
                     "scattering table: mu texels (even)")
            .ShapesTables()
            .Integer("scattering-mu-s", &C::scattering_mu_s, 2, 1024, "",
                     "scattering table: mu_s texels")
            .ShapesTables()
            .Integer("scattering-nu", &C::scattering_nu, 2, 1024, "", "scattering table: nu texels")
            .ShapesTables()
            .Validate([](const std::string& model, const C& c, const std::set<std::string>&) {
                if (c.scattering_mu % 2 != 0) {
                    Fail("model ", model,
                         ": option scattering-mu must be even (half of the "
                         "table is for rays that hit the ground), got ",
                         c.scattering_mu);
                }
            });
    return table;
}

BrunetonModel::BrunetonModel(const BrunetonConfig& options)
    : info_(StaticInfo()), config_(options), atm_(EarthAtmosphere()) {
    // The wide evaluator reads separate Mie tables (combined storage
    // extrapolates green and blue from red: no wide form).
    info_.capabilities.wide_channels = !config_.combined_mie;
}

namespace {

// Copies the three channels of `batch` into channels 3b .. 3b + 2 of `wide`
// (sized as `batch` with `channels` channels on the first batch).
void GatherChannels(const Table& batch, int b, int channels, Table* wide) {
    if (b == 0) wide->Resize(batch.width(), batch.height(), batch.depth(), channels);
    const size_t texels = static_cast<size_t>(batch.width()) * batch.height() * batch.depth();
    const size_t n = static_cast<size_t>(channels);
    const float* src = batch.data();
    float* dst = wide->data() + 3 * static_cast<size_t>(b);
    for (size_t i = 0; i < texels; ++i) {
        for (size_t c = 0; c < 3; ++c) dst[i * n + c] = src[i * 3 + c];
    }
}

}  // namespace

void BrunetonModel::PrepareWide(const std::vector<AtmosphereParameters>& batches,
                                const BatchPrepare& prepare_batch) {
    if (!info_.capabilities.wide_channels) Model::PrepareWide(batches, prepare_batch);
    const WideCoefficients wide = MakeWideCoefficients(batches);
    BrunetonTables wide_tables;
    const bool at_once = !prepare_batch && !IsDeviceBackend(CurrentBackend());
    if (at_once) {
        // One precomputation of every channel (bruneton_wide_precompute.cpp):
        // the batches' tables bit for bit, each texel's geometry once.
        for (const AtmosphereParameters& a : batches) WarnOutsideValidityDomain(Info(), a);
        PrecomputeBrunetonWide(batches, config_, &wide_tables);
    }
    // Otherwise the tables of each batch, as Prepare() computes them (or the
    // spectral run's prepare function: the table cache, --load), side by side.
    for (size_t b = 0; !at_once && b < batches.size(); ++b) {
        BrunetonModel batch_model(config_);
        if (prepare_batch) {
            prepare_batch(batches[b], &batch_model);
        } else {
            batch_model.Prepare(batches[b]);
        }
        if (!batch_model.prepared_) {
            Fail("model bruneton: the prepare function of a wide batch left its tables empty");
        }
        const BrunetonTables& t = batch_model.tables_;
        const int bi = static_cast<int>(b);
        GatherChannels(t.transmittance, bi, wide.channels, &wide_tables.transmittance);
        GatherChannels(t.irradiance, bi, wide.channels, &wide_tables.irradiance);
        GatherChannels(t.scattering, bi, wide.channels, &wide_tables.scattering);
        GatherChannels(t.single_mie, bi, wide.channels, &wide_tables.single_mie);
    }
    wide_tables_ = std::move(wide_tables);
    wide_atm_ = batches[0];
    wide_ = wide;
    wide_prepared_ = true;
}

namespace {
BrunetonWideEvaluator MakeWideEvaluator(const AtmosphereParameters& atm,
                                        const BrunetonConfig& config, const BrunetonTables& tables,
                                        const WideCoefficients* wide) {
    if (!wide) Fail("model bruneton: PrepareWide() must run before RenderWide() / SampleWide()");
    BrunetonWideEvaluator e;
    e.lut = MakeBrunetonLut(atm, config, tables);
    e.w = *wide;
    return e;
}
}  // namespace

void BrunetonModel::RenderWide(const RenderRequest& request, std::vector<float>* values) const {
    const BrunetonWideEvaluator e =
        MakeWideEvaluator(wide_atm_, config_, wide_tables_, wide_prepared_ ? &wide_ : nullptr);
    RenderWideImage(e, MakeWidePixelSetup(request, wide_atm_, e.w), values);
}

std::vector<float> BrunetonModel::SampleWide(const std::vector<SampleQuery>& queries) const {
    const BrunetonWideEvaluator e =
        MakeWideEvaluator(wide_atm_, config_, wide_tables_, wide_prepared_ ? &wide_ : nullptr);
    return SampleAllWide(e, wide_atm_.bottom_radius, queries);
}

void BrunetonModel::Prepare(const AtmosphereParameters& atmosphere) {
    WarnOutsideValidityDomain(Info(), atmosphere);  // its declared domain (atmos/model.h)
    // On a device backend the final tables stay on the device for the renders.
    ResidentScope scope(&resident_);
    atm_ = atmosphere;
    PrecomputeBruneton(atm_, config_, &tables_);
    prepared_ = true;
    scope.Keep(MakeEvaluator());
}

BrunetonEvaluator BrunetonModel::MakeEvaluator() const {
    if (!prepared_) Fail("model bruneton: Prepare() or LoadBaked() must run before rendering");
    BrunetonEvaluator e;
    e.lut = MakeBrunetonLut(atm_, config_, tables_);
    return e;
}

bool BrunetonModel::TableSkyIrradiance(double altitude_m, double mu_s, Rgb* out) const {
    if (!prepared_) Fail("model bruneton: Prepare() or LoadBaked() must run before rendering");
    const BrunetonLut lut = MakeBrunetonLut(atm_, config_, tables_);
    *out = lut.GetIrradiance(lut.irradiance_table, atm_.bottom_radius + altitude_m, mu_s);
    return true;
}

namespace {

// The #defines shaders/bruneton.glsl reads (written to DIR/shaders/
// bruneton_constants.glsl by the bake): the atmosphere and table sizes.
std::string GlslConstants(const AtmosphereParameters& a, const BrunetonConfig& c) {
    std::ostringstream s;
    BeginGlslConstants(
        s,
        "// Generated by `atmos bake bruneton`: the constants of these tables for\n"
        "// shaders/common.glsl and shaders/bruneton.glsl (include this first). Lengths in\n"
        "// metres.\n",
        a);
    s << "#define ATMOS_MU_S_MIN " << a.mu_s_min << "\n";
    s << "#define ATMOS_TRANSMITTANCE_WIDTH " << c.transmittance_width << "\n";
    s << "#define ATMOS_TRANSMITTANCE_HEIGHT " << c.transmittance_height << "\n";
    s << "#define ATMOS_IRRADIANCE_WIDTH " << c.irradiance_width << "\n";
    s << "#define ATMOS_IRRADIANCE_HEIGHT " << c.irradiance_height << "\n";
    s << "#define ATMOS_SCATTERING_R " << c.scattering_r << "\n";
    s << "#define ATMOS_SCATTERING_MU " << c.scattering_mu << "\n";
    s << "#define ATMOS_SCATTERING_MU_S " << c.scattering_mu_s << "\n";
    s << "#define ATMOS_SCATTERING_NU " << c.scattering_nu << "\n";
    s << "#define ATMOS_COMBINED_MIE " << (c.combined_mie ? 1 : 0) << "\n";
    // The view-ray quadrature of the precomputation (shaders/bruneton_precompute.glsl).
    s << "#define ATMOS_SCATTERING_SAMPLES " << c.scattering_samples << "\n";
    s << "#define ATMOS_SCATTERING_RULE " << c.scattering_rule << "\n";
    // The low-sun single Mie integral of SkyRadianceToPoint (issue 15).
    s << "#define ATMOS_LOW_SUN_MIE " << c.low_sun_mie << "\n";
    s << "#define ATMOS_LOW_SUN_MIE_STEPS " << c.low_sun_mie_steps << "\n";
    return s.str();
}

}  // namespace

namespace {
// The tables a bake writes raw (tables.f32/.f16), in their order.
std::vector<RawTable> RawTables(const BrunetonTables& tables, const BrunetonConfig& config) {
    std::vector<RawTable> raw = {{"transmittance", &tables.transmittance},
                                 {"irradiance", &tables.irradiance},
                                 {"scattering", &tables.scattering}};
    if (!config.combined_mie) raw.push_back({"single_mie_scattering", &tables.single_mie});
    return raw;
}
}  // namespace

namespace {
// The precomputation as GPU passes (io/gpu_passes.h; shaders/bruneton_precompute.glsl):
// the stages of PrecomputeBrunetonWith in its order, on targets sized from the config.
GpuPrecompute BrunetonGpuPrecompute(const BrunetonConfig& c) {
    GpuPrecompute p;
    p.shaders = {"shaders/bruneton_constants.glsl", "shaders/common.glsl", "shaders/bruneton.glsl",
                 "shaders/bruneton_precompute.glsl"};
    const int width = c.scattering_nu * c.scattering_mu_s;
    const GpuTarget scattering{width, c.scattering_mu, c.scattering_r, 4};
    const GpuTarget irradiance{c.irradiance_width, c.irradiance_height, 1, 4};
    p.targets["transmittance"] = {c.transmittance_width, c.transmittance_height, 1, 4};
    p.targets["delta_irradiance"] = irradiance;
    p.targets["irradiance"] = irradiance;
    p.targets["delta_rayleigh"] = scattering;
    p.targets["delta_mie"] = scattering;
    p.targets["scattering"] = scattering;
    if (!c.combined_mie) p.targets["single_mie_scattering"] = scattering;
    if (c.orders > 1) {
        p.targets["directions"] = {512, 1, 1, 4};
        p.targets["incident"] = {512, c.scattering_mu_s, c.scattering_r, 4};
        p.targets["delta_density"] = scattering;
        p.targets["delta_multiple"] = scattering;
    }
    const auto pass = [&p](const std::string& name, const std::string& entry,
                           const std::string& target, std::map<std::string, std::string> inputs,
                           bool add = false) {
        GpuPass g;
        g.name = name;
        g.entry = "ATMOS_PASS_" + entry;
        g.target = target;
        g.inputs = std::move(inputs);
        g.add = add;
        p.passes.push_back(std::move(g));
    };
    const std::string kT = "atmos_transmittance_texture";
    const std::string kRay = "atmos_delta_rayleigh_texture", kMie = "atmos_delta_mie_texture";
    const std::string kMul = "atmos_delta_multiple_texture";
    pass("transmittance", "TRANSMITTANCE", "transmittance", {});
    pass("direct irradiance", "DIRECT_IRRADIANCE", "delta_irradiance", {{kT, "transmittance"}});
    pass("single Rayleigh scattering", "SINGLE_RAYLEIGH", "delta_rayleigh",
         {{kT, "transmittance"}});
    pass("single Mie scattering", "SINGLE_MIE", "delta_mie", {{kT, "transmittance"}});
    pass("scattering after order 1", "SINGLE_TO_SCATTERING", "scattering",
         {{kRay, "delta_rayleigh"}, {kMie, "delta_mie"}});
    if (!c.combined_mie) {
        pass("single Mie table", "COPY_3D", "single_mie_scattering",
             {{"atmos_source_3d", "delta_mie"}});
    }
    if (c.orders == 1) pass("irradiance (single scattering only)", "ZERO", "irradiance", {});
    if (c.orders > 1) pass("density directions", "DIRECTIONS", "directions", {});
    for (int order = 2; order <= c.orders; ++order) {
        const std::string n = " (order " + std::to_string(order) + ")";
        if (order == 2) {
            pass("incident radiance" + n, "INCIDENT_SINGLE", "incident",
                 {{kT, "transmittance"},
                  {kRay, "delta_rayleigh"},
                  {kMie, "delta_mie"},
                  {"atmos_irradiance_texture", "delta_irradiance"}});
        } else {
            pass("incident radiance" + n, "INCIDENT_MULTIPLE", "incident",
                 {{kT, "transmittance"},
                  {kMul, "delta_multiple"},
                  {"atmos_irradiance_texture", "delta_irradiance"}});
        }
        pass("scattering density" + n, "SCATTERING_DENSITY", "delta_density",
             {{"atmos_incident_texture", "incident"}, {"atmos_directions_texture", "directions"}});
        if (order == 2) {
            pass("indirect irradiance" + n, "INDIRECT_IRRADIANCE_SINGLE", "delta_irradiance",
                 {{kRay, "delta_rayleigh"}, {kMie, "delta_mie"}});
        } else {
            pass("indirect irradiance" + n, "INDIRECT_IRRADIANCE_MULTIPLE", "delta_irradiance",
                 {{kMul, "delta_multiple"}});
        }
        pass("add irradiance" + n, "COPY_2D", "irradiance",
             {{"atmos_source_2d", "delta_irradiance"}}, order > 2);
        pass("multiple scattering" + n, "MULTIPLE_SCATTERING", "delta_multiple",
             {{kT, "transmittance"}, {"atmos_delta_density_texture", "delta_density"}});
        pass("accumulate" + n, "ACCUMULATE", "scattering", {{"atmos_source_3d", "delta_multiple"}},
             true);
    }
    return p;
}
}  // namespace

int64_t BrunetonModel::TableBytes() const {
    if (!prepared_) return -1;
    return static_cast<int64_t>(RawTablesFloat32Bytes(RawTables(tables_, config_)));
}

void BrunetonModel::Bake(const std::string& directory) const {
    if (!prepared_) Fail("model bruneton: nothing to bake (Prepare() has not run)");
    namespace fs = std::filesystem;
    const fs::path dir(directory);
    WriteTableExr(tables_.transmittance, (dir / "transmittance.exr").string());
    WriteTableExr(tables_.irradiance, (dir / "irradiance.exr").string());
    WriteTableExr(tables_.scattering, (dir / "scattering.exr").string());
    if (!config_.combined_mie) {
        WriteTableExr(tables_.single_mie, (dir / "single_mie_scattering.exr").string());
    }
    const double h =
        std::sqrt(atm_.top_radius * atm_.top_radius - atm_.bottom_radius * atm_.bottom_radius);
    nlohmann::ordered_json j;
    j["model"] = "bruneton";
    j["format_version"] = kBakeFormatVersion;
    j["description"] =
        "Bruneton 2017 precomputed atmospheric scattering tables (Bruneton's 2017 implementation "
        "notes mappings), float32, "
        "per unit solar irradiance (multiply radiance and irradiance by solar_irradiance). Each "
        "table is one EXR of W*D x H pixels: the D layers side by side.";
    j["options"] = OptionsJson(OptionRows().Specs(), OptionRows().Values(config_));
    nlohmann::ordered_json tables;
    tables["transmittance"] = {
        {"file", "transmittance.exr"},
        {"size", {config_.transmittance_width, config_.transmittance_height}},
        {"channels", "RGB"},
        {"mapping",
         "u = coord(x_mu, W), x_mu = (d - (r_top - r)) / (rho + H - (r_top - r)), d = distance to "
         "top; v = coord(rho / H, H_tex)"}};
    tables["irradiance"] = {
        {"file", "irradiance.exr"},
        {"size", {config_.irradiance_width, config_.irradiance_height}},
        {"channels", "RGB"},
        {"content", "indirect irradiance on a horizontal surface (direct: from transmittance)"},
        {"mapping",
         "u = coord(mu_s / 2 + 1 / 2, W), v = coord((r - r_bottom) / (r_top - "
         "r_bottom), H)"}};
    tables["scattering"] = {
        {"file", "scattering.exr"},
        {"size",
         {config_.scattering_nu * config_.scattering_mu_s, config_.scattering_mu,
          config_.scattering_r}},
        {"layout", "x = nu_index * MU_S + mu_s_index, y = mu, layer = r"},
        {"channels", config_.combined_mie ? "RGBA" : "RGB"},
        {"content", config_.combined_mie
                        ? "RGB: single Rayleigh + multiple scattering / RayleighPhase(nu); A: "
                          "single Mie red"
                        : "single Rayleigh + multiple scattering / RayleighPhase(nu)"},
        {"mapping", "Bruneton's 2017 implementation notes GetScatteringTextureUvwzFromRMuMuSNu"}};
    if (!config_.combined_mie) {
        tables["single_mie_scattering"] = {{"file", "single_mie_scattering.exr"},
                                           {"size",
                                            {config_.scattering_nu * config_.scattering_mu_s,
                                             config_.scattering_mu, config_.scattering_r}},
                                           {"channels", "RGB"},
                                           {"mapping", "as scattering"}};
    }
    j["tables"] = tables;
    j["constants"] = {{"bottom_radius", atm_.bottom_radius},
                      {"top_radius", atm_.top_radius},
                      {"H", h},
                      {"mu_s_min", atm_.mu_s_min},
                      {"texel_centre_mapping", "coord(x, n) = 0.5 / n + x (1 - 1 / n)"}};
    j["atmosphere"] = nlohmann::ordered_json::parse(AtmosphereToJson(atm_));
    j["raw"] = WriteRawTables(directory, RawTables(tables_, config_));
    j["shaders"] = WriteGlslConstants(directory, "bruneton", GlslConstants(atm_, config_));
    j["gpu_precompute"] = GpuPrecomputeJson(BrunetonGpuPrecompute(config_));
    const std::string path = (dir / kBakeJson).string();
    WriteFileAtomically(path, j.dump(2) + "\n");
}

void BrunetonModel::LoadBaked(const std::string& directory,
                              const AtmosphereParameters& atmosphere) {
    namespace fs = std::filesystem;
    const fs::path dir(directory);
    const std::string path = (dir / kBakeJson).string();
    nlohmann::ordered_json j;
    try {
        j = nlohmann::ordered_json::parse(ReadWholeFile(path));
    } catch (const nlohmann::json::exception& e) {
        Fail("'", path, "' is not valid JSON: ", e.what());
    }
    try {
        if (j.at("model").get<std::string>() != "bruneton") {
            Fail("'", path, "' holds tables of model '", j.at("model").get<std::string>(),
                 "', not bruneton");
        }
        if (j.at("format_version").get<int>() != kBakeFormatVersion) {
            Fail("'", path, "' has format_version ", j.at("format_version").get<int>(),
                 ", expected ", kBakeFormatVersion);
        }
        CheckBakedOptions(path, j.at("options"), OptionRows().Specs(),
                          OptionRows().Values(config_));
        const AtmosphereParameters baked =
            AtmosphereFromJson(j.at("atmosphere").dump(), path + ": atmosphere");
        if (AtmosphereToJson(baked) != AtmosphereToJson(atmosphere)) {
            Fail("'", path,
                 "' was baked for another atmosphere (its \"atmosphere\" differs from the one "
                 "requested)");
        }
    } catch (const nlohmann::json::exception& e) {
        Fail("'", path, "' is missing a field or has a wrong type: ", e.what());
    }
    BrunetonTables t;
    auto read = [&](const char* name, int depth, int channels, int w, int h) {
        Table table = ReadTableExr((dir / name).string(), depth, channels);
        if (table.width() != w || table.height() != h) {
            Fail("table '", (dir / name).string(), "' is ", table.width(), "x", table.height(),
                 ", expected ", w, "x", h);
        }
        return table;
    };
    const BrunetonConfig& c = config_;
    t.transmittance =
        read("transmittance.exr", 1, 3, c.transmittance_width, c.transmittance_height);
    t.irradiance = read("irradiance.exr", 1, 3, c.irradiance_width, c.irradiance_height);
    t.scattering = read("scattering.exr", c.scattering_r, c.combined_mie ? 4 : 3,
                        c.scattering_nu * c.scattering_mu_s, c.scattering_mu);
    if (!c.combined_mie) {
        t.single_mie = read("single_mie_scattering.exr", c.scattering_r, 3,
                            c.scattering_nu * c.scattering_mu_s, c.scattering_mu);
    }
    tables_ = std::move(t);
    atm_ = atmosphere;
    prepared_ = true;
}

}  // namespace atmos
