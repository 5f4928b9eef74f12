// atmos model `reference`: the Monte Carlo path tracer every model is measured against.
//
// Source: seed 003 sections 3.2, 4 and 11.2.2 (delta and ratio tracking after
// Fong et al. 2017 and Pharr et al. 2016, as Hillaire 2020's reference), with
// two changes that keep it unbiased and make it converge faster:
//
// * Spectral tracking (Kutz et al. 2017, "Spectral and Decomposition Tracking
//   for Rendering Heterogeneous Volumes", SIGGRAPH): one path carries all three
//   channels. Free-flight distances are sampled against a majorant sigma_bar >=
//   the extinction of every channel; at each tentative collision the event
//   (Rayleigh scattering, Mie scattering or null collision) is chosen with
//   probabilities proportional to the path-throughput-weighted channel averages
//   of sigma_R, sigma_M and sigma_n = sigma_bar - sigma_t, and the throughput of
//   channel c is multiplied by (sigma_e,c / sigma_bar) / P_e. Absorption (Mie
//   absorption, ozone) is never sampled as an event: its contribution is zero
//   (no emission), so leaving it out is unbiased and it acts through the
//   weights. Each channel's estimator is unbiased; the thesis traced one random
//   channel per path (also unbiased, three times the paths).
// * A piecewise-constant majorant over 48 spherical shells (altitudes
//   h_k = Delta (k/48)^2, fine near the ground), each the exact maximum of the
//   extinction over its shell (per-layer critical points of seed 004's
//   profiles). Tracking steps to the shell boundary and resamples there
//   (memoryless). A global majorant is the special case of one shell
//   (`--shells 1`); bench/reference_bench.cpp measures both.
// * A forced first collision on the view ray (when the segment ends in space
//   or on a black ground), its distance drawn from an equal mixture of the
//   majorant density and a uniform density over the segment (one-sample MIS):
//   thin rays (the limb, twilight) no longer waste most paths.
//
// Light: next-event estimation toward the sun at every tentative collision
// (with the expected value of the event choice, see TracePath) and at ground
// vertices, the sun's transmittance by ratio tracking (Novak et al. 2014; seed
// 003 Eq. 13) against the same majorants scaled for bounded variance, per
// channel (unbiased, and cheaper here than a deterministic integral of
// comparable accuracy, which would also carry quadrature bias); a light ray that hits the
// ground is blocked (planet shadow). The sun is directional (the other models
// treat it so too). A Lambertian ground of the atmosphere's albedo: NEE to the
// sun and a cosine-sampled bounce; albedo 0 ends the path (a black ground that
// still blocks light). Phase sampling: Rayleigh exactly (Cardano), Cornette-
// Shanks through Henyey-Greenstein with the weight CS/HG <= 1.5.
//
// Orders: `--max-order K` counts scattering vertices (volume or ground); 0 =
// unlimited with Russian roulette from the 4th vertex. Random numbers come from
// (seed, pixel, sample index) only (base/rng.h). The transmittance output is
// deterministic: the view segment's optical depth by the trapezoidal rule with
// 1024 intervals (noise-free; seed 004's transmittance uses 500).
//
// Output: radiance per unit solar irradiance. `sky` gathers paths whose first
// vertex is in the atmosphere, `ground` paths whose first vertex is the ground
// (DESIGN.md: `sample` reports only the former).
// Valid: everywhere (any camera, any sun). Deviations from the thesis: all
// channels per path, shell majorants, unlimited orders by default (the thesis
// used 4: `--max-order 4`), ratio tracking instead of delta tracking to the sun.
#pragma once

#include <stdint.h>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "base/rng.h"
#include "models/evaluator_model.h"
#include "physics/density.h"
#include "physics/geometry.h"
#include "physics/phase.h"
#include "physics/sampling.h"
#include "physics/transmittance.h"
#include "render/progressive.h"

namespace atmos {

constexpr int kMaxReferenceShells = 64;

// Shells of the piecewise-constant majorant: shell i spans radii
// [radius[i], radius[i + 1]); radius[0] = bottom, radius[count] = top.
struct MajorantShells {
    int count = 1;
    double radius[kMaxReferenceShells + 1] = {};
    double majorant[kMaxReferenceShells] = {};  // 1/m, >= every channel's extinction

