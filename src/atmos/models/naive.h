// atmos model `naive`: single scattering by direct numerical integration.
//
// Source: Nishita et al. 1993, "Display of the Earth taking into account
// atmospheric scattering", as formulated by Terrell 2016 (glsl-atmosphere) and
// used by Leenman's 2025 thesis section 11.2.6 (the thesis's "naive" model, with ozone
// absorption added); equations of Leenman's 2025 thesis section 3.2 (Eq. 1, 4, 8, 9).
//
// Implements: for the part of the view ray inside the atmosphere, split into
// `steps` equal segments and sampled at their midpoints x_i,
//   L = sum_i [ beta_R rho_R(x_i) P_R(nu) + beta_M rho_M(x_i) P_M(nu) ]
//             T(camera, x_i) T_sun(x_i) ds
// with T = exp(-tau) over Rayleigh scattering, Mie extinction and ozone
// absorption (Bruneton's 2017 implementation notes' layered profiles), T(camera, x_i) from the
// optical depth accumulated along the view ray up to the midpoint, and T_sun(x_i) from
// `light_steps` midpoint samples of the light ray to the top of the atmosphere.
// A light ray that hits the ground contributes nothing (the planet's shadow).
// Phases: Rayleigh 3/(16 pi)(1+nu^2), Cornette-Shanks for Mie (one or two
// lobes: physics/phase.h MiePhase).
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
// Wide channel batches (up to 16 batches of three in one model):
// NaiveWideEvaluator below, the geometry and light rays once per ray, bit for
// bit the batches' values.
#pragma once

#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "models/evaluator_model.h"
#include "physics/density.h"
#include "physics/geometry.h"
#include "physics/phase.h"
#include "physics/single_scattering.h"
#include "physics/vector_exp.h"
#include "physics/wide.h"

namespace atmos {

struct NaiveEvaluator {
    AtmosphereParameters atm;
    int steps = 16;       // primary (view) ray samples
    int light_steps = 8;  // light ray samples

    // Optical depth (per channel) from `p` to the top of the atmosphere toward
    // the sun, by `light_steps` midpoint samples, or false if that ray hits the
    // ground. The three densities are summed over the samples, then weighted by
    // the coefficients once. The samples go in blocks of kLightLanes (a vector
    // loop: the altitude |p + t s| - R = sqrt(r^2 + t (2 r mu_s + t)) - R, the
    // densities on ExpLane, none for a profile without an exponential); the
    // last block's lanes past light_steps weigh 0.
    static constexpr int kLightLanes = 4;
    // The three profiles as LaneProfile (once per ray, not per light ray).
    struct Profiles {
        LaneProfile rayleigh, mie, ozone;
        ATMOS_HD explicit Profiles(const AtmosphereParameters& a)
            : rayleigh(a.rayleigh_density), mie(a.mie_density), ozone(a.absorption_density) {}
    };
    ATMOS_HD bool LightDepth(const Vec3d& p, const Vec3d& sun, Vec3d* tau) const {
        return LightDepth(Profiles(atm), p, sun, tau);
    }
    ATMOS_HD bool LightDepth(const Profiles& prof, const Vec3d& p, const Vec3d& sun,
                             Vec3d* tau) const {
        const double r = Length(p);
        const double mu_s = ClampCosine(Dot(p, sun) / r);
        if (RayIntersectsGround(r, mu_s, atm.bottom_radius)) return false;
        const double length = DistanceToTopAtmosphereBoundary(r, mu_s, atm.top_radius);
        const double ds = length / light_steps;
        const double r2 = r * r;
        const double b = 2.0 * r * mu_s;
        double d_r, d_m, d_o;
        if (prof.ozone.any_exp) {
            LightSums<true>(prof, r2, b, ds, &d_r, &d_m, &d_o);
        } else {
            LightSums<false>(prof, r2, b, ds, &d_r, &d_m, &d_o);
        }
        *tau = Extinction(atm, Densities{d_r * ds, d_m * ds, d_o * ds});
        return true;
    }

