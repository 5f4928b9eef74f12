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

#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "models/analytic_ray.h"
#include "models/evaluator_model.h"
#include "physics/analytic_media.h"
#include "physics/analytic_optical_depth.h"
#include "physics/geometry.h"
#include "physics/phase.h"
#include "physics/wide.h"

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

    // The per-ray constants of the sample loop (Start) and each sample's
    // geometry (SampleAt), shared by Integrate and the wide evaluator.
    struct RayStart {
        OneilRayStart r, m;  // Rayleigh's and Mie's segment-start lengths
        double r0, mu0, camera_sun, dir_sun, ds;
    };
    ATMOS_HD RayStart Start(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                            const AtmosphereSegment& seg) const {
        const AnalyticMedia& m = optics.m;
        RayStart s;
        const Vec3d p0 = camera + dir * seg.t_start;
        s.r0 = Length(p0);
        s.mu0 = ClampCosine(Dot(p0, dir) / s.r0);
        const double mu0_abs = s.mu0 >= 0.0 ? s.mu0 : -s.mu0;
        const double r_c0 = s.r0 * SafeSqrt(1.0 - s.mu0 * s.mu0);
        s.r.f0 = optics.rayleigh.LengthToInfinity(s.r0, mu0_abs, m.bottom);
        s.m.f0 = optics.mie.LengthToInfinity(s.r0, mu0_abs, m.bottom);
        if (s.mu0 < 0.0) {
            s.r.f_tangent = optics.rayleigh.LengthToInfinity(r_c0, 0.0, m.bottom);
            s.m.f_tangent = optics.mie.LengthToInfinity(r_c0, 0.0, m.bottom);
        }
        s.camera_sun = Dot(camera, sun);
        s.dir_sun = Dot(dir, sun);
        s.ds = (seg.t_end - seg.t_start) / steps;
        return s;
    }
    // Sample i's optical lengths (light + view) of Rayleigh and Mie and its
    // weights rho ds.
    struct Sample {
        double l_r, l_m, w_r, w_m;
    };
    ATMOS_HD Sample SampleAt(const RayStart& s, const Vec3d& camera, const Vec3d& dir,
                             const AtmosphereSegment& seg, int i) const {
        const AnalyticMedia& m = optics.m;
        const double t = seg.t_start + (i + 0.5) * s.ds;
        const Vec3d p = camera + dir * t;
        const double r = Length(p);
        const double h = r - m.bottom;
        const double rho_r = SafeExp(-h / m.rayleigh_H);
        const double rho_m = SafeExp(-h / m.mie_H);
        const double mu1 = ClampCosine((s.r0 * s.mu0 + (t - seg.t_start)) / Max(r, 1e-9));
        const double mu_s = ClampCosine((s.camera_sun + t * s.dir_sun) / r);
        Sample out;
        out.l_r = ViewLength(optics.rayleigh, s.r, s.mu0, rho_r, mu1) +
                  LightLength(optics.rayleigh, r, rho_r, mu_s);
        out.l_m = ViewLength(optics.mie, s.m, s.mu0, rho_m, mu1) +
                  LightLength(optics.mie, r, rho_m, mu_s);
        out.w_r = rho_r * s.ds;
        out.w_m = rho_m * s.ds;
        return out;
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
        const RayStart s = Start(camera, dir, sun, seg);
        Vec3d sum_r, sum_m;
        for (int i = 0; i < steps; ++i) {
            const Sample x = SampleAt(s, camera, dir, seg, i);
            const Vec3d attenuation =
                Exp(-(m.rayleigh_scattering * x.l_r + m.mie_extinction * x.l_m));
            sum_r += attenuation * x.w_r;
            sum_m += attenuation * x.w_m;
        }
        FinishAnalyticRay(optics, camera, dir, sun, seg, want_ground, s.dir_sun, sum_r, sum_m,
                          Exp(-optics.SegmentDepth(camera, dir, seg.t_start, seg.t_end)), out);
    }
};

// The wide evaluator (physics/wide.h; docs/models/oneil.md "Wide channel
// batches"): OneilEvaluator::Evaluate for every channel of a wide batch. The
// clip, the segment start's lengths, each sample's position, densities, view
// and sun cosines and scale() lengths (OneilEvaluator::SampleAt: 6 to 8
// exponentials per sample, none per channel), the phase functions and the
// segment's and the ground's light lengths once per ray; per channel the
// optical depth beta_R l_R + beta_M l_M, its exponential and the two sums, in
// contiguous loops over the channels. Each channel's operations are the
// three-channel evaluator's, in its order (Exp per value, double sums): a
// channel equals it bit for bit.
struct OneilWideEvaluator {
    OneilEvaluator narrow;  // batch 0's optics (the common scale() fits, heights, phase)
    int channels = 0;
    // Each batch's AnalyticMedia coefficients (MakeOneilOptics), channel 3b + c.
    double rayleigh_scattering[kMaxWideChannels] = {};
    double mie_scattering[kMaxWideChannels] = {};
    double mie_extinction[kMaxWideChannels] = {};
    double ground_albedo[kMaxWideChannels] = {};

