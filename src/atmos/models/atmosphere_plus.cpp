// atmos model `atmosphere-plus`: precomputation and options (see atmosphere_plus.h).
#include "models/atmosphere_plus.h"
#include "models/order_check.h"

#include <chrono>
#include <cmath>
#include <vector>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "atmos/error.h"
#include "base/parallel.h"
#include "io/output_path.h"
#include "io/raw_tables.h"
#include "io/table_io.h"
#include "models/atmosphere_plus_stages.h"
#include "models/option_json.h"
#include "render/stages.h"

namespace atmos {

namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void CheckSettings(const AplusSettings& s) {
    AtmospherePlusModel::OptionRows().Check("atmosphere-plus", s);
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

    // Order 1 (Boody's Atmosphere Plus notes 2.1).
    start = std::chrono::steady_clock::now();
    Table order(s.width, s.height, s.depth, 4);
    RunStage("atmosphere-plus/order-1", count, 16, AplusSingleScatteringStage{atm, s, order.out()});
    session.Download(&order);
    out.scattering = order;
    out.order_seconds.push_back(SecondsSince(start));
    if (keep_orders) out.orders.push_back(order);

    // Orders 2..K (Boody's Atmosphere Plus notes 2.2): gather from order k-1, order k, add to the
    // sum. Each order's sum is recorded: orders that stop decreasing are reported
    // (models/order_check.h; orders >= 2 share their units).
    ScatteringOrders sums;
    sums.Add(1, TableSum(order));
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
        session.Download(&order);
        sums.Add(k, TableSum(order));
        if (keep_orders) out.orders.push_back(order);
        out.order_seconds.push_back(SecondsSince(start));
    }
    sums.WarnIfDiverging("atmosphere-plus", 3);
    session.Download(&out.transmittance);
    session.Download(&out.scattering);
    return out;
}

ModelInfo AtmospherePlusModel::StaticInfo() {
    ModelInfo info;
    info.name = "atmosphere-plus";
    info.title = "Atmosphere Plus (3D table without azimuth)";
    info.citation =
        "J. Boody, Atmosphere Plus notes: Boody's Atmosphere Plus notes sections 1.2-2.4 (the "
        "earlier Atmosphere Plus notes (Boody) earlier)";
    info.summary =
        "factored Rayleigh RGB + Mie alpha in a 3D table (h, view zenith, sun zenith), K orders "
        "by gathering; phase functions at render time";
    info.capabilities.multiple_scattering = true;
    info.capabilities.precomputed = true;
    info.capabilities.wide_channels = true;  // models/atmosphere_plus_wide.h
    info.options = OptionRows().Specs();
    info.capabilities.shader = "atmosphere_plus";
    info.capabilities.validity_notes = {
        "optically thick steps of the view-ray integrals use an energy-conserving rule "
        "(physics/exp_quadrature.h); Prepare still warns on stderr when a precomputed "
        "scattering order stops decreasing, and the radiance is then not valid"};
    // Measured: the zenith transmittance from the ground against its own at Earth
    // (docs/models/atmosphere-plus.md "Validity domain"): -1.6 % at a shell of
    // 26.4 column heights, -4.8 % at 44, -16 % at 88, T = (0.34, 0.15, 0.019) on
    // the 2x shell, 0 on the giant planet.
    info.domain.max_shell_heights = 35.0;
    info.domain.shell_heights_reason =
        "its tables' altitude mapping spreads their texels over the whole shell, few in the "
        "air near the ground (zenith transmittance -4.8 % at 44 heights, 0.019 (blue) on the 2x "
        "shell)";
    // Measured against the reference in dense air (docs/models/atmosphere-plus.md
    // "Validity domain"): Earth's Rayleigh times k, the worst of two ground
    // queries -4 % at k = 1, -12 % at k = 2 (blue optical depth ~0.54), -24 % at
    // k = 4, 8x too dark at 16; on `titan` its blue zenith is 12x too bright.
    info.domain.max_optical_depth = 0.6;
    info.domain.optical_depth_reason =
        "the sky is wrong in dense air: radiance -12 % at optical depth 0.54, -24 % at 1.07, "
        "8x too dark at 4.2 (against the reference)";
    return info;
}

