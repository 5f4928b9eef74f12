// atmos model `atmosphere-plus`: precomputation and options (see atmosphere_plus.h).
#include "models/atmosphere_plus.h"

#include <chrono>
#include <cmath>
#include <vector>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "atmos/error.h"
#include "base/parallel.h"
#include "io/table_io.h"
#include "models/atmosphere_plus_stages.h"
#include "render/stages.h"

namespace atmos {

namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void CheckSettings(const AplusSettings& s) {
    if (s.width < 2 || s.height < 2 || s.depth < 2)
        Fail("atmosphere-plus: table sizes must be >= 2");
    if (s.transmittance_width < 2 || s.transmittance_height < 2) {
        Fail("atmosphere-plus: transmittance table sizes must be >= 2");
    }
    if (s.orders < 1) Fail("atmosphere-plus: --orders must be >= 1");
    if (s.transmittance_steps < 1 || s.gather_theta < 1 || s.gather_phi < 1) {
        Fail("atmosphere-plus: integration step counts must be >= 1");
    }
}

}  // namespace

AplusTables AplusPrecompute(const AtmosphereParameters& atm, const AplusSettings& settings_in,
                            bool keep_orders) {
    AplusSettings s = settings_in;
    s.mapping.bottom_radius = atm.bottom_radius;
    s.mapping.height = atm.top_radius - atm.bottom_radius;
    CheckSettings(s);
    AplusTables out;
    // On a device backend every table stays on the device between the stages;
    // the host gets the orders it copies and the final tables (Download).
    StageSession session;
    auto start = std::chrono::steady_clock::now();
    out.transmittance = Table(s.transmittance_width, s.transmittance_height, 1, 3);
    RunStage("atmosphere-plus/transmittance",
             static_cast<int64_t>(s.transmittance_width) * s.transmittance_height, 64,
             AplusTransmittanceStage{atm, s, out.transmittance.out()});
    out.transmittance_seconds = SecondsSince(start);

    const int64_t count = static_cast<int64_t>(s.width) * s.height * s.depth;

    // Order 1 (seed 000 2.1).
    start = std::chrono::steady_clock::now();
    Table order(s.width, s.height, s.depth, 4);
    RunStage("atmosphere-plus/order-1", count, 16, AplusSingleScatteringStage{atm, s, order.out()});
    session.Download(&order);
    out.scattering = order;
    out.order_seconds.push_back(SecondsSince(start));
    if (keep_orders) out.orders.push_back(order);

    // Orders 2..K (seed 000 2.2): gather from order k-1, order k, add to the sum.
    for (int k = 2; k <= s.orders; ++k) {
        start = std::chrono::steady_clock::now();
        Table gather(s.width, s.height, s.depth, 4);
        RunStage("atmosphere-plus/gather", count, 16,
                 AplusGatherStage{atm, s, order.view(), gather.out()});
        Table next(s.width, s.height, s.depth, 4);
        RunStage("atmosphere-plus/order-k", count, 16,
                 AplusOrderStage{atm, s, gather.view(), next.out()});
        RunStage("atmosphere-plus/sum", count, 4096,
                 AplusAddStage{next.view(), out.scattering.out(true)});
        order = std::move(next);
        if (keep_orders) {
            session.Download(&order);
            out.orders.push_back(order);
        }
        out.order_seconds.push_back(SecondsSince(start));
    }
    session.Download(&out.transmittance);
    session.Download(&out.scattering);
    return out;
}

