// atmos model `oneil`: O'Neil's real-time single scattering (GPU Gems 2,
// chapter 16, "Accurate Atmospheric Scattering", 2005), evaluated per pixel.
//
// Source: O'Neil 2005 as Raush's O'Neil slides (2018) presents it (vertex shader
// "SkyFromAtmosphere": midpoint rule over the view ray, optical depth from the fitted scale()
// function, fragment-shader phase functions) and Leenman's 2025 thesis section 5.1 (Eq. 17).
//
// Implements: `steps` midpoint samples x_i of the part of the view ray inside
// the atmosphere (5 by default, O'Neil's outer integral; cameras in space start
// where the ray enters, as his SkyFromSpace shader). At each sample
//   attenuation = exp(-(beta_R (l_R,light + l_R,view) + beta_M^ext (l_M,light + l_M,view)))
//   L += attenuation * (beta_R^s rho_R(x_i) P_R(nu) + beta_M^s rho_M(x_i) P_M(nu)) ds
// with every optical length from scale(): l(x, mu) = L_atm exp(-h/H) (H/L_atm)
// exp(p(1 - mu)) to infinity (physics/analytic_optical_depth.h, OneilScale),
// the view part as a difference of two such lengths (camera to x_i).
//
// Mapping from our canonical parameters to O'Neil's inputs (documented in
// docs/models/oneil.md):
//   * fInnerRadius, fOuterRadius        = bottom_radius, top_radius (metres, not
//                                         his 10 / 10.25 units);
//   * fScaleDepth (0.25 of the thickness) = each medium's scale height H / L_atm:
//     `--fit refit` (default) gives Rayleigh and Mie their own H and their own
//     least-squares refit of p (Prepare(), physics/analytic_fit.h); `--fit
//     original` keeps his constants and his single scale depth 0.25 L_atm for
//     both media (exact only for L_atm = 2.5% of the radius);
//   * 4 pi Kr / lambda^4 (his Rayleigh out-scattering per unit length, with the
//     1/lambda^4 ratio over wavelengths 650, 570, 475 nm) = rayleigh_scattering
//     per metre, per channel (the ratio between our channels plays the role
//     of his 1/lambda^4); Kr ESun F_R = beta_R^s E P_R with his phase
//     0.75 (1 + cos^2) = 4 pi P_R;
//   * 4 pi Km = mie_extinction for out-scattering and Km F_M = mie_scattering
//     P_M for in-scattering (he has no absorption: with extinction =
//     scattering the two coincide); his g = -0.99 (negative = forward in his
//     convention) is our mie_phase_g with the opposite sign; the phase is the
//     same Cornette-Shanks form (plus the atmosphere's optional second lobe:
//     physics/phase.h MiePhase);
//   * ESun = the solar irradiance: the output is per unit irradiance, as every
//     model's.
// No ozone (O'Neil has none).
//
// Output: radiance per unit solar irradiance (1/sr); transmittance of the view
// segment (Rayleigh + Mie). Ground: a/pi max(0, n.s) T_sun T_view.
// Valid: where scale() fits (rays above the horizon, see the tests); the view
// ray below the horizon and the light ray from a point whose sun is below its
// horizon use the decomposition of SegmentFromToInfinity / Eq. 53 with scale()
// at mu >= 0 only. Deviation: O'Neil's shaders evaluate scale() for negative
// cosines too (the polynomial extrapolated past x = 1, which a refit does not
// control) and switch shader by camera position; per-pixel evaluation here
// (no vertex interpolation), in double.
#pragma once

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "models/analytic_ray.h"
#include "models/evaluator_model.h"
#include "physics/analytic_media.h"
#include "physics/analytic_optical_depth.h"
#include "physics/geometry.h"
#include "physics/phase.h"

namespace atmos {

// scale() as a function of (r, mu >= 0) for SegmentFromToInfinity.
struct OneilLength {
    OneilScale s;
    double bottom;
    ATMOS_HD double operator()(double r, double mu) const {
        return s.LengthToInfinity(r, mu, bottom);
    }
};

// O'Neil's optical lengths for the two media.
struct OneilOptics {
    AnalyticMedia m;
    OneilScale rayleigh, mie;

    // To infinity from p along direction cosine mu (any sign: Eq. 53's
    // decomposition below the horizon).
    ATMOS_HD double ToInfinity(const OneilScale& s, double r, double mu) const {
        if (mu >= 0.0) return s.LengthToInfinity(r, mu, m.bottom);
        const double r_c = r * SafeSqrt(1.0 - mu * mu);
        return ClampLength(2.0 * s.LengthToInfinity(r_c, 0.0, m.bottom) -
                           s.LengthToInfinity(r, -mu, m.bottom));
    }
    ATMOS_HD Vec3d LightDepth(const Vec3d& p, const Vec3d& sun) const {
        const double r = Length(p);
        const double mu_s = ClampCosine(Dot(p, sun) / r);
        return m.rayleigh_scattering * ToInfinity(rayleigh, r, mu_s) +
               m.mie_extinction * ToInfinity(mie, r, mu_s);
    }
    ATMOS_HD Vec3d SegmentDepth(const Vec3d& origin, const Vec3d& dir, double t0, double t1) const {
        return RayleighMieSegmentDepth(m.rayleigh_scattering, OneilLength{rayleigh, m.bottom},
                                       m.mie_extinction, OneilLength{mie, m.bottom}, origin, dir,
                                       t0, t1);
    }
};

// One medium's per-ray constants for the view segment from its start p0
// (radius r0, cosine mu0): SegmentFromToInfinity's f(r0, |mu0|) and, for a ray
// that starts downwards, f at the tangent point, hoisted out of the sample loop.
struct OneilRayStart {
    double f0 = 0.0;         // f(r0, |mu0|)
    double f_tangent = 0.0;  // f(r0 sqrt(1 - mu0^2), 0), only for mu0 < 0
};

struct OneilEvaluator : AnalyticEvaluator<OneilEvaluator, OneilOptics> {
    int steps = 5;