const OptionTable<AplusSettings>& AtmospherePlusModel::OptionRows() {
    using S = AplusSettings;
    using P = AplusParameterization;
    auto mapping = [](auto member) {
        return [member](S& s) -> decltype(s.mapping.*member)& { return s.mapping.*member; };
    };
    static const auto table =
        OptionTable<S>()
            .Choice("parameterization", mapping(&AplusMapping::kind),
                    {{"linear", P::kLinear},
                     {"nonlinear", P::kNonlinear},
                     {"power", P::kPower},
                     {"horizon", P::kHorizon}},
                    "table mapping (Boody's Atmosphere Plus notes 2.4)")
            .ShapesTables()
            .Integer("table-width", &S::width, 2, 1024, "", "table size over altitude (u)")
            .ShapesTables()
            .Integer("table-height", &S::height, 2, 4096, "",
                     "table size over view zenith (v): 256, 128 or 64")
            .ShapesTables()
            .Integer("table-depth", &S::depth, 2, 1024, "", "table size over sun zenith (w)")
            .ShapesTables()
            .Integer("transmittance-width", &S::transmittance_width, 2, 4096, "",
                     "transmittance table size over altitude")
            .ShapesTables()
            .Integer("transmittance-height", &S::transmittance_height, 2, 4096, "",
                     "transmittance table size over view zenith")
            .ShapesTables()
            .Integer("orders", &S::orders, 1, 20, "", "scattering orders K")
            .ShapesTables()
            .Integer("transmittance-steps", &S::transmittance_steps, 1, 10000, "",
                     "trapezoidal intervals along rays (seed: 30)")
            .ShapesTables()
            .Integer("gather-theta", &S::gather_theta, 1, 1000, "",
                     "2D trapezoid intervals over Theta in [0, pi] (the author's solver: 6)")
            .ShapesTables()
            .Integer("gather-phi", &S::gather_phi, 1, 2000, "",
                     "2D trapezoid intervals over Phi in [0, 2 pi] (the author's solver: 12)")
            .ShapesTables()
            .Real("p-u", mapping(&AplusMapping::p_u), 0.1, 10, "",
                  "power p_u of u (power, horizon)")
            .ShapesTables()
            .Real("p-v", mapping(&AplusMapping::p_v), 0.1, 10, "", "power p_v of v (power)")
            .ShapesTables()
            .Real("p-w", mapping(&AplusMapping::p_w), 0.1, 10, "",
                  "power p_w of w (power, horizon)")
            .ShapesTables()
            .Real("p-a", mapping(&AplusMapping::p_a), 0.1, 10, "", "atmosphere power p_a (horizon)")
            .ShapesTables()
            .Real("p-s", mapping(&AplusMapping::p_s), 0.1, 10, "", "surface power p_s (horizon)")
            .ShapesTables()
            .Real("surface-ratio", mapping(&AplusMapping::s), 0, 0.99, "",
                  "s: most texture space for surfaces (horizon)")
            .ShapesTables()
            .Choice(
                "horizon-angle", mapping(&AplusMapping::horizon_angle),
                {{"geometric", AplusHorizonAngle::kGeometric}, {"seed", AplusHorizonAngle::kSeed}},
                "horizon cosine of the horizon mapping: geometric -sqrt(1-(Rp/r)^2) or the "
                "seed's -1+Rp/r")
            .ShapesTables()
            .Choice("rayleigh-phase", &S::modified_rayleigh,
                    {{"standard", false}, {"modified", true}},
                    "render-time Rayleigh phase: standard 3/4(1+c^2) or modified 0.8(1.4+0.5c^2) "
                    "(Boody's Atmosphere Plus notes 1.7)")
            // Options that the chosen mapping ignores are errors, not silent no-ops.
            .Validate([](const std::string& model, const S& s, const std::set<std::string>& given) {
                const P kind = s.mapping.kind;
                const bool power = kind == P::kPower;
                const bool horizon = kind == P::kHorizon;
                for (const char* name :
                     {"p-u", "p-v", "p-w", "p-a", "p-s", "surface-ratio", "horizon-angle"}) {
                    const std::string n = name;
                    const bool used = (n == "p-u" || n == "p-w") ? (power || horizon)
                                      : n == "p-v"               ? power
                                                                 : horizon;
                    if (given.count(n) && !used) {
                        Fail("model ", model, ": option ", n,
                             " does not apply to this parameterization (p-u, p-w: power and "
                             "horizon; p-v: power; p-a, p-s, surface-ratio, horizon-angle: "
                             "horizon)");
                    }
                }
            });
    return table;
}

AtmospherePlusModel::AtmospherePlusModel(const AplusSettings& options)
    : info_(StaticInfo()), settings_(options) {
    atm_ = EarthAtmosphere();
}

void AtmospherePlusModel::Prepare(const AtmosphereParameters& atmosphere) {
    WarnOutsideValidityDomain(Info(), atmosphere);  // its declared domain (atmos/model.h)
    atm_ = atmosphere;
    settings_.mapping.bottom_radius = atm_.bottom_radius;
    settings_.mapping.height = atm_.top_radius - atm_.bottom_radius;
    // On a device backend the final tables stay on the device for the renders.
    ResidentScope scope(&resident_);
    tables_ = AplusPrecompute(atm_, settings_);
    scope.Keep(MakeEvaluator());
}