    // The light ray's density sums (LightDepth); kOzoneExp: whether the
    // absorption profile has an exponential term.
    template <bool kOzoneExp>
    ATMOS_HD void LightSums(const Profiles& prof, double r2, double b, double ds, double* d_r,
                            double* d_m, double* d_o) const {
        const double bottom = atm.bottom_radius;
        const int n = light_steps;
        const LaneProfile rayleigh = prof.rayleigh, mie = prof.mie, ozone = prof.ozone;
        double sum_r[kLightLanes] = {}, sum_m[kLightLanes] = {}, sum_o[kLightLanes] = {};
        // k + 0.5 per lane, as doubles (an int lane index keeps GCC at 2-lane vectors).
        const double half[kLightLanes] = {0.5, 1.5, 2.5, 3.5};
        for (int j0 = 0; j0 < n; j0 += kLightLanes) {
            const double jd = j0, nd = n;
            ATMOS_SIMD
            for (int k = 0; k < kLightLanes; ++k) {
                const double j = jd + half[k];
                const double t = j * ds;
                const double h = SafeSqrt(r2 + t * (b + t)) - bottom;
                const double w = j < nd ? 1.0 : 0.0;  // j + 0.5 < n: j < n
                sum_r[k] += w * rayleigh.Density<true>(h);
                sum_m[k] += w * mie.Density<true>(h);
                sum_o[k] += w * ozone.Density<kOzoneExp>(h);
            }
        }
        static_assert(kLightLanes == 4, "the pairwise sums below");
        *d_r = (sum_r[0] + sum_r[1]) + (sum_r[2] + sum_r[3]);
        *d_m = (sum_m[0] + sum_m[1]) + (sum_m[2] + sum_m[3]);
        *d_o = (sum_o[0] + sum_o[1]) + (sum_o[2] + sum_o[3]);
    }

    // The densities at the midpoints of view steps i0 .. i0 + kLightLanes - 1
    // (the altitude as Length(camera + dir t) - R: the same operations).
    template <bool kOzoneExp>
    ATMOS_HD void ViewDensities(const Profiles& prof, const Vec3d& camera, const Vec3d& dir,
                                double t_start, int i0, double ds, double* rho_r, double* rho_m,
                                double* rho_o) const {
        const double bottom = atm.bottom_radius;
        const LaneProfile rayleigh = prof.rayleigh, mie = prof.mie, ozone = prof.ozone;
        const double i0d = i0;
        const double half[kLightLanes] = {0.5, 1.5, 2.5, 3.5};
        ATMOS_SIMD
        for (int k = 0; k < kLightLanes; ++k) {
            const double t = t_start + (i0d + half[k]) * ds;
            const double px = camera.x + dir.x * t, py = camera.y + dir.y * t,
                         pz = camera.z + dir.z * t;
            const double h = Sqrt(px * px + py * py + pz * pz) - bottom;
            rho_r[k] = rayleigh.Density<true>(h);
            rho_m[k] = mie.Density<true>(h);
            rho_o[k] = ozone.Density<kOzoneExp>(h);
        }
    }

