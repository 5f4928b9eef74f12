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
// Wide channel batches (up to 16 batches of three in one model):
// OneilWideEvaluator below, the geometry once per ray, bit for bit the batches'
// values; the exponentials of both forms run as ExpLane vector loops
// (models/lane_loops.h: 8-double AVX-512 forms for 16 or more values where the
// CPU has them, the same bits).
#pragma once

#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "models/analytic_ray.h"
#include "models/evaluator_model.h"
#include "models/lane_loops.h"
#include "physics/analytic_media.h"
#include "physics/analytic_optical_depth.h"
#include "physics/geometry.h"
#include "physics/phase.h"
#include "physics/vector_exp.h"
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
    double scale0 = 0.0;     // scale(0) (the light rays' tangent points)
};

// x[i] = SafeExp(x[i]) (physics/analytic_optical_depth.h) on ExpLane.
template <int L>
ATMOS_HD ATMOS_LANE_BODY void OneilSafeExpLanesBody(double* __restrict__ x, int n) {
    ATMOS_SIMD_LEN(L)
    for (int i = 0; i < n; ++i) x[i] = ExpLane(Clamp(x[i], -700.0, 60.0));
}
ATMOS_DEFINE_LANE_LOOP(OneilSafeExpLanes, (double* __restrict__ x, int n), (x, n))
// One sample of n channels: the attenuation exp(-(a l_r + b l_m)) per
// channel (a, b: the Rayleigh scattering and Mie extinction coefficients)
// into the two sums.
template <int L>
ATMOS_HD ATMOS_LANE_BODY void OneilAttenuateLanesBody(const double* __restrict__ a,
                                                      const double* __restrict__ b, int n,
                                                      double l_r, double l_m, double w_r,
                                                      double w_m, double* __restrict__ sum_r,
                                                      double* __restrict__ sum_m) {
    ATMOS_SIMD_LEN(L)
    for (int c = 0; c < n; ++c) {
        const double att = ExpLane(-(a[c] * l_r + b[c] * l_m));
        sum_r[c] += att * w_r;
        sum_m[c] += att * w_m;
    }
}
ATMOS_DEFINE_LANE_LOOP(OneilAttenuateLanes,
                       (const double* __restrict__ a, const double* __restrict__ b, int n,
                        double l_r, double l_m, double w_r, double w_m, double* __restrict__ sum_r,
                        double* __restrict__ sum_m),
                       (a, b, n, l_r, l_m, w_r, w_m, sum_r, sum_m))

struct OneilEvaluator : AnalyticEvaluator<OneilEvaluator, OneilOptics> {
    int steps = 5;

