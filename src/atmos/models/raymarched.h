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
// Wide channel batches (up to 16 batches of three in one model):
// RaymarchedWideEvaluator below, bit for bit the batches' values.
#pragma once

#include <vector>

#include "atmos/model.h"
#include "models/flat.h"

namespace atmos {

// LinearExpIntegral (physics/analytic_media.h) along the chain of parts,
// whose exponent at a part's start, tau_view + light_a, is the previous
// part's at its end, tau_view + tau_i + light_b, as the same sum of the same
// numbers (bit for bit): exp(-b) of one part is exp(-a) of the next, one
// exponential per part instead of two, the same values.
struct ChainedExpIntegral {
    double exp_a = 0.0;  // exp(-a) of the next part, where have
    bool have = false;
    ATMOS_HD double Next(double a, double b) {
        const double ea = have ? exp_a : Exp(-a);
        const double d = b - a;
        if (Abs(d) < 1e-6) {
            have = false;
            return ea * (1.0 - 0.5 * d);
        }
        const double eb = Exp(-b);
        exp_a = eb;
        have = true;
        return (ea - eb) / d;
    }
};

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
        ChainedExpIntegral chain[3];
        for (int i = 0; i < steps; ++i) {
            const double ta = seg.t_start + i * dt;
            const double tb = (i + 1 == steps) ? seg.t_end : ta + dt;
            const MediaLengths l = optics.SegmentLengths(camera, dir, ta, tb);
            const Vec3d tau_i = m.Extinction(l.rayleigh, l.mie, l.ozone);
            const Vec3d light_b = optics.LightDepth(camera + dir * tb, sun);
            const Vec3d a = tau_view + light_a, b = tau_view + tau_i + light_b;
            const Vec3d e(chain[0].Next(a.x, b.x), chain[1].Next(a.y, b.y),
                          chain[2].Next(a.z, b.z));
            sum_r += e * l.rayleigh;
            sum_m += e * l.mie;
            tau_view += tau_i;
            light_a = light_b;
        }
        FinishAnalyticRay(optics, camera, dir, sun, seg, want_ground, Dot(dir, sun), sum_r, sum_m,
                          Exp(-tau_view), out);
    }
};

// The wide evaluator (docs/models/raymarched.md "Wide channel batches"):
// RaymarchedEvaluator::Integrate for every channel: each part's optical
// lengths, the light rays' lengths at the parts' ends and the phase
// functions once per ray; per channel the depths, LinearExpIntegral
// (ChainedExpIntegral), the sums and the transmittance, in the three-channel
// order: a channel equals it bit for bit.
struct RaymarchedWideEvaluator {
    FlatWideMedia w;
    int steps = 5;

    ATMOS_HD int Channels() const { return w.channels; }

    ATMOS_HD void EvaluateWide(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                               bool want_ground, WideRayResult* out) const {
        AtmosphereSegment seg;
        if (!w.Begin(camera, dir, sun, want_ground, out, &seg)) return;
        const FlatOptics& o = w.optics;
        const int n = w.channels;
        const double dt = (seg.t_end - seg.t_start) / steps;
        double tau_view[kMaxWideChannels], light_a[kMaxWideChannels], sum_r[kMaxWideChannels],
            sum_m[kMaxWideChannels];
        ChainedExpIntegral chain[kMaxWideChannels];
        const MediaLengths la = o.LightLengths(camera + dir * seg.t_start, sun);
        for (int c = 0; c < n; ++c) {
            tau_view[c] = sum_r[c] = sum_m[c] = 0.0;
            light_a[c] = w.Ext(c, la);
        }
        for (int i = 0; i < steps; ++i) {
            const double ta = seg.t_start + i * dt;
            const double tb = (i + 1 == steps) ? seg.t_end : ta + dt;
            const MediaLengths l = o.SegmentLengths(camera, dir, ta, tb);
            const MediaLengths lb = o.LightLengths(camera + dir * tb, sun);
            for (int c = 0; c < n; ++c) {
                const double tau_i = w.Ext(c, l);
                const double light_b = w.Ext(c, lb);
                const double e =
                    chain[c].Next(tau_view[c] + light_a[c], tau_view[c] + tau_i + light_b);
                sum_r[c] += e * l.rayleigh;
                sum_m[c] += e * l.mie;
                tau_view[c] += tau_i;
                light_a[c] = light_b;
            }
        }
        // FinishAnalyticRay.
        const double nu = Dot(dir, sun);
        const double pr = RayleighPhase(nu), pm = o.m.MiePhaseAt(nu);
        double t_view[kMaxWideChannels];
        for (int c = 0; c < n; ++c) {
            out->sky[c] = static_cast<float>(w.rayleigh_scattering[c] * sum_r[c] * pr +
                                             w.mie_scattering[c] * sum_m[c] * pm);
            t_view[c] = Exp(-tau_view[c]);
            out->transmittance[c] = static_cast<float>(t_view[c]);
        }
        if (want_ground && seg.hits_ground) {
            w.Ground(camera + dir * seg.t_end, sun, nullptr, t_view, out);
        }
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

    // Wide channel batches (RaymarchedWideEvaluator).
    void PrepareWide(const std::vector<AtmosphereParameters>& batches,
                     const BatchPrepare& prepare_batch = {}) override;
    void RenderWide(const RenderRequest& request, std::vector<float>* values) const override;
    std::vector<float> SampleWide(const std::vector<SampleQuery>& queries) const override;

  private:
    PreparedWide<RaymarchedWideEvaluator> wide_;
};

}  // namespace atmos