    // IntegrateSingleScattering (physics/single_scattering.h) with the view
    // samples in blocks of kLightLanes: their densities and then their
    // transmittances exp(-(tau_view + tau_sun)) per channel are vector loops
    // (ExpLane); the optical depths accumulate in the same order. A sample in
    // the planet's shadow gets tau = inf (transmittance 0).
    ATMOS_HD RayResult Evaluate(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                                bool want_ground) const {
        RayResult out;
        AtmosphereSegment seg;
        if (!BeginRay(camera, dir, atm.bottom_radius, atm.top_radius, &out, &seg)) {
            SingleScatteringGroundAtCamera(atm, *this, camera, sun, seg, want_ground, &out);
            return out;
        }
        constexpr int kL = kLightLanes;
        const double inf = HUGE_VAL;
        const double ds = (seg.t_end - seg.t_start) / steps;
        const Profiles prof(atm);
        Vec3d tau_view;  // camera to the start of the current step
        Vec3d sum_r, sum_m;
        for (int i0 = 0; i0 < steps; i0 += kL) {
            double rho_r[kL], rho_m[kL], rho_o[kL], tau[3][kL];
            if (prof.ozone.any_exp) {
                ViewDensities<true>(prof, camera, dir, seg.t_start, i0, ds, rho_r, rho_m, rho_o);
            } else {
                ViewDensities<false>(prof, camera, dir, seg.t_start, i0, ds, rho_r, rho_m, rho_o);
            }
            const int lanes = Min(kL, steps - i0);
            for (int k = 0; k < kL; ++k) {
                if (k >= lanes) {
                    tau[0][k] = tau[1][k] = tau[2][k] = inf;
                    continue;
                }
                const Vec3d ext = Extinction(atm, Densities{rho_r[k], rho_m[k], rho_o[k]});
                const Vec3d tau_mid = tau_view + ext * (0.5 * ds);
                tau_view += ext * ds;
                const Vec3d p = camera + dir * (seg.t_start + (i0 + k + 0.5) * ds);
                Vec3d tau_sun;
                const Vec3d total =
                    LightDepth(prof, p, sun, &tau_sun) ? tau_mid + tau_sun : Vec3d(inf);
                tau[0][k] = total.x;
                tau[1][k] = total.y;
                tau[2][k] = total.z;
            }
            double tr[3][kL];
            for (int c = 0; c < 3; ++c) {
                ATMOS_SIMD
                for (int k = 0; k < kL; ++k) tr[c][k] = ExpLane(-tau[c][k]);
            }
            for (int k = 0; k < lanes; ++k) {
                const Vec3d t(tr[0][k], tr[1][k], tr[2][k]);
                sum_r += t * (rho_r[k] * ds);
                sum_m += t * (rho_m[k] * ds);
            }
        }
        FinishSingleScattering(atm, *this, camera, dir, sun, seg, want_ground, sum_r, sum_m,
                               tau_view, &out);
        return out;
    }
};

// The wide evaluator (physics/wide.h; docs/models/naive.md "Wide channel
// batches"): NaiveEvaluator::Evaluate for every channel of a wide batch. The
// view ray's clip, sample positions, the three densities at each view sample
// and the light rays' density sums (the bulk of the work: light_steps x 3
// densities per view sample) are computed once per ray; per channel only the
// optical depths (the coefficients times those densities), their exponentials
// and the sums. Each channel's operations are the three-channel evaluator's,
// in its order (ExpLane per value, double sums): a channel equals it bit for
// bit.
struct NaiveWideEvaluator {
    NaiveEvaluator narrow;  // batch 0's atmosphere (its common fields), steps
    WideCoefficients w;

    ATMOS_HD int Channels() const { return w.channels; }

    // NaiveEvaluator::LightDepth's density sums times ds (false: in the
    // planet's shadow); tau per channel is the coefficients times these.
    ATMOS_HD bool LightDensities(const NaiveEvaluator::Profiles& prof, const Vec3d& p,
                                 const Vec3d& sun, double* d_r, double* d_m, double* d_o) const {
        const AtmosphereParameters& atm = narrow.atm;
        const double r = Length(p);
        const double mu_s = ClampCosine(Dot(p, sun) / r);
        if (RayIntersectsGround(r, mu_s, atm.bottom_radius)) return false;
        const double length = DistanceToTopAtmosphereBoundary(r, mu_s, atm.top_radius);
        const double ds = length / narrow.light_steps;
        const double r2 = r * r;
        const double b = 2.0 * r * mu_s;
        double sr, sm, so;
        if (prof.ozone.any_exp) {
            narrow.LightSums<true>(prof, r2, b, ds, &sr, &sm, &so);
        } else {
            narrow.LightSums<false>(prof, r2, b, ds, &sr, &sm, &so);
        }
        *d_r = sr * ds;
        *d_m = sm * ds;
        *d_o = so * ds;
        return true;
    }
    // Extinction (physics/density.h) of channel c at densities (r, m, o).
    ATMOS_HD double Ext(int c, double r, double m, double o) const {
        return w.rayleigh_scattering[c] * r + w.mie_extinction[c] * m +
               w.absorption_extinction[c] * o;
    }
    // The direct sun on the ground at g (FinishSingleScattering and
    // SingleScatteringGroundAtCamera), times t_view when given.
    ATMOS_HD void Ground(const NaiveEvaluator::Profiles& prof, const Vec3d& g, const Vec3d& sun,
                         const double* t_view, WideRayResult* out) const {
        const int n = w.channels;
        bool any = false;
        for (int b = 0; b < n / 3; ++b) any = any || w.BatchMaxAlbedo(b) > 0.0;
        if (!any) return;
        const double cos_sun = Dot(Normalize(g), sun);
        double d_r, d_m, d_o;
        if (!(cos_sun > 0.0 && LightDensities(prof, g, sun, &d_r, &d_m, &d_o))) return;
        for (int b = 0; b < n / 3; ++b) {
            if (!(w.BatchMaxAlbedo(b) > 0.0)) continue;
            for (int c = 3 * b; c < 3 * b + 3; ++c) {
                const double v = w.ground_albedo[c] * (cos_sun / kPi) * Exp(-Ext(c, d_r, d_m, d_o));
                out->ground[c] = static_cast<float>(t_view ? v * t_view[c] : v);
            }
        }
    }

