// atmos model `hosek-wilkie`: the published data, the blend, options, Prepare.
#include "models/hosek_wilkie.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "atmos/embedded_presets.h"
#include "atmos/error.h"
#include "atmos/spectral.h"
#include "io/output_path.h"
#include "io/raw_tables.h"
#include "models/option_json.h"

namespace atmos {

namespace {

constexpr int kAlbedos = 2, kTurbidities = 10, kPoints = 6, kParams = 9;
constexpr double kFirstNm = 320.0, kStepNm = 40.0, kLastNm = 720.0;

HosekWilkieData LoadDataset(const char* name, int channels) {
    const char* text = nullptr;
    for (const detail::EmbeddedPreset* e = detail::kEmbeddedHosekWilkie; e->name; ++e) {
        if (std::string(e->name) == name) text = e->json;
    }
    if (text == nullptr) Fail("model hosek-wilkie: data set '", name, "' is not embedded");
    const nlohmann::json j = nlohmann::json::parse(text);
    HosekWilkieData d;
    d.channels = channels;
    for (int c = 0; c < channels; ++c) {
        d.config.push_back(j.at("config").at(c).get<std::vector<double>>());
        d.radiance.push_back(j.at("radiance").at(c).get<std::vector<double>>());
        if (d.config.back().size() != kAlbedos * kTurbidities * kPoints * kParams ||
            d.radiance.back().size() != kAlbedos * kTurbidities * kPoints) {
            Fail("model hosek-wilkie: data set '", name, "' channel ", c, " has the wrong size");
        }
    }
    return d;
}

// The ten control-point rows of one (albedo index, turbidity 1..10) corner.
void CornerPoints(const HosekWilkieData& d, int channel, int a, int t, double out[6][10]) {
    for (int k = 0; k < kPoints; ++k) {
        const size_t row = static_cast<size_t>((a * kTurbidities + (t - 1)) * kPoints + k);
        for (int p = 0; p < kParams; ++p) out[k][p] = d.config[channel][row * kParams + p];
        out[k][9] = d.radiance[channel][row];
    }
}

// The four corners and their weights of the authors' blend.
struct Corner {
    int a, t;
    double w;
};
void Corners(double turbidity, double albedo, Corner out[4]) {
    const int lo = std::min(static_cast<int>(std::floor(turbidity)), kTurbidities - 1);
    const double u = turbidity - lo;
    out[0] = {0, lo, (1.0 - albedo) * (1.0 - u)};
    out[1] = {0, lo + 1, (1.0 - albedo) * u};
    out[2] = {1, lo, albedo * (1.0 - u)};
    out[3] = {1, lo + 1, albedo * u};
}

// Node index and weight of `nm` between the spectral nodes.
void Node(double nm, int* i, double* u) {
    const double x = (nm - kFirstNm) / kStepNm;
    *i = std::min(static_cast<int>(std::floor(x)), 9);
    *u = x - *i;
}

double ParseAlbedo(const std::string& text) {
    if (text.empty()) return -1.0;
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (end == text.c_str() || *end != '\0' || !(v >= 0.0 && v <= 1.0)) {
        Fail("model hosek-wilkie: option albedo '", text, "': expected a number in [0, 1]");
    }
    return v;
}

}  // namespace

const HosekWilkieData& HosekWilkieDataset(HosekWilkieColour which) {
    static const HosekWilkieData rgb = LoadDataset("rgb", 3);
    static const HosekWilkieData xyz = LoadDataset("xyz", 3);
    static const HosekWilkieData spectral = LoadDataset("spectral", 11);
    switch (which) {
        case HosekWilkieColour::kRgb:
            return rgb;
        case HosekWilkieColour::kXyz:
            return xyz;
        default:
            return spectral;
    }
}

void HosekWilkieBlend(const HosekWilkieData& data, int channel, double turbidity, double albedo,
                      double ctrl[6][10]) {
    Corner corners[4];
    Corners(turbidity, albedo, corners);
    for (int k = 0; k < kPoints; ++k) {
        for (int p = 0; p < 10; ++p) ctrl[k][p] = 0.0;
    }
    for (const Corner& c : corners) {
        if (c.w == 0.0) continue;
        double points[6][10];
        CornerPoints(data, channel, c.a, c.t, points);
        for (int k = 0; k < kPoints; ++k) {
            for (int p = 0; p < 10; ++p) ctrl[k][p] += c.w * points[k][p];
        }
    }
}

double HosekWilkieAuthorsRadiance(HosekWilkieColour which, int channel, double wavelength_nm,
                                  double turbidity, double albedo, double elevation, double theta,
                                  double gamma) {
    const HosekWilkieData& data = HosekWilkieDataset(which);
    auto one = [&](int ch) {
        Corner corners[4];
        Corners(turbidity, albedo, corners);
        HosekWilkieConfig k{};
        for (const Corner& c : corners) {
            if (c.w == 0.0) continue;
            double points[6][10];
            CornerPoints(data, ch, c.a, c.t, points);
            const HosekWilkieConfig kc = HosekWilkieCook(points, elevation);
            for (int p = 0; p < 10; ++p) k.v[p] += c.w * kc.v[p];
        }
        return HosekWilkieRadiance(k, std::cos(theta), gamma);
    };
    if (wavelength_nm <= 0.0) return one(channel);
    int i = 0;
    double u = 0.0;
    Node(wavelength_nm, &i, &u);
    return (1.0 - u) * one(i) + (u > 0.0 ? u * one(i + 1) : 0.0);
}

double HosekWilkieSolarIrradiance(double nm) {
    if (!(nm >= kFirstNm && nm <= kLastNm)) {
        Fail("model hosek-wilkie: ", WavelengthLabel(nm),
             " nm is outside its spectral data (320-720 nm)");
    }
    int i = 0;
    double u = 0.0;
    Node(nm, &i, &u);
    return ((1.0 - u) * kHosekWilkieSolarRadiance[i] + u * kHosekWilkieSolarRadiance[i + 1]) *
           kHosekWilkieSunSolidAngle;
}

namespace {

// The validity domain of a fitted file: the atmosphere `atmos fit` recorded in
// its "fit"."atmosphere_parameters" (none recorded: no check).
ValidityDomain FittedFileDomain(const HosekWilkieCoefficients& c, const std::string& path) {
    const nlohmann::json fit = nlohmann::json::parse(c.fit_json, nullptr, false);
    if (!fit.is_object() || !fit.contains("atmosphere_parameters")) return {};
    return FittedSkyDomain(c.atmosphere.empty() ? path : c.atmosphere,
                           AtmosphereFromJson(fit["atmosphere_parameters"].dump(),
                                              path + ": fit.atmosphere_parameters"));
}

}  // namespace

ModelInfo HosekWilkieModel::StaticInfo() {
    ModelInfo info;
    info.name = "hosek-wilkie";
    info.title = "Hosek & Wilkie 2012 analytic sky dome";
    info.citation =
        "Hosek & Wilkie 2012 (ACM TOG 31(4), eq. 8-9; coefficients of the reference "
        "implementation 1.4a, BSD-3); Leenman's 2025 thesis section 5.3 (Eq. 35-37)";
    info.summary =
        "fitted extended-Perez sky (turbidity, ground albedo) for a ground viewer; RGB, XYZ or "
        "spectral 320-720 nm, per unit extraterrestrial solar irradiance";
    info.capabilities = FittedSkyCapabilities();
    info.capabilities.shader = "hosek_wilkie";
    info.domain = FittedToEarthDomain();  // the published coefficients; a fitted file's below
    info.options = OptionRows().Specs();
    return info;
}

const OptionTable<HosekWilkieOptions>& HosekWilkieModel::OptionRows() {
    static const auto table =
        OptionTable<HosekWilkieOptions>()
            .Real("turbidity", &HosekWilkieOptions::turbidity, 1.0, 10.0, "",
                  "atmospheric turbidity T")
            .ShapesTables()
            .Text("albedo", &HosekWilkieOptions::albedo,
                  "ground albedo in [0, 1] (default: the atmosphere's, the mean of its channels)")
            .ShapesTables()
            .Choice("colour", &HosekWilkieOptions::colour,
                    {{"rgb", HosekWilkieColour::kRgb},
                     {"xyz", HosekWilkieColour::kXyz},
                     {"spectral", HosekWilkieColour::kSpectral}},
                    "coefficient set: the authors' RGB fit, their CIE XYZ fit (to linear sRGB), "
                    "or their spectral fit at 680/550/440 nm")
            .ShapesTables()
            .Text("coefficients", &HosekWilkieOptions::coefficients,
                  "coefficient file written by `atmos fit --model hosek-wilkie` (the form fitted "
                  "to an atmosphere; turbidity, albedo and colour then do not apply)")
            .ShapesTables()
            .Validate([](const std::string&, const HosekWilkieOptions& o,
                         const std::set<std::string>& given) {
                ParseAlbedo(o.albedo);
                if (o.coefficients.empty()) return;
                for (const char* name : {"turbidity", "albedo", "colour"}) {
                    if (given.count(name)) {
                        Fail("model hosek-wilkie: option ", name,
                             " does not apply with coefficients=FILE (the file holds one "
                             "fitted sky: no turbidity or albedo blend, RGB channels only)");
                    }
                }
            });
    return table;
}

HosekWilkieModel::HosekWilkieModel(const HosekWilkieOptions& options) : options_(options) {
    albedo_ = ParseAlbedo(options.albedo);
    if (!options.coefficients.empty()) {
        fitted_ = std::make_shared<const HosekWilkieCoefficients>(
            LoadHosekWilkieCoefficients(options.coefficients));
    }
    Prepare(EarthAtmosphere());
    if (fitted_) {
        // The file's own atmosphere (`atmos fit` records it), checked from here
        // on; Earth's default above is not one it was fitted to.
        info_.domain = FittedFileDomain(*fitted_, options.coefficients);
    }
}

void HosekWilkieModel::Prepare(const AtmosphereParameters& atmosphere) {
    SetAtmosphere(atmosphere);
    HosekWilkieEvaluator& e = evaluator_;
    e.bottom = atmosphere.bottom_radius;
    e.top = atmosphere.top_radius;
    e.view.has_view = false;
    for (auto& row : e.mix) {
        for (double& m : row) m = 0.0;
    }
    if (fitted_) {
        // The fitted control points, already in atmos's units.
        e.sources = 3;
        for (int c = 0; c < 3; ++c) {
            for (int i = 0; i < 6; ++i) {
                for (int p = 0; p < 10; ++p) e.ctrl[c][i][p] = fitted_->ctrl[c][i][p];
            }
            e.mix[c][c] = 1.0;
        }
        return;
    }
    const Vec3d& g = atmosphere.ground_albedo;
    const double mean_albedo = Clamp((g.x + g.y + g.z) / 3.0, 0.0, 1.0);
    const double T = options_.turbidity;
    if (spectral_batch_ || options_.colour == HosekWilkieColour::kSpectral) {
        // Two sources per channel: the nodes either side of its wavelength,
        // at that channel's own ground albedo.
        const HosekWilkieData& data = HosekWilkieDataset(HosekWilkieColour::kSpectral);
        e.sources = 6;
        const double channel_albedo[3] = {g.x, g.y, g.z};
        for (int c = 0; c < 3; ++c) {
            const double nm = spectral_batch_ ? nm_[c] : kRgbWavelengths[c];
            const double a = albedo_ >= 0.0 ? albedo_ : Clamp(channel_albedo[c], 0.0, 1.0);
            const double scale = 1.0 / HosekWilkieSolarIrradiance(nm);
            int i = 0;
            double u = 0.0;
            Node(nm, &i, &u);
            HosekWilkieBlend(data, i, T, a, e.ctrl[2 * c]);
            HosekWilkieBlend(data, i + 1, T, a, e.ctrl[2 * c + 1]);
            e.mix[c][2 * c] = (1.0 - u) * scale;
            e.mix[c][2 * c + 1] = u * scale;
        }
        return;
    }
    const double a = albedo_ >= 0.0 ? albedo_ : mean_albedo;
    const HosekWilkieData& data = HosekWilkieDataset(options_.colour);
    e.sources = 3;
    for (int c = 0; c < 3; ++c) HosekWilkieBlend(data, c, T, a, e.ctrl[c]);
    const double s = 1.0 / kHosekWilkieSunY;
    if (options_.colour == HosekWilkieColour::kRgb) {
        for (int c = 0; c < 3; ++c) e.mix[c][c] = s;
    } else {
        // XYZ -> linear sRGB (IEC 61966-2-1, D65).
        const double m[3][3] = {{3.2404542, -1.5371385, -0.4985314},
                                {-0.9692660, 1.8760108, 0.0415560},
                                {0.0556434, -0.2040259, 1.0572252}};
        for (int c = 0; c < 3; ++c) {
            for (int k = 0; k < 3; ++k) e.mix[c][k] = m[c][k] * s;
        }
    }
}

void HosekWilkieModel::SetSpectralBatch(const SpectralAtmosphere&, const double nm[3]) {
    if (fitted_) {
        Fail("model hosek-wilkie: coefficients=", options_.coefficients,
             " holds the RGB channels of its fit only: no --wavelengths");
    }
    for (int c = 0; c < 3; ++c) {
        HosekWilkieSolarIrradiance(nm[c]);  // fails outside 320-720 nm
        nm_[c] = nm[c];
    }
    spectral_batch_ = true;
}

namespace {

constexpr const char* kBakeJson = "hosek-wilkie.json";
constexpr int kBakeFormatVersion = 1;

// The #defines and arrays shaders/hosek_wilkie.glsl reads: ATMOS_HW_SOURCES,
// ATMOS_HW_CONTROL (source s, control point i, parameter p at
// 60 s + 10 i + p: A B C D E F G I H L_M) and ATMOS_HW_MIX (channel c, source s
// at kHosekWilkieMaxSources c + s), from the evaluator Prepare() built.
std::string GlslConstants(const AtmosphereParameters& a, const HosekWilkieEvaluator& e) {
    std::ostringstream o;
    BeginGlslConstants(
        o,
        "// atmos bake: the constants of the hosek-wilkie model (Hosek & Wilkie 2012, "
        "eq. 8-9),\n// blended in turbidity and albedo; read by shaders/common.glsl and "
        "shaders/hosek_wilkie.glsl.\n",
        a);
    o << "#define ATMOS_HW_SOURCES " << e.sources << "\n";
    o << "const float ATMOS_HW_CONTROL[" << e.sources * 60 << "] = float[](";
    for (int s = 0; s < e.sources; ++s) {
        for (int i = 0; i < 6; ++i) {
            o << "\n   ";
            for (int p = 0; p < 10; ++p) {
                o << " " << e.ctrl[s][i][p] << (s + 1 < e.sources || i < 5 || p < 9 ? "," : "");
            }
        }
    }
    o << ");\n";
    o << "const float ATMOS_HW_MIX[" << 3 * kHosekWilkieMaxSources << "] = float[](";
    for (int c = 0; c < 3; ++c) {
        o << "\n   ";
        for (int s = 0; s < kHosekWilkieMaxSources; ++s) {
            o << " " << e.mix[c][s] << (c < 2 || s + 1 < kHosekWilkieMaxSources ? "," : "");
        }
    }
    o << ");\n";
    return o.str();
}

}  // namespace

void HosekWilkieModel::Bake(const std::string& directory) const {
    namespace fs = std::filesystem;
    nlohmann::ordered_json j;
    j["model"] = "hosek-wilkie";
    j["format_version"] = kBakeFormatVersion;
    j["options"] = OptionsJson(OptionRows().Specs(), OptionRows().Values(options_));
    j["atmosphere"] = nlohmann::ordered_json::parse(AtmosphereToJson(atmosphere()));
    j["raw"] = WriteRawTables(directory, {});  // no tables: empty blobs
    j["shaders"] =
        WriteGlslConstants(directory, "hosek_wilkie", GlslConstants(atmosphere(), evaluator_));
    WriteFileAtomically((fs::path(directory) / kBakeJson).string(), j.dump(2) + "\n");
}

void HosekWilkieModel::LoadBaked(const std::string& directory,
                                 const AtmosphereParameters& atmosphere) {
    const std::string path = (std::filesystem::path(directory) / kBakeJson).string();
    std::ifstream in(path);
    if (!in) Fail("hosek-wilkie: cannot read ", path, " (not a hosek-wilkie bake directory?)");
    nlohmann::json j;
    try {
        in >> j;
    } catch (const std::exception& e) {
        Fail("hosek-wilkie: ", path, " is not valid JSON: ", e.what());
    }
    if (!j.is_object() || j.value("model", "") != "hosek-wilkie") {
        Fail("hosek-wilkie: ", path, " was not baked by model hosek-wilkie");
    }
    if (j.value("format_version", -1) != kBakeFormatVersion || !j.contains("options")) {
        Fail("hosek-wilkie: ", path, " was baked by another version of atmos: bake it again");
    }
    if (!j.contains("atmosphere") ||
        j["atmosphere"] != nlohmann::json::parse(AtmosphereToJson(atmosphere))) {
        Fail("hosek-wilkie: ", path, " was baked for another atmosphere");
    }
    CheckBakedOptions(path, nlohmann::ordered_json::parse(j["options"].dump()),
                      OptionRows().Specs(), OptionRows().Values(options_));
    Prepare(atmosphere);
}

}  // namespace atmos