    ATMOS_HD int ShellOf(double r) const {
        int i = 0;
        while (i + 1 < count && r >= radius[i + 1]) ++i;
        return i;
    }
};

// Builds `count` shells for the atmosphere (count 1: one global majorant).
MajorantShells BuildMajorantShells(const AtmosphereParameters& atm, int count);
// The exact maximum of a profile's (clamped) density over altitudes [h0, h1].
double MaxProfileDensity(const DensityProfile& profile, double h0, double h1);

struct ReferenceEvaluator {
    static constexpr bool kStochastic = true;

    AtmosphereParameters atm;
    MajorantShells shells;
    uint64_t seed = 0;
    int64_t sample_begin = 0;  // the samples [sample_begin, sample_begin + sample_count)
    int64_t sample_count = 1;
    // Whether the view ray's transmittance (1024-interval integral, ~20-40 us
    // per pixel on the CPU) is computed: only the sun's disc, the transmittance
    // output and `sample` use it; a radiance pass without the disc leaves it 1.
    bool need_transmittance = true;
    int max_order = 0;  // 0: unlimited (Russian roulette)
    // false: the thesis's estimator (seed 003 section 4: one random channel per
    // path, plain delta tracking against the shells' majorant, delta tracking
    // toward the sun, directions sampled uniformly). Kept as the baseline the
    // spectral estimator is measured against (bench, docs/models/reference.md).
    bool spectral = true;
    // 1: the sun is a point (directional light, as the other models); < 1: the
    // sun is a uniform disc of angular radius acos(sun_cone_cos), sampled
    // uniformly in its cone for each next-event estimate (the irradiance stays
    // 1, so the estimate is phase x transmittance for the sampled direction).
    double sun_cone_cos = 1.0;

    ATMOS_HD Vec3d SunDirection(const Vec3d& sun, Rng& rng) const {
        if (sun_cone_cos >= 1.0) return sun;
        const double mu = 1.0 - rng.Uniform() * (1.0 - sun_cone_cos);
        return MakeDirection(sun, mu, rng.Uniform());
    }

    enum class Step { kCollision, kGround, kEscaped };

    // Moves p along dir to the next tentative collision of the piecewise-
    // constant majorant (shell updated), or to the ground or out of the top.
    // Distance from p (in `shell`) along dir to the shell's boundary, and the
    // shell entered there (-1: the ground, shells.count: space).
    ATMOS_HD double ShellExit(const Vec3d& p, const Vec3d& dir, int shell, int* next) const {
        const double r = Length(p);
        const double mu = ClampCosine(Dot(p, dir) / r);
        const double inner = shells.radius[shell];
        if (RayIntersectsGround(r, mu, inner)) {
            *next = shell - 1;
            return DistanceToBottomAtmosphereBoundary(r, mu, inner);
        }
        *next = shell + 1;
        return DistanceToTopAtmosphereBoundary(r, mu, shells.radius[shell + 1]);
    }

    // Majorant optical depth from p along dir up to distance `length` (or the
    // ground / space, whichever comes first).
    ATMOS_HD double MajorantDepth(Vec3d p, const Vec3d& dir, int shell, double length) const {
        double tau = 0.0;
        for (int guard = 0; guard < 4 * kMaxReferenceShells + 4 && length > 0.0; ++guard) {
            int next;
            const double t = Min(ShellExit(p, dir, shell, &next), length);
            tau += shells.majorant[shell] * t;
            length -= t;
            p = p + dir * t;
            shell = next;
            if (next < 0 || next >= shells.count) break;
        }
        return tau;
    }

