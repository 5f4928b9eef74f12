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
// Shanks through Henyey-Greenstein with the weight CS/HG <= 1.5; a two-lobe
// Mie phase (mie_phase_weight2 > 0) through the mixture of the lobes'
// Henyey-Greenstein functions (lobe chosen with probability 1 - w / w, weight
// P / ((1 - w) HG(g) + w HG(g2)) <= 1.5: physics/sampling.h).
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

#include <memory>
#include <mutex>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "base/rng.h"
#include "base/texture.h"
#include "models/evaluator_model.h"
#include "physics/density.h"
#include "physics/geometry.h"
#include "physics/phase.h"
#include "physics/sampling.h"
#include "physics/transmittance.h"
#include "render/progressive.h"

namespace atmos {

// The version of what `reference` estimates, recorded in the fingerprint of
// shipped references (harness/shipped_references.h; data/references/). Bump it
// with any change that could move the expected value of an image: the
// physics (phase functions, densities, ground, sun), a table's resolution or
// quadrature (the sun column table, the order-1 table), a new bias or its
// removal. A change of variance only (sampling, majorants, MIS) keeps it; an
// option's default change is caught by the fingerprint's resolved options.
inline constexpr int kReferenceEstimatorVersion = 2;

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

// The estimators of `reference` (its `estimator` option).
enum class ReferenceEstimator : int {
    // The default: order 1 by deterministic quadrature along the view ray, the
    // Monte Carlo part (orders >= 2) from a first vertex drawn from the same
    // per-pixel table (pdf ~ sigma_s T_view), the sun's transmittance from a
    // converged table, looser continuation majorants (see HybridPath).
    kHybrid = 0,
    // Spectral tracking with a forced first collision and ratio-tracked sun
    // (the default until this round).
    kTracking = 1,
    // The thesis's estimator (seed 003 section 4), kept as a baseline.
    kThesis = 2,
};

// The optical depth of the segment origin + t dir, t in [0, length], by
// adaptive Simpson (issue 32): the segment is cut at its lowest point, each
// piece mapped by t = a + (b - a) u^2 from its low end (dense where the air
// is), 8 panels per piece to start, each halved (at most 1024 times in all,
// 30 deep) until Simpson agrees with its halves within 15 (1e-7 + 1e-5 dtau)
// and with the trapezoid in t on the same points within 1e-6 + dtau / 2 (a
// density concentrated near u = 0, where dt/du vanishes, cannot slip between
// the points). Converged on any geometry: a thin slab on a giant planet, an
// 8 km scale height in a 1e9 m shell, an optically thick layer. The
// reference's fallback where its sun table does not resolve an atmosphere,
// and its view transmittance output (`tracking`).
struct AdaptivePoint {
    double t, jac;
    Vec3d sigma;  // extinction
};

ATMOS_HD inline Vec3d AdaptiveOpticalDepth(const AtmosphereParameters& atm, const Vec3d& origin,
                                           const Vec3d& dir, double length) {
    if (!(length > 0.0)) return Vec3d(0.0);
    double cuts[3] = {0.0, length, length};
    int nc = 2;
    const double t_low = -Dot(origin, dir);
    if (t_low > 1e-9 * length && t_low < (1.0 - 1e-9) * length) {
        cuts[1] = t_low;
        nc = 3;
    }
    Vec3d tau;
    int budget = 1024;
    for (int k = 0; k + 1 < nc; ++k) {
        const double a = cuts[k], b = cuts[k + 1], span = b - a;
        const bool low_at_a = Length(origin + dir * a) <= Length(origin + dir * b);
        auto eval = [&](double u) {
            AdaptivePoint q;
            if (low_at_a) {
                q.t = a + span * u * u;
                q.jac = 2.0 * span * u;
            } else {
                q.t = b - span * (1.0 - u) * (1.0 - u);
                q.jac = 2.0 * span * (1.0 - u);
            }
            q.sigma =
                Extinction(atm, GetDensities(atm, Length(origin + dir * q.t) - atm.bottom_radius));
            return q;
        };
        struct Panel {
            double u0, u1;
            AdaptivePoint p0, p2, p4;
        };
        constexpr int kPanels = 8;
        constexpr int kStack = 32;
        for (int p = 0; p < kPanels; ++p) {
            Panel stack[kStack];
            int top = 0;
            Panel& first = stack[top++];
            first.u0 = static_cast<double>(p) / kPanels;
            first.u1 = static_cast<double>(p + 1) / kPanels;
            first.p0 = eval(first.u0);
            first.p2 = eval(0.5 * (first.u0 + first.u1));
            first.p4 = eval(first.u1);
            while (top > 0) {
                const Panel e = stack[--top];
                const double w = e.u1 - e.u0;
                const AdaptivePoint p1 = eval(e.u0 + 0.25 * w);
                const AdaptivePoint p3 = eval(e.u0 + 0.75 * w);
                const Vec3d g0 = e.p0.sigma * e.p0.jac, g1 = p1.sigma * p1.jac;
                const Vec3d g2 = e.p2.sigma * e.p2.jac, g3 = p3.sigma * p3.jac;
                const Vec3d g4 = e.p4.sigma * e.p4.jac;
                const Vec3d s1 = (g0 + g2 * 4.0 + g4) * (w / 6.0);
                const Vec3d s2 = (g0 + g1 * 4.0 + g2 * 2.0 + g3 * 4.0 + g4) * (w / 12.0);
                const double dtau = MaxComponent(s2);
                const double err = MaxComponent(Max(s2 - s1, s1 - s2));
                const Vec3d trap = ((e.p0.sigma + p1.sigma) * (p1.t - e.p0.t) +
                                    (p1.sigma + e.p2.sigma) * (e.p2.t - p1.t) +
                                    (e.p2.sigma + p3.sigma) * (p3.t - e.p2.t) +
                                    (p3.sigma + e.p4.sigma) * (e.p4.t - p3.t)) *
                                   0.5;
                const double gross = MaxComponent(Max(trap - s2, s2 - trap));
                const bool split = top + 2 <= kStack && budget > 0 &&
                                   (err > 15.0 * (1e-7 + 1e-5 * dtau) || gross > 1e-6 + 0.5 * dtau);
                if (split) {
                    --budget;
                    Panel& right = stack[top++];
                    right.u0 = e.u0 + 0.5 * w;
                    right.u1 = e.u1;
                    right.p0 = e.p2;
                    right.p2 = p3;
                    right.p4 = e.p4;
                    Panel& left = stack[top++];
                    left.u0 = e.u0;
                    left.u1 = e.u0 + 0.5 * w;
                    left.p0 = e.p0;
                    left.p2 = p1;
                    left.p4 = e.p2;
                    continue;
                }
                tau += s2;
            }
        }
    }
    return tau;
}

// The sun's transmittance from a point (r, mu_s) to space: 0 when the ray meets
// the ground (exact geometry), else exp(-tau) with tau = beta_R c_R + beta_M,ext
// c_M + beta_A c_A, the column densities c (m, density x length) bilinear in a
// table on seed 004's transmittance parameterisation (x_r = rho / H, x_mu =
// (d - d_min) / (d_max - d_min)), filled by Simpson quadrature
// (BuildSunColumnTable). The columns do not depend on wavelength: every batch of
// a spectral run shares one table (SharedSunColumnTable); bilinear interpolation
// is linear, so tau is what a table of optical depths would give. Its error
// against exact quadrature is measured and bounded by a test
// (ReferenceHybrid.SunTableMatchesQuadrature).
struct SunTransmittanceTable {
    TableView columns;  // 3 channels: Rayleigh, Mie, absorption column to the top boundary
    double bottom = 0.0, top = 0.0;
    Vec3d rayleigh, mie_extinction, absorption;  // the coefficients (1/m) per channel
    // true: the table does not resolve this atmosphere (SunTableResolves
    // failed: e.g. an 8 km scale height on a planet of radius 1e9 m, whose
    // seed 004 parameterisation puts the whole atmosphere in one texel): the
    // evaluator integrates each sun ray by AdaptiveOpticalDepth instead.
    bool direct = false;

