// The reference's hero-wavelength paths (`spectral=hero`, the default for
// spectral runs): one path carries up to kHeroMaxChannels wavelengths.
//
// Source: Wilkie, Nawaz, Droske, Weidlich and Hanika, "Hero Wavelength
// Spectral Sampling", EGSR 2014: a path is sampled for one (hero) wavelength
// and carries C others, each wavelength's contribution weighted by the
// one-sample balance heuristic over the C wavelengths' path pdfs,
// f_i(x) / ((1/C) sum_j p_j(x)), i.e. the path is drawn from the mixture of the
// C wavelengths' sampling densities. In the null-collision formulation
// (Miller, Georgiev and Jarosz 2019) with one majorant for all wavelengths,
// the distances and directions do not depend on the wavelength and p_j is the
// product over the tentative collisions of the event probabilities
// sigma_e,j / sigma_bar; drawing the hero at the start and then each event with
// the hero's probabilities, the next event has the marginal probability
// sum_j p_j(history) sigma_e,j / (sigma_bar sum_j p_j(history)), the
// throughput-weighted average of spectral tracking (Kutz et al. 2017), and the
// weight w_i = C prod sigma_e,i / sum_j prod sigma_e,j is the throughput that
// spectral tracking carries (by induction: the sum of the weights is C after
// every event). So the hero's choice is integrated out (Rao-Blackwellised):
// the continuations here are the hybrid estimator's (HybridContinue) with the
// throughput, the event choice and the next-event estimates over all C
// wavelengths, against majorants that bound every one of them.
//
// Orders: order 1 is the hybrid estimator's deterministic quadrature, run per
// group of three channels (channels 3g..3g+2 with the coefficients of those
// wavelengths: the same numbers as the batch of those three). The first
// vertex of orders >= 2 is drawn from one view table built for `atm` (the
// atmosphere at three of the wavelengths, spread over the range: the pdf is
// the mixture of those three's sigma_s T), its weight for every channel from
// the table's column densities (Rayleigh, Mie, absorption: optical depth is
// linear in them, tau_c = beta_c . column), so that each channel's estimate is
// unbiased whatever the three.
//
// Output: the sums over the samples of sky and ground radiance per unit
// irradiance for each channel (the caller divides by the count).
#pragma once

#include <stdint.h>

#include <vector>

#include "models/reference_hybrid.h"
#include "physics/vector_exp.h"

namespace atmos {

// The most wavelengths one path carries (more: several groups of paths).
constexpr int kHeroMaxChannels = 64;

// The per-wavelength coefficients of a hero path's channels (1/m at density 1;
// albedo of the ground).
struct HeroSpectrum {
    int count = 0;
    double rayleigh[kHeroMaxChannels] = {};
    double mie_scattering[kHeroMaxChannels] = {};
    double mie_extinction[kHeroMaxChannels] = {};
    double absorption[kHeroMaxChannels] = {};
    double albedo[kHeroMaxChannels] = {};
    // The largest of each coefficient over the channels (the direct sun
    // integral's scale: its tolerances are in optical depth).
    Vec3d column_scale;
};

// BuildMajorantShells (reference_common.h) whose majorants also bound every
// channel of `extra` (the hero paths' wavelengths).
MajorantShells BuildMajorantShells(const AtmosphereParameters& atm, int count,
                                   const std::vector<HeroSpectrum>& extra);

// The rate of the column densities (Rayleigh, Mie, absorption) scaled by
// `scale` (AdaptiveIntegral's integrand for the direct sun).
struct ScaledColumnRate {
    Vec3d scale;
    ATMOS_HD Vec3d operator()(const Densities& d) const {
        return Vec3d(d.rayleigh * scale.x, d.mie * scale.y, d.absorption * scale.z);
    }
};

struct ReferenceHero : ReferenceHybrid {
    HeroSpectrum spec;

    ATMOS_HD double Tau(const Vec3d& column, int c) const {
        return spec.rayleigh[c] * column.x + spec.mie_extinction[c] * column.y +
               spec.absorption[c] * column.z;
    }

