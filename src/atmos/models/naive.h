// atmos model `naive`: single scattering by direct numerical integration.
//
// Source: Nishita et al. 1993, "Display of the Earth taking into account
// atmospheric scattering", as formulated by Terrell 2016 (glsl-atmosphere) and
// used by seed 003 section 11.2.6 (the thesis's "naive" model, with ozone
// absorption added); equations of seed 003 section 3.2 (Eq. 1, 4, 8, 9).
//
// Implements: for the part of the view ray inside the atmosphere, split into
// `steps` equal segments and sampled at their midpoints x_i,
//   L = sum_i [ beta_R rho_R(x_i) P_R(nu) + beta_M rho_M(x_i) P_M(nu) ]
//             T(camera, x_i) T_sun(x_i) ds
// with T = exp(-tau) over Rayleigh scattering, Mie extinction and ozone
// absorption (seed 004's layered profiles), T(camera, x_i) from the optical
// depth accumulated along the view ray up to the midpoint, and T_sun(x_i) from
// `light_steps` midpoint samples of the light ray to the top of the atmosphere.
// A light ray that hits the ground contributes nothing (the planet's shadow).
// Phases: Rayleigh 3/(16 pi)(1+nu^2), Cornette-Shanks for Mie.
//
// Output: radiance per unit solar irradiance (1/sr), transmittance of the
// segment. Ground (albedo a): a/pi max(0, n.s) T_sun T_view, the direct sun only
// (no sky light: a single-scattering model has none).
//
// Valid: anywhere, any sun; error shrinks with steps (tests/naive_test.cpp).
// Deviations from Terrell: the view optical depth is taken to each sample's
// midpoint (Terrell adds the whole step first), the planet's shadow is tested
// (Terrell has none), cameras in space start where the ray enters the
// atmosphere, and everything runs in double.
#pragma once

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "models/evaluator_model.h"
#include "physics/density.h"
#include "physics/geometry.h"
#include "physics/phase.h"
#include "physics/single_scattering.h"

namespace atmos {

struct NaiveEvaluator {
    AtmosphereParameters atm;
    int steps = 16;       // primary (view) ray samples
    int light_steps = 8;  // light ray samples

    // Extinction (per channel) and the Rayleigh and Mie densities at an altitude.
    ATMOS_HD Vec3d ExtinctionAt(double altitude, double* rho_r, double* rho_m) const {
        const Densities d = GetDensities(atm, altitude);
        *rho_r = d.rayleigh;
        *rho_m = d.mie;
        return Extinction(atm, d);
    }

    // Optical depth (per channel) from `p` to the top of the atmosphere toward
    // the sun, by `light_steps` midpoint samples, or false if that ray hits the
    // ground.
    ATMOS_HD bool LightDepth(const Vec3d& p, const Vec3d& sun, Vec3d* tau) const {
        const double r = Length(p);
        const double mu_s = ClampCosine(Dot(p, sun) / r);
        if (RayIntersectsGround(r, mu_s, atm.bottom_radius)) return false;
        const double length = DistanceToTopAtmosphereBoundary(r, mu_s, atm.top_radius);
        const double ds = length / light_steps;
        Vec3d sum;
        for (int j = 0; j < light_steps; ++j) {
            const Vec3d q = p + sun * ((j + 0.5) * ds);
            sum += Extinction(atm, GetDensities(atm, Length(q) - atm.bottom_radius));
        }
        *tau = sum * ds;
        return true;
    }

    ATMOS_HD RayResult Evaluate(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                                bool want_ground) const {
        return IntegrateSingleScattering(atm, *this, steps, camera, dir, sun, want_ground);
    }
};

struct NaiveOptions {
    int steps = 16;       // view-ray samples
    int light_steps = 8;  // light-ray samples
};

class NaiveModel : public SimpleEvaluatorModel<NaiveModel, NaiveEvaluator> {
  public:
    static const OptionTable<NaiveOptions>& OptionRows();
    explicit NaiveModel(const NaiveOptions& options);
    static ModelInfo StaticInfo();
    // The evaluator's shell ends at EffectiveTopRadius (atmos/atmosphere.h):
    // the uniform steps then follow the density even where the atmosphere is
    // far thicker than its scale heights (issue 18 item 3).
    void Prepare(const AtmosphereParameters& atmosphere) override {
        AtmosphereParameters clipped = atmosphere;
        clipped.top_radius = EffectiveTopRadius(atmosphere);
        SetAtmosphere(clipped);
    }
};

}  // namespace atmos
