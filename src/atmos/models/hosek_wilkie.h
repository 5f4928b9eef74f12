// atmos model `hosek-wilkie`: the analytic sky-dome model of Hosek & Wilkie
// 2012 ("An Analytic Model for Full Spectral Sky-Dome Radiance", ACM TOG
// 31(4), SIGGRAPH 2012) with the authors' published coefficients.
//
// Source: the paper's eq. 8-9 (Leenman's 2025 thesis section 5.3, eq. 35-37; the seed's
// chi drops the paper's exponent 3/2) and its coefficient data (reference
// implementation 1.4a, BSD-3, shipped in data/hosek-wilkie-2012/ with its
// licence): for each channel (RGB, CIE XYZ or 11 wavelengths 320-720 nm), 2
// albedos x 10 turbidities x 6 Bezier control points of the nine parameters
// and of the radiance scale L_M.
//
// Implements: L = F(theta, gamma) L_M with
//   F = (1 + A exp(B / (cos theta + 0.01)))
//       (C + D exp(E gamma) + F cos^2 gamma + G chi(H, gamma) + I sqrt(cos theta)),
//   chi(g, a) = (1 + cos^2 a) / (1 + g^2 - 2 g cos a)^(3/2),
// each of A..I and L_M the quintic Bezier (Bernstein) curve of its 6 control
// points over x = (elevation / (pi/2))^(1/3), blended linearly between the two
// neighbouring integer turbidities and between albedo 0 and 1 (the authors'
// scheme; since the curve is linear in its control points, atmos blends the
// control points once in Prepare() and evaluates one curve per query). theta
// is the view's zenith angle, gamma the angle between view and sun, elevation
// the sun's, all at the camera. The data store each configuration as
// A B C D E F G I H (the anisotropy H last).
//
// Output (radiance per unit solar irradiance, 1/sr, like every model):
// * colour=rgb / xyz: the authors' value (W m^-2 sr^-1, the spectral model
//   through the CIE 1931 observer or the authors' RGB fit of it) divided by
//   kHosekWilkieSunY = 191.770 W m^-2: the Y of the extraterrestrial solar
//   spectrum they fitted with (kHosekWilkieSolarRadiance x kHosekWilkieSunSolidAngle,
//   over the CIE 1931 table's 360-720 nm rows, 5 nm), so Y is the sky's
//   luminance per unit solar illuminance; xyz then goes to linear sRGB with the
//   IEC 61966-2-1 (D65) matrix.
// * colour=spectral, and every `--wavelengths` run: per channel at wavelength
//   lambda (680, 550, 440 nm for an RGB run), the authors' spectral radiance
//   (W m^-2 sr^-1 nm^-1; linear between the 40 nm nodes, as the authors do)
//   divided by their extraterrestrial solar irradiance there
//   (kHosekWilkieSolarRadiance, linear between the nodes, times the sun's solid
//   angle 6.87e-5 sr, as clear-sky-models (Bruneton 2016) divides it).
// So atmos / authors is one constant per channel. Negative sums (the fit's
// edge near the horizon) are clamped to 0.
//
// Valid: a viewer on the ground, the sun 0-90 degrees above the horizon,
// turbidity 1-10, ground albedo 0-1, wavelengths 320-720 nm (refused outside).
// Capabilities say so (space_views = false, sun_below_horizon = false).
// Outside: a camera above the ground is treated as on the ground (same
// directions); a sun below the horizon is raised to it (elevation 0, as
// preetham does); rays that hit the ground are black (no ground term, T = 0:
// the lower hemisphere is black, not the authors' ground convention); views
// just below the horizon that miss the ground use cos theta = 0. No
// transmittance (1 for sky rays). The 2013 solar-radiance function is not used:
// the render loop draws the sun disc itself (render/render.h).
#pragma once

#include <memory>
#include <string>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "models/evaluator_model.h"
#include "models/fitted_sky.h"
#include "models/hosek_wilkie_coefficients.h"
#include "physics/geometry.h"