    // The per-ray constants of the sample loop (Start) and each sample's
    // geometry (SampleBlock), shared by Integrate and the wide evaluator.
    struct RayStart {
        OneilRayStart r, m;  // Rayleigh's and Mie's segment-start lengths
        double r0, mu0, camera_sun, dir_sun, ds;
        double depth_r, depth_m;  // the whole segment's lengths (SegmentFromToInfinity)
    };
    // The segment start's lengths f(r0, |mu0|) and f(r_c, 0), scale(0), and
    // the whole segment's lengths (SegmentFromToInfinity of each medium from
    // the same f(r0, |mu0|) and f(r_c, 0), with f at the segment's end): their
    // 12 exponentials as one vector loop.
    ATMOS_HD RayStart Start(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                            const AtmosphereSegment& seg) const {
        const AnalyticMedia& m = optics.m;
        const OneilScale& sr = optics.rayleigh;
        const OneilScale& sm = optics.mie;
        RayStart s;
        const Vec3d p0 = camera + dir * seg.t_start;
        s.r0 = Length(p0);
        s.mu0 = ClampCosine(Dot(p0, dir) / s.r0);
        const double r0 = s.r0, mu0 = s.mu0;
        const double mu0_abs = mu0 >= 0.0 ? mu0 : -mu0;
        const double r_c0 = r0 * SafeSqrt(1.0 - mu0 * mu0);
        // The segment's end (SegmentFromToInfinity): radius r1, cosine mu1,
        // f(r1, -mu1) where the segment goes down at both ends.
        const double d = Max(seg.t_end - seg.t_start, 0.0);
        const double r1 = SafeSqrt(d * d + 2.0 * r0 * mu0 * d + r0 * r0);
        const double mu1 = ClampCosine((r0 * mu0 + d) / Max(r1, 1e-9));
        const bool down = mu0 < 0.0 && mu1 <= 0.0;
        const double mv1 = down ? -mu1 : mu1;
        double e[12] = {-(r0 - m.bottom) / sr.scale_height,
                        -(r0 - m.bottom) / sm.scale_height,
                        ScaleExponent(sr, mu0_abs),
                        ScaleExponent(sm, mu0_abs),
                        -(r_c0 - m.bottom) / sr.scale_height,
                        -(r_c0 - m.bottom) / sm.scale_height,
                        ScaleExponent(sr, 0.0),
                        ScaleExponent(sm, 0.0),
                        -(r1 - m.bottom) / sr.scale_height,
                        -(r1 - m.bottom) / sm.scale_height,
                        ScaleExponent(sr, mv1),
                        ScaleExponent(sm, mv1)};
        OneilSafeExpLanes(e, 12);
        s.r.scale0 = (sr.scale_height / sr.thickness) * e[6];
        s.m.scale0 = (sm.scale_height / sm.thickness) * e[7];
        s.r.f0 = LengthFrom(sr, e[0], e[2]);
        s.m.f0 = LengthFrom(sm, e[1], e[3]);
        if (mu0 < 0.0) {
            s.r.f_tangent = ClampLength(sr.thickness * e[4] * s.r.scale0);
            s.m.f_tangent = ClampLength(sm.thickness * e[5] * s.m.scale0);
        }
        const double f1_r = LengthFrom(sr, e[8], e[10]), f1_m = LengthFrom(sm, e[9], e[11]);
        if (mu0 >= 0.0) {
            s.depth_r = s.r.f0 - f1_r;
            s.depth_m = s.m.f0 - f1_m;
        } else if (down) {
            s.depth_r = f1_r - s.r.f0;
            s.depth_m = f1_m - s.m.f0;
        } else {
            s.depth_r = 2.0 * s.r.f_tangent - s.r.f0 - f1_r;
            s.depth_m = 2.0 * s.m.f_tangent - s.m.f0 - f1_m;
        }
        s.depth_r = ClampLength(s.depth_r);
        s.depth_m = ClampLength(s.depth_m);
        s.camera_sun = Dot(camera, sun);
        s.dir_sun = Dot(dir, sun);
        s.ds = (seg.t_end - seg.t_start) / steps;
        return s;
    }
    // The optical lengths (light + view) of Rayleigh and Mie and the weights
    // rho ds of samples i0 .. i0 + lanes - 1 (lanes <= kLanes). Each sample
    // takes 8 exponentials, whose arguments depend on the geometry only: the
    // two densities exp(-h/H), scale()'s exp(p(1 - mu)) of each medium at the
    // view cosine and at the sun cosine, and each medium's density at the
    // light ray's tangent point (used where the sun is below the sample's
    // horizon). Their arguments are gathered first, then all 8 x lanes
    // exponentials run as one vector loop (ExpLane), then the lengths are
    // assembled as OneilOptics::ToInfinity and SegmentFromToInfinity do.
    static constexpr int kLanes = 8;
    static constexpr int kExps = 8;  // exponentials per sample
    struct Block {
        double l_r[kLanes], l_m[kLanes], w_r[kLanes], w_m[kLanes];
    };
    // scale()'s exponent p(1 - mu).
    ATMOS_HD static double ScaleExponent(const OneilScale& s, double mu) {
        return s.Polynomial(1.0 - mu);
    }
    // f = L exp(-h/H) scale(mu) from exp(-h/H) and exp(p(1 - mu)), clamped as
    // OneilScale::LengthToInfinity.
    ATMOS_HD static double LengthFrom(const OneilScale& s, double density, double exp_p) {
        return ClampLength(s.thickness * density * ((s.scale_height / s.thickness) * exp_p));
    }
    // The view segment from its start (SegmentFromToInfinity's three cases)
    // given f(p1, +-mu1) and the light ray (OneilOptics::ToInfinity) given
    // f(p, |mu_s|) and the density at the tangent point, for one medium.
    ATMOS_HD static double ViewPlusLight(const OneilScale& s, const OneilRayStart& start,
                                         double mu0, double mu1, double mu_s, double f1, double fs,
                                         double tangent_density) {
        double view;
        if (mu0 >= 0.0) {
            view = start.f0 - f1;
        } else if (mu1 <= 0.0) {
            view = f1 - start.f0;
        } else {
            view = 2.0 * start.f_tangent - start.f0 - f1;
        }
        view = ClampLength(view);
        if (mu_s >= 0.0) return view + fs;
        const double f_c = ClampLength(s.thickness * tangent_density * start.scale0);
        return view + ClampLength(2.0 * f_c - fs);
    }
    ATMOS_HD void SampleBlock(const RayStart& s, const Vec3d& camera, const Vec3d& dir,
                              const AtmosphereSegment& seg, int i0, int lanes, Block* out) const {
        const AnalyticMedia& m = optics.m;
        const OneilScale& sr = optics.rayleigh;
        const OneilScale& sm = optics.mie;
        double x[kExps * kLanes], mu1[kLanes], mu_s[kLanes];
        for (int k = 0; k < lanes; ++k) {
            const double t = seg.t_start + (i0 + k + 0.5) * s.ds;
            const Vec3d p = camera + dir * t;
            const double r = Length(p);
            const double h = r - m.bottom;
            mu1[k] = ClampCosine((s.r0 * s.mu0 + (t - seg.t_start)) / Max(r, 1e-9));
            mu_s[k] = ClampCosine((s.camera_sun + t * s.dir_sun) / r);
            // The view: f(p1, -mu1) where the segment goes down at the sample.
            const double mv = (s.mu0 < 0.0 && mu1[k] <= 0.0) ? -mu1[k] : mu1[k];
            const double ms = mu_s[k] >= 0.0 ? mu_s[k] : -mu_s[k];
            const double r_c = r * SafeSqrt(1.0 - mu_s[k] * mu_s[k]);
            double* e = x + kExps * k;
            e[0] = -h / m.rayleigh_H;
            e[1] = -h / m.mie_H;
            e[2] = ScaleExponent(sr, mv);
            e[3] = ScaleExponent(sm, mv);
            e[4] = ScaleExponent(sr, ms);
            e[5] = ScaleExponent(sm, ms);
            e[6] = -(r_c - m.bottom) / sr.scale_height;
            e[7] = -(r_c - m.bottom) / sm.scale_height;
        }
        OneilSafeExpLanes(x, kExps * lanes);
        for (int k = 0; k < lanes; ++k) {
            const double* e = x + kExps * k;
            const double rho_r = e[0], rho_m = e[1];
            out->l_r[k] =
                ViewPlusLight(sr, s.r, s.mu0, mu1[k], mu_s[k], LengthFrom(sr, rho_r, e[2]),
                              LengthFrom(sr, rho_r, e[4]), e[6]);
            out->l_m[k] =
                ViewPlusLight(sm, s.m, s.mu0, mu1[k], mu_s[k], LengthFrom(sm, rho_m, e[3]),
                              LengthFrom(sm, rho_m, e[5]), e[7]);
            out->w_r[k] = rho_r * s.ds;
            out->w_m[k] = rho_m * s.ds;
        }
    }

