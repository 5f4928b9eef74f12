// atmos model `preetham`: the analytic daylight model of Preetham, Shirley and
// Smits 1999 ("A Practical Analytic Model for Daylight", SIGGRAPH 99).
//
// Source: the paper (Perez et al. 1993 distribution, its Eq. 3 / appendix A.2:
// the Perez coefficients of Y, x, y as linear functions of turbidity T; zenith
// luminance Y_z = (4.0453 T - 4.9710) tan(chi) - 0.2155 T + 2.4192 kcd/m^2 with
// chi = (4/9 - T/120)(pi - 2 theta_s); zenith chromaticities x_z, y_z as
// [T^2 T 1] M [theta_s^3 theta_s^2 theta_s 1]^T), as Leenman's 2025 thesis section 5.3
// (Eq. 32-34) and section 11.2.5 use it.
//
// Implements: Y = Y_z F(theta, gamma) / F(0, theta_s) and the same for x and y
// (Eq. 33-34), F(theta, gamma) = (1 + A exp(B / cos theta))(1 + C exp(D gamma)
// + E cos^2 gamma) (Eq. 32); xyY -> XYZ -> linear sRGB (IEC 61966-2-1 matrix,
// D65). theta is the view's zenith angle, theta_s the sun's, gamma the angle
// between them, all at the camera.
//
// Radiance scale (so it is comparable with the physical models, which output
// radiance per unit solar irradiance, 1/sr): luminance in cd/m^2 = lm/(m^2 sr)
// divided by the extraterrestrial solar illuminance 128 klx (128e3 lm/m^2, the
// value used by Perez et al. and the IES): L = Y[kcd/m^2] * 1000 / 128000.
// A grey sky of luminance Y gives RGB (L, L, L).
//
// Valid: a viewer on the ground, the sun above the horizon, views above the
// horizon, turbidity about 2 to 10 (`--turbidity`, default 2.5). Capabilities
// say so (space_views = false, sun_below_horizon = false). Outside, it renders
// something defined: a camera above the ground is treated as on the ground
// (same directions); a sun below the horizon is raised to the horizon (theta_s
// = 90 deg); a view below the horizon that does not hit the ground uses the
// horizon (cos theta clamped to 0.001); a ray that hits the ground, or misses
// the atmosphere, gets no sky. It has no transmittance (capabilities:
// transmittance = false; 1 is reported for sky rays) and no ground term.
//
// Spectral form (`--wavelengths`; Preetham et al. 1999 section 3 and appendix
// A.2 turn xyY into a spectrum the same way): the sky's spectrum is the CIE
// daylight spectrum of its chromaticity, S(lambda) = S0 + M1 S1 + M2 S2
// (CIE 15:2004 section 3.1 eqs. 3.5-3.6 after Judd, MacAdam & Wyszecki 1964;
// components from data/spectra/cie-daylight-components.csv, 300-830 nm every
// 10 nm, linear in between), scaled so that its Y (the spectral pipeline's
// convention: sum over the CIE 1931 table's 5 nm wavelengths of S y-bar w,
// divided by CieYIntegral()) is L times the Y of the atmosphere's solar
// spectrum (1 for an RGB atmosphere): the luminance per unit solar
// illuminance of the RGB form, times the sun. Each channel then holds that
// spectrum at its wavelength divided by the solar irradiance there (radiance
// per unit irradiance: the render and sample loops multiply it back). Values
// below 0 (M1, M2 of chromaticities far from daylight) are clamped to 0.
#pragma once

#include <functional>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "models/evaluator_model.h"
#include "models/fitted_sky.h"
#include "physics/geometry.h"

