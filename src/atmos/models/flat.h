// atmos model `flat`: single scattering in one segment of a homogeneous-sphere
// atmosphere (the thesis's "flat" model).
//
// Source: Leenman's 2025 thesis section 10 (Eq. 45-55, 59) and section 11.2.9, after Jodie
// 2019 and Rapp-Arraras & Domingo-Santos 2011 (Eq. 49, "DR-1").
//
// Implements: each medium's optical length along a ray from radius r with
// cosine mu is that of a homogeneous sphere of radius r + H (Eq. 50) times the
// density at the point (Eq. 51); looking down uses Eq. 53's decomposition (see
// physics/analytic_optical_depth.h); a segment's length is a difference of
// such lengths (SegmentFromToInfinity). Ozone is a constant-density shell
// (Eq. 59, 17.5-32.5 km for `earth`) whose length along a ray is exact. The
// whole view segment inside the atmosphere is one segment of Eq. 54-55:
//   L = (beta_R^s l_R P_R(nu) + beta_M^s l_M P_M(nu)) * integral_0^1 exp(-(T0 + u (T1 - T0))) du
// with T0 = the light's optical depth at the segment's start, T1 = the
// segment's optical depth plus the light's at its end, i.e. the exponent
// varying linearly along the segment. Looking up from inside the atmosphere
// this is Eq. 52 (the light's depth at the far end, the top of the
// atmosphere, is ~0); a ray that hits the ground is the segment of Eq. 55, as
// the thesis does; cameras in space start where the ray enters.
//
// Output: radiance per unit solar irradiance (1/sr); transmittance exp(-tau)
// of the segment. Ground (albedo a): a/pi max(0, n.s) T_sun T_view.
//
// Valid: views from the ground looking up, sun above the horizon (the
// assumptions of Eq. 45-52); elsewhere a rough approximation (the thesis's
// flat model is worst in the planet-shadow views). Deviations: Eq. 52 prints
// exp(+tau); the integral it comes from (Eq. 46) gives exp(-tau), used here;
// Eq. 53 carries the density at the tangent point (see the physics header);
// the light depth of a point whose sun is below the horizon uses the same
// Eq. 53 form (so the planet's shadow is a smooth, very large depth instead of
// an explicit test); the shell is fitted to any absorption profile by its
// column and centroid (physics/analytic_media.h).
// Wide channel batches (up to 16 batches of three in one model):
// FlatWideEvaluator below, bit for bit the batches' values.
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

// Eq. 51 as a function of (r, mu) for SegmentFromToInfinity.
struct FlatUpLength {
    double H, bottom;
    ATMOS_HD double operator()(double r, double mu) const { return FlatLengthUp(r, mu, H, bottom); }
};

// The flat approximation's optical quantities, shared by `flat`, `raymarched`
// and `transmittance-flat`.
struct FlatOptics {
    AnalyticMedia m;

    // Optical lengths of the segment [t0, t1] of the ray origin + t dir.
    ATMOS_HD MediaLengths SegmentLengths(const Vec3d& origin, const Vec3d& dir, double t0,
                                         double t1) const {
        const auto [r, mu, d] = RaySegmentStartOf(origin, dir, t0, t1);
        MediaLengths l;
        l.rayleigh = SegmentFromToInfinity(FlatUpLength{m.rayleigh_H, m.bottom}, r, mu, d);
        l.mie = SegmentFromToInfinity(FlatUpLength{m.mie_H, m.bottom}, r, mu, d);
        l.ozone = ShellLength(m.ozone, origin, dir, t0, t1);
        return l;
    }

    ATMOS_HD Vec3d SegmentDepth(const Vec3d& origin, const Vec3d& dir, double t0, double t1) const {
        const MediaLengths l = SegmentLengths(origin, dir, t0, t1);
        return m.Extinction(l.rayleigh, l.mie, l.ozone);
    }