namespace atmos {

// The extraterrestrial solar radiance (W m^-2 sr^-1 nm^-1) of the path tracer
// the model was fitted to, at 320, 360, ..., 720 nm (the authors' reference
// implementation 1.4a, `originalSolarRadianceTable`: Preetham et al. 1999's
// sun extended into the UV).
constexpr double kHosekWilkieSolarRadiance[11] = {7500.0,  12500.0, 21127.5, 26760.5,
                                                  30663.7, 27825.0, 25503.8, 25134.2,
                                                  23212.1, 21526.7, 19870.8};
// The sun's solid angle (sr) that turns it into irradiance (clear-sky-models,
// Bruneton 2016, hosek.cc: kSunSolidAngle).
constexpr double kHosekWilkieSunSolidAngle = 6.87e-5;
// The Y (W m^-2, CIE 1931 y-bar weighted) of that extraterrestrial irradiance:
// sum over the CIE table's rows 360..720 nm of E(nm) y-bar(nm) 5 nm
// (scripts/hosek_wilkie_reference.py prints it; a test recomputes it).
constexpr double kHosekWilkieSunY = 191.7702627;

// Which coefficient set the RGB output comes from.
enum class HosekWilkieColour { kRgb, kXyz, kSpectral };

constexpr int kHosekWilkieMaxSources = 6;

// One channel's cooked configuration: A B C D E F G I H (data order), L_M.
struct HosekWilkieConfig {
    double v[10];
};

// Eq. 8-9: F(theta, gamma) L_M for one cooked configuration.
ATMOS_HD inline double HosekWilkieRadiance(const HosekWilkieConfig& k, double cos_theta,
                                           double gamma) {
    const double cos_gamma = cos(gamma);
    const double h = k.v[8];
    const double q = 1.0 + h * h - 2.0 * h * cos_gamma;
    const double chi = (1.0 + cos_gamma * cos_gamma) / (q * sqrt(q));
    const double f = (1.0 + k.v[0] * Exp(k.v[1] / (cos_theta + 0.01))) *
                     (k.v[2] + k.v[3] * Exp(k.v[4] * gamma) + k.v[5] * cos_gamma * cos_gamma +
                      k.v[6] * chi + k.v[7] * sqrt(cos_theta));
    return f * k.v[9];
}

// The quintic Bezier of six control points (10 values each) at solar
// elevation `elevation` (radians, clamped to [0, pi/2]).
ATMOS_HD inline HosekWilkieConfig HosekWilkieCook(const double ctrl[6][10], double elevation) {
    const double x = cbrt(Clamp(elevation / (0.5 * kPi), 0.0, 1.0));
    const double y = 1.0 - x;
    const double b[6] = {y * y * y * y * y,        5.0 * y * y * y * y * x,
                         10.0 * y * y * y * x * x, 10.0 * y * y * x * x * x,
                         5.0 * y * x * x * x * x,  x * x * x * x * x};
    HosekWilkieConfig k;
    for (int p = 0; p < 10; ++p) {
        double s = 0.0;
        for (int i = 0; i < 6; ++i) s += b[i] * ctrl[i][p];
        k.v[p] = s;
    }
    return k;
}

// The sun terms of one view (sun and camera up only).
struct HosekWilkieSunTerms {
    Vec3d s;  // the sun, raised to the horizon when below it
    HosekWilkieConfig k[kHosekWilkieMaxSources];
};

struct HosekWilkieEvaluator : FittedSkyEvaluator<HosekWilkieEvaluator, HosekWilkieSunTerms> {
    int sources = 3;
    // Per source: the control points blended in turbidity and albedo.
    double ctrl[kHosekWilkieMaxSources][6][10] = {};
    // Output channel c = max(sum_s mix[c][s] L_s, 0).
    double mix[3][kHosekWilkieMaxSources] = {};