    ATMOS_HD int Channels() const { return channels; }

    // AnalyticGround for every channel at ground point g, times t_view when
    // given (else 1, as BeginAnalyticRay's Vec3d(1.0)).
    ATMOS_HD void Ground(const Vec3d& g, const Vec3d& sun, const double* t_view,
                         WideRayResult* out) const {
        const OneilOptics& o = narrow.optics;
        const int n = channels;
        bool any[kMaxWideChannels / 3];
        bool some = false;
        for (int b = 0; b < n / 3; ++b) {
            const double* a = ground_albedo + 3 * b;
            any[b] = !(Max(a[0], Max(a[1], a[2])) <= 0.0);
            some = some || any[b];
        }
        if (!some) return;
        const double cos_sun = Dot(Normalize(g), sun);
        if (cos_sun <= 0.0) return;
        const double r = Length(g);
        const double mu_s = ClampCosine(Dot(g, sun) / r);
        const double l_r = o.ToInfinity(o.rayleigh, r, mu_s);
        const double l_m = o.ToInfinity(o.mie, r, mu_s);
        for (int c = 0; c < n; ++c) {
            if (!any[c / 3]) continue;
            const double v = ground_albedo[c] * (cos_sun / kPi) *
                             Exp(-(rayleigh_scattering[c] * l_r + mie_extinction[c] * l_m)) *
                             (t_view ? t_view[c] : 1.0);
            out->ground[c] = static_cast<float>(v);
        }
    }

    ATMOS_HD void EvaluateWide(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                               bool want_ground, WideRayResult* out) const {
        const OneilOptics& o = narrow.optics;
        const int n = channels;
        for (int c = 0; c < n; ++c) {
            out->sky[c] = 0.0f;
            out->ground[c] = 0.0f;
            out->transmittance[c] = 1.0f;
        }
        const AtmosphereSegment seg = ClipToAtmosphere(camera, dir, o.m.bottom, o.m.top);
        out->hits_ground = seg.hits_ground;
        if (!seg.inside) {
            if (want_ground && GroundAtCamera(seg)) Ground(camera, sun, nullptr, out);
            return;
        }
        const OneilEvaluator::RayStart s = narrow.Start(camera, dir, sun, seg);
        double sum_r[kMaxWideChannels], sum_m[kMaxWideChannels];
        for (int c = 0; c < n; ++c) sum_r[c] = sum_m[c] = 0.0;
        for (int i = 0; i < narrow.steps; ++i) {
            const OneilEvaluator::Sample x = narrow.SampleAt(s, camera, dir, seg, i);
            for (int c = 0; c < n; ++c) {
                const double a = Exp(-(rayleigh_scattering[c] * x.l_r + mie_extinction[c] * x.l_m));
                sum_r[c] += a * x.w_r;
                sum_m[c] += a * x.w_m;
            }
        }
        // FinishAnalyticRay, with OneilOptics::SegmentDepth's two lengths once.
        const RaySegmentStart g = RaySegmentStartOf(camera, dir, seg.t_start, seg.t_end);
        const double d_r =
            SegmentFromToInfinity(OneilLength{o.rayleigh, o.m.bottom}, g.r, g.mu, g.d);
        const double d_m = SegmentFromToInfinity(OneilLength{o.mie, o.m.bottom}, g.r, g.mu, g.d);
        const double pr = RayleighPhase(s.dir_sun), pm = o.m.MiePhaseAt(s.dir_sun);
        double t_view[kMaxWideChannels];
        for (int c = 0; c < n; ++c) {
            out->sky[c] = static_cast<float>(rayleigh_scattering[c] * sum_r[c] * pr +
                                             mie_scattering[c] * sum_m[c] * pm);
            t_view[c] = Exp(-(rayleigh_scattering[c] * d_r + mie_extinction[c] * d_m));
            out->transmittance[c] = static_cast<float>(t_view[c]);
        }
        if (want_ground && seg.hits_ground) Ground(camera + dir * seg.t_end, sun, t_view, out);
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

    // Wide channel batches (OneilWideEvaluator).
    void PrepareWide(const std::vector<AtmosphereParameters>& batches,
                     const BatchPrepare& prepare_batch = {}) override;
    void RenderWide(const RenderRequest& request, std::vector<float>* values) const override;
    std::vector<float> SampleWide(const std::vector<SampleQuery>& queries) const override;

  private:
    bool refit_ = true;
    bool wide_prepared_ = false;
    OneilWideEvaluator wide_;
    AtmosphereParameters wide_atmosphere_;  // batch 0's (the common fields)
    WideCoefficients wide_solar_;           // the batches' coefficients (solar irradiance)
};

}  // namespace atmos
