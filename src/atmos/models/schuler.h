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
// Wide channel batches (up to 16 batches of three in one model):
// SchulerWideEvaluator below, bit for bit the batches' values.
#pragma once

#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "models/evaluator_model.h"
#include "models/lane_loops.h"
#include "physics/analytic_media.h"
#include "physics/analytic_optical_depth.h"
#include "physics/density.h"
#include "physics/geometry.h"
#include "physics/phase.h"
#include "physics/single_scattering.h"
#include "physics/wide.h"

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

    // The Chapman optical lengths (Eq. 24-25) of Rayleigh and Mie to the sun,
    // or false if the light ray hits the ground.
    ATMOS_HD bool LightLengths(const Vec3d& p, const Vec3d& sun, double* l_r, double* l_m) const {
        const double r = Length(p);
        const double mu_s = ClampCosine(Dot(p, sun) / r);
        if (RayIntersectsGround(r, mu_s, m.bottom)) return false;
        *l_r = ChapmanLengthToInfinity(r, mu_s, m.rayleigh_H, m.bottom, chapman_unit);
        *l_m = ChapmanLengthToInfinity(r, mu_s, m.mie_H, m.bottom, chapman_unit);
        return true;
    }
    // Chapman light depth (Eq. 24-25), or false if the light ray hits the ground.
    ATMOS_HD bool LightDepth(const Vec3d& p, const Vec3d& sun, Vec3d* tau) const {
        double l_r, l_m;
        if (!LightLengths(p, sun, &l_r, &l_m)) return false;
        *tau = m.rayleigh_scattering * l_r + m.mie_extinction * l_m;
        return true;
    }

    // IntegrateSingleScattering (physics/single_scattering.h) with the
    // attenuations exp(-(tau_mid + tau_sun)) of kLanes samples at a time as one
    // vector loop (ExpNegLanes, ExpLane: within 1 ulp of glibc's exp, which
    // the loop used before); the depths and the sums in its order.
    static constexpr int kLanes = 8;
    ATMOS_HD RayResult Evaluate(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                                bool want_ground) const {
        RayResult out;
        AtmosphereSegment seg;
        if (!BeginRay(camera, dir, atm.bottom_radius, atm.top_radius, &out, &seg)) {
            SingleScatteringGroundAtCamera(atm, *this, camera, sun, seg, want_ground, &out);
            return out;
        }
        const double ds = (seg.t_end - seg.t_start) / steps;
        Vec3d tau_view;  // camera to the start of the current step
        Vec3d sum_r, sum_m;
        for (int i0 = 0; i0 < steps; i0 += kLanes) {
            const int lanes = Min(kLanes, steps - i0);
            double tau[3 * kLanes], w_r[kLanes], w_m[kLanes];
            bool lit[kLanes];
            for (int k = 0; k < lanes; ++k) {
                const Vec3d p = camera + dir * (seg.t_start + (i0 + k + 0.5) * ds);
                double rho_r, rho_m;
                const Vec3d ext = ExtinctionAt(Length(p) - atm.bottom_radius, &rho_r, &rho_m);
                const Vec3d tau_mid = tau_view + ext * (0.5 * ds);
                tau_view += ext * ds;
                Vec3d tau_sun;
                lit[k] = LightDepth(p, sun, &tau_sun);
                const Vec3d t = lit[k] ? tau_mid + tau_sun : Vec3d(0.0);
                tau[3 * k] = t.x;
                tau[3 * k + 1] = t.y;
                tau[3 * k + 2] = t.z;
                w_r[k] = rho_r * ds;
                w_m[k] = rho_m * ds;
            }
            ExpNegLanes(tau, 3 * lanes);
            for (int k = 0; k < lanes; ++k) {
                if (!lit[k]) continue;
                const Vec3d t(tau[3 * k], tau[3 * k + 1], tau[3 * k + 2]);
                sum_r += t * w_r[k];
                sum_m += t * w_m[k];
            }
        }
        FinishSingleScattering(atm, *this, camera, dir, sun, seg, want_ground, sum_r, sum_m,
                               tau_view, &out);
        return out;
    }
};