namespace {

// The bake's "options": every option (those that shape the tables are checked
// by LoadBaked).
nlohmann::json SettingsJson(const AplusSettings& s) {
    const auto& table = AtmospherePlusModel::OptionRows();
    return nlohmann::json::parse(OptionsJson(table.Specs(), table.Values(s)).dump());
}

// The #defines shaders/atmosphere_plus.glsl reads (written to DIR/shaders/
// atmosphere_plus_constants.glsl by the bake): the atmosphere, the mapping
// (its effective powers) and the table sizes.
std::string GlslConstants(const AtmosphereParameters& a, const AplusSettings& s) {
    std::ostringstream o;
    BeginGlslConstants(
        o,
        "// Generated by `atmos bake atmosphere-plus`: the constants of these tables for\n"
        "// shaders/common.glsl and shaders/atmosphere_plus.glsl (include this first).\n"
        "// Lengths in metres.\n",
        a);
    const AplusMapping& m = s.mapping;
    o << "#define ATMOS_APLUS_HORIZON_MAPPING "
      << (m.kind == AplusParameterization::kHorizon ? 1 : 0) << "\n";
    o << "#define ATMOS_APLUS_SEED_HORIZON "
      << (m.horizon_angle == AplusHorizonAngle::kSeed ? 1 : 0) << "\n";
    o << "#define ATMOS_APLUS_POWER_U " << m.PowerU() << "\n";
    o << "#define ATMOS_APLUS_POWER_V " << m.PowerV() << "\n";
    o << "#define ATMOS_APLUS_POWER_W " << m.PowerW() << "\n";
    o << "#define ATMOS_APLUS_P_A " << m.p_a << "\n";
    o << "#define ATMOS_APLUS_P_S " << m.p_s << "\n";
    o << "#define ATMOS_APLUS_SURFACE_RATIO " << m.s << "\n";
    o << "#define ATMOS_APLUS_MODIFIED_RAYLEIGH " << (s.modified_rayleigh ? 1 : 0) << "\n";
    o << "#define ATMOS_SCATTERING_WIDTH " << s.width << "\n";
    o << "#define ATMOS_SCATTERING_HEIGHT " << s.height << "\n";
    o << "#define ATMOS_SCATTERING_DEPTH " << s.depth << "\n";
    o << "#define ATMOS_TRANSMITTANCE_WIDTH " << s.transmittance_width << "\n";
    o << "#define ATMOS_TRANSMITTANCE_HEIGHT " << s.transmittance_height << "\n";
    return o.str();
}

}  // namespace

namespace {
// The tables a bake writes raw (tables.f32/.f16), in their order.
std::vector<RawTable> RawTables(const AplusTables& tables) {
    return {{"scattering", &tables.scattering}, {"transmittance", &tables.transmittance}};
}
}  // namespace

int64_t AtmospherePlusModel::TableBytes() const {
    if (tables_.scattering.size() == 0) return -1;
    return static_cast<int64_t>(RawTablesFloat32Bytes(RawTables(tables_)));
}

void AtmospherePlusModel::Bake(const std::string& directory) const {
    if (tables_.scattering.size() == 0) Fail("atmosphere-plus: nothing to bake before Prepare()");
    namespace fs = std::filesystem;
    WriteTableExr(tables_.scattering, (fs::path(directory) / "scattering.exr").string());
    WriteTableExr(tables_.transmittance, (fs::path(directory) / "transmittance.exr").string());
    nlohmann::json j;
    j["model"] = "atmosphere-plus";
    j["format_version"] = 2;  // 2: "options" from the option table
    j["options"] = SettingsJson(settings_);
    j["scattering"] = {
        {"file", "scattering.exr"},
        {"layout",
         "W*D x H pixels: D layers (sun zenith, w) side by side; x: altitude (u), "
         "y: view zenith (v); texel i holds the value at i/(size-1) of Boody's Atmosphere Plus "
         "notes 2.4"},
        {"channels", "R, G, B: Rayleigh factored intensity; A: Mie (green channel)"}};
    j["transmittance"] = {{"file", "transmittance.exr"},
                          {"layout", "W x H: altitude (u) x view zenith (v), same mapping"}};
    j["atmosphere"] = nlohmann::json::parse(AtmosphereToJson(atm_));
    j["raw"] = nlohmann::json::parse(WriteRawTables(directory, RawTables(tables_)).dump());
    j["shaders"] = nlohmann::json::parse(
        WriteGlslConstants(directory, "atmosphere_plus", GlslConstants(atm_, settings_)).dump());
    WriteFileAtomically((fs::path(directory) / "atmosphere-plus.json").string(), j.dump(2) + "\n");
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
    if (!j.contains("format_version") || j["format_version"] != 2 || !j.contains("options")) {
        Fail("atmosphere-plus: the tables in ", directory,
             " were baked by another version of atmos (format_version ",
             j.value("format_version", nlohmann::json()).dump(), ", expected 2): bake them again");
    }
    CheckBakedOptions(json_path.string(), nlohmann::ordered_json::parse(j["options"].dump()),
                      OptionRows().Specs(), OptionRows().Values(s));
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
