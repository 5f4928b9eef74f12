// atmos model `reference`: the Monte Carlo path tracer every model is measured against.
//
// Source: Leenman's 2025 thesis sections 3.2, 4 and 11.2.2 (delta and ratio tracking after
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
//   extinction over its shell (per-layer critical points of Bruneton's 2017 implementation notes'
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
// Shanks through Henyey-Greenstein with the weight CS/HG <= 1.5; a two-lobe
// Mie phase (mie_phase_weight2 > 0) through the mixture of the lobes'
// Henyey-Greenstein functions (lobe chosen with probability 1 - w / w, weight
// P / ((1 - w) HG(g) + w HG(g2)) <= 1.5: physics/sampling.h).
//
// Orders: `--max-order K` counts scattering vertices (volume or ground); 0 =
// unlimited with Russian roulette from the 4th vertex. Random numbers come from
// (seed, pixel, sample index) only (base/rng.h). The transmittance output is
// deterministic: the view segment's optical depth by adaptive Simpson
// (AdaptiveOpticalDepth, reference_common.h; the hybrid estimator: its view
// table's).
//
// Output: radiance per unit solar irradiance. `sky` gathers paths whose first
// vertex is in the atmosphere, `ground` paths whose first vertex is the ground
// (DESIGN.md: `sample` reports only the former).
// Valid: everywhere (any camera, any sun). Deviations from the thesis: all
// channels per path, shell majorants, unlimited orders by default (the thesis
// used 4: `--max-order 4`), ratio tracking instead of delta tracking to the sun.
//
// Files: reference_common.h (shells, AdaptiveOpticalDepth, the sun table),
// reference_tracking.h (spectral tracking and the shared path machinery),
// reference_baseline.h (the thesis's estimator), reference_hybrid.h (the
// default estimator); this file: the evaluator that dispatches to them, and
// the model.
#pragma once

#include <stdint.h>

#include <memory>
#include <mutex>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "base/texture.h"
#include "models/evaluator_model.h"
#include "models/reference_common.h"
#include "models/reference_hero.h"
#include "models/reference_hybrid.h"
#include "render/progressive.h"

namespace atmos {

struct ReferenceEvaluator : ReferenceHybrid {
    static constexpr bool kStochastic = true;

    template <typename V>
    void VisitTables(V& v) {
        v(sun_table.columns);
        v(order1_table);
    }

    ATMOS_HD RayResult EvaluateKeyed(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                                     bool want_ground, uint64_t key) const {
        RayResult out;
        out.transmittance = Rgb(1.0f);
        AtmosphereSegment seg = ClipToAtmosphere(camera, dir, atm.bottom_radius, atm.top_radius);
        out.hits_ground = seg.hits_ground;
        // A camera on the ground looking down sees the ground at its feet: a
        // segment of length 0 that ends on the ground (issue 18 item 2; the
        // clip gives such rays an empty segment).
        const bool ground_at_camera = seg.hits_ground && !(seg.t_end > seg.t_start);
        if (ground_at_camera) {
            seg.t_start = seg.t_end = 0.0;
        } else if (!seg.inside) {
            return out;
        }
        const Vec3d start =
            ground_at_camera ? Normalize(camera) * atm.bottom_radius : camera + dir * seg.t_start;
        const double length = seg.t_end - seg.t_start;
        Vec3d sky, ground;
        if (estimator == ReferenceEstimator::kHybrid) {
            if (sample_count <= 0) {  // the transmittance alone: the same table
                if (length > 0.0) {
                    ViewNode nodes[kHybridNodeCapacity];
                    Vec3d order1;
                    const int n = BuildViewTable(start, dir, sun, length, nodes, &order1);
                    out.transmittance = Rgb(Exp(-nodes[n - 1].tau));
                }
                return out;
            }
            Vec3d tau;
            EvaluateHybrid(start, dir, sun, length, seg.hits_ground, key, &sky, &ground, &tau);
            out.transmittance = Rgb(Exp(-tau));
        } else {
            if (need_transmittance && length > 0.0) {
                out.transmittance = Rgb(Exp(-AdaptiveOpticalDepth(atm, start, dir, length)));
            }
            const int shell = seg.t_start > 0.0 ? shells.count - 1 : shells.ShellOf(Length(start));
            // Forced first collision unless the segment ends on a reflecting ground.
            const bool reflective_end = seg.hits_ground && MaxComponent(atm.ground_albedo) > 0.0;
            const double forced = reflective_end ? 0.0 : MajorantDepth(start, dir, shell, length);
            for (int64_t s = 0; s < sample_count; ++s) {
                Rng rng(seed, key, static_cast<uint64_t>(sample_begin + s));
                if (spectral) {
                    TracePath(start, dir, shell, sun, rng, forced, length, &sky, &ground);
                } else {
                    TracePathThesis(start, dir, shell, sun, rng, &sky, &ground);
                }
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
    ReferenceEstimator estimator = ReferenceEstimator::kHybrid;
    int max_order = 0;            // 0: unlimited
    int shells = 0;               // altitude shells of the majorant (0: 8 hybrid, 48 else)
    double majorant_scale = 4.0;  // hybrid: factor on the continuation majorants
    int nee_comb = 2;             // hybrid: comb points per continuation segment (twilight)
    double sun_lobe = 0.5;        // hybrid: the first direction's sun-lobe probability (twilight)
    double sun_lobe_g = 0.8;      // hybrid: its Henyey-Greenstein g
    bool hero = true;             // spectral runs: hero-wavelength paths (else batches of three)
};

// The sun's optical-depth table of the hybrid estimator: texels along x_mu and
// x_r, and the Simpson intervals per texel (error bound: reference_test.cpp).
constexpr int kSunTableMuSize = 512;
constexpr int kSunTableRSize = 256;
constexpr int kSunTableIntervals = 128;

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
    // Hero-wavelength paths (reference_hero.h): all of a spectral run's
    // wavelengths per path, in groups of at most kHeroMaxChannels.
    void SetSpectralPaths(const SpectralAtmosphere& atmosphere,
                          const std::vector<double>& nm) override;
    void RenderSpectralPaths(const RenderRequest& request,
                             std::vector<float>* values) const override;
    std::vector<float> SampleSpectralPaths(const std::vector<SampleQuery>& queries,
                                           const MonteCarloSettings& mc) const override;
    // The evaluator (its sun table built on first use after Prepare).
    const ReferenceEvaluator& evaluator() const;

  private:
    // The order-1 image of a radiance render's pixel setup (computed on its
    // first pass, a deterministic launch of max-order 1).
    // Shared: the cache and every pass using it hold it.
    std::shared_ptr<const Table> Order1Table(const PixelSetup& setup,
                                             const ReferenceEvaluator& e) const;

    ModelInfo info_;
    mutable ReferenceEvaluator evaluator_;
    mutable std::shared_ptr<const Table> sun_table_;
    mutable bool sun_table_ready_ = false;
    mutable std::mutex sun_table_mutex_;
    mutable ResidentTables resident_;  // the sun table's device copy (render/stages.h)
    // The hybrid estimator's order-1 image of the last radiance request (its
    // pixel setup's numbers as the key), reused by every pass of a render.
    mutable std::shared_ptr<const Table> order1_table_;
    mutable std::vector<double> order1_key_;
    // SetSpectralPaths' channels (empty: none); Prepare() bounds the majorants
    // over all of them.
    std::vector<HeroSpectrum> hero_groups_;
    int shell_count_ = 48;
    bool sun_disc_light_ = false;
};

}  // namespace atmos