    // Optical depth from p toward the sun to infinity (Eq. 51, or Eq. 53 for
    // a sun below the local horizon), ozone shell included.
    ATMOS_HD Vec3d LightDepth(const Vec3d& p, const Vec3d& sun) const {
        const MediaLengths l = LightLengths(p, sun);
        return m.Extinction(l.rayleigh, l.mie, l.ozone);
    }
    // The three media's optical lengths of LightDepth.
    ATMOS_HD MediaLengths LightLengths(const Vec3d& p, const Vec3d& sun) const {
        const double r = Length(p);
        const double mu_s = ClampCosine(Dot(p, sun) / r);
        MediaLengths l;
        l.rayleigh = FlatLengthToInfinity(r, mu_s, m.rayleigh_H, m.bottom);
        l.mie = FlatLengthToInfinity(r, mu_s, m.mie_H, m.bottom);
        l.ozone = ShellLength(m.ozone, p, sun, 0.0, 4.0 * m.top);
        return l;
    }
};

// The per-channel coefficients of a wide batch of FlatOptics (flat and
// raymarched, physics/wide.h): each batch's AnalyticMedia coefficients side
// by side (channel 3b + c) and one FlatOptics for the geometry (the heights
// and the ozone shell, which do not depend on the coefficients: a batch
// whose shell is empty, no absorption at its wavelengths, has 0 for its
// ozone coefficient, so that its channels' depths are the same numbers).
struct FlatWideMedia {
    FlatOptics optics;
    int channels = 0;
    double rayleigh_scattering[kMaxWideChannels] = {};
    double mie_scattering[kMaxWideChannels] = {};
    double mie_extinction[kMaxWideChannels] = {};
    double ozone_absorption[kMaxWideChannels] = {};
    double ground_albedo[kMaxWideChannels] = {};

    // AnalyticMedia::Extinction of channel c.
    ATMOS_HD double Ext(int c, const MediaLengths& l) const {
        return rayleigh_scattering[c] * l.rayleigh + mie_extinction[c] * l.mie +
               ozone_absorption[c] * l.ozone;
    }
    // AnalyticGround (models/analytic_ray.h) of every channel at ground point
    // g, with LightLengths(g) given, times t_view when given.
    ATMOS_HD void Ground(const Vec3d& g, const Vec3d& sun, const MediaLengths* light,
                         const double* t_view, WideRayResult* out) const {
        const int n = channels;
        const double cos_sun = Dot(Normalize(g), sun);
        MediaLengths l;
        bool have = light != nullptr;
        if (have) l = *light;
        for (int b = 0; b < n / 3; ++b) {
            const double* a = ground_albedo + 3 * b;
            if (Max(a[0], Max(a[1], a[2])) <= 0.0 || cos_sun <= 0.0) continue;
            if (!have) {
                l = optics.LightLengths(g, sun);
                have = true;
            }
            for (int c = 3 * b; c < 3 * b + 3; ++c) {
                const double v = ground_albedo[c] * (cos_sun / kPi) * Exp(-Ext(c, l)) *
                                 (t_view ? t_view[c] : 1.0);
                out->ground[c] = static_cast<float>(v);
            }
        }
    }
    // Clears out and clips the ray (BeginAnalyticRay); false when it misses
    // the atmosphere (the ground at the camera done).
    ATMOS_HD bool Begin(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun, bool want_ground,
                        WideRayResult* out, AtmosphereSegment* seg) const {
        out->Reset(channels);
        *seg = ClipToAtmosphere(camera, dir, optics.m.bottom, optics.m.top);
        out->hits_ground = seg->hits_ground;
        if (seg->inside) return true;
        if (want_ground && GroundAtCamera(*seg)) Ground(camera, sun, nullptr, nullptr, out);
        return false;
    }
};

// FlatWideMedia for the batches (throws as MakeWideCoefficients).
FlatWideMedia MakeFlatWideMedia(const std::vector<AtmosphereParameters>& batches);