    ATMOS_HD HosekWilkieSunTerms SunTerms(const Vec3d& up, const Vec3d& sun) const {
        HosekWilkieSunTerms t;
        double cos_s;
        t.s = SunRaisedToHorizon(up, sun, &cos_s);
        const double elevation = 0.5 * kPi - acos(Clamp(cos_s, -1.0, 1.0));
        for (int i = 0; i < sources; ++i) t.k[i] = HosekWilkieCook(ctrl[i], elevation);
        return t;
    }
    // The sky toward `dir` (models/fitted_sky.h).
    ATMOS_HD Rgb Sky(const HosekWilkieSunTerms& st, const Vec3d& up, const Vec3d& dir) const {
        const double cos_theta = Max(Dot(dir, up), 0.0);
        const double gamma = acos(Clamp(Dot(dir, st.s), -1.0, 1.0));
        double l[kHosekWilkieMaxSources];
        for (int i = 0; i < sources; ++i) l[i] = HosekWilkieRadiance(st.k[i], cos_theta, gamma);
        float c[3];
        for (int j = 0; j < 3; ++j) {
            double v = 0.0;
            for (int i = 0; i < sources; ++i) v += mix[j][i] * l[i];
            c[j] = static_cast<float>(Max(v, 0.0));
        }
        return Rgb(c[0], c[1], c[2]);
    }
};

struct HosekWilkieOptions {
    double turbidity = 3.0;  // atmospheric turbidity (the data's 1-10)
    std::string albedo;      // ground albedo 0-1; empty: the atmosphere's
    HosekWilkieColour colour = HosekWilkieColour::kRgb;
    // A coefficient file of `atmos fit --model hosek-wilkie`
    // (models/hosek_wilkie_coefficients.h); empty: the published data. With it,
    // turbidity, albedo and colour do not apply (refused when given).
    std::string coefficients;
};

// The published data (data/hosek-wilkie-2012/, embedded): channel count and,
// per channel, config[1080] and radiance[120] in the data's layout.
struct HosekWilkieData {
    int channels = 0;
    std::vector<std::vector<double>> config, radiance;
};
const HosekWilkieData& HosekWilkieDataset(HosekWilkieColour which);

// The control points of one channel blended linearly in turbidity (between
// floor(T) and floor(T) + 1, 10 at most) and albedo (between 0 and 1).
void HosekWilkieBlend(const HosekWilkieData& data, int channel, double turbidity, double albedo,
                      double ctrl[6][10]);

// The authors' value (their units) of one channel, computed the authors' way
// round (each of the four corner configurations cooked, then blended): the
// yardstick of the units test. `wavelength_nm` > 0 for the spectral set
// (linear between the nodes), else `channel`.
double HosekWilkieAuthorsRadiance(HosekWilkieColour which, int channel, double wavelength_nm,
                                  double turbidity, double albedo, double elevation, double theta,
                                  double gamma);

// The extraterrestrial solar irradiance (W m^-2 nm^-1) the spectral data were
// fitted with, linear between the nodes; atmos::Error outside 320-720 nm.
double HosekWilkieSolarIrradiance(double nm);

class HosekWilkieModel : public SimpleEvaluatorModel<HosekWilkieModel, HosekWilkieEvaluator> {
  public:
    static const OptionTable<HosekWilkieOptions>& OptionRows();
    explicit HosekWilkieModel(const HosekWilkieOptions& options);
    static ModelInfo StaticInfo();
    void Prepare(const AtmosphereParameters& atmosphere) override;
    // The batch's wavelengths (atmos::Error outside 320-720 nm); the next
    // Prepare() builds the spectral form at them.
    void SetSpectralBatch(const SpectralAtmosphere& atmosphere, const double nm[3]) override;
    // No tables: a bake writes the blended control points and the channel mix
    // as shader constants (shaders/hosek_wilkie.glsl) and hosek-wilkie.json;
    // LoadBaked checks that JSON against the options and atmosphere and
    // prepares again (microseconds).
    bool CanBake() const override { return true; }
    void Bake(const std::string& directory) const override;
    int64_t TableBytes() const override { return 0; }
    void LoadBaked(const std::string& directory, const AtmosphereParameters& atmosphere) override;

  private:
    HosekWilkieOptions options_;
    double albedo_ = -1.0;  // the option's value; < 0: the atmosphere's
    bool spectral_batch_ = false;
    double nm_[3] = {};
    // Loaded from options_.coefficients (null: the published data).
    std::shared_ptr<const HosekWilkieCoefficients> fitted_;
};

}  // namespace atmos