    ATMOS_HD void EvaluateWide(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                               bool want_ground, WideRayResult* out) const {
        const AtmosphereParameters& atm = narrow.atm;
        const int n = w.channels;
        out->Reset(n);
        const NaiveEvaluator::Profiles prof(atm);
        const AtmosphereSegment seg =
            ClipToAtmosphere(camera, dir, atm.bottom_radius, atm.top_radius);
        out->hits_ground = seg.hits_ground;
        if (!seg.inside) {
            if (want_ground && GroundAtCamera(seg)) Ground(prof, camera, sun, nullptr, out);
            return;
        }
        constexpr int kL = NaiveEvaluator::kLightLanes;
        const double inf = HUGE_VAL;
        const int steps = narrow.steps;
        const double ds = (seg.t_end - seg.t_start) / steps;
        double tau_view[kMaxWideChannels], sum_r[kMaxWideChannels], sum_m[kMaxWideChannels];
        for (int c = 0; c < n; ++c) tau_view[c] = sum_r[c] = sum_m[c] = 0.0;
        for (int i0 = 0; i0 < steps; i0 += kL) {
            double rho_r[kL], rho_m[kL], rho_o[kL];
            if (prof.ozone.any_exp) {
                narrow.ViewDensities<true>(prof, camera, dir, seg.t_start, i0, ds, rho_r, rho_m,
                                           rho_o);
            } else {
                narrow.ViewDensities<false>(prof, camera, dir, seg.t_start, i0, ds, rho_r, rho_m,
                                            rho_o);
            }
            const int lanes = Min(kL, steps - i0);
            for (int k = 0; k < lanes; ++k) {
                const Vec3d p = camera + dir * (seg.t_start + (i0 + k + 0.5) * ds);
                double l_r, l_m, l_o;
                const bool lit = LightDensities(prof, p, sun, &l_r, &l_m, &l_o);
                const double wr = rho_r[k] * ds, wm = rho_m[k] * ds;
                double t[kMaxWideChannels];
                for (int c = 0; c < n; ++c) {
                    const double ext = Ext(c, rho_r[k], rho_m[k], rho_o[k]);
                    const double tau_mid = tau_view[c] + ext * (0.5 * ds);
                    tau_view[c] += ext * ds;
                    t[c] = lit ? tau_mid + Ext(c, l_r, l_m, l_o) : inf;
                }
                ATMOS_SIMD
                for (int c = 0; c < n; ++c) t[c] = ExpLane(-t[c]);
                for (int c = 0; c < n; ++c) {
                    sum_r[c] += t[c] * wr;
                    sum_m[c] += t[c] * wm;
                }
            }
        }
        double t_view[kMaxWideChannels];
        FinishWideSingleScattering(atm, w, dir, sun, sum_r, sum_m, tau_view, t_view, out);
        if (want_ground && seg.hits_ground)
            Ground(prof, camera + dir * seg.t_end, sun, t_view, out);
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

    // Wide channel batches (NaiveWideEvaluator).
    void PrepareWide(const std::vector<AtmosphereParameters>& batches,
                     const BatchPrepare& prepare_batch = {}) override;
    void RenderWide(const RenderRequest& request, std::vector<float>* values) const override;
    std::vector<float> SampleWide(const std::vector<SampleQuery>& queries) const override;

  private:
    std::vector<AtmosphereParameters> wide_batches_;  // as Prepare() clips each
    bool wide_shared_ = false;                        // the batches' shells end at the same radius
    NaiveWideEvaluator wide_;
};

}  // namespace atmos
