// atmos model `schuler`: the naive single-scattering integrator with the light
// ray's optical depth from Schuler's Chapman-function approximation.
//
// Source: Schuler 2012, "An Approximation to the Chapman Grazing-Incidence
// Function for Atmospheric Scattering" (GPU Pro 3), as Leenman's 2025 thesis section 5.1
// (Eq. 22-25) gives it and section 11.2.7 uses it.
//
// Implements: the view ray of `naive` (midpoint rule, `steps` samples, the
// view optical depth accumulated numerically to each sample's midpoint), and
// at each sample the light's optical depth to infinity
//   tau_light = beta_R H_R Ch_R + beta_M^ext H_M Ch_M   (Eq. 24-25)
// instead of the inner loop. A light ray that hits the ground contributes
// nothing (the naive integrator's planet-shadow test is kept).
//
// No ozone: the Chapman function describes exponential media only, so, as the
// thesis's version, this model has no ozone absorption anywhere (view or
// light); its sky is therefore a little brighter and less blue at sunset.
//
// Output: radiance per unit solar irradiance (1/sr); transmittance of the view
// segment (Rayleigh + Mie). Ground: a/pi max(0, n.s) T_sun T_view.
// `--chapman-unit seed|half-height`: Eq. 25 as the seed prints it (default) or
// in Schuler's own unit, the 50% height H ln 2 (physics/analytic_optical_depth.h).
// Valid: any camera and sun; error of the approximation: tests/analytic_test.cpp
// (Chapman.*) and docs/models/schuler.md.
#pragma once

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "models/evaluator_model.h"
#include "physics/analytic_media.h"
#include "physics/analytic_optical_depth.h"
#include "physics/density.h"
#include "physics/geometry.h"
#include "physics/phase.h"
#include "physics/single_scattering.h"

namespace atmos {

struct SchulerEvaluator {
    AtmosphereParameters atm;  // profiles for the view ray
    AnalyticMedia m;           // scale heights and coefficients for the light
    int steps = 16;
    double chapman_unit = kChapmanSeedUnit;  // `--chapman-unit`

    // Rayleigh + Mie extinction (no ozone) at an altitude.
    ATMOS_HD Vec3d ExtinctionAt(double altitude, double* rho_r, double* rho_m) const {
        *rho_r = GetProfileDensity(atm.rayleigh_density, altitude);
        *rho_m = GetProfileDensity(atm.mie_density, altitude);
        return atm.rayleigh_scattering * *rho_r + atm.mie_extinction * *rho_m;
    }

    // Chapman light depth (Eq. 24-25), or false if the light ray hits the ground.
    ATMOS_HD bool LightDepth(const Vec3d& p, const Vec3d& sun, Vec3d* tau) const {
        const double r = Length(p);
        const double mu_s = ClampCosine(Dot(p, sun) / r);
        if (RayIntersectsGround(r, mu_s, m.bottom)) return false;
        *tau = m.rayleigh_scattering *
                   ChapmanLengthToInfinity(r, mu_s, m.rayleigh_H, m.bottom, chapman_unit) +
               m.mie_extinction * ChapmanLengthToInfinity(r, mu_s, m.mie_H, m.bottom, chapman_unit);
        return true;
    }

    ATMOS_HD RayResult Evaluate(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                                bool want_ground) const {
        return IntegrateSingleScattering(atm, *this, steps, camera, dir, sun, want_ground);
    }
};

struct SchulerOptions {
    int steps = 16;                          // view-ray samples
    double chapman_unit = kChapmanSeedUnit;  // length unit of the Chapman approximation
};

class SchulerModel : public SimpleEvaluatorModel<SchulerModel, SchulerEvaluator> {
  public:
    static const OptionTable<SchulerOptions>& OptionRows();
    explicit SchulerModel(const SchulerOptions& options);
    static ModelInfo StaticInfo();
    void Prepare(const AtmosphereParameters& atmosphere) override;
};

}  // namespace atmos