namespace atmos {

// The five Perez coefficients.
struct PerezCoefficients {
    double a, b, c, d, e;
};

// Eq. 32.
ATMOS_HD inline double PerezF(const PerezCoefficients& k, double cos_theta, double gamma) {
    const double cos_gamma = cos(gamma);
    return (1.0 + k.a * Exp(k.b / cos_theta)) *
           (1.0 + k.c * Exp(k.d * gamma) + k.e * cos_gamma * cos_gamma);
}

// Preetham et al. 1999, appendix A.2: distribution coefficients of Y, x, y.
inline PerezCoefficients PreethamLuminanceCoefficients(double T) {
    return {0.1787 * T - 1.4630, -0.3554 * T + 0.4275, -0.0227 * T + 5.3251, 0.1206 * T - 2.5771,
            -0.0670 * T + 0.3703};
}
inline PerezCoefficients PreethamXCoefficients(double T) {
    return {-0.0193 * T - 0.2592, -0.0665 * T + 0.0008, -0.0004 * T + 0.2125, -0.0641 * T - 0.8989,
            -0.0033 * T + 0.0452};
}
inline PerezCoefficients PreethamYCoefficients(double T) {
    return {-0.0167 * T - 0.2608, -0.0950 * T + 0.0092, -0.0079 * T + 0.2102, -0.0441 * T - 1.6537,
            -0.0109 * T + 0.0529};
}

// Preetham et al. 1999, appendix A.2: zenith luminance (kcd/m^2) and
// chromaticity for turbidity T and sun zenith angle theta_s (radians).
double PreethamZenithLuminance(double T, double theta_s);
double PreethamZenithX(double T, double theta_s);
double PreethamZenithY(double T, double theta_s);

// Extraterrestrial solar illuminance (lm/m^2) the radiance scale divides by.
constexpr double kPreethamSolarIlluminance = 128e3;

// CIE 15:2004 eqs. (3.5)-(3.6) (Judd, MacAdam & Wyszecki 1964): the weights M1,
// M2 of the daylight components S1, S2 for chromaticity (x, y). False where
// the denominator vanishes (far from any daylight chromaticity).
ATMOS_HD inline bool CieDaylightWeights(double x, double y, double* m1, double* m2) {
    const double m = 0.0241 + 0.2562 * x - 0.7341 * y;
    if (!(Abs(m) > 1e-9)) return false;
    *m1 = (-1.3515 - 1.7703 * x + 5.9114 * y) / m;
    *m2 = (0.0300 - 31.4424 * x + 30.0717 * y) / m;
    return true;
}

// The CIE daylight component S_k (k = 0, 1, 2) at `nm`: the linear
// interpolation of data/spectra/cie-daylight-components.csv; atmos::Error
// outside its 300-830 nm.
double CieDaylightComponent(int k, double nm);
// Y of the spectrum f(nm) in the spectral pipeline's convention (the sum over
// the CIE 1931 table's wavelengths, 360-830 nm every 5 nm, of f y-bar w,
// divided by CieYIntegral(): a flat spectrum 1 has Y = 1).
double PipelineLuminance(const std::function<double(double)>& f);

// The terms of one view that depend on the sun and the camera's up only.
struct PreethamSunTerms {
    Vec3d s;                                 // the sun, raised to the horizon when below it
    double theta_s = 0.0;                    // its zenith angle
    double Yz = 0.0, xz = 0.0, yz = 0.0;     // zenith luminance and chromaticity
    double fY0 = 1.0, fx0 = 1.0, fy0 = 1.0;  // F(0, theta_s) of Y, x, y
};

struct PreethamEvaluator : FittedSkyEvaluator<PreethamEvaluator, PreethamSunTerms> {
    double turbidity = 2.5;
    PerezCoefficients kY{}, kx{}, ky{};
    // Spectral batch (PreethamModel::SetSpectralBatch, then Prepare): the
    // channels are three wavelengths of the daylight spectrum, not sRGB.
    bool spectral = false;
    double basis[3][3] = {};       // basis[c][k]: S_k at channel c's wavelength
    double basis_y[3] = {};        // Y of S_k (PipelineLuminance)
    double channel_scale[3] = {};  // the sun's Y / its irradiance at channel c (0 where 0)

    ATMOS_HD PreethamSunTerms SunTerms(const Vec3d& up, const Vec3d& sun) const {
        PreethamSunTerms t;
        double cos_s;
        t.s = SunRaisedToHorizon(up, sun, &cos_s);
        t.theta_s = acos(Clamp(cos_s, -1.0, 1.0));
        t.Yz = ZenithLuminance(t.theta_s);
        t.xz = ZenithChromaticity(t.theta_s, true);
        t.yz = ZenithChromaticity(t.theta_s, false);
        t.fY0 = PerezF(kY, 1.0, t.theta_s);
        t.fx0 = PerezF(kx, 1.0, t.theta_s);
        t.fy0 = PerezF(ky, 1.0, t.theta_s);
        return t;
    }
    // The sky toward `dir` (models/fitted_sky.h).
    ATMOS_HD Rgb Sky(const PreethamSunTerms& st, const Vec3d& up, const Vec3d& dir) const {
        double L = 0.0, x = 0.0, y = 0.0;
        SkyXyY(st, up, dir, &L, &x, &y);
        return spectral ? DaylightChannels(L, x, y) : XyYToSrgb(L, x, y);
    }

