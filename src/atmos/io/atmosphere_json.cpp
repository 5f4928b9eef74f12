// atmos: atmosphere parameter files (JSON), the embedded presets and --set overrides.
//
// Format (DESIGN.md "Canonical parameters"): one JSON object whose keys are the
// field names of AtmosphereParameters (SI units), plus optional "name" and
// "description" strings. RGB fields take a number or an array of 3 numbers.
// Density fields take one of
//   {"layers": [LAYER] or [LAYER, LAYER]}   Bruneton's 2017 implementation notes'
//   DensityProfileLayer list; a
//       LAYER is an object with any of width, exp_term, exp_scale, linear_term,
//       constant_term (missing ones are 0); one layer goes to layers[1] (the
//       profile's layers[0] then has width 0 and never applies);
//   {"scale_height": H}                      exp(-h / H);
//   {"tent": {"center": c, "half_width": w}} 1 at c, falling linearly to 0 at c -/+ w.
// Every field is required except mu_s_min (default cos(102 deg), Bruneton's 2017 implementation
// notes' demo) and the second Mie lobe's mie_phase_g2 and mie_phase_weight2 (default 0: one lobe).
// Unknown keys are errors (they are usually typos).
#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/embedded_presets.h"
#include "atmos/error.h"
#include "atmos/number.h"
#include "atmos/spectral.h"
#include "io/bounded_read.h"