    // The table `columns` (BuildSunColumnTable) of the atmosphere `atm`.
    void Set(const TableView& table, const AtmosphereParameters& atm) {
        columns = table;
        bottom = atm.bottom_radius;
        top = atm.top_radius;
        rayleigh = atm.rayleigh_scattering;
        mie_extinction = atm.mie_extinction;
        absorption = atm.absorption_extinction;
        direct = false;
    }

    ATMOS_HD Vec3d Lookup(double r, double mu) const {
        if (RayIntersectsGround(r, mu, bottom)) return Vec3d(0.0);
        r = Clamp(r, bottom, top);
        const double H = Sqrt(top * top - bottom * bottom);
        const double rho = SafeSqrt(r * r - bottom * bottom);
        const double d = DistanceToTopAtmosphereBoundary(r, mu, top);
        const double d_min = top - r;
        const double d_max = rho + H;
        const double x_mu = d_max > d_min ? (d - d_min) / (d_max - d_min) : 0.0;
        const double x_r = rho / H;
        const Vec4f v = columns.SampleBilinear(GetTextureCoordFromUnitRange(x_mu, columns.width),
                                               GetTextureCoordFromUnitRange(x_r, columns.height));
        return Exp(-(rayleigh * static_cast<double>(v.x) +
                     mie_extinction * static_cast<double>(v.y) +
                     absorption * static_cast<double>(v.z)));
    }
};

// Fills a table of mu_size x r_size texels of the Rayleigh, Mie and absorption
// columns (Simpson, `intervals` per ray). Depends on the radii and the density
// profiles only.
Table BuildSunColumnTable(const AtmosphereParameters& atm, int mu_size, int r_size,
                          int intervals = 512);
// BuildSunColumnTable(atm, kSunTableMuSize, kSunTableRSize, kSunTableIntervals),
// built once per geometry (radii and density profiles) in the process and shared
// (not copied): the batches of a spectral run differ in their coefficients only.
// Thread-safe; the last few geometries are kept (a table stays alive while a
// model holds it).
std::shared_ptr<const Table> SharedSunColumnTable(const AtmosphereParameters& atm);
// Optical depth from (r, mu) to the top boundary by composite Simpson with
// `intervals` (even) intervals (what the table gives at its texels).
Vec3d SunOpticalDepthQuadrature(const AtmosphereParameters& atm, double r, double mu,
                                int intervals);
// Whether `table` (the sun table of `atm`) gives the sun's transmittance
// within 1e-3 absolute and 1e-2 relative (where T > 0.01) of
// AdaptiveOpticalDepth at 64 x 64 points (altitudes dense near the ground,
// directions dense near the horizon); *worst gets the largest |dT|.
bool SunTableResolves(const SunTransmittanceTable& table, const AtmosphereParameters& atm,
                      double* worst = nullptr);

// The view ray's per-pixel table of the hybrid estimator: about this many
// intervals in all, at most kHybridMaxNodes nodes.
constexpr int kHybridViewIntervals = 96;
constexpr int kHybridMaxNodes = 128;
// The table's capacity: adaptive refinement (BuildViewTable) adds nodes where
// the initial ones do not resolve the ray, up to this many in all, halving a
// panel at most kMaxViewLevels times.
constexpr int kHybridNodeCapacity = 256;
constexpr int kMaxViewLevels = 20;
// BuildViewTable's acceptance of a panel: Simpson against its halves within
// 15 (kViewTauAbs + kViewTauRel dtau), the trapezoid within kViewGrossAbs +
// dtau / 2, at most kViewMaxStep of view or sun optical depth across it (all
// relaxed by exp(tau0 / 5) where the light is already attenuated by tau0).
constexpr double kViewTauAbs = 1e-5;
constexpr double kViewTauRel = 1e-4;
constexpr double kViewGrossAbs = 1e-4;
constexpr double kViewMaxStep = 0.5;
// The most next-event comb points per continuation segment.
constexpr int kMaxNeeComb = 8;
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
    // The estimator; kTracking with spectral = false is the thesis's. (The
    // evaluator's default stays kTracking so that an evaluator made without a
    // sun table works; the model's default is kHybrid.)
    ReferenceEstimator estimator = ReferenceEstimator::kTracking;
    // kHybrid: the sun's transmittance table and the factor (>= 1) on the
    // continuation segments' majorants.
    SunTransmittanceTable sun_table;
    double continuation_majorant_scale = 4.0;
    // kHybrid: uniform next-event points per continuation segment (0: none),
    // and the first direction's sun lobe (probability, Henyey-Greenstein g).
    int nee_comb = 0;
    double sun_lobe = 0.0;
    double sun_lobe_g = 0.8;
    // kHybrid renders: order 1 of every pixel (sky + ground, per unit
    // irradiance; width x height x 3, texel (key % width, key / width)),
    // computed once per request and reused by every pass (order1_cached),
    // which then skips the view table's sun transmittances and Simpson sums.
    TableView order1_table;
    bool order1_cached = false;