    // Moves p along dir to where the majorant optical depth reaches tau.
    ATMOS_HD void AdvanceMajorantDepth(Vec3d* p, const Vec3d& dir, int* shell, double tau) const {
        for (int guard = 0; guard < 4 * kMaxReferenceShells + 4; ++guard) {
            int next;
            const double t_exit = ShellExit(*p, dir, *shell, &next);
            const double sigma_bar = shells.majorant[*shell];
            if (sigma_bar > 0.0 && tau < sigma_bar * t_exit) {
                *p = *p + dir * (tau / sigma_bar);
                return;
            }
            tau -= sigma_bar * t_exit;
            *p = *p + dir * t_exit;
            if (next < 0 || next >= shells.count) return;  // rounding at the very end
            *shell = next;
        }
    }

    // `scale` (>= 1) multiplies the majorants (a looser majorant: see RatioTracking).
    ATMOS_HD Step Track(Vec3d* p, const Vec3d& dir, int* shell, Rng& rng,
                        double scale = 1.0) const {
        for (int guard = 0; guard < 100000; ++guard) {
            int next;
            const double t_exit = ShellExit(*p, dir, *shell, &next);
            const double sigma_bar = scale * shells.majorant[*shell];
            const double t = sigma_bar > 0.0 ? -log(1.0 - rng.Uniform()) / sigma_bar : t_exit + 1.0;
            if (t < t_exit) {
                *p = *p + dir * t;
                return Step::kCollision;
            }
            *p = *p + dir * t_exit;
            *shell = next;
            if (next < 0) {
                *p = Normalize(*p) * atm.bottom_radius;
                *shell = 0;
                return Step::kGround;
            }
            if (next >= shells.count) return Step::kEscaped;
        }
        return Step::kEscaped;
    }

    // Transmittance from p toward `dir` to space by ratio tracking (0 if the
    // ray meets the ground), per channel; unbiased.
    //
    // With a majorant k times the extinction, the estimate's relative variance
    // in a homogeneous medium is exp(tau / k) - 1 (Novak et al. 2014), at a
    // cost of ~k tau_bar steps: a tight majorant (k = 1) is noisy in deep shadow
    // (tau = 14: 1e6) and still 35 % at tau = 0.3. So the majorants are scaled
    // by k chosen from tau_bar, the ray's majorant optical depth (computed
    // exactly by walking the shells):
    //   tau_bar <= 1.77: k = max(1, 20 tau_bar): relative variance <= 5 %, <= 64 steps;
    //   1.77 .. 8:       k = 64 / tau_bar:        <= e - 1, 64 steps;
    //   > 8:             k = tau_bar:             <= e - 1, tau_bar^2 steps
    // (only deep-shadow rays, whose transmittance is below 3e-4, cost more).
    ATMOS_HD static double RatioTrackingScale(double tau_bar) {
        if (tau_bar <= 1.77) return Max(1.0, 20.0 * tau_bar);
        if (tau_bar <= 8.0) return 64.0 / tau_bar;
        return tau_bar;
    }

    ATMOS_HD Vec3d RatioTracking(Vec3d p, const Vec3d& dir, int shell, Rng& rng) const {
        const double r = Length(p);
        if (RayIntersectsGround(r, ClampCosine(Dot(p, dir) / r), atm.bottom_radius)) {
            return Vec3d(0.0);
        }
        const double k = RatioTrackingScale(MajorantDepth(p, dir, shell, 1e300));
        Vec3d t(1.0);
        for (int guard = 0; guard < 1000000; ++guard) {
            const Step step = Track(&p, dir, &shell, rng, k);
            if (step == Step::kEscaped) return t;
            if (step == Step::kGround) return Vec3d(0.0);
            const Densities d = GetDensities(atm, Length(p) - atm.bottom_radius);
            const Vec3d sigma_t = Extinction(atm, d);
            t = t * (Vec3d(1.0) - sigma_t / (k * shells.majorant[shell]));
            if (MaxComponent(t) <= 0.0) return t;
        }
        return t;
    }