    // O'Neil's loop with every exponential computed once: per sample, the two
    // densities (shared by the in-scattering term, the view segment's and the
    // light ray's optical lengths), scale() of the view and sun cosines, and
    // the attenuation; the segment start's lengths once per ray (Start, which
    // also gives the whole segment's lengths for the transmittance). The view
    // segment's end is evaluated at the sample's own radius |p| (the generic
    // SegmentDepth recomputes it from the segment's start: the same radius up
    // to rounding, results within ~1e-13 relative;
    // Oneil.HoistedLoopMatchesTheGenericOne in tests/analytic_test.cpp holds
    // this loop against the generic one). Every exponential is ExpLane, in
    // the vector loops of SampleBlock, Start and ExpNegLanes.
    ATMOS_HD void Integrate(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                            bool want_ground, const AtmosphereSegment& seg, RayResult* out) const {
        const AnalyticMedia& m = optics.m;
        const RayStart s = Start(camera, dir, sun, seg);
        Vec3d sum_r, sum_m;
        for (int i0 = 0; i0 < steps; i0 += kLanes) {
            const int lanes = Min(kLanes, steps - i0);
            Block x;
            SampleBlock(s, camera, dir, seg, i0, lanes, &x);
            double tau[3 * kLanes];
            for (int k = 0; k < lanes; ++k) {
                const Vec3d t = m.rayleigh_scattering * x.l_r[k] + m.mie_extinction * x.l_m[k];
                tau[3 * k] = t.x;
                tau[3 * k + 1] = t.y;
                tau[3 * k + 2] = t.z;
            }
            ExpNegLanes(tau, 3 * lanes);
            for (int k = 0; k < lanes; ++k) {
                const Vec3d attenuation(tau[3 * k], tau[3 * k + 1], tau[3 * k + 2]);
                sum_r += attenuation * x.w_r[k];
                sum_m += attenuation * x.w_m[k];
            }
        }
        const Vec3d depth = m.rayleigh_scattering * s.depth_r + m.mie_extinction * s.depth_m;
        double t_view[3] = {depth.x, depth.y, depth.z};
        ExpNegLanes(t_view, 3);
        FinishAnalyticRay(optics, camera, dir, sun, seg, want_ground, s.dir_sun, sum_r, sum_m,
                          Vec3d(t_view[0], t_view[1], t_view[2]), out);
    }
};