struct FlatEvaluator : AnalyticEvaluator<FlatEvaluator, FlatOptics> {
    // The segment inside the atmosphere (AnalyticEvaluator::Evaluate).
    ATMOS_HD void Integrate(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                            bool want_ground, const AtmosphereSegment& seg, RayResult* out) const {
        const AnalyticMedia& m = optics.m;
        const MediaLengths l = optics.SegmentLengths(camera, dir, seg.t_start, seg.t_end);
        const Vec3d tau = m.Extinction(l.rayleigh, l.mie, l.ozone);
        const Vec3d p0 = camera + dir * seg.t_start;
        const Vec3d p1 = camera + dir * seg.t_end;
        const Vec3d t0 = optics.LightDepth(p0, sun);
        const Vec3d t1 = tau + optics.LightDepth(p1, sun);
        const Vec3d e = LinearExpIntegral(t0, t1);
        const double nu = Dot(dir, sun);
        const Vec3d sky = (m.rayleigh_scattering * (l.rayleigh * RayleighPhase(nu)) +
                           m.mie_scattering * (l.mie * m.MiePhaseAt(nu))) *
                          e;
        const Vec3d t_view = Exp(-tau);
        out->sky = Rgb(sky);
        out->transmittance = Rgb(t_view);
        if (want_ground && seg.hits_ground) out->ground = AnalyticGround(optics, p1, sun, t_view);
    }
};

// The wide evaluator (docs/models/flat.md "Wide channel batches"):
// FlatEvaluator::Integrate for every channel: the segment's and the two light
// rays' optical lengths and the phase functions once per ray, per channel the
// depths, LinearExpIntegral and the transmittance, in the three-channel
// order: a channel equals it bit for bit.
struct FlatWideEvaluator {
    FlatWideMedia w;

    ATMOS_HD int Channels() const { return w.channels; }

    ATMOS_HD void EvaluateWide(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                               bool want_ground, WideRayResult* out) const {
        AtmosphereSegment seg;
        if (!w.Begin(camera, dir, sun, want_ground, out, &seg)) return;
        const FlatOptics& o = w.optics;
        const MediaLengths l = o.SegmentLengths(camera, dir, seg.t_start, seg.t_end);
        const Vec3d p0 = camera + dir * seg.t_start;
        const Vec3d p1 = camera + dir * seg.t_end;
        const MediaLengths light0 = o.LightLengths(p0, sun);
        const MediaLengths light1 = o.LightLengths(p1, sun);
        const double nu = Dot(dir, sun);
        const double lr = l.rayleigh * RayleighPhase(nu), lm = l.mie * o.m.MiePhaseAt(nu);
        double t_view[kMaxWideChannels];
        for (int c = 0; c < w.channels; ++c) {
            const double tau = w.Ext(c, l);
            const double t0 = w.Ext(c, light0);
            const double t1 = tau + w.Ext(c, light1);
            const double e = LinearExpIntegral(t0, t1);
            out->sky[c] =
                static_cast<float>((w.rayleigh_scattering[c] * lr + w.mie_scattering[c] * lm) * e);
            t_view[c] = Exp(-tau);
            out->transmittance[c] = static_cast<float>(t_view[c]);
        }
        if (want_ground && seg.hits_ground) w.Ground(p1, sun, &light1, t_view, out);
    }
};

class FlatModel : public SimpleEvaluatorModel<FlatModel, FlatEvaluator> {
  public:
    static const OptionTable<NoOptions>& OptionRows() { return NoOptionTable(); }
    explicit FlatModel(const NoOptions& options);
    static ModelInfo StaticInfo();
    void Prepare(const AtmosphereParameters& atmosphere) override;

    // Wide channel batches (FlatWideEvaluator).
    void PrepareWide(const std::vector<AtmosphereParameters>& batches,
                     const BatchPrepare& prepare_batch = {}) override;
    void RenderWide(const RenderRequest& request, std::vector<float>* values) const override;
    std::vector<float> SampleWide(const std::vector<SampleQuery>& queries) const override;

  private:
    PreparedWide<FlatWideEvaluator> wide_;
};

}  // namespace atmos