    // f(r, mu) = L exp(-h/H) scale(mu) of one medium with exp(-h/H) given
    // (the density, shared with the in-scattering term and the light ray).
    ATMOS_HD static double LengthAt(const OneilScale& s, double density, double mu) {
        return ClampLength(s.thickness * density * s.Scale(mu));
    }
    // The optical length of the light ray from a sample point (radius r,
    // density exp(-h/H), sun cosine mu_s): OneilOptics::ToInfinity.
    ATMOS_HD double LightLength(const OneilScale& s, double r, double density, double mu_s) const {
        if (mu_s >= 0.0) return LengthAt(s, density, mu_s);
        const double r_c = r * SafeSqrt(1.0 - mu_s * mu_s);
        return ClampLength(2.0 * s.LengthToInfinity(r_c, 0.0, optics.m.bottom) -
                           LengthAt(s, density, -mu_s));
    }
    // The view segment from its start to a sample point (radius r1, cosine
    // mu1, density exp(-h/H)): SegmentFromToInfinity's three cases.
    ATMOS_HD static double ViewLength(const OneilScale& s, const OneilRayStart& start, double mu0,
                                      double density, double mu1) {
        double l;
        if (mu0 >= 0.0) {
            l = start.f0 - LengthAt(s, density, mu1);
        } else if (mu1 <= 0.0) {
            l = LengthAt(s, density, -mu1) - start.f0;
        } else {
            l = 2.0 * start.f_tangent - start.f0 - LengthAt(s, density, mu1);
        }
        return ClampLength(l);
    }

    // O'Neil's loop with every exponential computed once: per sample, the two
    // densities (shared by the in-scattering term, the view segment's and the
    // light ray's optical lengths), scale() of the view and sun cosines, and
    // the attenuation; the segment start's lengths once per ray. The view
    // segment's end is evaluated at the sample's own radius |p| (the generic
    // SegmentDepth recomputes it from the segment's start: the same radius up
    // to rounding, results within ~1e-13 relative; tests/oneil_test.cpp holds
    // this loop against the generic one).
    ATMOS_HD void Integrate(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                            bool want_ground, const AtmosphereSegment& seg, RayResult* out) const {
        const AnalyticMedia& m = optics.m;
        const Vec3d p0 = camera + dir * seg.t_start;
        const double r0 = Length(p0);
        const double mu0 = ClampCosine(Dot(p0, dir) / r0);
        const double mu0_abs = mu0 >= 0.0 ? mu0 : -mu0;
        const double r_c0 = r0 * SafeSqrt(1.0 - mu0 * mu0);
        OneilRayStart start_r, start_m;
        start_r.f0 = optics.rayleigh.LengthToInfinity(r0, mu0_abs, m.bottom);
        start_m.f0 = optics.mie.LengthToInfinity(r0, mu0_abs, m.bottom);
        if (mu0 < 0.0) {
            start_r.f_tangent = optics.rayleigh.LengthToInfinity(r_c0, 0.0, m.bottom);
            start_m.f_tangent = optics.mie.LengthToInfinity(r_c0, 0.0, m.bottom);
        }
        const double camera_sun = Dot(camera, sun);
        const double dir_sun = Dot(dir, sun);
        const double ds = (seg.t_end - seg.t_start) / steps;
        Vec3d sum_r, sum_m;
        for (int i = 0; i < steps; ++i) {
            const double t = seg.t_start + (i + 0.5) * ds;
            const Vec3d p = camera + dir * t;
            const double r = Length(p);
            const double h = r - m.bottom;
            const double rho_r = SafeExp(-h / m.rayleigh_H);
            const double rho_m = SafeExp(-h / m.mie_H);
            const double mu1 = ClampCosine((r0 * mu0 + (t - seg.t_start)) / Max(r, 1e-9));
            const double mu_s = ClampCosine((camera_sun + t * dir_sun) / r);
            const double l_r = ViewLength(optics.rayleigh, start_r, mu0, rho_r, mu1) +
                               LightLength(optics.rayleigh, r, rho_r, mu_s);
            const double l_m = ViewLength(optics.mie, start_m, mu0, rho_m, mu1) +
                               LightLength(optics.mie, r, rho_m, mu_s);
            const Vec3d attenuation = Exp(-(m.rayleigh_scattering * l_r + m.mie_extinction * l_m));
            sum_r += attenuation * (rho_r * ds);
            sum_m += attenuation * (rho_m * ds);
        }
        FinishAnalyticRay(optics, camera, dir, sun, seg, want_ground, dir_sun, sum_r, sum_m,
                          Exp(-optics.SegmentDepth(camera, dir, seg.t_start, seg.t_end)), out);
    }
};

// Builds O'Neil's optics for an atmosphere: `refit` fits scale() per medium
// (physics/analytic_fit.h); otherwise his constants with scale depth 0.25.
OneilOptics MakeOneilOptics(const AtmosphereParameters& atmosphere, bool refit);

struct OneilOptions {
    int steps = 5;      // view-ray samples
    bool refit = true;  // scale() refitted per medium (false: O'Neil's constants)
};

class OneilModel : public SimpleEvaluatorModel<OneilModel, OneilEvaluator> {
  public:
    static const OptionTable<OneilOptions>& OptionRows();
    explicit OneilModel(const OneilOptions& options);
    static ModelInfo StaticInfo();
    void Prepare(const AtmosphereParameters& atmosphere) override;

  private:
    bool refit_ = true;
};

}  // namespace atmos