    // One path from `origin` (inside the atmosphere or on its boundary) along
    // `dir`; adds its radiance to *sky (first vertex in the atmosphere) or
    // *ground (first vertex on the ground).
    //
    // `forced_depth` > 0 forces the first tentative collision inside the view
    // segment (forced collision: the free-flight distance is sampled
    // conditioned on colliding before the segment ends, whose majorant optical
    // depth is forced_depth, and the path is weighted by the probability of
    // that, 1 - exp(-forced_depth)). Unbiased when the segment's end
    // contributes nothing (space, or a black ground); it removes the paths
    // that cross thin segments without a collision and carry nothing.
    //
    // The forced collision's distance is drawn from an equal mixture of that
    // density (concentrated where the air is dense) and a uniform density over
    // the segment (which reaches the thin, still sunlit air at twilight and at
    // the limb), weighted by one-sample MIS with the balance heuristic: the
    // weight T_bar(t) sigma_bar(t) / q(t), q the mixture's pdf, then the usual
    // event choice.
    ATMOS_HD void TracePath(Vec3d p, Vec3d dir, int shell, const Vec3d& sun, Rng& rng,
                            double forced_depth, double forced_length, Vec3d* sky,
                            Vec3d* ground) const {
        Vec3d w(1.0);
        // Light found before the path first meets the ground is the sky's;
        // once the path has met the ground before any real volume scattering,
        // everything it gathers is light reflected by the ground.
        Vec3d sky_radiance, ground_radiance;
        Vec3d* radiance = &sky_radiance;
        int order = 0;
        const double bar = 1.0 / 3.0;
        for (int guard = 0; guard < 1000000; ++guard) {
            Step step;
            if (forced_depth > 0.0) {
                const double p_collide = -expm1(-forced_depth);
                const Vec3d start = p;
                const int start_shell = shell;
                double tau;
                if (rng.Uniform() < 0.5) {
                    tau = -log1p(-rng.Uniform() * p_collide);
                    AdvanceMajorantDepth(&p, dir, &shell, tau);
                } else {
                    const double t = rng.Uniform() * forced_length;
                    tau = MajorantDepth(start, dir, start_shell, t);
                    p = start + dir * t;
                    shell = shells.ShellOf(Length(p));
                }
                const double density = shells.majorant[shell] * exp(-tau);  // sigma_bar T_bar
                const double q = 0.5 * density / p_collide + 0.5 / forced_length;
                w = w * (density / q);
                forced_depth = 0.0;
                step = Step::kCollision;
            } else {
                step = Track(&p, dir, &shell, rng);
            }
            if (step == Step::kEscaped) break;
            if (step == Step::kGround) {
                if (order == 0) radiance = &ground_radiance;
                ++order;
                if (max_order > 0 && order > max_order) break;
                if (MaxComponent(atm.ground_albedo) <= 0.0) break;
                const Vec3d n = Normalize(p);
                const Vec3d light = SunDirection(sun, rng);
                const double cos_sun = Dot(n, light);
                if (cos_sun > 0.0) {
                    *radiance +=
                        w * atm.ground_albedo * (cos_sun / kPi) * RatioTracking(p, light, 0, rng);
                }
                dir = MakeDirection(n, SampleCosineHemisphereCosine(rng.Uniform()), rng.Uniform());
                w = w * atm.ground_albedo;
            } else {
                const Densities d = GetDensities(atm, Length(p) - atm.bottom_radius);
                const Vec3d sigma_r = atm.rayleigh_scattering * d.rayleigh;
                const Vec3d sigma_m = atm.mie_scattering * d.mie;
                const double sigma_bar = shells.majorant[shell];
                const Vec3d sigma_n = Vec3d(sigma_bar) - Extinction(atm, d);
                const double a_r = Dot(w, sigma_r) * bar;
                const double a_m = Dot(w, sigma_m) * bar;
                const double a_n = Max(Dot(w, sigma_n), 0.0) * bar;
                const double total = a_r + a_m + a_n;
                if (!(total > 0.0)) break;
                // Next-event estimation at every tentative collision, with the
                // expected value of the event choice: the light scattered here
                // toward the camera is sigma_s(x) / sigma_bar times its phase
                // (Rayleigh and Mie together) whether or not this collision is
                // then taken as real; the event chosen below only decides how
                // the path continues (its indirect light). This removes the
                // real/null and Rayleigh/Mie coin flips from the direct light.
                if (max_order == 0 || order < max_order) {
                    const Vec3d light = SunDirection(sun, rng);
                    const double nu = Dot(dir, light);
                    const Vec3d scatter = sigma_r * RayleighPhase(nu) +
                                          sigma_m * CornetteShanksPhase(atm.mie_phase_g, nu);
                    if (MaxComponent(w * scatter) > 0.0) {
                        *radiance +=
                            w * scatter * (1.0 / sigma_bar) * RatioTracking(p, light, shell, rng);
                    }
                }
                const double xi = rng.Uniform() * total;
                if (xi >= a_r + a_m) {  // null collision: continue straight on
                    w = w * sigma_n * (1.0 / (sigma_bar * (a_n / total)));
                    continue;
                }
                const bool rayleigh = xi < a_r;
                w = w * (rayleigh ? sigma_r : sigma_m) *
                    (1.0 / (sigma_bar * ((rayleigh ? a_r : a_m) / total)));
                ++order;
                if (max_order > 0 && order >= max_order) break;  // its NEE is done
                if (rayleigh) {
                    dir = MakeDirection(dir, SampleRayleighCosine(rng.Uniform()), rng.Uniform());
                } else {
                    const double mu = SampleHenyeyGreensteinCosine(atm.mie_phase_g, rng.Uniform());
                    w = w * CornetteShanksOverHenyeyGreenstein(atm.mie_phase_g, mu);
                    dir = MakeDirection(dir, mu, rng.Uniform());
                }
            }
            // Russian roulette from the 4th vertex on (unlimited orders).
            if (order >= 3) {
                const double q = Min(0.95, MaxComponent(w));
                if (rng.Uniform() >= q) break;
                w = w * (1.0 / q);
            }
        }
        *sky += sky_radiance;
        *ground += ground_radiance;
    }