    // The columns from p to the sun (false: the ground blocks it).
    ATMOS_HD bool SunColumnsAt(const Vec3d& p, const Vec3d& sun, Vec3d* column) const {
        const double r = Length(p);
        const double mu = ClampCosine(Dot(p, sun) / r);
        if (sun_table.direct) {
            if (RayIntersectsGround(r, mu, atm.bottom_radius)) return false;
            const double rc = Min(r, atm.top_radius);
            const Vec3d s = spec.column_scale;
            const Vec3d scaled = AdaptiveIntegral(
                atm, p * (rc / r), sun, DistanceToTopAtmosphereBoundary(rc, mu, atm.top_radius),
                ScaledColumnRate{s});
            *column = Vec3d(s.x > 0.0 ? scaled.x / s.x : 0.0, s.y > 0.0 ? scaled.y / s.y : 0.0,
                            s.z > 0.0 ? scaled.z / s.z : 0.0);
            return true;
        }
        return sun_table.Columns(r, mu, column);
    }

    // Adds weight[c] * scatter_c * sun_c * factor to out[c], where scatter_c =
    // sigma_R,c P_R(nu) + sigma_M,c P_M(nu) at densities d.
    ATMOS_HD void AddInScatter(const Vec3d& p, const Densities& d, double nu, const Vec3d& sun,
                               const double* weight, double factor, double* out) const {
        const double pr = d.rayleigh * RayleighPhase(nu);
        const double pm = d.mie * MiePhase(atm, nu);
        if (!(pr + pm > 0.0)) return;
        Vec3d column;
        if (!SunColumnsAt(p, sun, &column)) return;
        // Every channel (a zero weight adds zero): a loop that vectorises
        // (ExpLane: physics/vector_exp.h).
        ATMOS_SIMD
        for (int c = 0; c < spec.count; ++c) {
            const double scatter = spec.rayleigh[c] * pr + spec.mie_scattering[c] * pm;
            out[c] += weight[c] * scatter * factor * ExpLane(-Tau(column, c));
        }
    }

    // HybridContinue with the throughput w[0..count) of every channel (see
    // there and the file's comment): the same geometry, random numbers per
    // decision and next-event estimates, the event chosen by the
    // throughput-weighted sums over the channels.
    ATMOS_HD void HeroContinue(Vec3d p, Vec3d dir, double* w, int order, const Vec3d& sun, Rng& rng,
                               double* radiance) const {
        const int n = spec.count;
        int shell = shells.ShellOf(Length(p));
        const double k = continuation_majorant_scale;
        CombSegment seg;
        bool new_segment = true;
        for (int guard = 0; guard < 1000000; ++guard) {
            if (new_segment) {
                new_segment = false;
                BeginCombSegment(p, dir, sun, rng, &seg);
            }
            const Step step = Track(&p, dir, &shell, rng, k, &seg.travelled);
            const bool light = max_order == 0 || order < max_order;
            const double reached = step == Step::kCollision ? seg.travelled : seg.length;
            for (; seg.next < seg.n && seg.t[seg.next] <= reached; ++seg.next) {
                if (!light) continue;
                const Vec3d q = seg.origin + dir * seg.t[seg.next];
                const double r = Length(q);
                const Densities d = GetDensities(atm, r - atm.bottom_radius);
                const double sigma_bar =
                    continuation_majorant_scale * shells.majorant[shells.ShellOf(r)];
                AddInScatter(q, d, Dot(dir, sun), sun, w, 1.0 / (sigma_bar + seg.intensity),
                             radiance);
            }
            if (step == Step::kEscaped) break;
            double max_w = 0.0;
            if (step == Step::kGround) {
                ++order;
                if (max_order > 0 && order > max_order) break;
                double max_albedo = 0.0;
                for (int c = 0; c < n; ++c) max_albedo = Max(max_albedo, spec.albedo[c]);
                if (max_albedo <= 0.0) break;
                const Vec3d normal = Normalize(p);
                const double cos_sun = Dot(normal, sun);
                Vec3d column;
                if (cos_sun > 0.0 && SunColumnsAt(p, sun, &column)) {
                    for (int c = 0; c < n; ++c) {
                        radiance[c] +=
                            w[c] * spec.albedo[c] * (cos_sun / kPi) * ExpLane(-Tau(column, c));
                    }
                }
                dir = MakeDirection(normal, SampleCosineHemisphereCosine(rng.Uniform()),
                                    rng.Uniform());
                for (int c = 0; c < n; ++c) {
                    w[c] *= spec.albedo[c];
                    max_w = Max(max_w, w[c]);
                }
                new_segment = true;
            } else {
                const double sigma_bar = k * shells.majorant[shell];
                const Densities d = GetDensities(atm, Length(p) - atm.bottom_radius);
                double a_r = 0.0, a_m = 0.0, a_n = 0.0;
                for (int c = 0; c < n; ++c) {
                    const double sigma_t = spec.rayleigh[c] * d.rayleigh +
                                           spec.mie_extinction[c] * d.mie +
                                           spec.absorption[c] * d.absorption;
                    a_r += w[c] * spec.rayleigh[c] * d.rayleigh;
                    a_m += w[c] * spec.mie_scattering[c] * d.mie;
                    a_n += w[c] * (sigma_bar - sigma_t);
                }
                a_n = Max(a_n, 0.0);
                const double total = a_r + a_m + a_n;
                if (!(total > 0.0)) break;
                if (light) {
                    AddInScatter(p, d, Dot(dir, sun), sun, w, 1.0 / (sigma_bar + seg.intensity),
                                 radiance);
                }
                // The event by the throughput-weighted sums (ChooseEvent).
                const double xi = rng.Uniform() * total;
                if (xi >= a_r + a_m) {
                    const double f = 1.0 / (sigma_bar * (a_n / total));
                    for (int c = 0; c < n; ++c) {
                        const double sigma_t = spec.rayleigh[c] * d.rayleigh +
                                               spec.mie_extinction[c] * d.mie +
                                               spec.absorption[c] * d.absorption;
                        w[c] *= (sigma_bar - sigma_t) * f;
                    }
                    continue;
                }
                const bool rayleigh = xi < a_r;
                const double f = 1.0 / (sigma_bar * ((rayleigh ? a_r : a_m) / total));
                for (int c = 0; c < n; ++c) {
                    w[c] *= (rayleigh ? spec.rayleigh[c] * d.rayleigh
                                      : spec.mie_scattering[c] * d.mie) *
                            f;
                }
                ++order;
                if (max_order > 0 && order >= max_order) break;
                Vec3d factor(1.0);
                dir = SamplePhaseDirection(dir, rayleigh, rng, &factor);
                for (int c = 0; c < n; ++c) {
                    w[c] *= factor.x;
                    max_w = Max(max_w, w[c]);
                }
                new_segment = true;
            }
            if (order >= 3) {
                const double q = RouletteSurvival(order, max_w);
                if (rng.Uniform() >= q) break;
                for (int c = 0; c < n; ++c) w[c] *= 1.0 / q;
            }
        }
    }