ModelInfo AtmospherePlusModel::StaticInfo() {
    using T = ModelOptionSpec::Type;
    ModelInfo info;
    info.name = "atmosphere-plus";
    info.title = "Atmosphere Plus (3D table without azimuth)";
    info.citation = "J. Boody, Atmosphere Plus notes: seed 000 sections 1.2-2.4 (seed 002 earlier)";
    info.summary =
        "factored Rayleigh RGB + Mie alpha in a 3D table (h, view zenith, sun zenith), K orders "
        "by gathering; phase functions at render time";
    info.capabilities.multiple_scattering = true;
    info.capabilities.precomputed = true;
    info.options = {
        {"parameterization",
         T::kChoice,
         "horizon",
         "table mapping (seed 000 2.4)",
         0,
         0,
         {"linear", "nonlinear", "power", "horizon"}},
        {"table-width", T::kInteger, "32", "table size over altitude (u)", 2, 1024, {}},
        {"table-height",
         T::kInteger,
         "64",
         "table size over view zenith (v): 256, 128 or 64",
         2,
         4096,
         {}},
        {"table-depth", T::kInteger, "32", "table size over sun zenith (w)", 2, 1024, {}},
        {"transmittance-width",
         T::kInteger,
         "64",
         "transmittance table size over altitude",
         2,
         4096,
         {}},
        {"transmittance-height",
         T::kInteger,
         "256",
         "transmittance table size over view zenith",
         2,
         4096,
         {}},
        {"orders", T::kInteger, "5", "scattering orders K", 1, 20, {}},
        {"transmittance-steps",
         T::kInteger,
         "30",
         "trapezoidal intervals along rays (seed: 30)",
         1,
         10000,
         {}},
        {"gather-theta",
         T::kInteger,
         "6",
         "2D trapezoid intervals over Theta in [0, pi]",
         1,
         1000,
         {}},
        {"gather-phi",
         T::kInteger,
         "12",
         "2D trapezoid intervals over Phi in [0, 2 pi]",
         1,
         2000,
         {}},
        {"p-u", T::kReal, "2", "power p_u of u (power, horizon)", 0.1, 10, {}},
        {"p-v", T::kReal, "3", "power p_v of v (power)", 0.1, 10, {}},
        {"p-w", T::kReal, "3", "power p_w of w (power, horizon)", 0.1, 10, {}},
        {"p-a", T::kReal, "3", "atmosphere power p_a (horizon)", 0.1, 10, {}},
        {"p-s", T::kReal, "3", "surface power p_s (horizon)", 0.1, 10, {}},
        {"surface-ratio",
         T::kReal,
         "0.5",
         "s: most texture space for surfaces (horizon)",
         0,
         0.99,
         {}},
        {"horizon-angle",
         T::kChoice,
         "geometric",
         "horizon cosine of the horizon mapping: geometric -sqrt(1-(Rp/r)^2) or the seed's "
         "-1+Rp/r",
         0,
         0,
         {"geometric", "seed"}},
        {"rayleigh-phase",
         T::kChoice,
         "standard",
         "render-time Rayleigh phase: standard 3/4(1+c^2) or modified 0.8(1.4+0.5c^2) (seed 000 "
         "1.7)",
         0,
         0,
         {"standard", "modified"}},
    };
    return info;
}

AplusSettings AplusSettingsFromOptions(const ModelOptions& o) {
    AplusSettings s;
    const std::string& p = o.GetText("parameterization");
    s.mapping.kind = p == "linear"      ? AplusParameterization::kLinear
                     : p == "nonlinear" ? AplusParameterization::kNonlinear
                     : p == "power"     ? AplusParameterization::kPower
                                        : AplusParameterization::kHorizon;
    s.mapping.horizon_angle = o.GetText("horizon-angle") == "seed" ? AplusHorizonAngle::kSeed
                                                                   : AplusHorizonAngle::kGeometric;
    // Options that the chosen mapping ignores are errors, not silent no-ops.
    const bool power = s.mapping.kind == AplusParameterization::kPower;
    const bool horizon = s.mapping.kind == AplusParameterization::kHorizon;
    for (const char* name : {"p-u", "p-v", "p-w", "p-a", "p-s", "surface-ratio", "horizon-angle"}) {
        const std::string n = name;
        const bool used = (n == "p-u" || n == "p-w") ? (power || horizon)
                          : n == "p-v"               ? power
                                                     : horizon;
        if (o.WasSet(n) && !used) {
            Fail("atmosphere-plus: --", n, " does not apply to --parameterization ", p,
                 " (p-u, p-w: power and horizon; p-v: power; p-a, p-s, surface-ratio, "
                 "horizon-angle: horizon)");
        }
    }
    s.mapping.p_u = o.GetReal("p-u");
    s.mapping.p_v = o.GetReal("p-v");
    s.mapping.p_w = o.GetReal("p-w");
    s.mapping.p_a = o.GetReal("p-a");
    s.mapping.p_s = o.GetReal("p-s");
    s.mapping.s = o.GetReal("surface-ratio");
    s.width = o.GetInt("table-width");
    s.height = o.GetInt("table-height");
    s.depth = o.GetInt("table-depth");
    s.transmittance_width = o.GetInt("transmittance-width");
    s.transmittance_height = o.GetInt("transmittance-height");
    s.orders = o.GetInt("orders");
    s.transmittance_steps = o.GetInt("transmittance-steps");
    s.gather_theta = o.GetInt("gather-theta");
    s.gather_phi = o.GetInt("gather-phi");
    s.modified_rayleigh = o.GetText("rayleigh-phase") == "modified";
    CheckSettings(s);
    return s;
}

AtmospherePlusModel::AtmospherePlusModel(const ModelOptions& options)
    : info_(StaticInfo()), settings_(AplusSettingsFromOptions(options)) {
    atm_ = EarthAtmosphere();
}

void AtmospherePlusModel::Prepare(const AtmosphereParameters& atmosphere) {
    atm_ = atmosphere;
    settings_.mapping.bottom_radius = atm_.bottom_radius;
    settings_.mapping.height = atm_.top_radius - atm_.bottom_radius;
    // On a device backend the final tables stay on the device for the renders.
    ResidentScope scope(&resident_);
    tables_ = AplusPrecompute(atm_, settings_);
    scope.Keep(MakeEvaluator());
}