// The wide evaluator (physics/wide.h; docs/models/oneil.md "Wide channel
// batches"): OneilEvaluator::Evaluate for every channel of a wide batch. The
// clip, the segment start's lengths, each sample's position, densities, view
// and sun cosines and scale() lengths (OneilEvaluator::SampleBlock: 8
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
        out->Reset(n);
        const AtmosphereSegment seg = ClipToAtmosphere(camera, dir, o.m.bottom, o.m.top);
        out->hits_ground = seg.hits_ground;
        if (!seg.inside) {
            if (want_ground && GroundAtCamera(seg)) Ground(camera, sun, nullptr, out);
            return;
        }
        const OneilEvaluator::RayStart s = narrow.Start(camera, dir, sun, seg);
        double sum_r[kMaxWideChannels], sum_m[kMaxWideChannels];
        for (int c = 0; c < n; ++c) sum_r[c] = sum_m[c] = 0.0;
        constexpr int kLanes = OneilEvaluator::kLanes;
        for (int i0 = 0; i0 < narrow.steps; i0 += kLanes) {
            const int lanes = Min(kLanes, narrow.steps - i0);
            OneilEvaluator::Block x;
            narrow.SampleBlock(s, camera, dir, seg, i0, lanes, &x);
            for (int k = 0; k < lanes; ++k) {
                OneilAttenuateLanes(rayleigh_scattering, mie_extinction, n, x.l_r[k], x.l_m[k],
                                    x.w_r[k], x.w_m[k], sum_r, sum_m);
            }
        }
        // FinishAnalyticRay, with the segment's two lengths once.
        const double d_r = s.depth_r, d_m = s.depth_m;
        const double pr = RayleighPhase(s.dir_sun), pm = o.m.MiePhaseAt(s.dir_sun);
        double t_view[kMaxWideChannels];
        for (int c = 0; c < n; ++c) {
            out->sky[c] = static_cast<float>(rayleigh_scattering[c] * sum_r[c] * pr +
                                             mie_scattering[c] * sum_m[c] * pm);
            t_view[c] = rayleigh_scattering[c] * d_r + mie_extinction[c] * d_m;
        }
        ExpNegLanes(t_view, n);
        for (int c = 0; c < n; ++c) out->transmittance[c] = static_cast<float>(t_view[c]);
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
    PreparedWide<OneilWideEvaluator> wide_;
};

}  // namespace atmos