    // The sky's luminance per unit solar illuminance L (Y[kcd/m^2] 1000 /
    // 128 klx, >= 0) and chromaticity (x, y) toward `dir` (Eq. 32-34).
    ATMOS_HD void SkyXyY(const PreethamSunTerms& st, const Vec3d& up, const Vec3d& dir, double* L,
                         double* x, double* y) const {
        const double cos_theta = Max(Dot(dir, up), 0.001);
        const double gamma = acos(Clamp(Dot(dir, st.s), -1.0, 1.0));
        const double Y = st.Yz * PerezF(kY, cos_theta, gamma) / st.fY0;
        *x = st.xz * PerezF(kx, cos_theta, gamma) / st.fx0;
        *y = st.yz * PerezF(ky, cos_theta, gamma) / st.fy0;
        *L = Max(Y, 0.0) * 1000.0 / kPreethamSolarIlluminance;
    }

    // The RGB form: xyY -> XYZ -> linear sRGB.
    ATMOS_HD static Rgb XyYToSrgb(double L, double x, double y) {
        const double yy = Max(y, 1e-6);
        const double X = x / yy * L;
        const double Z = (1.0 - x - y) / yy * L;
        // XYZ -> linear sRGB (IEC 61966-2-1).
        const double R = 3.2404542 * X - 1.5371385 * L - 0.4985314 * Z;
        const double G = -0.9692660 * X + 1.8760108 * L + 0.0415560 * Z;
        const double B = 0.0556434 * X - 0.2040259 * L + 1.0572252 * Z;
        return Rgb(static_cast<float>(Max(R, 0.0)), static_cast<float>(Max(G, 0.0)),
                   static_cast<float>(Max(B, 0.0)));
    }

    // The spectral form: the daylight spectrum of (x, y) with Y = L x the sun's
    // Y, at the batch's three wavelengths, per unit solar irradiance there;
    // clamped to >= 0.
    ATMOS_HD Rgb DaylightChannels(double L, double x, double y) const {
        double m1 = 0.0, m2 = 0.0;
        if (!(L > 0.0) || !CieDaylightWeights(x, y, &m1, &m2)) return Rgb(0.0f);
        const double sy = basis_y[0] + m1 * basis_y[1] + m2 * basis_y[2];
        if (!(sy > 0.0)) return Rgb(0.0f);
        float v[3];
        for (int c = 0; c < 3; ++c) {
            const double s = basis[c][0] + m1 * basis[c][1] + m2 * basis[c][2];
            v[c] = static_cast<float>(Max(L * s / sy * channel_scale[c], 0.0));
        }
        return Rgb(v[0], v[1], v[2]);
    }

    ATMOS_HD double ZenithLuminance(double theta_s) const {
        const double T = turbidity;
        const double chi = (4.0 / 9.0 - T / 120.0) * (kPi - 2.0 * theta_s);
        return Max((4.0453 * T - 4.9710) * tan(chi) - 0.2155 * T + 2.4192, 0.0);
    }
    ATMOS_HD double ZenithChromaticity(double theta_s, bool x) const {
        // Preetham et al. 1999 appendix A.2, rows for T^2, T, 1; columns for
        // theta_s^3, theta_s^2, theta_s, 1.
        const double mx[3][4] = {{0.00166, -0.00375, 0.00209, 0.0},
                                 {-0.02903, 0.06377, -0.03202, 0.00394},
                                 {0.11693, -0.21196, 0.06052, 0.25886}};
        const double my[3][4] = {{0.00275, -0.00610, 0.00317, 0.0},
                                 {-0.04214, 0.08970, -0.04153, 0.00516},
                                 {0.15346, -0.26756, 0.06670, 0.26688}};
        const double T = turbidity;
        const double t[3] = {T * T, T, 1.0};
        const double s[4] = {theta_s * theta_s * theta_s, theta_s * theta_s, theta_s, 1.0};
        double sum = 0.0;
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 4; ++j) sum += t[i] * (x ? mx[i][j] : my[i][j]) * s[j];
        }
        return sum;
    }
};

struct PreethamOptions {
    double turbidity = 2.5;  // atmospheric turbidity T (Preetham's fit: [1.7, 10])
};

class PreethamModel : public SimpleEvaluatorModel<PreethamModel, PreethamEvaluator> {
  public:
    static const OptionTable<PreethamOptions>& OptionRows();
    explicit PreethamModel(const PreethamOptions& options);
    static ModelInfo StaticInfo();
    void Prepare(const AtmosphereParameters& atmosphere) override;
    // The batch's wavelengths (atmos::Error outside the components' 300-830 nm)
    // and the Y of the solar spectrum; the next Prepare() builds the spectral form.
    void SetSpectralBatch(const SpectralAtmosphere& atmosphere, const double nm[3]) override;

  private:
    bool spectral_ = false;
    double nm_[3] = {};
    double solar_y_ = 1.0;
};

}  // namespace atmos