namespace {

// Everything that determines the tables' content, for the bake's JSON.
nlohmann::json SettingsJson(const AplusSettings& s) {
    const char* kinds[] = {"linear", "nonlinear", "power", "horizon"};
    const AplusMapping& m = s.mapping;
    nlohmann::json j;
    j["parameterization"] = kinds[static_cast<int>(m.kind)];
    j["horizon_angle"] = m.horizon_angle == AplusHorizonAngle::kSeed ? "seed" : "geometric";
    j["p_u"] = m.p_u;
    j["p_v"] = m.p_v;
    j["p_w"] = m.p_w;
    j["p_a"] = m.p_a;
    j["p_s"] = m.p_s;
    j["surface_ratio"] = m.s;
    j["table_size"] = {s.width, s.height, s.depth};
    j["transmittance_size"] = {s.transmittance_width, s.transmittance_height};
    j["orders"] = s.orders;
    j["transmittance_steps"] = s.transmittance_steps;
    j["gather"] = {s.gather_theta, s.gather_phi};
    return j;
}

}  // namespace

void AtmospherePlusModel::Bake(const std::string& directory) const {
    if (tables_.scattering.size() == 0) Fail("atmosphere-plus: nothing to bake before Prepare()");
    namespace fs = std::filesystem;
    WriteTableExr(tables_.scattering, (fs::path(directory) / "scattering.exr").string());
    WriteTableExr(tables_.transmittance, (fs::path(directory) / "transmittance.exr").string());
    nlohmann::json j;
    j["model"] = "atmosphere-plus";
    j["settings"] = SettingsJson(settings_);
    j["scattering"] = {
        {"file", "scattering.exr"},
        {"layout",
         "W*D x H pixels: D layers (sun zenith, w) side by side; x: altitude (u), "
         "y: view zenith (v); texel i holds the value at i/(size-1) of seed 000 2.4"},
        {"channels", "R, G, B: Rayleigh factored intensity; A: Mie (green channel)"}};
    j["transmittance"] = {{"file", "transmittance.exr"},
                          {"layout", "W x H: altitude (u) x view zenith (v), same mapping"}};
    j["atmosphere"] = nlohmann::json::parse(AtmosphereToJson(atm_));
    std::ofstream out(fs::path(directory) / "atmosphere-plus.json");
    out << j.dump(2) << "\n";
    if (!out) Fail("atmosphere-plus: cannot write ", directory, "/atmosphere-plus.json");
}

void AtmospherePlusModel::LoadBaked(const std::string& directory,
                                    const AtmosphereParameters& atmosphere) {
    namespace fs = std::filesystem;
    const fs::path json_path = fs::path(directory) / "atmosphere-plus.json";
    std::ifstream in(json_path);
    if (!in) Fail("atmosphere-plus: cannot read ", json_path.string());
    std::stringstream text;
    text << in.rdbuf();
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(text.str());
    } catch (const std::exception& e) {
        Fail("atmosphere-plus: ", json_path.string(), " is not valid JSON: ", e.what());
    }
    AplusSettings s = settings_;
    s.mapping.bottom_radius = atmosphere.bottom_radius;
    s.mapping.height = atmosphere.top_radius - atmosphere.bottom_radius;
    if (!j.contains("settings") || j["settings"] != SettingsJson(s)) {
        Fail("atmosphere-plus: the tables in ", directory, " were baked with other model options (",
             j.value("settings", nlohmann::json()).dump(), ")");
    }
    if (!j.contains("atmosphere") ||
        j["atmosphere"] != nlohmann::json::parse(AtmosphereToJson(atmosphere))) {
        Fail("atmosphere-plus: the tables in ", directory, " were baked for another atmosphere");
    }
    AplusTables t;
    t.scattering = ReadTableExr((fs::path(directory) / "scattering.exr").string(), s.depth, 4);
    t.transmittance = ReadTableExr((fs::path(directory) / "transmittance.exr").string(), 1, 3);
    if (t.scattering.width() != s.width || t.scattering.height() != s.height ||
        t.transmittance.width() != s.transmittance_width ||
        t.transmittance.height() != s.transmittance_height) {
        Fail("atmosphere-plus: table sizes in ", directory, " do not match the options");
    }
    atm_ = atmosphere;
    settings_ = s;
    tables_ = std::move(t);
}

AtmospherePlusEvaluator AtmospherePlusModel::MakeEvaluator() const {
    if (tables_.scattering.size() == 0) Fail("atmosphere-plus: Prepare() was not called");
    AtmospherePlusEvaluator e;
    e.atm = atm_;
    e.mapping = settings_.mapping;
    e.scattering = tables_.scattering.view();
    e.transmittance = tables_.transmittance.view();
    e.modified_rayleigh = settings_.modified_rayleigh;
    return e;
}

}  // namespace atmos