    // The hero estimate of one pixel or query: sky[c] and ground[c] get the
    // sums over samples [sample_begin, sample_begin + sample_count) for the
    // spec.count channels (zeroed first). `want_ground` false: the ground's
    // part is not computed (sample queries that exclude it).
    ATMOS_HD void EvaluateHero(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                               bool want_ground, uint64_t key, double* sky, double* ground) const {
        const int n = spec.count;
        for (int c = 0; c < n; ++c) sky[c] = ground[c] = 0.0;
        AtmosphereSegment seg = ClipToAtmosphere(camera, dir, atm.bottom_radius, atm.top_radius);
        const bool ground_at_camera = seg.hits_ground && !(seg.t_end > seg.t_start);
        if (ground_at_camera) {
            seg.t_start = seg.t_end = 0.0;
        } else if (!seg.inside) {
            return;
        }
        if (sample_count <= 0) return;
        const Vec3d start =
            ground_at_camera ? Normalize(camera) * atm.bottom_radius : camera + dir * seg.t_start;
        const double length = seg.t_end - seg.t_start;
        // Order 1 per group of three channels: the hybrid estimator's.
        for (int g = 0; g < n; g += 3) {
            ReferenceHybrid group = *this;
            for (int i = 0; i < 3; ++i) {
                const int c = Min(g + i, n - 1);
                group.atm.rayleigh_scattering[i] = spec.rayleigh[c];
                group.atm.mie_scattering[i] = spec.mie_scattering[c];
                group.atm.mie_extinction[i] = spec.mie_extinction[c];
                group.atm.absorption_extinction[i] = spec.absorption[c];
                group.atm.ground_albedo[i] = spec.albedo[c];
            }
            group.sun_table.rayleigh = group.atm.rayleigh_scattering;
            group.sun_table.mie_extinction = group.atm.mie_extinction;
            group.sun_table.absorption = group.atm.absorption_extinction;
            group.max_order = 1;
            group.order1_cached = false;
            Vec3d s3, g3, tau;
            group.EvaluateHybrid(start, dir, sun, length, seg.hits_ground, key, &s3, &g3, &tau);
            for (int i = 0; i < 3 && g + i < n; ++i) {
                sky[g + i] += s3[i];
                if (want_ground) ground[g + i] += g3[i];
            }
        }
        if (max_order == 1) return;
        // Orders >= 2: the first vertex from the table of `atm` (EvaluateHybrid).
        ViewNode nodes[kHybridNodeCapacity];
        int count = 1;
        if (length > 0.0) {
            Vec3d unused;
            count = BuildViewTable(start, dir, sun, length, nodes, &unused, false);
        } else {
            nodes[0] = ViewNode();
        }
        const Vec3d column_end = nodes[count - 1].column;
        const double mass = nodes[count - 1].cdf;
        double max_albedo = 0.0;
        for (int c = 0; c < n; ++c) max_albedo = Max(max_albedo, spec.albedo[c]);
        const bool reflective = seg.hits_ground && max_albedo > 0.0;
        const Vec3d normal = Normalize(start + dir * length);
        double t_end[kHeroMaxChannels];
        double ground_mass = 0.0;
        for (int c = 0; c < n; ++c) {
            t_end[c] = ExpLane(-Tau(column_end, c));
            ground_mass += t_end[c] * spec.albedo[c];
        }
        ground_mass = reflective ? ground_mass / n : 0.0;
        double p_ground = 0.0;
        if (ground_mass > 0.0) {
            p_ground = mass > 0.0 ? Clamp(ground_mass / (ground_mass + mass), 0.05, 0.95) : 1.0;
        }
        if (!(mass > 0.0) && p_ground <= 0.0) return;
        double w[kHeroMaxChannels];
        double discard[kHeroMaxChannels];
        for (int64_t s = 0; s < sample_count; ++s) {
            Rng rng(seed, key, static_cast<uint64_t>(sample_begin + s));
            if (rng.Uniform() < p_ground) {
                for (int c = 0; c < n; ++c) w[c] = t_end[c] * spec.albedo[c] * (1.0 / p_ground);
                const Vec3d next = MakeDirection(
                    normal, SampleCosineHemisphereCosine(rng.Uniform()), rng.Uniform());
                HeroContinue(normal * (atm.bottom_radius + 1e-3), next, w, 1, sun, rng,
                             want_ground ? ground : discard);
                continue;
            }
            ViewIntervalPoint v;
            if (!DrawViewInterval(nodes, count, mass, rng, &v)) continue;
            const ViewNode& a = nodes[v.lo];
            const double t = v.t;
            const Vec3d x = start + dir * t;
            const Densities d = GetDensities(atm, Length(x) - atm.bottom_radius);
            const Vec3d rho(d.rayleigh, d.mie, d.absorption);
            const Vec3d column = a.column + (a.rho + rho) * (0.5 * (t - a.t));
            const double pdf = (1.0 - p_ground) * v.p_interval / v.width;
            double a_r = 0.0, a_m = 0.0;
            for (int c = 0; c < n; ++c) {
                w[c] = ExpLane(-Tau(column, c)) * (1.0 / pdf);
                a_r += w[c] * spec.rayleigh[c] * d.rayleigh;
                a_m += w[c] * spec.mie_scattering[c] * d.mie;
            }
            if (!(a_r + a_m > 0.0)) continue;
            const bool rayleigh = rng.Uniform() * (a_r + a_m) < a_r;
            const double f = rayleigh ? (a_r + a_m) / a_r : (a_r + a_m) / a_m;
            for (int c = 0; c < n; ++c) {
                w[c] *=
                    (rayleigh ? spec.rayleigh[c] * d.rayleigh : spec.mie_scattering[c] * d.mie) * f;
            }
            Vec3d factor(1.0);
            const Vec3d next = SampleFirstDirection(x, dir, rayleigh, sun, rng, &factor);
            for (int c = 0; c < n; ++c) w[c] *= factor.x;
            HeroContinue(x, next, w, 1, sun, rng, sky);
        }
    }
};

}  // namespace atmos
