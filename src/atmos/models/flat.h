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
        const double r = Length(p);
        const double mu_s = ClampCosine(Dot(p, sun) / r);
        const double l_r = FlatLengthToInfinity(r, mu_s, m.rayleigh_H, m.bottom);
        const double l_m = FlatLengthToInfinity(r, mu_s, m.mie_H, m.bottom);
        const double l_o = ShellLength(m.ozone, p, sun, 0.0, 4.0 * m.top);
        return m.Extinction(l_r, l_m, l_o);
    }
};

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

class FlatModel : public SimpleEvaluatorModel<FlatModel, FlatEvaluator> {
  public:
    static const OptionTable<NoOptions>& OptionRows() { return NoOptionTable(); }
    explicit FlatModel(const NoOptions& options);
    static ModelInfo StaticInfo();
    void Prepare(const AtmosphereParameters& atmosphere) override;
};

}  // namespace atmos
