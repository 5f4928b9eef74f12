// atmos: the single-scattering integral along a view ray, by the midpoint rule.
//
// Source: Leenman's 2025 thesis section 3.2 (Eq. 8, 9) and section 5.1 (Nishita 93 as
// formulated by Terrell 2016): for the part of the view ray inside the
// atmosphere, `steps` equal segments sampled at their midpoints x_i,
//   L = sum_i [ beta_R rho_R(x_i) P_R(nu) + beta_M rho_M(x_i) P_M(nu) ]
//             T(camera, x_i) T_sun(x_i) ds,
// with T(camera, x_i) from the extinction accumulated along the view ray to the
// midpoint. The models that share it differ only in their medium:
//   Vec3d ExtinctionAt(double altitude, double* rho_r, double* rho_m) const;
//   bool LightDepth(const Vec3d& p, const Vec3d& sun, Vec3d* tau) const;
// (LightDepth: the optical depth to the sun, false when the light ray hits the
// ground: the planet's shadow). `naive` integrates the light ray numerically,
// `schuler` uses the Chapman approximation.
#pragma once

#include "atmos/atmosphere.h"
#include "atmos/math.h"
#include "physics/geometry.h"
#include "physics/phase.h"
#include "physics/ray.h"
#include "physics/wide.h"

namespace atmos {

// A camera on the ground looking down (physics/ray.h, BeginRay false): the
// ground at the camera, lit by the direct sun.
template <typename Medium>
ATMOS_HD inline void SingleScatteringGroundAtCamera(const AtmosphereParameters& atm,
                                                    const Medium& medium, const Vec3d& camera,
                                                    const Vec3d& sun, const AtmosphereSegment& seg,
                                                    bool want_ground, RayResult* out) {
    if (want_ground && GroundAtCamera(seg) && MaxComponent(atm.ground_albedo) > 0.0) {
        const double cos_sun = Dot(Normalize(camera), sun);
        Vec3d tau_sun;
        if (cos_sun > 0.0 && medium.LightDepth(camera, sun, &tau_sun)) {
            out->ground = Rgb(atm.ground_albedo * (cos_sun / kPi) * Exp(-tau_sun));
        }
    }
}

// After the march: the sky from the phase-weighted sums, the transmittance
// exp(-tau_view), and the ground (albedo a) lit by the direct sun only:
// a / pi max(0, n.s) T_sun T_view.
template <typename Medium>
ATMOS_HD inline void FinishSingleScattering(const AtmosphereParameters& atm, const Medium& medium,
                                            const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                                            const AtmosphereSegment& seg, bool want_ground,
                                            const Vec3d& sum_r, const Vec3d& sum_m,
                                            const Vec3d& tau_view, RayResult* out) {
    const double nu = Dot(dir, sun);
    const Vec3d sky = atm.rayleigh_scattering * sum_r * RayleighPhase(nu) +
                      atm.mie_scattering * sum_m * MiePhase(atm, nu);
    const Vec3d t_view = Exp(-tau_view);
    out->sky = Rgb(sky);
    out->transmittance = Rgb(t_view);
    if (want_ground && seg.hits_ground && MaxComponent(atm.ground_albedo) > 0.0) {
        const Vec3d g = camera + dir * seg.t_end;
        const double cos_sun = Dot(Normalize(g), sun);
        Vec3d tau_sun;
        if (cos_sun > 0.0 && medium.LightDepth(g, sun, &tau_sun)) {
            out->ground = Rgb(atm.ground_albedo * (cos_sun / kPi) * Exp(-tau_sun) * t_view);
        }
    }
}

template <typename Medium>
ATMOS_HD inline RayResult IntegrateSingleScattering(const AtmosphereParameters& atm,
                                                    const Medium& medium, int steps,
                                                    const Vec3d& camera, const Vec3d& dir,
                                                    const Vec3d& sun, bool want_ground) {
    RayResult out;
    AtmosphereSegment seg;
    if (!BeginRay(camera, dir, atm.bottom_radius, atm.top_radius, &out, &seg)) {
        SingleScatteringGroundAtCamera(atm, medium, camera, sun, seg, want_ground, &out);
        return out;
    }
    const double ds = (seg.t_end - seg.t_start) / steps;
    Vec3d tau_view;  // camera to the start of the current step
    Vec3d sum_r, sum_m;
    for (int i = 0; i < steps; ++i) {
        const Vec3d p = camera + dir * (seg.t_start + (i + 0.5) * ds);
        double rho_r, rho_m;
        const Vec3d ext = medium.ExtinctionAt(Length(p) - atm.bottom_radius, &rho_r, &rho_m);
        const Vec3d tau_mid = tau_view + ext * (0.5 * ds);
        tau_view += ext * ds;
        Vec3d tau_sun;
        if (!medium.LightDepth(p, sun, &tau_sun)) continue;
        const Vec3d t = Exp(-(tau_mid + tau_sun));
        sum_r += t * (rho_r * ds);
        sum_m += t * (rho_m * ds);
    }
    FinishSingleScattering(atm, medium, camera, dir, sun, seg, want_ground, sum_r, sum_m, tau_view,
                           &out);
    return out;
}

// FinishSingleScattering's sky and transmittance for the n = w.channels
// channels of a wide evaluator (physics/wide.h): the phase functions once, then
// per channel the same operations as the three-channel form. Writes the view
// ray's transmittance per channel to t_view (for the ground term).
ATMOS_HD inline void FinishWideSingleScattering(const AtmosphereParameters& atm,
                                                const WideCoefficients& w, const Vec3d& dir,
                                                const Vec3d& sun, const double* sum_r,
                                                const double* sum_m, const double* tau_view,
                                                double* t_view, WideRayResult* out) {
    const double nu = Dot(dir, sun);
    const double pr = RayleighPhase(nu), pm = MiePhase(atm, nu);
    for (int c = 0; c < w.channels; ++c) {
        out->sky[c] = static_cast<float>(w.rayleigh_scattering[c] * sum_r[c] * pr +
                                         w.mie_scattering[c] * sum_m[c] * pm);
        t_view[c] = Exp(-tau_view[c]);
        out->transmittance[c] = static_cast<float>(t_view[c]);
    }
}

}  // namespace atmos
