// atmos model `raymarched`: single scattering summed over a few segments, each
// integrated in closed form with the flat optical depth (the thesis's
// "raymarched" model).
//
// Source: Leenman's 2025 thesis section 10.4 (Eq. 54-57) and section 11.2.10; optical depth
// of section 10.2 (Eq. 50-51, 53), ozone shell of section 10.5 (Eq. 59).
//
// Implements: the view segment inside the atmosphere is cut into `steps`
// equal parts (default 5, as the thesis). Part i, from a to b, contributes
// Eq. 55 with the optical depth from the camera to a added to both ends:
//   T_view(a) (beta_R^s l_R,i P_R + beta_M^s l_M,i P_M) * integral_0^1 exp(-(T0 + u (T1 - T0))) du,
//   T0 = tau_light(a), T1 = tau_i + tau_light(b),
// l_*,i the part's optical lengths and tau_i its optical depth (flat
// approximation, physics/analytic_optical_depth.h), tau_light the flat light
// depth (models/flat.h). With the light depth equal at both ends this is
// Eq. 56-57's closed form S (1 - exp(-tau_i)) / sigma_t.
//
// Output: radiance per unit solar irradiance (1/sr); transmittance exp(-tau)
// of the view segment. Ground as `flat`.
//
// Valid: any camera and sun where the flat optical depth is (looking up is its
// best case); single scattering only. Deviations: those of `flat` (density at
// the tangent point in Eq. 53, smooth planet shadow, fitted shell).
#pragma once

#include "atmos/model.h"
#include "models/flat.h"

namespace atmos {

struct RaymarchedEvaluator : AnalyticEvaluator<RaymarchedEvaluator, FlatOptics> {
    int steps = 5;

    // The segment inside the atmosphere (AnalyticEvaluator::Evaluate).
    ATMOS_HD void Integrate(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                            bool want_ground, const AtmosphereSegment& seg, RayResult* out) const {
        const AnalyticMedia& m = optics.m;
        const double dt = (seg.t_end - seg.t_start) / steps;
        Vec3d tau_view;  // camera to the start of the current part
        Vec3d light_a = optics.LightDepth(camera + dir * seg.t_start, sun);
        Vec3d sum_r, sum_m;
        for (int i = 0; i < steps; ++i) {
            const double ta = seg.t_start + i * dt;
            const double tb = (i + 1 == steps) ? seg.t_end : ta + dt;
            const MediaLengths l = optics.SegmentLengths(camera, dir, ta, tb);
            const Vec3d tau_i = m.Extinction(l.rayleigh, l.mie, l.ozone);
            const Vec3d light_b = optics.LightDepth(camera + dir * tb, sun);
            const Vec3d e = LinearExpIntegral(tau_view + light_a, tau_view + tau_i + light_b);
            sum_r += e * l.rayleigh;
            sum_m += e * l.mie;
            tau_view += tau_i;
            light_a = light_b;
        }
        FinishAnalyticRay(optics, camera, dir, sun, seg, want_ground, Dot(dir, sun), sum_r, sum_m,
                          Exp(-tau_view), out);
    }
};

struct RaymarchedOptions {
    int steps = 5;  // view-ray segments
};

class RaymarchedModel : public SimpleEvaluatorModel<RaymarchedModel, RaymarchedEvaluator> {
  public:
    static const OptionTable<RaymarchedOptions>& OptionRows();
    explicit RaymarchedModel(const RaymarchedOptions& options);
    static ModelInfo StaticInfo();
    void Prepare(const AtmosphereParameters& atmosphere) override;
};

}  // namespace atmos
