// atmos: the parameters of a planet's atmosphere.
//
// Field names and the layered density profile follow Bruneton 2017,
// "AtmosphereParameters" and "DensityProfileLayer". All values are SI: metres,
// per-metre coefficients, radians. The struct is trivially copyable so that it
// can be passed by value to device code.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "atmos/math.h"

namespace atmos {

// One layer of a density profile (Bruneton's 2017 implementation notes): the density at altitude h
// (metres above bottom_radius) is
//   clamp(exp_term * exp(exp_scale * h) + linear_term * h + constant_term, 0, 1)
// Bruneton's 2017 implementation notes: layers[0] applies below layers[0].width (altitude from the
// ground), layers[1] everywhere above.
struct DensityProfileLayer {
    double width = 0.0;          // m; the last layer's width is ignored
    double exp_term = 0.0;       // dimensionless
    double exp_scale = 0.0;      // 1/m (negative for a decaying profile: -1/H)
    double linear_term = 0.0;    // 1/m
    double constant_term = 0.0;  // dimensionless
};

// Bruneton's 2017 implementation notes' two-layer profile: layers[0] applies below layers[0].width,
// layers[1] above. A single exponential uses layers[1] alone (layers[0] has
// width 0).
struct DensityProfile {
    DensityProfileLayer layers[2];
};

// The kind of the aerosol (Mie) phase function (physics/phase.h MiePhase; docs/atmosphere.md
// "Mie phase functions"). The numbers are fixed: they appear in baked constants.
enum class MiePhaseKind : int {
    kCornetteShanks = 0,    // one or two Cornette-Shanks lobes (mie_phase_g, _g2, _weight2)
    kHenyeyGreenstein = 1,  // one or two Henyey-Greenstein lobes (the same three fields)
    kIsotropic = 2,         // 1 / (4 pi)
    kTabulated = 3,         // MiePhaseTable: values at scattering angles
};

// The most nodes a tabulated phase function may have.
constexpr int kMaxMiePhaseNodes = 256;

// A tabulated phase function, trivially copyable (per-pixel code reads it). The
// nodes are scattering angles, increasing from 0 to 180 deg; between two nodes the
// phase is linear in nu = cos(angle), so its integral over the sphere, its mean
// cosine and its CDF are exact sums, and the CDF inverts in closed form (one
// quadratic per sample: physics/sampling.h). `angle_deg` and `value` are kept as
// given (any positive unit: AERONET's 4 pi-normalised values, per steradian, ...),
// so that the JSON round trip is exact; `scale` makes it a phase function in 1/sr.
// FinishMiePhaseTable fills mu, cdf, scale and mean_cosine.
struct MiePhaseTable {
    int count = 0;                             // nodes, 2..kMaxMiePhaseNodes
    double scale = 0.0;                        // 1 / (integral of `value` over the sphere)
    double mean_cosine = 0.0;                  // <nu>, the table's asymmetry parameter g
    double angle_deg[kMaxMiePhaseNodes] = {};  // 0 = angle_deg[0] < ... < angle_deg[count-1] = 180
    double value[kMaxMiePhaseNodes] = {};      // > 0 and finite, as given
    double mu[kMaxMiePhaseNodes] = {};         // cos(angle_deg): 1 = mu[0] > ... = -1
    double cdf[kMaxMiePhaseNodes] = {};        // P(angle <= angle_deg[i]); 0 .. 1
};

struct AtmosphereParameters {
    double bottom_radius = 6360e3;  // m: the planet's surface
    double top_radius = 6460e3;     // m: where the atmosphere is taken to end
    Vec3d rayleigh_scattering;      // 1/m at density 1 (Rayleigh: no absorption)
    DensityProfile rayleigh_density;
    Vec3d mie_scattering;  // 1/m at density 1
    Vec3d mie_extinction;  // 1/m at density 1 (>= mie_scattering)
    DensityProfile mie_density;
    double mie_phase_g = 0.8;  // Cornette-Shanks asymmetry
    // An optional second Cornette-Shanks lobe: the Mie phase function is
    // (1 - w) CS(mie_phase_g) + w CS(mie_phase_g2) with w = mie_phase_weight2
    // (physics/phase.h MiePhase); w = 0 (the default) is the single lobe.
    double mie_phase_g2 = 0.0;       // Cornette-Shanks asymmetry of the second lobe
    double mie_phase_weight2 = 0.0;  // the second lobe's weight w, [0, 1]
    // The phase function's kind; Cornette-Shanks (the default) reads the three
    // fields above, Henyey-Greenstein the same three, isotropic none, tabulated
    // mie_phase_table (mie_phase_g then holds the table's mean cosine, for models
    // that take an asymmetry parameter).
    MiePhaseKind mie_phase_kind = MiePhaseKind::kCornetteShanks;
    MiePhaseTable mie_phase_table;
    Vec3d absorption_extinction;  // 1/m at density 1 (ozone: absorption only)
    DensityProfile absorption_density;
    Vec3d ground_albedo;                    // Lambertian, [0, 1]
    double sun_angular_radius = 0.004675;   // rad
    Vec3d solar_irradiance{1.0};            // per channel, top of atmosphere
    double mu_s_min = -0.2079116908177593;  // cos(102 deg): lowest sun tables cover
};

// A profile made of one exponential with scale height `scale_height` (metres).
DensityProfile ExponentialProfile(double scale_height);

// The canonical `earth` of DESIGN.md, built in code (also shipped as
// data/atmospheres/earth.json; a test checks that the two agree).
AtmosphereParameters EarthAtmosphere();

// Checks every field; throws atmos::Error naming the first invalid field and its
// allowed range.
void ValidateAtmosphere(const AtmosphereParameters& atmosphere);

// The radius above which the atmosphere's vertical column has an optical depth
// below `column_depth` (per channel, at most top_radius): models that step
// uniformly along a ray integrate up to it, so that their steps follow the
// density where the atmosphere is much thicker than its scale heights (a giant
// planet: 16 steps over 10^9 m would miss an 8 km scale height). For the
// presets it is top_radius.
double EffectiveTopRadius(const AtmosphereParameters& atmosphere, double column_depth = 1e-9);

// Fills a MiePhaseTable's derived members (mu, cdf, scale, mean_cosine) from its
// count, angle_deg and value, after checking them; throws atmos::Error naming
// `field` (e.g. "mie_phase.values[3]") and the rule on a bad table.
void FinishMiePhaseTable(MiePhaseTable* table, const std::string& field = "mie_phase");

// "cornette-shanks", "henyey-greenstein", "isotropic", "tabulated".
const char* MiePhaseKindName(MiePhaseKind kind);

// Names of the presets shipped in data/atmospheres (without ".json").
std::vector<std::string> AtmospherePresetNames();

// Loads a preset by name ("earth", "earth-bruneton", ...) or a JSON file by path,
// applies the overrides `FIELD=VALUE` in order (DESIGN.md: --set), validates and
// returns it. Throws atmos::Error with one clear message on any problem.
AtmosphereParameters LoadAtmosphere(const std::string& name_or_path,
                                    const std::vector<std::string>& overrides = {});

// Parses / serialises the JSON text of an atmosphere (the format of the preset
// files). Parsing validates.
AtmosphereParameters AtmosphereFromJson(const std::string& json_text,
                                        const std::string& source_name = "<json>");
std::string AtmosphereToJson(const AtmosphereParameters& atmosphere);

}  // namespace atmos