    template <typename V>
    void VisitTables(V& v) {
        v(sun_table.columns);
        v(order1_table);
    }

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
    // `travelled` (optional) accumulates the distance moved.
    ATMOS_HD Step Track(Vec3d* p, const Vec3d& dir, int* shell, Rng& rng, double scale = 1.0,
                        double* travelled = nullptr) const {
        for (int guard = 0; guard < 100000; ++guard) {
            int next;
            const double t_exit = ShellExit(*p, dir, *shell, &next);
            const double sigma_bar = scale * shells.majorant[*shell];
            const double t = sigma_bar > 0.0 ? -log(1.0 - rng.Uniform()) / sigma_bar : t_exit + 1.0;
            if (t < t_exit) {
                *p = *p + dir * t;
                if (travelled) *travelled += t;
                return Step::kCollision;
            }
            *p = *p + dir * t_exit;
            if (travelled) *travelled += t_exit;
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
    // in a homogeneous medium is exp(tau / k) - 1 (Novak et al. 2014), its
    // second moment T^2 exp(tau / k) = exp(-tau (2 - 1/k)), at a cost of
    // ~k tau_bar steps: a tight majorant (k = 1) is noisy relative to T in
    // deep shadow (tau = 14: 1e6) and still 35 % at tau = 0.3. So the
    // majorants are scaled by k chosen from tau_bar, the ray's majorant
    // optical depth (computed exactly by walking the shells):
    //   tau_bar <= 1.77: k = max(1, 20 tau_bar): relative variance <= 5 %, <= 64 steps;
    //   1.77 .. 8:       k = 64 / tau_bar:       <= e - 1, 64 steps;
    //   8 .. 32:         k = tau_bar:            <= e - 1, tau_bar^2 <= 1024 steps;
    //   > 32:            k = max(1, 1024 / tau_bar): max(1024, tau_bar) steps.
    // Beyond 32 (deep shadow: T = exp(-32) = 1.3e-14 where the majorant is
    // tight) the relative variance grows (exp(tau tau_bar / 1024) - 1) but the second moment stays
    // below exp(-tau); the cost per shadow ray is at most max(1024, tau_bar) steps, linear in the
    // optical depth (issue 18 item 9: k = tau_bar without the cap cost tau_bar^2 steps, 7.3e5 for a
    // horizontal ray near the ground of a dense layer, and a 64x36 image was projected at hours).
    // Unbiased for any k >= 1.
    ATMOS_HD static double RatioTrackingScale(double tau_bar) {
        if (tau_bar <= 1.77) return Max(1.0, 20.0 * tau_bar);
        if (tau_bar <= 8.0) return 64.0 / tau_bar;
        if (tau_bar <= 32.0) return tau_bar;
        return Max(1.0, 1024.0 / tau_bar);
    }

    // `steps` (optional) counts the tentative collisions (tests: the cost).
    ATMOS_HD Vec3d RatioTracking(Vec3d p, const Vec3d& dir, int shell, Rng& rng,
                                 int64_t* steps = nullptr) const {
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
            if (steps) ++*steps;
            const Densities d = GetDensities(atm, Length(p) - atm.bottom_radius);
            const Vec3d sigma_t = Extinction(atm, d);
            t = t * (Vec3d(1.0) - sigma_t / (k * shells.majorant[shell]));
            if (MaxComponent(t) <= 0.0) return t;
        }
        return t;
    }

    // ---- one tentative collision, shared by TracePath and HybridContinue ----
    //
    // Spectral tracking (Kutz et al. 2017): at a tentative collision of a path
    // of throughput w against the majorant sigma_bar, the events (Rayleigh,
    // Mie, null) have the masses a_e = mean_c(w_c sigma_e,c); the one chosen
    // with probability a_e / total multiplies w by sigma_e / (sigma_bar a_e /
    // total). Absorption is no event: it acts through the weights.
    struct Collision {
        Vec3d sigma_r, sigma_m, sigma_n;
        double sigma_bar, a_r, a_m, a_n, total;
    };
    enum class Event { kNull, kRayleigh, kMie };

    ATMOS_HD Collision CollisionAt(const Vec3d& p, double sigma_bar, const Vec3d& w) const {
        const Densities d = GetDensities(atm, Length(p) - atm.bottom_radius);
        Collision c;
        c.sigma_r = atm.rayleigh_scattering * d.rayleigh;
        c.sigma_m = atm.mie_scattering * d.mie;
        c.sigma_n = Vec3d(sigma_bar) - Extinction(atm, d);
        c.sigma_bar = sigma_bar;
        const double bar = 1.0 / 3.0;
        c.a_r = Dot(w, c.sigma_r) * bar;
        c.a_m = Dot(w, c.sigma_m) * bar;
        c.a_n = Max(Dot(w, c.sigma_n), 0.0) * bar;
        c.total = c.a_r + c.a_m + c.a_n;
        return c;
    }

    // sigma_R P_R(nu) + sigma_M P_M(nu): the light scattered by angle acos(nu).
    ATMOS_HD Vec3d InScatter(const Vec3d& sigma_r, const Vec3d& sigma_m, double nu) const {
        return sigma_r * RayleighPhase(nu) + sigma_m * MiePhase(atm, nu);
    }

    // Chooses the collision's event and weights w by it (c.total > 0).
    ATMOS_HD Event ChooseEvent(const Collision& c, Rng& rng, Vec3d* w) const {
        const double xi = rng.Uniform() * c.total;
        if (xi >= c.a_r + c.a_m) {
            *w = *w * c.sigma_n * (1.0 / (c.sigma_bar * (c.a_n / c.total)));
            return Event::kNull;
        }
        const bool rayleigh = xi < c.a_r;
        *w = *w * (rayleigh ? c.sigma_r : c.sigma_m) *
             (1.0 / (c.sigma_bar * ((rayleigh ? c.a_r : c.a_m) / c.total)));
        return rayleigh ? Event::kRayleigh : Event::kMie;
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
                const Collision c = CollisionAt(p, shells.majorant[shell], w);
                if (!(c.total > 0.0)) break;
                // Next-event estimation at every tentative collision, with the
                // expected value of the event choice: the light scattered here
                // toward the camera is sigma_s(x) / sigma_bar times its phase
                // (Rayleigh and Mie together) whether or not this collision is
                // then taken as real; the event chosen below only decides how
                // the path continues (its indirect light). This removes the
                // real/null and Rayleigh/Mie coin flips from the direct light.
                if (max_order == 0 || order < max_order) {
                    const Vec3d light = SunDirection(sun, rng);
                    const Vec3d scatter = InScatter(c.sigma_r, c.sigma_m, Dot(dir, light));
                    if (MaxComponent(w * scatter) > 0.0) {
                        *radiance +=
                            w * scatter * (1.0 / c.sigma_bar) * RatioTracking(p, light, shell, rng);
                    }
                }
                const Event event = ChooseEvent(c, rng, &w);
                if (event == Event::kNull) continue;  // null collision: continue straight on
                ++order;
                if (max_order > 0 && order >= max_order) break;  // its NEE is done
                dir = SamplePhaseDirection(dir, event == Event::kRayleigh, rng, &w);
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
                    radiance += w * (rayleigh ? RayleighPhase(nu) : MiePhase(atm, nu));
                }
                const Vec3d next = MakeDirection(dir, 1.0 - 2.0 * rng.Uniform(), rng.Uniform());
                const double mu = Dot(next, dir);
                w *= 4.0 * kPi * (rayleigh ? RayleighPhase(mu) : MiePhase(atm, mu));
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

    // ---- the hybrid estimator (ReferenceEstimator::kHybrid) ----
    //
    // The radiance of a view segment [0, L] is order 1 (light scattered once,
    // toward the camera, from the sun) plus orders >= 2. Order 1 is
    //   L1 = int_0^L T(t) [sigma_R(t) P_R(nu) + sigma_M(t) P_M(nu)] T_sun(x(t)) dt
    //        (+ T(L) rho/pi cos_s T_sun(x(L)) on a reflecting ground),
    // computed deterministically by composite Simpson on a per-pixel table of
    // nodes (uniform within pieces split at the planet's shadow cylinder, so
    // T_sun's jump there is a piece boundary). Orders >= 2 are one Monte Carlo
    // path per sample: its first real vertex is drawn from the same table,
    // in the volume with pdf ~ mean_c(sigma_s,c T_c) (interval by its
    // trapezoid mass, then uniform in it; the weight uses sigma_s and T at the
    // drawn point exactly: T by the table's optical depth at the interval's
    // start plus the trapezoid of sigma_t over the partial interval), or on the
    // ground (probability P_g, below); every path thus scatters for real at
    // least once, and its next-event estimates start at order 2. The path then
    // continues by spectral tracking against the shells' majorants times
    // continuation_majorant_scale (next-event estimation at every tentative
    // collision: a looser majorant means more, cheaper estimates), the sun's
    // transmittance of every estimate from sun_table.
    struct ViewNode {
        double t;
        Vec3d tau;      // view optical depth from the segment's start
        Vec3d sigma_t;  // extinction at the node
        double cdf;     // first-vertex mass of the intervals before this node
        // Build-time only: dt/du, Rayleigh and Mie densities, sun transmittance.
        double jac, rho_r, rho_m;
        Vec3d sun_t;
    };

    // A monotonic piece [a, b] of the view segment: t = a + span u^2 from its
    // low end (b - span (1 - u)^2 when the low end is b), n initial intervals.
    struct ViewPiece {
        double a, b, span;
        bool low_at_a;
        int n;
    };
    // A Simpson panel waiting to be tested: nodes j0, j0 + 1, j0 + 2 of
    // n 2^level intervals (its start is the table's last node).
    struct ViewPanel {
        int level;
        int64_t j0;
        ViewNode mid, end;
    };

    // The node u = j / denom of a piece (the sun's transmittance only with_sun).
    ATMOS_HD ViewNode MakeViewNode(const Vec3d& start, const Vec3d& dir, const Vec3d& sun,
                                   const ViewPiece& pc, int64_t j, int64_t denom,
                                   bool with_sun) const {
        const double u = static_cast<double>(j) / static_cast<double>(denom);
        double t, jac;
        if (pc.low_at_a) {
            t = pc.a + pc.span * u * u;
            jac = 2.0 * pc.span * u;
        } else {
            t = pc.b - pc.span * (1.0 - u) * (1.0 - u);
            jac = 2.0 * pc.span * (1.0 - u);
        }
        if (j == denom) t = pc.b;
        const Densities d = GetDensities(atm, Length(start + dir * t) - atm.bottom_radius);
        ViewNode node;
        node.t = t;
        node.tau = Vec3d(0.0);
        node.sigma_t = Extinction(atm, d);
        node.cdf = 0.0;
        node.jac = jac;
        node.rho_r = d.rayleigh;
        node.rho_m = d.mie;
        // The sun's transmittance just inside the piece at its ends (it
        // jumps at a shadow crossing: each piece takes its side).
        const double ts = j == 0 ? t + 1e-7 * pc.span : (j == denom ? t - 1e-7 * pc.span : t);
        node.sun_t = with_sun ? SunTransmittanceAt(start + dir * ts, sun) : Vec3d(0.0);
        return node;
    }

    ATMOS_HD Vec3d SunTransmittanceAt(const Vec3d& p, const Vec3d& sun) const {
        const double r = Length(p);
        const double mu = ClampCosine(Dot(p, sun) / r);
        if (sun_table.direct) {
            if (RayIntersectsGround(r, mu, atm.bottom_radius)) return Vec3d(0.0);
            const double rc = Min(r, atm.top_radius);
            return Exp(-AdaptiveOpticalDepth(
                atm, p * (rc / r), sun, DistanceToTopAtmosphereBoundary(rc, mu, atm.top_radius)));
        }
        return sun_table.Lookup(r, mu);
    }

    // Where p + t dir crosses the planet's shadow cylinder (radius bottom,
    // axis -sun) on its night side, for t in (0, length): up to 2, sorted.
    ATMOS_HD int ShadowCrossings(const Vec3d& p, const Vec3d& dir, const Vec3d& sun, double length,
                                 double* out) const {
        const Vec3d pp = p - sun * Dot(p, sun);
        const Vec3d dp = dir - sun * Dot(dir, sun);
        const double a = Dot(dp, dp);
        const double b = Dot(pp, dp);
        const double c = Dot(pp, pp) - atm.bottom_radius * atm.bottom_radius;
        const double disc = b * b - a * c;
        int n = 0;
        if (a <= 0.0 || disc <= 0.0) return 0;
        const double q = Sqrt(disc);
        const double roots[2] = {(-b - q) / a, (-b + q) / a};
        for (double t : roots) {
            if (t > 0.0 && t < length && Dot(p + dir * t, sun) < 0.0) out[n++] = t;
        }
        return n;
    }

    // Builds the table (returns the node count) and order 1 of the volume.
    //
    // Pieces: the segment is cut at its lowest point (the tangent point, where
    // the altitude turns) and where it crosses the planet's shadow, so that in
    // each piece the altitude is monotonic and the sun's transmittance smooth.
    // In each piece t = a + (b - a) u^2 from its low end (u uniform, n_k even
    // intervals, about kHybridViewIntervals in all by length): nodes are dense
    // where the air is. Integrals over t are Simpson's rule in u with the
    // Jacobian dt/du (the integrand times it is smooth, also at u = 0); the
    // optical depth at odd nodes by the 3-point rule h/12 (5 g0 + 8 g1 - g2).
    //
    // Adaptive panels (issue 32): each Simpson panel (two intervals) is
    // accepted only where it resolves the ray, else halved in u (depth first,
    // in the order of t, so the optical depth at a panel's start is known):
    // its optical depth must agree with the two half panels' (|S2 - S1| <= 15
    // (1e-6 + 1e-4 S2), the adaptive Simpson test: a density whose scale is
    // far below the piece's length, e.g. an 8 km scale height on a 1e9 m
    // shell, is found and resolved), and its optical depth and the change of
    // the sun's optical depth across it must stay below 0.5 (Simpson on
    // exp(-tau) is then good to ~1e-4 of the panel). Where the light is
    // already attenuated (the least attenuated channel's tau0 at the panel's
    // start) the bounds grow by exp(tau0 / 5), which equidistributes the
    // error exp(-tau0) dtau^5 over the ray: an optically thick ray (tau 277
    // in issue 32's slab) needs ~20 panels near the camera instead of
    // resolving all of it. At most kHybridNodeCapacity nodes and
    // kMaxViewLevels halvings; panels the initial placement resolves are
    // unchanged (Earth's views: the same nodes and sums as before).
    // with_order1 false: the table alone (no sun transmittances, *order1 0).
    ATMOS_HD int BuildViewTable(const Vec3d& start, const Vec3d& dir, const Vec3d& sun,
                                double length, ViewNode* nodes, Vec3d* order1,
                                bool with_order1 = true) const {
        double cuts[6];
        int nc = 0;
        cuts[nc++] = 0.0;
        const double t_low = -Dot(start, dir);
        if (t_low > 1e-6 * length && t_low < (1.0 - 1e-6) * length) cuts[nc++] = t_low;
        double crossings[2];
        const int ns = ShadowCrossings(start, dir, sun, length, crossings);
        for (int i = 0; i < ns; ++i) {
            // Insert sorted (at most 4 cuts so far).
            int j = nc++;
            while (j > 0 && cuts[j - 1] > crossings[i]) {
                cuts[j] = cuts[j - 1];
                --j;
            }
            cuts[j] = crossings[i];
        }
        cuts[nc++] = length;
        const double nu = Dot(dir, sun);
        const double p_r = RayleighPhase(nu);
        const double p_m = MiePhase(atm, nu);
        // The initial intervals per piece (about kHybridViewIntervals in all,
        // at most kHybridMaxNodes nodes); refinement may add up to the capacity.
        ViewPiece pieces[5];
        int count = 0;
        for (int k = 0; k + 1 < nc; ++k) {
            ViewPiece& pc = pieces[k];
            pc.a = cuts[k];
            pc.b = cuts[k + 1];
            pc.span = pc.b - pc.a;
            int n = static_cast<int>(kHybridViewIntervals * pc.span / length + 0.5);
            n = Max(4, n + (n & 1));
            n = Min(n, kHybridMaxNodes - 1 - count - 4 * (nc - 2 - k));
            n -= n & 1;
            pc.n = n;
            pc.low_at_a = Length(start + dir * pc.a) <= Length(start + dir * pc.b);
            count += k == 0 ? n + 1 : n;
        }
        int spare = kHybridNodeCapacity - count;  // nodes refinement may still add
        Vec3d o1;
        nodes[0] = MakeViewNode(start, dir, sun, pieces[0], 0, pieces[0].n, with_order1);
        nodes[0].tau = Vec3d(0.0);
        nodes[0].cdf = 0.0;
        count = 1;
        // Adds node `cur`'s first-vertex mass after node `prev`.
        auto mass = [&](const ViewNode& prev, ViewNode* cur) {
            const Vec3d sigma_s_prev =
                atm.rayleigh_scattering * prev.rho_r + atm.mie_scattering * prev.rho_m;
            const Vec3d sigma_s =
                atm.rayleigh_scattering * cur->rho_r + atm.mie_scattering * cur->rho_m;
            const double g0 = Dot(sigma_s_prev * Exp(-prev.tau), Vec3d(1.0 / 3.0));
            const double g1 = Dot(sigma_s * Exp(-cur->tau), Vec3d(1.0 / 3.0));
            cur->cdf = prev.cdf + 0.5 * (cur->t - prev.t) * (g0 + g1);
        };
        // Order 1's integrand at a node (times its Jacobian and weight later).
        auto source = [&](const ViewNode& node, const Vec3d& sun_t) {
            return (atm.rayleigh_scattering * (node.rho_r * p_r) +
                    atm.mie_scattering * (node.rho_m * p_m)) *
                   Exp(-node.tau) * sun_t;
        };
        for (int k = 0; k + 1 < nc; ++k) {
            const ViewPiece& pc = pieces[k];
            const double h0 = 1.0 / pc.n;
            // The piece's u = 0 node is the previous piece's last node, except
            // for its sun transmittance (the other side of a cut) and dt/du.
            double start_jac = pc.low_at_a ? 0.0 : 2.0 * (cuts[k + 1] - cuts[k]);
            Vec3d start_sun =
                k == 0 || !with_order1
                    ? nodes[0].sun_t
                    : SunTransmittanceAt(start + dir * (cuts[k] + 1e-7 * (cuts[k + 1] - cuts[k])),
                                         sun);
            double pending_h = 0.0;  // the start node's weight from the panel before it
            for (int p = 0; p < pc.n / 2; ++p) {
                ViewPanel stack[kMaxViewLevels + 2];
                int top = 0;
                stack[top].level = 0;
                stack[top].j0 = 2 * p;
                stack[top].mid = MakeViewNode(start, dir, sun, pc, 2 * p + 1, pc.n, with_order1);
                stack[top].end = MakeViewNode(start, dir, sun, pc, 2 * p + 2, pc.n, with_order1);
                ++top;
                while (top > 0) {
                    const ViewPanel e = stack[--top];
                    const int64_t denom = static_cast<int64_t>(pc.n) << e.level;
                    const double h = h0 / static_cast<double>(int64_t(1) << e.level);
                    const ViewNode& s = nodes[count - 1];
                    if (e.level < kMaxViewLevels && spare >= 2) {
                        ViewNode q1 =
                            MakeViewNode(start, dir, sun, pc, 2 * e.j0 + 1, 2 * denom, false);
                        ViewNode q3 =
                            MakeViewNode(start, dir, sun, pc, 2 * e.j0 + 3, 2 * denom, false);
                        const Vec3d g0 = s.sigma_t * start_jac, g2 = e.mid.sigma_t * e.mid.jac;
                        const Vec3d g4 = e.end.sigma_t * e.end.jac;
                        const Vec3d s1 = (g0 + g2 * 4.0 + g4) * (h / 3.0);
                        const Vec3d s2 = (g0 + q1.sigma_t * (4.0 * q1.jac) + g2 * 2.0 +
                                          q3.sigma_t * (4.0 * q3.jac) + g4) *
                                         (h / 6.0);
                        const double dtau = MaxComponent(s2);
                        const double err = MaxComponent(Max(s2 - s1, s1 - s2));
                        const double relax = exp(Min(MinComponent(s.tau), 60.0) / 5.0);
                        // The trapezoid in t on the same five points: far from
                        // Simpson's where a density concentrated near u = 0
                        // (where dt/du vanishes) slipped between the points.
                        const Vec3d trap = ((s.sigma_t + q1.sigma_t) * (q1.t - s.t) +
                                            (q1.sigma_t + e.mid.sigma_t) * (e.mid.t - q1.t) +
                                            (e.mid.sigma_t + q3.sigma_t) * (q3.t - e.mid.t) +
                                            (q3.sigma_t + e.end.sigma_t) * (e.end.t - q3.t)) *
                                           0.5;
                        const double gross = MaxComponent(Max(trap - s2, s2 - trap));
                        bool split = err > 15.0 * (kViewTauAbs + kViewTauRel * dtau) * relax ||
                                     dtau > kViewMaxStep * relax ||
                                     gross > (kViewGrossAbs + 0.5 * dtau) * relax;
                        // The sun's optical depth across the panel, from the
                        // geometry alone (so that the table is the same with
                        // or without order 1, as the order-1 cache needs):
                        // sigma_t |dr| / |mu_s| (plane-parallel; |mu_s| >= 0.05).
                        if (!split) {
                            const Vec3d xs = start + dir * s.t, xm = start + dir * e.mid.t;
                            const double dr = Abs(Length(start + dir * e.end.t) - Length(xs));
                            const double mu_s = Dot(xm, sun) / Length(xm);
                            const double sigma =
                                MaxComponent(Max(s.sigma_t, Max(e.mid.sigma_t, e.end.sigma_t)));
                            split = sigma * dr / Max(Abs(mu_s), 0.05) > kViewMaxStep * relax;
                        }
                        if (split) {
                            if (with_order1) {
                                q1.sun_t = SunTransmittanceAt(start + dir * q1.t, sun);
                                q3.sun_t = SunTransmittanceAt(start + dir * q3.t, sun);
                            }
                            spare -= 2;
                            // Right half below, left half on top (done first).
                            stack[top].level = e.level + 1;
                            stack[top].j0 = 2 * e.j0 + 2;
                            stack[top].mid = q3;
                            stack[top].end = e.end;
                            ++top;
                            stack[top].level = e.level + 1;
                            stack[top].j0 = 2 * e.j0;
                            stack[top].mid = q1;
                            stack[top].end = e.mid;
                            ++top;
                            continue;
                        }
                    }
                    // Accept the panel: its middle and end nodes.
                    ViewNode& mid = nodes[count];
                    ViewNode& end = nodes[count + 1];
                    mid = e.mid;
                    end = e.end;
                    mid.tau = s.tau + (s.sigma_t * (5.0 * start_jac) +
                                       mid.sigma_t * (8.0 * mid.jac) - end.sigma_t * end.jac) *
                                          (h / 12.0);
                    end.tau = s.tau + (s.sigma_t * start_jac + mid.sigma_t * (4.0 * mid.jac) +
                                       end.sigma_t * end.jac) *
                                          (h / 3.0);
                    // Optical depth never decreases (the 3-point rule can
                    // undershoot where the extinction rises steeply).
                    mid.tau = Max(mid.tau, s.tau);
                    end.tau = Max(end.tau, mid.tau);
                    mass(s, &mid);
                    mass(mid, &end);
                    if (with_order1) {
                        o1 += source(s, start_sun) * (start_jac * (pending_h + h) / 3.0);
                        o1 += source(mid, mid.sun_t) * (mid.jac * 4.0 * h / 3.0);
                    }
                    count += 2;
                    start_jac = end.jac;
                    start_sun = end.sun_t;
                    pending_h = h;
                }
            }
            if (with_order1) {
                const ViewNode& last = nodes[count - 1];
                o1 += source(last, last.sun_t) * (last.jac * pending_h / 3.0);
            }
        }
        *order1 = o1;
        return count;
    }

    // Continues a path from a real vertex (direction already sampled): adds
    // every next-event estimate (orders >= order + 1) to *radiance.
    //
    // Next-event estimates on each segment (from a real vertex to the ground
    // or space) come from two point sets, combined by multiple importance
    // sampling (balance heuristic): the tentative collisions of the tracking
    // (intensity sigma_bar(t), the continuation majorant; weight w, an
    // unbiased estimate of the segment's transmittance T(t)), and a comb of
    // `nee_comb` stratified uniform points over the segment's geometric length
    // d (intensity n / d), each scored with the path's weight w where the path
    // reached it (E[w 1(reached t)] = T(t): spectral tracking's transmittance
    // estimate), nothing beyond the segment's real collision. Both score
    // w sigma_s P T_sun / (sigma_bar(t) + n / d), so their sum estimates
    // int T sigma_s P T_sun dt without bias; the comb samples the thin, lit
    // air where sigma_bar is small and the collisions rare (twilight).
    ATMOS_HD void HybridContinue(Vec3d p, Vec3d dir, Vec3d w, int order, const Vec3d& sun, Rng& rng,
                                 Vec3d* radiance) const {
        int shell = shells.ShellOf(Length(p));
        const double k = continuation_majorant_scale;
        // The segment being tracked: its origin, the distance moved along it,
        // its length, the comb's intensity and points.
        Vec3d origin = p;
        double travelled = 0.0, seg_length = 0.0, comb = 0.0;
        double comb_t[kMaxNeeComb];
        int comb_n = 0, comb_next = 0;
        bool new_segment = true;
        for (int guard = 0; guard < 1000000; ++guard) {
            if (new_segment) {
                new_segment = false;
                origin = p;
                travelled = 0.0;
                comb_n = comb_next = 0;
                comb = 0.0;
                // Only where the sun is below the origin's horizon (twilight:
                // the lit air is thin and far); a choice by the segment's
                // origin alone, so both strategies stay unbiased.
                if (nee_comb > 0 && Dot(p, sun) < 0.0) {
                    const double r = Length(p);
                    const double mu = ClampCosine(Dot(p, dir) / r);
                    seg_length = RayIntersectsGround(r, mu, atm.bottom_radius)
                                     ? DistanceToBottomAtmosphereBoundary(r, mu, atm.bottom_radius)
                                     : DistanceToTopAtmosphereBoundary(r, mu, atm.top_radius);
                    if (seg_length > 0.0) {
                        comb_n = Min(nee_comb, kMaxNeeComb);
                        comb = comb_n / seg_length;
                        for (int j = 0; j < comb_n; ++j) {
                            comb_t[j] = seg_length * (j + rng.Uniform()) / comb_n;
                        }
                    }
                }
            }
            const Step step = Track(&p, dir, &shell, rng, k, &travelled);
            const bool light = max_order == 0 || order < max_order;
            // The comb's points the path has passed (all, once it leaves the segment).
            const double reached = step == Step::kCollision ? travelled : seg_length;
            for (; comb_next < comb_n && comb_t[comb_next] <= reached; ++comb_next) {
                if (light)
                    *radiance += w * CombEstimate(origin + dir * comb_t[comb_next], dir, sun, comb);
            }
            if (step == Step::kEscaped) break;
            if (step == Step::kGround) {
                ++order;
                if (max_order > 0 && order > max_order) break;
                if (MaxComponent(atm.ground_albedo) <= 0.0) break;
                const Vec3d n = Normalize(p);
                const double cos_sun = Dot(n, sun);
                if (cos_sun > 0.0) {
                    *radiance +=
                        w * atm.ground_albedo * (cos_sun / kPi) * SunTransmittanceAt(p, sun);
                }
                dir = MakeDirection(n, SampleCosineHemisphereCosine(rng.Uniform()), rng.Uniform());
                w = w * atm.ground_albedo;
                new_segment = true;
            } else {
                const Collision c = CollisionAt(p, k * shells.majorant[shell], w);
                if (!(c.total > 0.0)) break;
                // Next-event estimate with the expected value of the event
                // choice (as TracePath), MIS-weighted against the comb.
                if (light) {
                    const Vec3d scatter = InScatter(c.sigma_r, c.sigma_m, Dot(dir, sun));
                    if (MaxComponent(w * scatter) > 0.0) {
                        *radiance +=
                            w * scatter * (1.0 / (c.sigma_bar + comb)) * SunTransmittanceAt(p, sun);
                    }
                }
                const Event event = ChooseEvent(c, rng, &w);
                if (event == Event::kNull) continue;
                ++order;
                if (max_order > 0 && order >= max_order) break;
                dir = SamplePhaseDirection(dir, event == Event::kRayleigh, rng, &w);
                new_segment = true;
            }
            if (order >= 3) {
                const double q = Min(0.95, MaxComponent(w));
                if (rng.Uniform() >= q) break;
                w = w * (1.0 / q);
            }
        }
    }

    // A comb point's next-event estimate per unit throughput: sigma_s P T_sun
    // over the sum of both strategies' intensities there.
    ATMOS_HD Vec3d CombEstimate(const Vec3d& q, const Vec3d& dir, const Vec3d& sun,
                                double comb) const {
        const double r = Length(q);
        const Densities d = GetDensities(atm, r - atm.bottom_radius);
        const Vec3d scatter = InScatter(atm.rayleigh_scattering * d.rayleigh,
                                        atm.mie_scattering * d.mie, Dot(dir, sun));
        if (!(MaxComponent(scatter) > 0.0)) return Vec3d(0.0);
        const double sigma_bar = continuation_majorant_scale * shells.majorant[shells.ShellOf(r)];
        return scatter * (1.0 / (sigma_bar + comb)) * SunTransmittanceAt(q, sun);
    }

    // The first vertex's continuation direction: the phase function, or, at
    // a vertex x with the sun below its horizon (twilight), with probability
    // sun_lobe a Henyey-Greenstein lobe (sun_lobe_g) around the sun (one-
    // sample MIS, balance heuristic: w *= phase / (mixture pdf)).
    ATMOS_HD Vec3d SampleFirstDirection(const Vec3d& x, const Vec3d& dir, bool rayleigh,
                                        const Vec3d& sun, Rng& rng, Vec3d* w) const {
        if (!(sun_lobe > 0.0) || Dot(x, sun) >= 0.0) {
            return SamplePhaseDirection(dir, rayleigh, rng, w);
        }
        Vec3d next;
        if (rng.Uniform() < sun_lobe) {
            next = MakeDirection(sun, SampleHenyeyGreensteinCosine(sun_lobe_g, rng.Uniform()),
                                 rng.Uniform());
        } else {
            const double xi = rng.Uniform();
            next = MakeDirection(
                dir, rayleigh ? SampleRayleighCosine(xi) : SampleMiePhaseCosine(atm, xi),
                rng.Uniform());
        }
        const double mu = Dot(dir, next);
        const double phase = rayleigh ? RayleighPhase(mu) : MiePhase(atm, mu);
        const double p_phase = rayleigh ? phase : MiePhaseSamplingPdf(atm, mu);
        const double pdf = (1.0 - sun_lobe) * p_phase +
                           sun_lobe * HenyeyGreensteinPhase(sun_lobe_g, Dot(next, sun));
        *w = *w * (phase / pdf);
        return next;
    }

    ATMOS_HD Vec3d SamplePhaseDirection(const Vec3d& dir, bool rayleigh, Rng& rng, Vec3d* w) const {
        if (rayleigh) {
            return MakeDirection(dir, SampleRayleighCosine(rng.Uniform()), rng.Uniform());
        }
        const double mu = SampleMiePhaseCosine(atm, rng.Uniform());
        *w = *w * MiePhaseOverSamplingPdf(atm, mu);
        return MakeDirection(dir, mu, rng.Uniform());
    }

    // The hybrid estimate of one view segment from `start` (length 0 with
    // hits_ground: a camera on the ground looking down).
    ATMOS_HD void EvaluateHybrid(const Vec3d& start, const Vec3d& dir, const Vec3d& sun,
                                 double length, bool hits_ground, uint64_t key, Vec3d* sky,
                                 Vec3d* ground, Vec3d* tau_out) const {
        ViewNode nodes[kHybridNodeCapacity];
        Vec3d order1;
        int count = 1;
        if (length > 0.0) {
            count = BuildViewTable(start, dir, sun, length, nodes, &order1, !order1_cached);
        } else {
            nodes[0] = {0.0, Vec3d(0.0), Vec3d(0.0), 0.0, 0.0, 0.0, 0.0, Vec3d(0.0)};
        }
        const Vec3d tau_end = nodes[count - 1].tau;
        *tau_out = tau_end;
        const double mass = nodes[count - 1].cdf;  // int mean_c(sigma_s T) dt
        const bool reflective = hits_ground && MaxComponent(atm.ground_albedo) > 0.0;
        const Vec3d t_end = Exp(-tau_end);
        const Vec3d ground_point = start + dir * length;
        const Vec3d normal = Normalize(ground_point);
        // Order 1 (deterministic; sky and ground together when cached).
        if (order1_cached) {
            const int w = order1_table.width;
            const Vec4f o = order1_table.Fetch(static_cast<int>(key % static_cast<uint64_t>(w)),
                                               static_cast<int>(key / static_cast<uint64_t>(w)));
            *sky += Vec3d(o.x, o.y, o.z) * static_cast<double>(sample_count);
        } else {
            *sky += order1 * static_cast<double>(sample_count);
        }
        if (reflective && !order1_cached) {
            const double cos_sun = Dot(normal, sun);
            if (cos_sun > 0.0) {
                *ground += t_end * atm.ground_albedo * (cos_sun / kPi) *
                           SunTransmittanceAt(ground_point, sun) *
                           static_cast<double>(sample_count);
            }
        }
        if (max_order == 1) return;
        // The first real vertex: ground with probability p_ground, else the volume.
        const double ground_mass =
            reflective ? Dot(t_end * atm.ground_albedo, Vec3d(1.0 / 3.0)) : 0.0;
        double p_ground = 0.0;
        if (ground_mass > 0.0) {
            p_ground = mass > 0.0 ? Clamp(ground_mass / (ground_mass + mass), 0.05, 0.95) : 1.0;
        }
        if (!(mass > 0.0) && p_ground <= 0.0) return;
        for (int64_t s = 0; s < sample_count; ++s) {
            Rng rng(seed, key, static_cast<uint64_t>(sample_begin + s));
            if (rng.Uniform() < p_ground) {
                const Vec3d w = t_end * atm.ground_albedo * (1.0 / p_ground);
                const Vec3d next = MakeDirection(
                    normal, SampleCosineHemisphereCosine(rng.Uniform()), rng.Uniform());
                // A hair above the ground so the first track starts inside.
                HybridContinue(normal * (atm.bottom_radius + 1e-3), next, w, 1, sun, rng, ground);
                continue;
            }
            // Interval by its mass (binary search on the cdf), then uniform.
            const double u = rng.Uniform() * mass;
            int lo = 0, hi = count - 1;  // nodes[lo].cdf <= u < nodes[hi].cdf
            while (hi - lo > 1) {
                const int mid = (lo + hi) / 2;
                if (nodes[mid].cdf <= u) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            const ViewNode& a = nodes[lo];
            const ViewNode& b = nodes[hi];
            const double width = b.t - a.t;
            const double p_interval = (b.cdf - a.cdf) / mass;
            if (!(p_interval > 0.0) || !(width > 0.0)) continue;
            const double t = a.t + rng.Uniform() * width;
            const Vec3d x = start + dir * t;
            const Densities d = GetDensities(atm, Length(x) - atm.bottom_radius);
            const Vec3d sigma_t = Extinction(atm, d);
            const Vec3d trans = Exp(-(a.tau + (a.sigma_t + sigma_t) * (0.5 * (t - a.t))));
            const double pdf = (1.0 - p_ground) * p_interval / width;
            const Vec3d w0 = trans * (1.0 / pdf);
            const Vec3d sigma_r = atm.rayleigh_scattering * d.rayleigh;
            const Vec3d sigma_m = atm.mie_scattering * d.mie;
            const double a_r = Dot(w0, sigma_r), a_m = Dot(w0, sigma_m);
            if (!(a_r + a_m > 0.0)) continue;
            const bool rayleigh = rng.Uniform() * (a_r + a_m) < a_r;
            Vec3d w =
                w0 * (rayleigh ? sigma_r * ((a_r + a_m) / a_r) : sigma_m * ((a_r + a_m) / a_m));
            const Vec3d next = SampleFirstDirection(x, dir, rayleigh, sun, rng, &w);
            HybridContinue(x, next, w, 1, sun, rng, sky);
        }
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
    int shell_count_ = 48;
    bool sun_disc_light_ = false;
};

}  // namespace atmos