namespace atmos {

namespace {

// Keeps the keys in file order, so a written file reads like the presets.
using Json = nlohmann::ordered_json;

enum class FieldKind { kScalar, kRgb, kDensity, kPhase };

struct FieldSpec {
    const char* name;
    FieldKind kind;
};

// The fields in the order of AtmosphereParameters (and of the files we write).
constexpr FieldSpec kFields[] = {
    {"bottom_radius", FieldKind::kScalar},
    {"top_radius", FieldKind::kScalar},
    {"rayleigh_scattering", FieldKind::kRgb},
    {"rayleigh_density", FieldKind::kDensity},
    {"mie_scattering", FieldKind::kRgb},
    {"mie_extinction", FieldKind::kRgb},
    {"mie_density", FieldKind::kDensity},
    {"mie_phase", FieldKind::kPhase},
    {"mie_phase_g", FieldKind::kScalar},
    {"mie_phase_g2", FieldKind::kScalar},
    {"mie_phase_weight2", FieldKind::kScalar},
    {"absorption_extinction", FieldKind::kRgb},
    {"absorption_density", FieldKind::kDensity},
    {"ground_albedo", FieldKind::kRgb},
    {"sun_angular_radius", FieldKind::kScalar},
    {"solar_irradiance", FieldKind::kRgb},
    {"mu_s_min", FieldKind::kScalar},
};

constexpr const char* kLayerKeys[] = {"width", "exp_term", "exp_scale", "linear_term",
                                      "constant_term"};

const char kDensityForms[] =
    "a density is {\"layers\": [...]}, {\"scale_height\": H} or "
    "{\"tent\": {\"center\": c, \"half_width\": w}}";

// Bruneton's 2017 implementation notes' demo: max_sun_zenith_angle = 102 degrees.
double DefaultMuSMin() { return std::cos(102.0 / 180.0 * kPi); }

// The fields a file may leave out: mu_s_min (DefaultMuSMin), the phase
// function's kind (Cornette-Shanks), the second Mie lobe (weight 0: one lobe);
// mie_phase_g too, which ReadTree requires for the kinds that use it.
bool IsOptionalField(const std::string& name) {
    return name == "mu_s_min" || name == "mie_phase" || name == "mie_phase_g" ||
           name == "mie_phase_g2" || name == "mie_phase_weight2";
}

const FieldSpec* FindField(const std::string& name) {
    for (const FieldSpec& spec : kFields) {
        if (name == spec.name) return &spec;
    }
    return nullptr;
}

std::string FieldList() {
    std::string list;
    for (const FieldSpec& spec : kFields) {
        if (!list.empty()) list += ", ";
        list += spec.name;
    }
    return list;
}

std::string Join(const std::vector<std::string>& items, const std::string& separator) {
    std::string joined;
    for (size_t i = 0; i < items.size(); ++i) {
        if (i > 0) joined += separator;
        joined += items[i];
    }
    return joined;
}

bool IsLayerKey(const std::string& key) {
    return std::any_of(std::begin(kLayerKeys), std::end(kLayerKeys),
                       [&](const char* k) { return key == k; });
}

// nlohmann's messages start with "[json.exception.parse_error.101] "; keep the rest.
std::string JsonMessage(const nlohmann::json::exception& e) {
    std::string message = e.what();
    if (!message.empty() && message[0] == '[') {
        const size_t end = message.find("] ");
        if (end != std::string::npos) message = message.substr(end + 2);
    }
    return message;
}

// ---------------------------------------------------------------------------------------
// Reading the tree. `where` is the message prefix, e.g. "atmosphere 'earth'".

double ReadNumber(const Json& node, const std::string& where, const std::string& path) {
    if (!node.is_number()) Fail(where, ": field '", path, "' must be a number");
    return node.get<double>();
}

Vec3d ReadRgb(const Json& node, const std::string& where, const std::string& path) {
    if (node.is_number()) return Vec3d(node.get<double>());
    if (node.is_array() && node.size() == 3 &&
        std::all_of(node.begin(), node.end(), [](const Json& v) { return v.is_number(); })) {
        return Vec3d(node[0].get<double>(), node[1].get<double>(), node[2].get<double>());
    }
    Fail(where, ": field '", path, "' must be a number or an array of 3 numbers");
}

DensityProfileLayer ReadLayer(const Json& node, const std::string& where, const std::string& path) {
    if (!node.is_object()) Fail(where, ": field '", path, "' must be an object");
    for (const auto& item : node.items()) {
        if (!IsLayerKey(item.key())) {
            Fail(where, ": unknown field '", path, ".", item.key(),
                 "' (a layer has width, exp_term, exp_scale, linear_term, constant_term)");
        }
    }
    DensityProfileLayer layer;
    double* const values[] = {&layer.width, &layer.exp_term, &layer.exp_scale, &layer.linear_term,
                              &layer.constant_term};
    for (size_t i = 0; i < std::size(kLayerKeys); ++i) {
        const auto it = node.find(kLayerKeys[i]);
        if (it != node.end()) *values[i] = ReadNumber(*it, where, path + "." + kLayerKeys[i]);
    }
    return layer;
}

DensityProfile ReadDensity(const Json& node, const std::string& where, const std::string& path) {
    if (!node.is_object() || node.size() != 1) {
        Fail(where, ": field '", path, "' must be an object with exactly one key (", kDensityForms,
             ")");
    }
    const std::string key = node.begin().key();
    const Json& value = node.begin().value();
    if (key == "scale_height") {
        const double scale_height = ReadNumber(value, where, path + ".scale_height");
        if (!(scale_height > 0.0) || !std::isfinite(scale_height)) {
            Fail(where, ": field '", path, ".scale_height' must be a finite number > 0 (m)");
        }
        return ExponentialProfile(scale_height);
    }
    if (key == "tent") {
        if (!value.is_object()) Fail(where, ": field '", path, ".tent' must be an object");
        for (const auto& item : value.items()) {
            if (item.key() != "center" && item.key() != "half_width") {
                Fail(where, ": unknown field '", path, ".tent.", item.key(),
                     "' (a tent has center and half_width)");
            }
        }
        for (const char* required : {"center", "half_width"}) {
            if (!value.contains(required)) {
                Fail(where, ": field '", path, ".tent.", required, "' is missing");
            }
        }
        const double center = ReadNumber(value["center"], where, path + ".tent.center");
        const double half_width = ReadNumber(value["half_width"], where, path + ".tent.half_width");
        if (!(center >= 0.0) || !std::isfinite(center)) {
            Fail(where, ": field '", path, ".tent.center' must be a finite number >= 0 (m)");
        }
        if (!(half_width > 0.0) || !std::isfinite(half_width)) {
            Fail(where, ": field '", path, ".tent.half_width' must be a finite number > 0 (m)");
        }
        // Below the centre: (h - c + w) / w; above: (c + w - h) / w (Bruneton's 2017 implementation
        // notes' clamp to [0, 1] cuts both ends). The constant terms are written as one division
        // each so that the canonical ozone layer (c = 25 km, w = 15 km) gives exactly -2/3 and 8/3.
        DensityProfile profile;
        profile.layers[0].width = center;
        profile.layers[0].linear_term = 1.0 / half_width;
        profile.layers[0].constant_term = (half_width - center) / half_width;
        profile.layers[1].linear_term = -1.0 / half_width;
        profile.layers[1].constant_term = (half_width + center) / half_width;
        return profile;
    }
    if (key == "layers") {
        if (!value.is_array() || value.empty() || value.size() > 2) {
            Fail(where, ": field '", path, ".layers' must be an array of 1 or 2 layers");
        }
        DensityProfile profile;
        if (value.size() == 1) {
            profile.layers[1] = ReadLayer(value[0], where, path + ".layers[0]");
        } else {
            profile.layers[0] = ReadLayer(value[0], where, path + ".layers[0]");
            profile.layers[1] = ReadLayer(value[1], where, path + ".layers[1]");
        }
        return profile;
    }
    Fail(where, ": unknown field '", path, ".", key, "' (", kDensityForms, ")");
}

// ---------------------------------------------------------------------------------------
// Spectral fields (include/atmos/spectral.h). A wavelength-dependent field may be an
// object with one key (docs/atmosphere.md "Spectral fields"); ResolveSpectra parses
// those into spectra and replaces each by its values at 680/550/440 nm, so that
// the rest of the reader (and every RGB user) sees an RGB atmosphere.

constexpr const char* kSpectralFields[] = {"rayleigh_scattering", "mie_extinction",
                                           "mie_scattering",      "absorption_extinction",
                                           "ground_albedo",       "solar_irradiance"};

const char kSpectrumForms[] =
    "a spectrum is a number, [r, g, b], {\"table\": ...}, {\"penndorf\": {...}}, "
    "{\"power_law\": {...}}, {\"angstrom\": {...}}, {\"single_scattering_albedo\": ...} "
    "(mie_scattering) or {\"ozone\": {...}} (absorption_extinction)";

void CheckKeys(const Json& node, const std::string& where, const std::string& path,
               const std::vector<std::string>& allowed) {
    if (!node.is_object()) Fail(where, ": field '", path, "' must be an object");
    for (const auto& item : node.items()) {
        if (std::find(allowed.begin(), allowed.end(), item.key()) == allowed.end()) {
            Fail(where, ": unknown field '", path, ".", item.key(), "' (", path, " has ",
                 Join(allowed, ", "), ")");
        }
    }
}

double ReadPositive(const Json& node, const std::string& key, const std::string& where,
                    const std::string& path, bool allow_zero) {
    if (!node.contains(key)) Fail(where, ": field '", path, ".", key, "' is missing");
    const double v = ReadNumber(node[key], where, path + "." + key);
    if (!std::isfinite(v) || v < 0.0 || (!allow_zero && v == 0.0)) {
        Fail(where, ": field '", path, ".", key, "' must be a finite number ",
             allow_zero ? ">= 0" : "> 0");
    }
    return v;
}

std::vector<double> ReadNumberArray(const Json& node, const std::string& where,
                                    const std::string& path) {
    if (!node.is_array() || node.empty()) {
        Fail(where, ": field '", path, "' must be a non-empty array of numbers");
    }
    std::vector<double> values;
    for (size_t i = 0; i < node.size(); ++i) {
        values.push_back(ReadNumber(node[i], where, path + "[" + std::to_string(i) + "]"));
        if (!std::isfinite(values.back())) {
            Fail(where, ": field '", path, "[", i, "]' must be a finite number");
        }
    }
    return values;
}

Spectrum ReadTable(const Json& node, const std::string& where, const std::string& path) {
    if (node.is_string()) {
        std::vector<double> nm, values;
        try {
            SpectralDataTable(node.get<std::string>(), 0, &nm, &values);
        } catch (const Error& e) {
            Fail(where, ": field '", path, "': ", e.what());
        }
        return Spectrum::Table(nm, values);
    }
    CheckKeys(node, where, path, {"nm", "value", "name", "scale"});
    std::vector<double> nm, values;
    if (node.contains("name")) {
        if (node.contains("nm") || node.contains("value")) {
            Fail(where, ": field '", path, "' takes either name or nm and value");
        }
        if (!node["name"].is_string()) Fail(where, ": field '", path, ".name' must be a string");
        try {
            SpectralDataTable(node["name"].get<std::string>(), 0, &nm, &values);
        } catch (const Error& e) {
            Fail(where, ": field '", path, ".name': ", e.what());
        }
    } else {
        if (!node.contains("nm")) Fail(where, ": field '", path, ".nm' is missing");
        if (!node.contains("value")) Fail(where, ": field '", path, ".value' is missing");
        nm = ReadNumberArray(node["nm"], where, path + ".nm");
        values = ReadNumberArray(node["value"], where, path + ".value");
        if (nm.size() != values.size()) {
            Fail(where, ": field '", path, "': nm has ", nm.size(), " entries and value ",
                 values.size());
        }
        for (size_t i = 1; i < nm.size(); ++i) {
            if (!(nm[i] > nm[i - 1])) {
                Fail(where, ": field '", path, ".nm' must increase strictly (entry ", i, ")");
            }
        }
    }
    const double scale =
        node.contains("scale") ? ReadPositive(node, "scale", where, path, true) : 1.0;
    return Spectrum::Table(nm, values, scale);
}

// The integral of a density profile over [0, top - bottom] (m): 10^5 midpoint steps.
double DensityIntegral(const DensityProfile& profile, double height) {
    auto density = [&](double h) {
        const DensityProfileLayer& l =
            h < profile.layers[0].width ? profile.layers[0] : profile.layers[1];
        const double e = l.exp_term == 0.0 ? 0.0 : l.exp_term * std::exp(l.exp_scale * h);
        return std::clamp(e + l.linear_term * h + l.constant_term, 0.0, 1.0);
    };
    constexpr int kSteps = 100000;
    const double dh = height / kSteps;
    double sum = 0.0;
    for (int i = 0; i < kSteps; ++i) sum += density((i + 0.5) * dh);
    return sum * dh;
}

Spectrum ReadSpectrum(const Json& node, const Json& root, const std::string& field,
                      const std::string& where, const std::string& path,
                      const Spectrum* mie_extinction) {
    if (!node.is_object()) return Spectrum::FromRgb(ReadRgb(node, where, path));
    if (node.size() != 1) {
        Fail(where, ": field '", path, "' must be an object with exactly one key (", kSpectrumForms,
             ")");
    }
    const std::string key = node.begin().key();
    const Json& value = node.begin().value();
    const std::string sub = path + "." + key;
    if (key == "table") return ReadTable(value, where, sub);
    if (key == "penndorf") {
        CheckKeys(value, where, sub, {"scale"});
        Spectrum s;
        SpectralTerm t;
        t.kind = SpectralTerm::Kind::kPenndorf;
        t.value = value.contains("scale") ? ReadPositive(value, "scale", where, sub, true) : 1.0;
        s.terms.push_back(t);
        return s;
    }
    if (key == "power_law") {
        CheckKeys(value, where, sub, {"value", "reference_nm", "exponent"});
        Spectrum s;
        SpectralTerm t;
        t.kind = SpectralTerm::Kind::kPowerLaw;
        t.value = ReadPositive(value, "value", where, sub, true);
        t.reference_nm = ReadPositive(value, "reference_nm", where, sub, false);
        if (!value.contains("exponent")) Fail(where, ": field '", sub, ".exponent' is missing");
        t.exponent = ReadNumber(value["exponent"], where, sub + ".exponent");
        if (!std::isfinite(t.exponent) || std::abs(t.exponent) > 10.0) {
            Fail(where, ": field '", sub, ".exponent' must be in [-10, 10]");
        }
        s.terms.push_back(t);
        return s;
    }
    if (key == "angstrom" && (field == "mie_extinction" || field == "mie_scattering")) {
        CheckKeys(value, where, sub, {"alpha", "beta", "scale_height"});
        if (!value.contains("alpha")) Fail(where, ": field '", sub, ".alpha' is missing");
        const double alpha = ReadNumber(value["alpha"], where, sub + ".alpha");
        if (!std::isfinite(alpha) || std::abs(alpha) > 10.0) {
            Fail(where, ": field '", sub, ".alpha' must be in [-10, 10]");
        }
        const double beta = ReadPositive(value, "beta", where, sub, true);
        double scale_height = 0.0;
        if (value.contains("scale_height")) {
            scale_height = ReadPositive(value, "scale_height", where, sub, false);
        } else {
            const Json& mie_density = root.contains("mie_density") ? root["mie_density"] : Json();
            if (!mie_density.is_object() || !mie_density.contains("scale_height")) {
                Fail(where, ": field '", sub,
                     ".scale_height' is missing (needed unless mie_density is "
                     "{\"scale_height\": H})");
            }
            scale_height = ReadPositive(mie_density, "scale_height", where, "mie_density", false);
        }
        // beta_ext(lambda) = beta (lambda / 1000 nm)^-alpha / H: beta is the optical
        // depth of the exponential column at 1 um.
        Spectrum s;
        SpectralTerm t;
        t.kind = SpectralTerm::Kind::kPowerLaw;
        t.value = beta / scale_height;
        t.reference_nm = 1000.0;
        t.exponent = alpha;
        s.terms.push_back(t);
        return s;
    }
    if (key == "single_scattering_albedo" && field == "mie_scattering") {
        Spectrum albedo = ReadSpectrum(value, root, "albedo", where, sub, nullptr);
        Spectrum s = *mie_extinction;
        s.terms.insert(s.terms.end(), albedo.terms.begin(), albedo.terms.end());
        return s;
    }
    if (key == "ozone" && field == "absorption_extinction") {
        CheckKeys(value, where, sub, {"dobson", "number_density", "cross_section"});
        if (value.contains("dobson") == value.contains("number_density")) {
            Fail(where, ": field '", sub, "' takes one of dobson and number_density");
        }
        if (!value.contains("cross_section")) {
            Fail(where, ": field '", sub, ".cross_section' is missing");
        }
        double number_density = 0.0;  // molecules per m^3 at density 1
        if (value.contains("number_density")) {
            number_density = ReadPositive(value, "number_density", where, sub, true);
        } else {
            // 1 Dobson unit = 2.687e20 molecules per m^2 (Bruneton 2017's demo,
            // kDobsonUnit); the peak density is the column over the profile's integral.
            const double dobson = ReadPositive(value, "dobson", where, sub, true);
            if (!root.contains("absorption_density")) {
                Fail(where, ": field 'absorption_density' is missing");
            }
            const DensityProfile profile =
                ReadDensity(root["absorption_density"], where, "absorption_density");
            const double bottom =
                ReadNumber(root.value("bottom_radius", Json(0.0)), where, "bottom_radius");
            const double top = ReadNumber(root.value("top_radius", Json(0.0)), where, "top_radius");
            const double integral = DensityIntegral(profile, std::max(top - bottom, 0.0));
            if (!(integral > 0.0)) {
                Fail(where, ": field '", sub,
                     ".dobson' needs an absorption_density with a non-zero column");
            }
            number_density = dobson * 2.687e20 / integral;
        }
        Spectrum s = ReadSpectrum(value["cross_section"], root, "cross_section", where,
                                  sub + ".cross_section", nullptr);
        SpectralTerm t;
        t.value = number_density;
        s.terms.push_back(t);
        return s;
    }
    Fail(where, ": unknown field '", sub, "' (", kSpectrumForms, ")");
}

// Parses the spectral fields of `root` into `out` (may be null) and replaces each
// by its values at kRgbWavelengths.
void ResolveSpectra(Json& root, const std::string& where, SpectralAtmosphere* out) {
    if (!root.is_object()) return;
    SpectralAtmosphere local;
    SpectralAtmosphere& s = out != nullptr ? *out : local;
    Spectrum* targets[] = {&s.rayleigh_scattering,   &s.mie_extinction, &s.mie_scattering,
                           &s.absorption_extinction, &s.ground_albedo,  &s.solar_irradiance};
    for (size_t i = 0; i < std::size(kSpectralFields); ++i) {
        const char* field = kSpectralFields[i];
        if (!root.contains(field)) continue;  // ReadTree names the missing field
        Json& node = root[field];
        if (node.is_object()) s.spectral = true;
        *targets[i] = ReadSpectrum(node, root, field, where, field, &s.mie_extinction);
        if (node.is_object()) {
            node =
                Json::array({targets[i]->At(kRgbWavelengths[0]), targets[i]->At(kRgbWavelengths[1]),
                             targets[i]->At(kRgbWavelengths[2])});
        }
    }
}

// ---------------------------------------------------------------------------------------
// The Mie phase function (docs/atmosphere.md "Mie phase functions"):
//   "mie_phase": "cornette-shanks" | "henyey-greenstein" | "isotropic", or
//   "mie_phase": {"kind": KIND} with, for "tabulated", one of
//     "angles_deg": [...], "values": [...]       the nodes inline;
//     "table": NAME (+ "column": i)              an embedded table of data/spectra/NAME.csv
//                                                (first column the angle in deg);
//     "file": PATH (+ "column": i)               a CSV file of the same form.

const char kPhaseForms[] =
    "mie_phase is \"cornette-shanks\", \"henyey-greenstein\", \"isotropic\" or "
    "{\"kind\": \"tabulated\", \"angles_deg\": [...], \"values\": [...]} (or \"table\": NAME "
    "or \"file\": PATH instead of the arrays, with an optional \"column\")";

MiePhaseKind ParsePhaseKind(const Json& node, const std::string& where, const std::string& path) {
    if (!node.is_string()) Fail(where, ": field '", path, "' must be a string (", kPhaseForms, ")");
    const std::string name = node.get<std::string>();
    for (MiePhaseKind kind : {MiePhaseKind::kCornetteShanks, MiePhaseKind::kHenyeyGreenstein,
                              MiePhaseKind::kIsotropic, MiePhaseKind::kTabulated}) {
        if (name == MiePhaseKindName(kind)) return kind;
    }
    Fail(where, ": field '", path, "' is '", name,
         "' (kinds: cornette-shanks, henyey-greenstein, isotropic, tabulated)");
}

// The angle and value columns of a phase CSV's text: '#' comments, one header
// line, then rows of numbers (the angle first).
void ParsePhaseCsv(const std::string& text, int column, const std::string& where,
                   const std::string& path, std::vector<double>* angles,
                   std::vector<double>* values) {
    std::string_view rest(text);
    bool header = false;
    int line_number = 0;
    while (!rest.empty()) {
        const size_t eol = rest.find('\n');
        std::string_view line = rest.substr(0, eol);
        rest = eol == std::string_view::npos ? std::string_view() : rest.substr(eol + 1);
        ++line_number;
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        if (line.empty() || line[0] == '#') continue;
        if (!header) {
            header = true;
            continue;
        }
        std::vector<double> row;
        size_t begin = 0;
        while (true) {
            const size_t comma = line.find(',', begin);
            const std::string_view field = line.substr(
                begin, comma == std::string_view::npos ? std::string_view::npos : comma - begin);
            double v = 0.0;
            const NumberError e = ParseNumber(field, &v);
            if (e != NumberError::kNone) {
                Fail(where, ": field '", path, "': line ", line_number, ": '", std::string(field),
                     "' ", NumberErrorText(e));
            }
            row.push_back(v);
            if (comma == std::string_view::npos) break;
            begin = comma + 1;
        }
        if (static_cast<int>(row.size()) < column + 2) {
            Fail(where, ": field '", path, "': line ", line_number, " has ", row.size(),
                 " columns; the angle and value column ", column, " need ", column + 2);
        }
        angles->push_back(row[0]);
        values->push_back(row[static_cast<size_t>(column) + 1]);
    }
}

void ReadMiePhase(const Json& node, const std::string& where, AtmosphereParameters* a) {
    const std::string path = "mie_phase";
    if (node.is_string()) {
        a->mie_phase_kind = ParsePhaseKind(node, where, path);
        if (a->mie_phase_kind == MiePhaseKind::kTabulated) {
            Fail(where, ": field 'mie_phase': a tabulated phase function needs its table (",
                 kPhaseForms, ")");
        }
        return;
    }
    if (!node.is_object())
        Fail(where, ": field 'mie_phase' must be a string or an object (", kPhaseForms, ")");
    if (!node.contains("kind"))
        Fail(where, ": field 'mie_phase.kind' is missing (", kPhaseForms, ")");
    a->mie_phase_kind = ParsePhaseKind(node["kind"], where, path + ".kind");
    if (a->mie_phase_kind != MiePhaseKind::kTabulated) {
        CheckKeys(node, where, path, {"kind"});
        return;
    }
    CheckKeys(node, where, path, {"kind", "angles_deg", "values", "table", "file", "column"});
    const int sources = static_cast<int>(node.contains("angles_deg") || node.contains("values")) +
                        static_cast<int>(node.contains("table")) +
                        static_cast<int>(node.contains("file"));
    if (sources != 1) {
        Fail(where, ": field 'mie_phase' takes exactly one of angles_deg and values, table, file");
    }
    std::vector<double> angles, values;
    if (node.contains("table") || node.contains("file")) {
        int column = 0;
        if (node.contains("column")) {
            const double c = ReadNumber(node["column"], where, path + ".column");
            if (!(c >= 0.0 && c <= 64.0) || c != std::floor(c)) {
                Fail(where, ": field 'mie_phase.column' must be an integer in [0, 64]");
            }
            column = static_cast<int>(c);
        }
        if (node.contains("table")) {
            if (!node["table"].is_string()) {
                Fail(where, ": field 'mie_phase.table' must be a string (a table name)");
            }
            try {
                SpectralDataTable(node["table"].get<std::string>(), column, &angles, &values);
            } catch (const Error& e) {
                Fail(where, ": field 'mie_phase.table': ", e.what());
            }
        } else {
            if (!node["file"].is_string()) {
                Fail(where, ": field 'mie_phase.file' must be a string (a CSV file's path)");
            }
            const std::string file = node["file"].get<std::string>();
            std::string text;
            try {
                text = ReadFileBounded(file, size_t{1} << 20, 4096);
            } catch (const Error& e) {
                Fail(where, ": field 'mie_phase.file': ", e.what());
            }
            ParsePhaseCsv(text, column, where, path + ".file", &angles, &values);
        }
    } else {
        if (node.contains("column")) {
            Fail(where, ": field 'mie_phase.column' goes with table or file");
        }
        if (!node.contains("angles_deg")) Fail(where, ": field 'mie_phase.angles_deg' is missing");
        if (!node.contains("values")) Fail(where, ": field 'mie_phase.values' is missing");
        angles = ReadNumberArray(node["angles_deg"], where, path + ".angles_deg");
        values = ReadNumberArray(node["values"], where, path + ".values");
    }
    if (angles.size() != values.size()) {
        Fail(where, ": field 'mie_phase': angles_deg has ", angles.size(), " entries and values ",
             values.size());
    }
    if (angles.size() < 2 || angles.size() > static_cast<size_t>(kMaxMiePhaseNodes)) {
        Fail(where, ": field 'mie_phase': a tabulated phase function has 2 to ", kMaxMiePhaseNodes,
             " nodes, not ", angles.size());
    }
    MiePhaseTable& t = a->mie_phase_table;
    t.count = static_cast<int>(angles.size());
    for (int i = 0; i < t.count; ++i) {
        t.angle_deg[i] = angles[static_cast<size_t>(i)];
        t.value[i] = values[static_cast<size_t>(i)];
    }
    try {
        FinishMiePhaseTable(&t, path);
    } catch (const Error& e) {
        Fail(where, ": ", e.what());
    }
}

AtmosphereParameters ReadTree(const Json& root, const std::string& where) {
    if (!root.is_object()) Fail(where, ": the top level must be a JSON object");
    for (const auto& item : root.items()) {
        const std::string& key = item.key();
        if (key == "name" || key == "description") {
            if (!item.value().is_string()) Fail(where, ": field '", key, "' must be a string");
            continue;
        }
        if (FindField(key) == nullptr) {
            Fail(where, ": unknown field '", key, "' (fields: ", FieldList(),
                 ", and the optional name, description)");
        }
    }
    for (const FieldSpec& spec : kFields) {
        if (!root.contains(spec.name) && !IsOptionalField(spec.name)) {
            Fail(where, ": field '", spec.name, "' is missing");
        }
    }

    AtmosphereParameters a;
    a.bottom_radius = ReadNumber(root["bottom_radius"], where, "bottom_radius");
    a.top_radius = ReadNumber(root["top_radius"], where, "top_radius");
    a.rayleigh_scattering = ReadRgb(root["rayleigh_scattering"], where, "rayleigh_scattering");
    a.rayleigh_density = ReadDensity(root["rayleigh_density"], where, "rayleigh_density");
    a.mie_scattering = ReadRgb(root["mie_scattering"], where, "mie_scattering");
    a.mie_extinction = ReadRgb(root["mie_extinction"], where, "mie_extinction");
    a.mie_density = ReadDensity(root["mie_density"], where, "mie_density");
    if (root.contains("mie_phase")) ReadMiePhase(root["mie_phase"], where, &a);
    if (a.mie_phase_kind == MiePhaseKind::kCornetteShanks ||
        a.mie_phase_kind == MiePhaseKind::kHenyeyGreenstein) {
        if (!root.contains("mie_phase_g")) Fail(where, ": field 'mie_phase_g' is missing");
        a.mie_phase_g = ReadNumber(root["mie_phase_g"], where, "mie_phase_g");
        if (root.contains("mie_phase_g2")) {
            a.mie_phase_g2 = ReadNumber(root["mie_phase_g2"], where, "mie_phase_g2");
        }
        if (root.contains("mie_phase_weight2")) {
            a.mie_phase_weight2 = ReadNumber(root["mie_phase_weight2"], where, "mie_phase_weight2");
        }
    } else {
        // Isotropic and tabulated phase functions have no lobes: the lobe fields
        // are not read (so that --set mie_phase=... works on any preset);
        // mie_phase_g is the function's mean cosine, for models that take an
        // asymmetry parameter.
        a.mie_phase_g =
            a.mie_phase_kind == MiePhaseKind::kTabulated ? a.mie_phase_table.mean_cosine : 0.0;
        a.mie_phase_g2 = 0.0;
        a.mie_phase_weight2 = 0.0;
    }
    a.absorption_extinction =
        ReadRgb(root["absorption_extinction"], where, "absorption_extinction");
    a.absorption_density = ReadDensity(root["absorption_density"], where, "absorption_density");
    a.ground_albedo = ReadRgb(root["ground_albedo"], where, "ground_albedo");
    a.sun_angular_radius = ReadNumber(root["sun_angular_radius"], where, "sun_angular_radius");
    a.solar_irradiance = ReadRgb(root["solar_irradiance"], where, "solar_irradiance");
    a.mu_s_min = root.contains("mu_s_min") ? ReadNumber(root["mu_s_min"], where, "mu_s_min")
                                           : DefaultMuSMin();
    try {
        ValidateAtmosphere(a);
    } catch (const Error& e) {
        Fail(where, ": ", e.what());
    }
    return a;
}

Json ParseText(const std::string& text, const std::string& source_name) {
    // Duplicate keys are errors (JSON parsers keep either; a typo'd copy would
    // silently win): the parser's callback sees each key, a stack holds the
    // keys of the objects being read.
    std::vector<std::vector<std::string>> keys;
    std::string duplicate;
    auto callback = [&](int depth, nlohmann::json::parse_event_t event, Json& parsed) {
        (void)depth;
        using Event = nlohmann::json::parse_event_t;
        if (event == Event::object_start) {
            keys.emplace_back();
        } else if (event == Event::object_end) {
            if (!keys.empty()) keys.pop_back();
        } else if (event == Event::key && !keys.empty()) {
            const std::string key = parsed.get<std::string>();
            std::vector<std::string>& seen = keys.back();
            if (duplicate.empty() && std::find(seen.begin(), seen.end(), key) != seen.end()) {
                duplicate = key;
            }
            seen.push_back(key);
        }
        return true;
    };
    try {
        Json root = Json::parse(text, callback);
        if (!duplicate.empty()) {
            Fail("atmosphere '", source_name, "': the key \"", duplicate,
                 "\" appears twice in one object (each field once)");
        }
        return root;
    } catch (const nlohmann::json::parse_error& e) {
        Fail("atmosphere '", source_name, "': JSON syntax error: ", JsonMessage(e));
    }
}

// ---------------------------------------------------------------------------------------
// Writing.

Json RgbToJson(const Vec3d& v) { return Json::array({v.x, v.y, v.z}); }

Json LayerToJson(const DensityProfileLayer& layer) {
    Json node = Json::object();
    node["width"] = layer.width;
    node["exp_term"] = layer.exp_term;
    node["exp_scale"] = layer.exp_scale;
    node["linear_term"] = layer.linear_term;
    node["constant_term"] = layer.constant_term;
    return node;
}

Json DensityToJson(const DensityProfile& profile) {
    Json node = Json::object();
    node["layers"] = Json::array({LayerToJson(profile.layers[0]), LayerToJson(profile.layers[1])});
    return node;
}

// ---------------------------------------------------------------------------------------
// --set FIELD=VALUE.

std::string Trim(const std::string& s) {
    const size_t begin = s.find_first_not_of(" \t");
    if (begin == std::string::npos) return "";
    const size_t end = s.find_last_not_of(" \t");
    return s.substr(begin, end - begin + 1);
}

std::vector<std::string> Split(const std::string& s, char separator) {
    std::vector<std::string> parts;
    size_t begin = 0;
    while (true) {
        const size_t end = s.find(separator, begin);
        parts.push_back(
            s.substr(begin, end == std::string::npos ? std::string::npos : end - begin));
        if (end == std::string::npos) break;
        begin = end + 1;
    }
    return parts;
}

// VALUE is JSON when it parses as JSON, else a comma-separated list of finite
// numbers (one number -> a number, several -> an array).
Json ParseOverrideValue(const std::string& value_text, const std::string& override_text) {
    if (Trim(value_text).empty()) Fail("--set ", override_text, ": the value is empty");
    Json parsed = Json::parse(value_text, nullptr, /*allow_exceptions=*/false);
    if (!parsed.is_discarded()) return parsed;
    Json numbers = Json::array();
    for (const std::string& raw : Split(value_text, ',')) {
        std::string item = Trim(raw);
        if (!item.empty() && item[0] == '+') item = item.substr(1);
        double number = 0.0;
        const char* first = item.data();
        const char* last = item.data() + item.size();
        const auto result = std::from_chars(first, last, number);
        if (result.ec == std::errc::result_out_of_range) {
            Fail("--set ", override_text, ": '", Trim(raw), "' is out of the range of a double");
        }
        if (item.empty() || result.ec != std::errc() || result.ptr != last) {
            Fail("--set ", override_text, ": '", Trim(raw),
                 "' is not a number (VALUE is JSON or a comma-separated list of numbers)");
        }
        if (!std::isfinite(number)) {
            Fail("--set ", override_text, ": '", Trim(raw), "' is not a finite number");
        }
        numbers.push_back(number);
    }
    if (numbers.size() == 1) return numbers[0];
    return numbers;
}

bool ParseIndex(const std::string& text, int count, int* index) {
    if (text.size() != 1 || text[0] < '0' || text[0] >= '0' + count) return false;
    *index = text[0] - '0';
    return true;
}

[[noreturn]] void FailUnknownField(const std::string& field, const std::string& text,
                                   const std::string& hint) {
    Fail("unknown atmosphere field '", field, "' in --set ", text, " (fields: ", FieldList(), hint,
         ")");
}

void ApplyOverride(Json& root, const std::string& text, const std::string& where) {
    const size_t eq = text.find('=');
    if (eq == std::string::npos) {
        Fail("--set '", text,
             "': expected FIELD=VALUE, e.g. --set ground_albedo=0.3 (fields: ", FieldList(), ")");
    }
    const std::string field = text.substr(0, eq);
    const std::vector<std::string> path = Split(field, '.');
    const FieldSpec* spec = FindField(path[0]);
    if (spec == nullptr) FailUnknownField(field, text, "");
    if (spec->kind == FieldKind::kPhase) {
        // --set mie_phase=KIND (a bare name) or --set mie_phase=JSON, or
        // --set mie_phase.KEY=VALUE on an object (e.g. mie_phase.column=1).
        const std::string value_text = Trim(text.substr(eq + 1));
        Json value = Json::parse(value_text, nullptr, /*allow_exceptions=*/false);
        if (value.is_discarded()) value = value_text;
        Json& node = root[path[0]];
        if (path.size() == 1) {
            node = value;
            return;
        }
        if (path.size() == 2 && node.is_object()) {
            node[path[1]] = value;
            return;
        }
        FailUnknownField(field, text,
                         "; mie_phase takes mie_phase=KIND, mie_phase=JSON or, "
                         "on an object, mie_phase.KEY=VALUE");
    }
    const Json value = ParseOverrideValue(text.substr(eq + 1), text);
    Json& node = root[path[0]];
    if (path.size() == 1) {
        node = value;
        return;
    }
    if (spec->kind == FieldKind::kScalar) FailUnknownField(field, text, "");
    if (spec->kind == FieldKind::kRgb && node.is_object()) {
        // A spectral field: FIELD.KEY.KEY...=VALUE sets that member of its object
        // (e.g. mie_extinction.angstrom.beta=0.05); the reader validates the result.
        Json* target = &node;
        for (size_t i = 1; i < path.size(); ++i) {
            if (!target->is_object() || !target->contains(path[i])) {
                Fail("--set ", text, ": field '", path[0], "' has no member '",
                     Join(std::vector<std::string>(path.begin() + 1, path.begin() + i + 1), "."),
                     "'");
            }
            target = &(*target)[path[i]];
        }
        *target = value;
        return;
    }
    if (spec->kind == FieldKind::kRgb) {
        int channel = 0;
        if (path.size() != 2 || !ParseIndex(path[1], 3, &channel)) {
            FailUnknownField(
                field, text,
                "; an RGB field takes FIELD=v, FIELD=r,g,b or FIELD.I=v with I in 0..2");
        }
        if (node.is_number()) node = Json::array({node, node, node});
        if (!node.is_array() || node.size() != 3) {
            Fail("--set ", text, ": field '", path[0], "' is not a number or an array of 3");
        }
        node[static_cast<size_t>(channel)] = value;
        return;
    }
    // A density profile.
    const char density_hint[] =
        "; a density takes FIELD.scale_height, FIELD.tent.center, FIELD.tent.half_width or "
        "FIELD.layers.I.KEY with I in 0..1 and KEY one of width, exp_term, exp_scale, "
        "linear_term, constant_term";
    const std::string& form = path[1];
    if (form == "scale_height" && path.size() == 2) {
        node = Json::object({{"scale_height", value}});
        return;
    }
    if (form == "tent" && path.size() == 2) {
        node = Json::object({{"tent", value}});
        return;
    }
    if (form == "tent" && path.size() == 3 && (path[2] == "center" || path[2] == "half_width")) {
        const bool is_tent = node.is_object() && node.size() == 1 && node.contains("tent") &&
                             node["tent"].is_object();
        if (!is_tent) node = Json::object({{"tent", Json::object()}});
        node["tent"][path[2]] = value;
        return;
    }
    if (form == "layers") {
        // Rewrite the profile in the two-layer form of DensityProfile first, so that
        // layer indices mean the same whatever form the file used.
        const DensityProfile current =
            node.is_null() ? DensityProfile{} : ReadDensity(node, where, path[0]);
        node = DensityToJson(current);
        Json& layers = node["layers"];
        int index = 0;
        if (path.size() == 2) {
            layers = value;
            return;
        }
        if (ParseIndex(path[2], 2, &index)) {
            if (path.size() == 3) {
                layers[static_cast<size_t>(index)] = value;
                return;
            }
            if (path.size() == 4 && IsLayerKey(path[3])) {
                layers[static_cast<size_t>(index)][path[3]] = value;
                return;
            }
        }
    }
    FailUnknownField(field, text, density_hint);
}

}  // namespace

AtmosphereParameters AtmosphereFromJson(const std::string& json_text,
                                        const std::string& source_name) {
    Json root = ParseText(json_text, source_name);
    const std::string where = "atmosphere '" + source_name + "'";
    ResolveSpectra(root, where, nullptr);
    return ReadTree(root, where);
}

std::string AtmosphereToJson(const AtmosphereParameters& a) {
    Json root = Json::object();
    root["bottom_radius"] = a.bottom_radius;
    root["top_radius"] = a.top_radius;
    root["rayleigh_scattering"] = RgbToJson(a.rayleigh_scattering);
    root["rayleigh_density"] = DensityToJson(a.rayleigh_density);
    root["mie_scattering"] = RgbToJson(a.mie_scattering);
    root["mie_extinction"] = RgbToJson(a.mie_extinction);
    root["mie_density"] = DensityToJson(a.mie_density);
    // The kind only when it is not the default Cornette-Shanks, and the lobe
    // fields only for the kinds with lobes, so that Cornette-Shanks atmospheres
    // keep their text and fingerprints; a tabulated function is written inline,
    // its nodes as given (the reader renormalises them the same way again).
    const MiePhaseKind kind = a.mie_phase_kind;
    if (kind == MiePhaseKind::kTabulated) {
        const MiePhaseTable& t = a.mie_phase_table;
        Json angles = Json::array(), values = Json::array();
        for (int i = 0; i < t.count; ++i) {
            angles.push_back(t.angle_deg[i]);
            values.push_back(t.value[i]);
        }
        root["mie_phase"] = Json::object(
            {{"kind", MiePhaseKindName(kind)}, {"angles_deg", angles}, {"values", values}});
    } else if (kind != MiePhaseKind::kCornetteShanks) {
        root["mie_phase"] = MiePhaseKindName(kind);
    }
    if (kind == MiePhaseKind::kCornetteShanks || kind == MiePhaseKind::kHenyeyGreenstein) {
        root["mie_phase_g"] = a.mie_phase_g;
        // The second lobe only when there is one, so that one-lobe atmospheres
        // (every preset but kider-2013-aeronet) keep their text and fingerprints.
        if (a.mie_phase_weight2 != 0.0 || a.mie_phase_g2 != 0.0) {
            root["mie_phase_g2"] = a.mie_phase_g2;
            root["mie_phase_weight2"] = a.mie_phase_weight2;
        }
    }
    root["absorption_extinction"] = RgbToJson(a.absorption_extinction);
    root["absorption_density"] = DensityToJson(a.absorption_density);
    root["ground_albedo"] = RgbToJson(a.ground_albedo);
    root["sun_angular_radius"] = a.sun_angular_radius;
    root["solar_irradiance"] = RgbToJson(a.solar_irradiance);
    root["mu_s_min"] = a.mu_s_min;
    // One field a line, one layer a line. nlohmann writes doubles with the
    // shortest digits that read back exactly.
    std::string text = "{\n";
    bool first = true;
    for (const auto& item : root.items()) {
        if (!first) text += ",\n";
        first = false;
        text += "  " + Json(item.key()).dump() + ": ";
        const Json& value = item.value();
        if (value.is_object() && value.contains("layers")) {
            text += "{\"layers\": [\n    " + value["layers"][0].dump() + ",\n    " +
                    value["layers"][1].dump() + "\n  ]}";
        } else {
            text += value.dump();
        }
    }
    return text + "\n}\n";
}

std::vector<std::string> AtmospherePresetNames() {
    return detail::SortedNames(detail::kEmbeddedPresets, detail::kEmbeddedPresetCount);
}

namespace {

// The preset's or file's JSON with the overrides applied; `where` names it in errors.
Json LoadRoot(const std::string& name_or_path, const std::vector<std::string>& overrides,
              std::string* where_out) {
    std::string text;
    bool found = false;
    for (int i = 0; i < detail::kEmbeddedPresetCount; ++i) {
        if (name_or_path == detail::kEmbeddedPresets[i].name) {
            text = detail::kEmbeddedPresets[i].json;
            found = true;
            break;
        }
    }
    if (!found) {
        std::error_code ec;
        if (!std::filesystem::exists(name_or_path, ec)) {
            Fail("unknown atmosphere '", name_or_path, "': not a preset (",
                 Join(AtmospherePresetNames(), ", "), ") and not a readable file");
        }
        // Checked before opening: a FIFO with no writer would block the open.
        if (!std::filesystem::is_regular_file(name_or_path, ec)) {
            Fail("atmosphere '", name_or_path,
                 "': cannot read the file (not a regular file: a directory, a FIFO or a "
                 "device)");
        }
        std::ifstream in(name_or_path, std::ios::binary);
        if (!in) Fail("atmosphere '", name_or_path, "': cannot read the file");
        in.seekg(0, std::ios::end);
        const std::streamoff size = in.tellg();
        in.seekg(0, std::ios::beg);
        if (size < 0) Fail("atmosphere '", name_or_path, "': cannot read the file");
        // An atmosphere is a few hundred bytes; a huge file is a mistake (a
        // 100 MiB file took 6 s and 520 MB to refuse).
        constexpr std::streamoff kMaxBytes = 1 << 20;
        if (size > kMaxBytes) {
            Fail("atmosphere '", name_or_path, "': the file is ", size,
                 " bytes, more than the 1 MiB an atmosphere file may have");
        }
        text.resize(static_cast<size_t>(size));
        if (!in.read(text.data(), size)) {
            Fail("atmosphere '", name_or_path, "': cannot read the file");
        }
    }
    Json root = ParseText(text, name_or_path);
    const std::string where = "atmosphere '" + name_or_path + "'";
    if (!root.is_object()) Fail(where, ": the top level must be a JSON object");
    for (const std::string& override_text : overrides) {
        ApplyOverride(root, override_text, where);
    }
    *where_out =
        overrides.empty() ? where : where + " (with --set " + Join(overrides, " --set ") + ")";
    return root;
}

}  // namespace

AtmosphereParameters LoadAtmosphere(const std::string& name_or_path,
                                    const std::vector<std::string>& overrides) {
    std::string where;
    Json root = LoadRoot(name_or_path, overrides, &where);
    ResolveSpectra(root, where, nullptr);
    return ReadTree(root, where);
}

SpectralAtmosphere LoadSpectralAtmosphere(const std::string& name_or_path,
                                          const std::vector<std::string>& overrides) {
    std::string where;
    Json root = LoadRoot(name_or_path, overrides, &where);
    SpectralAtmosphere spectral;
    ResolveSpectra(root, where, &spectral);
    spectral.base = ReadTree(root, where);
    spectral.name = root.contains("name") && root["name"].is_string()
                        ? root["name"].get<std::string>()
                        : name_or_path;
    if (spectral.spectral) {
        // Every wavelength of the visible range must give a valid atmosphere.
        for (int nm = 360; nm <= 830; nm += 10) {
            try {
                (void)spectral.AtWavelengths(nm, nm, nm);
            } catch (const Error& e) {
                Fail(where, ": at ", nm, " nm: ", e.what());
            }
        }
    }
    return spectral;
}

}  // namespace atmos