    // Thesis baseline: is the sun visible from p (delta tracking in channel c)?
    ATMOS_HD bool SunVisibleDelta(Vec3d p, const Vec3d& dir, int shell, int c, Rng& rng) const {
        const double r = Length(p);
        if (RayIntersectsGround(r, ClampCosine(Dot(p, dir) / r), atm.bottom_radius)) return false;
        for (int guard = 0; guard < 1000000; ++guard) {
            const Step step = Track(&p, dir, &shell, rng);
            if (step == Step::kEscaped) return true;
            if (step == Step::kGround) return false;
            const Vec3d sigma_t = Extinction(atm, GetDensities(atm, Length(p) - atm.bottom_radius));
            if (rng.Uniform() * shells.majorant[shell] < sigma_t[c]) return false;
        }
        return false;
    }

    // Thesis baseline path (see `spectral`): adds to one random channel, times 3.
    ATMOS_HD void TracePathThesis(Vec3d p, Vec3d dir, int shell, const Vec3d& sun, Rng& rng,
                                  Vec3d* sky, Vec3d* ground) const {
        const int c = Min(static_cast<int>(rng.Uniform() * 3.0), 2);
        double w = 3.0;
        double radiance = 0.0;
        int order = 0;
        bool first_on_ground = false;
        for (int guard = 0; guard < 1000000; ++guard) {
            const Step step = Track(&p, dir, &shell, rng);
            if (step == Step::kEscaped) break;
            if (step == Step::kGround) {
                if (order == 0) first_on_ground = true;
                ++order;
                if ((max_order > 0 && order > max_order) || atm.ground_albedo[c] <= 0.0) break;
                const Vec3d n = Normalize(p);
                const double cos_sun = Dot(n, sun);
                if (cos_sun > 0.0 && SunVisibleDelta(p, sun, 0, c, rng)) {
                    radiance += w * atm.ground_albedo[c] * cos_sun / kPi;
                }
                dir = MakeDirection(n, SampleCosineHemisphereCosine(rng.Uniform()), rng.Uniform());
                w *= atm.ground_albedo[c];
            } else {
                const Densities d = GetDensities(atm, Length(p) - atm.bottom_radius);
                const double sigma_r = atm.rayleigh_scattering[c] * d.rayleigh;
                const double sigma_m = atm.mie_scattering[c] * d.mie;
                const double sigma_t = Extinction(atm, d)[c];
                const double xi = rng.Uniform() * shells.majorant[shell];
                if (xi >= sigma_t) continue;         // null collision
                if (xi >= sigma_r + sigma_m) break;  // absorbed
                const bool rayleigh = xi < sigma_r;
                ++order;
                if (max_order > 0 && order > max_order) break;
                const double nu = Dot(dir, sun);
                if (SunVisibleDelta(p, sun, shell, c, rng)) {
                    radiance += w * (rayleigh ? RayleighPhase(nu)
                                              : CornetteShanksPhase(atm.mie_phase_g, nu));
                }
                const Vec3d next = MakeDirection(dir, 1.0 - 2.0 * rng.Uniform(), rng.Uniform());
                const double mu = Dot(next, dir);
                w *= 4.0 * kPi *
                     (rayleigh ? RayleighPhase(mu) : CornetteShanksPhase(atm.mie_phase_g, mu));
                dir = next;
            }
            if (order >= 3) {
                const double q = Min(0.95, w);
                if (rng.Uniform() >= q) break;
                w /= q;
            }
        }
        Vec3d add;
        add[c] = radiance;
        if (first_on_ground) {
            *ground += add;
        } else {
            *sky += add;
        }
    }

