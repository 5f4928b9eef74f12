// atmos: the opening and the end of the analytic single-scattering models'
// view rays (flat, raymarched, oneil), written once.
//
// `Optics` holds the analytic media `m` (physics/analytic_media.h) and
// `Vec3d LightDepth(p, sun)`, the optical depth from p to the sun.
#pragma once

#include "atmos/math.h"
#include "physics/analytic_media.h"
#include "physics/phase.h"
#include "physics/ray.h"

namespace atmos {

// Direct sunlight reflected by the Lambertian ground at p, attenuated by
// t_view (per unit solar irradiance): a / pi max(0, n.s) T_sun T_view.
template <typename Optics>
ATMOS_HD inline Rgb AnalyticGround(const Optics& optics, const Vec3d& p, const Vec3d& sun,
                                   const Vec3d& t_view) {
    const AnalyticMedia& m = optics.m;
    if (MaxComponent(m.ground_albedo) <= 0.0) return Rgb(0.0f);
    const double cos_sun = Dot(Normalize(p), sun);
    if (cos_sun <= 0.0) return Rgb(0.0f);
    return Rgb(m.ground_albedo * (cos_sun / kPi) * Exp(-optics.LightDepth(p, sun)) * t_view);
}

// Clips the view ray to the shell (physics/ray.h BeginRay); false when it
// misses the atmosphere, with the ground at the camera for a camera on the
// ground looking down.
template <typename Optics>
ATMOS_HD inline bool BeginAnalyticRay(const Optics& optics, const Vec3d& camera, const Vec3d& dir,
                                      const Vec3d& sun, bool want_ground, RayResult* out,
                                      AtmosphereSegment* seg) {
    if (BeginRay(camera, dir, optics.m.bottom, optics.m.top, out, seg)) return true;
    if (want_ground && GroundAtCamera(*seg)) {
        out->ground = AnalyticGround(optics, camera, sun, Vec3d(1.0));
    }
    return false;
}

// The evaluator of the analytic single-scattering models (CRTP: no virtual
// call): Evaluate clips the view ray (BeginAnalyticRay) and hands the segment
// inside the atmosphere to Derived's
//   ATMOS_HD void Integrate(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
//                           bool want_ground, const AtmosphereSegment& seg,
//                           RayResult* out) const;
template <typename Derived, typename Optics>
struct AnalyticEvaluator {
    Optics optics;

    ATMOS_HD RayResult Evaluate(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                                bool want_ground) const {
        RayResult out;
        AtmosphereSegment seg;
        if (BeginAnalyticRay(optics, camera, dir, sun, want_ground, &out, &seg)) {
            static_cast<const Derived&>(*this).Integrate(camera, dir, sun, want_ground, seg, &out);
        }
        return out;
    }
};

// The end of the single-scattering sum: the sky from the attenuation-weighted
// Rayleigh and Mie optical lengths (sum_r, sum_m) and the phase functions at
// nu = dir.sun, the view's transmittance t_view, and the lit ground where the
// segment ends on it.
template <typename Optics>
ATMOS_HD inline void FinishAnalyticRay(const Optics& optics, const Vec3d& camera, const Vec3d& dir,
                                       const Vec3d& sun, const AtmosphereSegment& seg,
                                       bool want_ground, double nu, const Vec3d& sum_r,
                                       const Vec3d& sum_m, const Vec3d& t_view, RayResult* out) {
    const AnalyticMedia& m = optics.m;
    const Vec3d sky = m.rayleigh_scattering * sum_r * RayleighPhase(nu) +
                      m.mie_scattering * sum_m * m.MiePhaseAt(nu);
    out->sky = Rgb(sky);
    out->transmittance = Rgb(t_view);
    if (want_ground && seg.hits_ground) {
        out->ground = AnalyticGround(optics, camera + dir * seg.t_end, sun, t_view);
    }
}

}  // namespace atmos