// The wide evaluator (physics/wide.h; docs/models/schuler.md "Wide channel
// batches"): SchulerEvaluator::Evaluate (IntegrateSingleScattering) for
// every channel of a wide batch. The clip, each view sample's position and
// densities, its planet-shadow test and Chapman lengths (two square roots
// and two to four exponentials per sample), the phase functions and the
// ground's light lengths once per ray; per channel the extinction, the view
// optical depth, the attenuation (ExpNegLanes, a vector loop over the
// channels, as the three-channel loop's) and the sums, in the three-channel
// order: a channel equals it bit for bit.
struct SchulerWideEvaluator {
    SchulerEvaluator narrow;  // batch 0's atmosphere and media (the common fields), steps
    WideCoefficients w;       // the batches' AtmosphereParameters coefficients
    // Each batch's AnalyticMedia coefficients (the light's), channel 3b + c.
    double light_rayleigh[kMaxWideChannels] = {};
    double light_mie[kMaxWideChannels] = {};

    ATMOS_HD int Channels() const { return w.channels; }

    // The lit ground at g for every channel whose batch has an albedo, times
    // t_view when given (SingleScatteringGroundAtCamera, FinishSingleScattering).
    ATMOS_HD void Ground(const Vec3d& g, const Vec3d& sun, const double* t_view,
                         WideRayResult* out) const {
        const int n = w.channels;
        bool any = false;
        for (int b = 0; b < n / 3; ++b) any = any || w.BatchMaxAlbedo(b) > 0.0;
        if (!any) return;
        const double cos_sun = Dot(Normalize(g), sun);
        double l_r, l_m;
        if (!(cos_sun > 0.0 && narrow.LightLengths(g, sun, &l_r, &l_m))) return;
        for (int b = 0; b < n / 3; ++b) {
            if (!(w.BatchMaxAlbedo(b) > 0.0)) continue;
            for (int c = 3 * b; c < 3 * b + 3; ++c) {
                const double v = w.ground_albedo[c] * (cos_sun / kPi) *
                                 Exp(-(light_rayleigh[c] * l_r + light_mie[c] * l_m));
                out->ground[c] = static_cast<float>(t_view ? v * t_view[c] : v);
            }
        }
    }

    ATMOS_HD void EvaluateWide(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                               bool want_ground, WideRayResult* out) const {
        const AtmosphereParameters& atm = narrow.atm;
        const int n = w.channels;
        out->Reset(n);
        const AtmosphereSegment seg =
            ClipToAtmosphere(camera, dir, atm.bottom_radius, atm.top_radius);
        out->hits_ground = seg.hits_ground;
        if (!seg.inside) {
            if (want_ground && GroundAtCamera(seg)) Ground(camera, sun, nullptr, out);
            return;
        }
        const int steps = narrow.steps;
        const double ds = (seg.t_end - seg.t_start) / steps;
        double tau_view[kMaxWideChannels], sum_r[kMaxWideChannels], sum_m[kMaxWideChannels];
        for (int c = 0; c < n; ++c) tau_view[c] = sum_r[c] = sum_m[c] = 0.0;
        for (int i = 0; i < steps; ++i) {
            const Vec3d p = camera + dir * (seg.t_start + (i + 0.5) * ds);
            const double h = Length(p) - atm.bottom_radius;
            const double rho_r = GetProfileDensity(atm.rayleigh_density, h);
            const double rho_m = GetProfileDensity(atm.mie_density, h);
            double l_r = 0.0, l_m = 0.0;  // unused where unlit
            const bool lit = narrow.LightLengths(p, sun, &l_r, &l_m);
            const double wr = rho_r * ds, wm = rho_m * ds;
            double t[kMaxWideChannels];
            for (int c = 0; c < n; ++c) {
                const double ext = w.rayleigh_scattering[c] * rho_r + w.mie_extinction[c] * rho_m;
                const double tau_mid = tau_view[c] + ext * (0.5 * ds);
                tau_view[c] += ext * ds;
                t[c] = tau_mid + (light_rayleigh[c] * l_r + light_mie[c] * l_m);
            }
            if (!lit) continue;
            ExpNegLanes(t, n);
            for (int c = 0; c < n; ++c) {
                sum_r[c] += t[c] * wr;
                sum_m[c] += t[c] * wm;
            }
        }
        double t_view[kMaxWideChannels];
        FinishWideSingleScattering(atm, w, dir, sun, sum_r, sum_m, tau_view, t_view, out);
        if (want_ground && seg.hits_ground) Ground(camera + dir * seg.t_end, sun, t_view, out);
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

    // Wide channel batches (SchulerWideEvaluator).
    void PrepareWide(const std::vector<AtmosphereParameters>& batches,
                     const BatchPrepare& prepare_batch = {}) override;
    void RenderWide(const RenderRequest& request, std::vector<float>* values) const override;
    std::vector<float> SampleWide(const std::vector<SampleQuery>& queries) const override;

  private:
    PreparedWide<SchulerWideEvaluator> wide_;
};

}  // namespace atmos