    ATMOS_HD RayResult EvaluateKeyed(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                                     bool want_ground, uint64_t key) const {
        RayResult out;
        AtmosphereSegment seg;
        if (!BeginRay(camera, dir, atm.bottom_radius, atm.top_radius, &out, &seg)) return out;
        const Vec3d start = camera + dir * seg.t_start;
        if (need_transmittance) {
            out.transmittance =
                Rgb(Exp(-OpticalDepth(atm, start, dir, seg.t_end - seg.t_start, 1024)));
        }
        const int shell = seg.t_start > 0.0 ? shells.count - 1 : shells.ShellOf(Length(start));
        // Forced first collision unless the segment ends on a reflecting ground.
        const bool reflective_end = seg.hits_ground && MaxComponent(atm.ground_albedo) > 0.0;
        const double forced =
            reflective_end ? 0.0 : MajorantDepth(start, dir, shell, seg.t_end - seg.t_start);
        Vec3d sky, ground;
        for (int64_t s = 0; s < sample_count; ++s) {
            Rng rng(seed, key, static_cast<uint64_t>(sample_begin + s));
            if (spectral) {
                TracePath(start, dir, shell, sun, rng, forced, seg.t_end - seg.t_start, &sky,
                          &ground);
            } else {
                TracePathThesis(start, dir, shell, sun, rng, &sky, &ground);
            }
        }
        if (sample_count > 0) {
            const double inv = 1.0 / sample_count;
            out.sky = Rgb(sky * inv);
            if (want_ground) out.ground = Rgb(ground * inv);
        }
        return out;
    }
};

struct ReferenceOptions {
    int sun_disc_light = 0;  // 1: light from the sun's disc
    bool spectral = true;    // estimator: spectral (true) or the thesis's (false)
    int max_order = 0;       // 0: unlimited
    int shells = 48;         // altitude shells of the majorant
};

// The host side: one pass is the evaluator with the pass's seed and samples;
// the passes, checkpoints and variance are the progressive driver's.
class ReferenceModel : public MonteCarloModel {
  public:
    static const OptionTable<ReferenceOptions>& OptionRows();
    explicit ReferenceModel(const ReferenceOptions& options);
    static ModelInfo StaticInfo();
    const ModelInfo& Info() const override { return info_; }
    void Prepare(const AtmosphereParameters& atmosphere) override;
    void RenderPass(const RenderRequest& request, const MonteCarloPass& pass, Image* out,
                    Progress* progress) const override;
    std::vector<SampleAnswer> SamplePass(const std::vector<SampleQuery>& queries,
                                         const MonteCarloPass& pass) const override;
    std::string PassKey() const override;
    const ReferenceEvaluator& evaluator() const { return evaluator_; }

  private:
    ModelInfo info_;
    ReferenceEvaluator evaluator_;
    int shell_count_ = 48;
    bool sun_disc_light_ = false;
};

}  // namespace atmos
