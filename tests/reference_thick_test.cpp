// The reference on thick media and unusual planets (issue 32 items 1-2, issue
// 38 item 3): its deterministic parts against closed forms and an independent
// brute-force quadrature, and its two estimators against each other on
// atmospheres drawn at random.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "base/rng.h"
#include "models/reference.h"
#include "physics/density.h"
#include "physics/geometry.h"
#include "physics/phase.h"

namespace atmos {
namespace {

// The model's evaluator for `atm` (sun table, its check, the shells), as a
// render or `sample` gets it.
ReferenceEvaluator Prepared(const AtmosphereParameters& atm, ReferenceEstimator estimator,
                            int max_order = 0) {
    ReferenceOptions options;
    options.estimator = estimator;
    options.max_order = max_order;
    ReferenceModel model(options);
    model.Prepare(atm);
    ReferenceEvaluator e = model.evaluator();
    // The sun table outlives the model: SharedSunColumnTable keeps it.
    return e;
}

// Issue 32's slab: a 1 km layer of constant-density Rayleigh air (optical
// thickness 5, no absorption, a black ground) on a planet of radius 1e9 m.
AtmosphereParameters Slab(double thickness = 1000.0, double sigma = 5e-3) {
    AtmosphereParameters a = EarthAtmosphere();
    a.bottom_radius = 1e9;
    a.top_radius = 1e9 + thickness;
    a.rayleigh_scattering = Vec3d(sigma);
    a.rayleigh_density = DensityProfile();
    a.rayleigh_density.layers[1].constant_term = 1.0;
    a.rayleigh_density.layers[0] = a.rayleigh_density.layers[1];
    a.mie_scattering = a.mie_extinction = Vec3d(0.0);
    a.absorption_extinction = Vec3d(0.0);
    a.ground_albedo = Vec3d(0.0);
    ValidateAtmosphere(a);
    return a;
}

// Single scattering of a plane-parallel homogeneous slab (optical thickness
// tau, black ground) seen from depth z0 below its top looking down at mu_v
// (cosine from the downward vertical) with the sun at mu_s: the closed form
// P(nu) mu_s / (mu_s + mu_v) e^{-s z0 / mu_s} (1 - e^{-(tau - s z0)(1 / mu_v + 1 / mu_s)}).
double SlabSingleScattering(double sigma, double thickness, double z0, double mu_v, double mu_s,
                            double phase) {
    const double tau_below = sigma * (thickness - z0);
    return phase * mu_s / (mu_s + mu_v) * std::exp(-sigma * z0 / mu_s) *
           (1.0 - std::exp(-tau_below * (1.0 / mu_v + 1.0 / mu_s)));
}

struct Ray {
    Vec3d camera, dir, sun;
};

// The query (altitude, mu, mu_s, azimuth 0) of `atmos sample`.
Ray QueryRay(const AtmosphereParameters& atm, double altitude, double mu, double mu_s) {
    Ray r;
    r.camera = Vec3d(0.0, 0.0, atm.bottom_radius + altitude);
    r.dir = Vec3d(std::sqrt(1.0 - mu * mu), 0.0, mu);
    r.sun = Vec3d(std::sqrt(1.0 - mu_s * mu_s), 0.0, mu_s);
    return r;
}

Vec3d Order1(const ReferenceEvaluator& e, const Ray& r) {
    ReferenceEvaluator one = e;
    one.max_order = 1;
    one.sample_count = 1;
    const RayResult out = one.EvaluateKeyed(r.camera, r.dir, r.sun, true, 0);
    return Vec3d(out.sky) + Vec3d(out.ground);
}

TEST(ReferenceThick, SlabOrder1MatchesTheClosedForm) {
    // Issue 32's case (altitude 999.99, mu -0.018014, mu_s 0.080442: 0.230
    // before the fix, closed form 0.0970) and others, three thicknesses.
    int checked = 0;
    for (const double thickness : {100.0, 1000.0, 10000.0}) {
        const double sigma = 5.0 / thickness;  // optical thickness 5
        const AtmosphereParameters atm = Slab(thickness, sigma);
        const ReferenceEvaluator e = Prepared(atm, ReferenceEstimator::kHybrid);
        for (const double mu : {-0.018014, -0.1, -0.538, -0.9}) {
            for (const double mu_s : {0.080442, 0.3, 1.0}) {
                const double z0 = thickness * 1e-5;
                const Ray r = QueryRay(atm, thickness - z0, mu, mu_s);
                const double nu = Dot(r.dir, r.sun);
                const double want =
                    SlabSingleScattering(sigma, thickness, z0, -mu, mu_s, RayleighPhase(nu));
                const Vec3d got = Order1(e, r);
                EXPECT_NEAR(got.x, want, 1e-3 * want)
                    << "thickness " << thickness << " mu " << mu << " mu_s " << mu_s;
                ++checked;
            }
        }
    }
    EXPECT_EQ(checked, 36);
}

// Mean and standard error (batch means) of all orders at one ray.
void Estimate(const ReferenceEvaluator& base, const Ray& r, int batches, int per_batch,
              uint64_t key, Vec3d* mean, Vec3d* se) {
    ReferenceEvaluator e = base;
    e.sample_count = per_batch;
    Vec3d sum, sum_sq;
    for (int b = 0; b < batches; ++b) {
        e.sample_begin = static_cast<int64_t>(b) * per_batch;
        const RayResult out = e.EvaluateKeyed(r.camera, r.dir, r.sun, true, key);
        const Vec3d v = Vec3d(out.sky) + Vec3d(out.ground);
        sum += v;
        sum_sq += v * v;
    }
    *mean = sum / static_cast<double>(batches);
    for (int c = 0; c < 3; ++c) {
        const double var = std::max(sum_sq[c] / batches - (*mean)[c] * (*mean)[c], 0.0) * batches /
                           (batches - 1.0);
        (*se)[c] = std::sqrt(var / batches);
    }
}

TEST(ReferenceThick, SlabEstimatorsAgree) {
    // All orders of issue 32's query: hybrid 0.249 against tracking 0.117
    // before the fix; now within 4 combined standard errors.
    const AtmosphereParameters atm = Slab();
    const Ray r = QueryRay(atm, 999.99, -0.018014, 0.080442);
    Vec3d mh, sh, mt, st;
    Estimate(Prepared(atm, ReferenceEstimator::kHybrid), r, 16, 256, 1, &mh, &sh);
    Estimate(Prepared(atm, ReferenceEstimator::kTracking), r, 16, 512, 1, &mt, &st);
    std::printf("slab: hybrid %.5f +- %.5f, tracking %.5f +- %.5f\n", mh.x, sh.x, mt.x, st.x);
    EXPECT_NEAR(mh.x, mt.x, 4.0 * std::hypot(sh.x, st.x));
    EXPECT_GT(mh.x, 0.1);
}

// The analytic zenith optical depth from the ground of a planet whose
// atmosphere is far thicker than its scale heights: beta H per exponential
// profile, the tent's area for the ozone.
// Energy conservation, exact: a conservatively scattering slab (optical
// thickness 30, no absorption, a black ground) under a zenith sun reflects
// and transmits all it receives, R + T = 1 per unit irradiance, R and T the
// upwelling flux at the top and the downwelling (diffuse + direct) flux at
// the bottom, pi int L d(mu^2) by the midpoint rule in mu^2 (16 directions
// each). Paths cross hundreds of vertices there: the Russian roulette's fixed
// survival cap of 0.95 per vertex (before 0.3.0) gave R + T = 0.84 (T 1e-4
// against 0.05) at 2048 paths, unbiased in expectation but so heavy-tailed
// that it never showed.
TEST(ReferenceThick, ConservativeSlabReflectsAndTransmitsAllItReceives) {
    constexpr double kTau = 30.0, kThickness = 1000.0;
    const AtmosphereParameters atm = Slab(kThickness, kTau / kThickness);
    constexpr int kDirections = 16, kBatches = 8, kPerBatch = 64;
    for (const ReferenceEstimator estimator :
         {ReferenceEstimator::kHybrid, ReferenceEstimator::kTracking}) {
        ReferenceEvaluator e = Prepared(atm, estimator);
        e.sample_count = kPerBatch;
        double sum = 0.0, sum_sq = 0.0, t_sum = 0.0;
        for (int b = 0; b < kBatches; ++b) {
            e.sample_begin = static_cast<int64_t>(b) * kPerBatch;
            double r_flux = 0.0, t_flux = 0.0;
            for (int i = 0; i < kDirections; ++i) {
                const double mu = std::sqrt((i + 0.5) / kDirections);
                const Ray up = QueryRay(atm, kThickness - 1e-3, -mu, 1.0);
                const Ray down = QueryRay(atm, 1e-3, mu, 1.0);
                const RayResult ru = e.EvaluateKeyed(up.camera, up.dir, up.sun, true, 2 * i + 1);
                const RayResult rd =
                    e.EvaluateKeyed(down.camera, down.dir, down.sun, true, 2 * i + 2);
                r_flux += kPi * (Vec3d(ru.sky).x + Vec3d(ru.ground).x) / kDirections;
                t_flux += kPi * (Vec3d(rd.sky).x + Vec3d(rd.ground).x) / kDirections;
            }
            t_flux += std::exp(-kTau);  // the direct beam
            sum += r_flux + t_flux;
            sum_sq += (r_flux + t_flux) * (r_flux + t_flux);
            t_sum += t_flux;
        }
        const double mean = sum / kBatches;
        const double se =
            std::sqrt(std::max(sum_sq / kBatches - mean * mean, 0.0) / (kBatches - 1.0));
        const char* name = estimator == ReferenceEstimator::kHybrid ? "hybrid" : "tracking";
        EXPECT_NEAR(mean, 1.0, std::max(4.0 * se, 0.02)) << name << ": R + T, s.e. " << se;
        // Transmission through 30 optical depths: about 0.05 (two-stream,
        // 4 / (3 (tau + 4/3)) x 1.2); 1e-4 with the capped roulette.
        EXPECT_GT(t_sum / kBatches, 0.03) << name;
    }
}

TEST(ReferenceThick, GiantPlanetZenithTransmittance) {
    // Issue 38 item 3: bottom 1e9 m, top 2e9 m, earth's coefficients. The
    // analytic zenith transmittance is (0.940, 0.868, 0.762); before the fix
    // the hybrid gave 0.999998 and tracking 0.0067.
    AtmosphereParameters atm = EarthAtmosphere();
    atm.bottom_radius = 1e9;
    atm.top_radius = 2e9;
    ValidateAtmosphere(atm);
    const Vec3d tau = atm.rayleigh_scattering * 8000.0 + atm.mie_extinction * 1200.0 +
                      atm.absorption_extinction * 15000.0;
    const Vec3d want = Exp(-tau);
    for (const ReferenceEstimator est :
         {ReferenceEstimator::kHybrid, ReferenceEstimator::kTracking}) {
        const ReferenceEvaluator e = Prepared(atm, est, 1);
        for (const double mu_s : {0.5, -0.5}) {
            const Ray r = QueryRay(atm, 0.0, 1.0, mu_s);
            ReferenceEvaluator one = e;
            one.sample_count = 1;
            const RayResult out = one.EvaluateKeyed(r.camera, r.dir, r.sun, true, 0);
            for (int c = 0; c < 3; ++c) {
                EXPECT_NEAR(out.transmittance[c], want[c], 5e-4 * want[c])
                    << "estimator " << static_cast<int>(est) << " mu_s " << mu_s << " ch " << c;
            }
        }
    }
    // The sun table cannot resolve an 8 km scale height on this planet (its
    // parameterisation puts the atmosphere in one texel): the check finds it
    // and the estimator integrates the sun's rays instead; on earth and mars
    // the table stands.
    EXPECT_TRUE(Prepared(atm, ReferenceEstimator::kHybrid).sun_table.direct);
    EXPECT_FALSE(Prepared(EarthAtmosphere(), ReferenceEstimator::kHybrid).sun_table.direct);
    EXPECT_FALSE(Prepared(LoadAtmosphere("mars"), ReferenceEstimator::kHybrid).sun_table.direct);
}

// ---- an independent brute-force single-scattering quadrature ----
//
// Plain midpoint rules on maps t = a + span u^4 from each monotonic piece's
// low end (dense where the air is, down to span 1e-16: any scale height on
// any planet), 4000 steps on the view ray (each step's transmittance
// integrated exactly for a constant extinction: e^{-tau} (1 - e^{-dtau}) /
// sigma_t, so optically thick steps are exact too) and 1500 on each sun ray.
// No code shared with the estimator but the densities and phase functions.

Vec3d BruteDepth(const AtmosphereParameters& atm, const Vec3d& p, const Vec3d& dir, double length,
                 int steps) {
    double cuts[3] = {0.0, length, length};
    int nc = 2;
    const double tl = -Dot(p, dir);
    if (tl > 0.0 && tl < length) {
        cuts[1] = tl;
        nc = 3;
    }
    Vec3d tau;
    for (int k = 0; k + 1 < nc; ++k) {
        const double a = cuts[k], b = cuts[k + 1], span = b - a;
        const bool low_a = Length(p + dir * a) <= Length(p + dir * b);
        for (int i = 0; i < steps; ++i) {
            const double u0 = static_cast<double>(i) / steps, u1 = (i + 1.0) / steps;
            const double um = 0.5 * (u0 + u1);
            auto map = [&](double u) {
                return low_a ? a + span * u * u * u * u
                             : b - span * (1.0 - u) * (1.0 - u) * (1.0 - u) * (1.0 - u);
            };
            const double dt = std::abs(map(u1) - map(u0));
            const double t = map(um);
            tau += Extinction(atm, GetDensities(atm, Length(p + dir * t) - atm.bottom_radius)) * dt;
        }
    }
    return tau;
}

Vec3d BruteSunTransmittance(const AtmosphereParameters& atm, const Vec3d& x, const Vec3d& sun) {
    const double r = Length(x);
    const double mu = Dot(x, sun) / r;
    if (RayIntersectsGround(r, mu, atm.bottom_radius)) return Vec3d(0.0);
    return Exp(
        -BruteDepth(atm, x, sun, DistanceToTopAtmosphereBoundary(r, mu, atm.top_radius), 1500));
}

// Order 1 (sky + ground) by brute force.
Vec3d BruteOrder1(const AtmosphereParameters& atm, const Ray& ray) {
    const AtmosphereSegment seg =
        ClipToAtmosphere(ray.camera, ray.dir, atm.bottom_radius, atm.top_radius);
    if (!seg.inside || !(seg.t_end > seg.t_start)) return Vec3d(0.0);  // not drawn by the test
    const Vec3d start = ray.camera + ray.dir * seg.t_start;
    const double length = seg.t_end - seg.t_start;
    // Pieces: the lowest point and the shadow cylinder's crossings.
    std::vector<double> cuts = {0.0, length};
    const double tl = -Dot(start, ray.dir);
    if (tl > 0.0 && tl < length) cuts.push_back(tl);
    {
        const Vec3d pp = start - ray.sun * Dot(start, ray.sun);
        const Vec3d dp = ray.dir - ray.sun * Dot(ray.dir, ray.sun);
        const double qa = Dot(dp, dp), qb = Dot(pp, dp);
        const double qc = Dot(pp, pp) - atm.bottom_radius * atm.bottom_radius;
        const double disc = qb * qb - qa * qc;
        if (qa > 0.0 && disc > 0.0) {
            for (const double s : {-1.0, 1.0}) {
                const double t = (-qb + s * std::sqrt(disc)) / qa;
                if (t > 0.0 && t < length) cuts.push_back(t);
            }
        }
    }
    std::sort(cuts.begin(), cuts.end());
    const double nu = Dot(ray.dir, ray.sun);
    const Vec3d phase_r = atm.rayleigh_scattering * RayleighPhase(nu);
    const Vec3d phase_m = atm.mie_scattering * MiePhase(atm, nu);
    Vec3d sum, tau;
    const int steps = 4000;
    for (size_t k = 0; k + 1 < cuts.size(); ++k) {
        const double a = cuts[k], b = cuts[k + 1], span = b - a;
        if (!(span > 0.0)) continue;
        const bool low_a = Length(start + ray.dir * a) <= Length(start + ray.dir * b);
        auto map = [&](double u) {
            return low_a ? a + span * u * u * u * u
                         : b - span * (1.0 - u) * (1.0 - u) * (1.0 - u) * (1.0 - u);
        };
        for (int i = 0; i < steps; ++i) {
            const double t0 = map(static_cast<double>(i) / steps), t1 = map((i + 1.0) / steps);
            const double lo = std::min(t0, t1), dt = std::abs(t1 - t0);
            const Vec3d x = start + ray.dir * (lo + 0.5 * dt);
            const Densities d = GetDensities(atm, Length(x) - atm.bottom_radius);
            const Vec3d sigma_t = Extinction(atm, d);
            const Vec3d src =
                (phase_r * d.rayleigh + phase_m * d.mie) * BruteSunTransmittance(atm, x, ray.sun);
            for (int c = 0; c < 3; ++c) {
                const double dtau = sigma_t[c] * dt;
                const double w = dtau > 1e-9 ? std::exp(-tau[c]) * -std::expm1(-dtau) / sigma_t[c]
                                             : std::exp(-tau[c]) * dt;
                sum[c] += src[c] * w;
            }
            tau += sigma_t * dt;
        }
    }
    if (seg.hits_ground) {
        const Vec3d g = start + ray.dir * length;
        const Vec3d n = Normalize(g);
        const double cos_sun = Dot(n, ray.sun);
        if (cos_sun > 0.0) {
            sum += Exp(-tau) * atm.ground_albedo * (cos_sun / kPi) *
                   BruteSunTransmittance(
                       atm, n * (atm.bottom_radius + 1e-6 * (atm.top_radius - atm.bottom_radius)),
                       ray.sun);
        }
    }
    return sum;
}

// ---- atmospheres drawn at random ----

double LogUniform(Rng& rng, double lo, double hi) { return lo * std::pow(hi / lo, rng.Uniform()); }

// An atmosphere drawn from the ranges: planets of radius 1e4 to 1e9 m
// with shells from 1e-6 to 1 of the radius, vertical optical depths from 1e-3
// to 30 (Rayleigh, Mie or both), scale heights from the shell's 1/200 to
// constant, Mie g from -0.5 to 0.95 (some with a second lobe), absorption,
// ground albedo 0 to 1.
AtmosphereParameters RandomAtmosphere(Rng& rng) {
    AtmosphereParameters a = EarthAtmosphere();
    a.bottom_radius = LogUniform(rng, 1e4, 1e9);
    const double shell =
        a.bottom_radius * LogUniform(rng, std::max(1e-6, 100.0 / a.bottom_radius), 0.99);
    a.top_radius = a.bottom_radius + shell;
    auto profile = [&]() {
        const double kind = rng.Uniform();
        if (kind < 0.3) {
            DensityProfile p;
            p.layers[0].constant_term = p.layers[1].constant_term = 1.0;
            return std::make_pair(p, shell);
        }
        const double h = shell * LogUniform(rng, 1.0 / 200.0, 0.5);
        return std::make_pair(ExponentialProfile(h), h);
    };
    const auto [pr, hr] = profile();
    const auto [pm, hm] = profile();
    a.rayleigh_density = pr;
    a.mie_density = pm;
    const double tau_r = rng.Uniform() < 0.2 ? 0.0 : LogUniform(rng, 1e-2, 50.0);
    const double tau_m = rng.Uniform() < 0.3 ? 0.0 : LogUniform(rng, 1e-2, 50.0);
    a.rayleigh_scattering = Vec3d(0.4, 0.7, 1.0) * (tau_r / hr);
    const double albedo_m = rng.Uniform() < 0.5 ? 1.0 : 0.5 + 0.5 * rng.Uniform();
    a.mie_extinction = Vec3d(tau_m / hm);
    a.mie_scattering = a.mie_extinction * albedo_m;
    a.mie_phase_g = -0.5 + 1.45 * rng.Uniform();
    if (rng.Uniform() < 0.25) {
        a.mie_phase_g2 = -0.5 + rng.Uniform();
        a.mie_phase_weight2 = 0.3 * rng.Uniform();
    }
    a.absorption_density = pr;
    a.absorption_extinction = rng.Uniform() < 0.5
                                  ? Vec3d(0.0)
                                  : Vec3d(0.1, 0.3, 0.05) * (LogUniform(rng, 1e-3, 1.0) / hr);
    a.ground_albedo = Vec3d(rng.Uniform() < 0.3 ? 0.0 : rng.Uniform());
    ValidateAtmosphere(a);
    return a;
}

// A ray: camera on the ground, in the air or in space, any direction that
// meets the atmosphere, the sun from 20 degrees below the horizon to the zenith.
Ray RandomRay(const AtmosphereParameters& atm, Rng& rng, int where) {
    const double shell = atm.top_radius - atm.bottom_radius;
    const double altitude = where == 0                 ? 0.0
                            : where == 1 || where == 3 ? shell * rng.Uniform()
                                                       : shell * (1.0 + 0.5 * rng.Uniform());
    Ray r;
    r.camera = Vec3d(0.0, 0.0, atm.bottom_radius + altitude);
    for (int tries = 0; tries < 1000; ++tries) {
        // 3: in the air, within 0.1 of the horizontal (long, optically thick rays).
        const double mu = where == 0   ? rng.Uniform()
                          : where == 3 ? 0.2 * rng.Uniform() - 0.1
                                       : 2.0 * rng.Uniform() - 1.0;
        const double phi = 2.0 * kPi * rng.Uniform();
        const double s = std::sqrt(1.0 - mu * mu);
        r.dir = Vec3d(s * std::cos(phi), s * std::sin(phi), mu);
        const AtmosphereSegment seg =
            ClipToAtmosphere(r.camera, r.dir, atm.bottom_radius, atm.top_radius);
        if (seg.inside && seg.t_end > seg.t_start) break;
    }
    const double el = Radians(-20.0 + 110.0 * rng.Uniform());
    const double az = 2.0 * kPi * rng.Uniform();
    r.sun = Vec3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
    return r;
}

// `atmospheres` drawn atmospheres, 4 rays each (ground, air, space, in the
// air near the horizontal): the hybrid's deterministic order 1 against the
// brute-force quadrature (1e-2 relative + 1e-6 absolute), and all orders of
// hybrid and tracking within 4.5 combined standard errors (20 batch means
// each) in every channel. Under normal batch means a channel exceeds 4.5
// with probability 6.8e-6 (a ray, three correlated channels: < 2e-5); but
// the tracking estimator's sun transmittance is heavy-tailed in deep shadow
// (docs/models/reference.md): a twilight ray inside a thick haze can sit many
// standard errors low at 640 paths (seen: 5.7e-6 against the hybrid's
// 1.05e-5, which 8192 tracking paths confirm), so one ray in 30 may differ.
void ExpectEstimatorsAgree(int atmospheres, uint64_t seed) {
    Rng rng(seed, 32, 2);
    int compared = 0, beyond = 0, order1 = 0, order1_bad = 0;
    for (int i = 0; i < atmospheres; ++i) {
        const AtmosphereParameters atm = RandomAtmosphere(rng);
        const ReferenceEvaluator hybrid = Prepared(atm, ReferenceEstimator::kHybrid);
        const ReferenceEvaluator tracking = Prepared(atm, ReferenceEstimator::kTracking);
        for (int where = 0; where < 4; ++where) {
            const Ray r = RandomRay(atm, rng, where);
            const Vec3d want = BruteOrder1(atm, r);
            const Vec3d got = Order1(hybrid, r);
            for (int c = 0; c < 3; ++c) {
                ++order1;
                if (std::abs(got[c] - want[c]) > 1e-2 * want[c] + 1e-6) {
                    ++order1_bad;
                    std::printf(
                        "order 1: atmosphere %d (R %.3g, shell %.3g) ray %d ch %d: %.6g vs "
                        "brute %.6g\n",
                        i, atm.bottom_radius, atm.top_radius - atm.bottom_radius, where, c, got[c],
                        want[c]);
                }
            }
            Vec3d mh, sh, mt, st;
            const uint64_t key = static_cast<uint64_t>(i) * 4 + where;
            Estimate(hybrid, r, 20, 16, key, &mh, &sh);
            Estimate(tracking, r, 20, 32, key, &mt, &st);
            ++compared;
            bool off = false;
            for (int c = 0; c < 3; ++c) {
                const double se = std::hypot(sh[c], st[c]);
                if (std::abs(mh[c] - mt[c]) > 4.5 * se + 1e-9) {
                    if (!off) ++beyond;
                    off = true;
                    std::printf(
                        "beyond: atmosphere %d (R %.3g, shell %.3g, albedo %.2f) ray %d ch %d: "
                        "hybrid %.6g tracking %.6g (se %.3g)\n",
                        i, atm.bottom_radius, atm.top_radius - atm.bottom_radius,
                        atm.ground_albedo.x, where, c, mh[c], mt[c], se);
                    if (c == 0) {
                        std::printf(
                            "  camera %.17g %.17g %.17g dir %.17g %.17g %.17g sun %.17g "
                            "%.17g %.17g\n  %s\n",
                            r.camera.x, r.camera.y, r.camera.z, r.dir.x, r.dir.y, r.dir.z, r.sun.x,
                            r.sun.y, r.sun.z, AtmosphereToJson(atm).c_str());
                    }
                }
            }
        }
    }
    std::printf(
        "random atmospheres: order 1 %d of %d channels off the quadrature; %d of %d rays "
        "beyond 4.5 combined standard errors\n",
        order1_bad, order1, beyond, compared);
    EXPECT_EQ(order1_bad, 0);
    EXPECT_LE(beyond, std::max(1, compared / 30));
}

// Issue 32 item 5: the thick presets at a few rays each (ground at noon and
// near sunset, in the air, from space): order 1 of the hybrid against the
// brute-force quadrature (1e-2), all orders of hybrid and tracking within 4.5
// combined standard errors of 20 batch means each (tracking with twice the
// paths; under normal means a false alarm about once in 5e4 rays, but the
// paths' weights are heavy-tailed here: at 20 x 16 paths two rays sat 2-2.5
// standard errors off values that 65,536 paths of each estimator agree on). On
// `venus` the orders stop at 8: the paths' Russian roulette (survival 0.95
// per vertex from the 4th, reference_tracking.h) makes the hundreds of
// vertices a path needs to cross its clouds (optical depth 30) so rare and
// so heavy that batch means of all orders are not normal at any affordable
// count (docs/atmosphere.md, "Thick presets"); up to order 8 the weights grow
// at most 1.3x. Below the clouds orders <= 8 are ~0, so the Venus rays are
// above or inside them.
void ExpectEstimatorsAgreeOnThickPresets(int paths_per_batch) {
    struct Case {
        const char* preset;
        int max_order;
        double altitude, mu, mu_s;
    };
    const Case cases[] = {
        {"titan", 0, 0.0, 1.0, 1.0},     // ground, zenith, noon
        {"titan", 0, 0.0, 0.05, 0.1},    // ground, near the horizon, sun 6 deg up
        {"titan", 0, 150e3, -0.3, 0.5},  // in the haze, looking down
        {"titan", 0, 900e3, -0.6, 0.8},  // from space (inside the 600 km shell's reach)
        {"venus", 8, 60e3, 0.2, 0.6},    // inside the upper cloud
        {"venus", 8, 75e3, 0.0, 0.1},    // above the cloud top, horizontal, sun low
        {"venus", 8, 200e3, -1.0, 1.0},  // from space, nadir, noon
        {"venus", 8, 200e3, -0.3, 0.4},  // from space, oblique
    };
    int compared = 0;
    for (const Case& k : cases) {
        const AtmosphereParameters atm = LoadAtmosphere(k.preset);
        const ReferenceEvaluator hybrid = Prepared(atm, ReferenceEstimator::kHybrid, k.max_order);
        const ReferenceEvaluator tracking =
            Prepared(atm, ReferenceEstimator::kTracking, k.max_order);
        const Ray r = QueryRay(atm, k.altitude, k.mu, k.mu_s);
        const Vec3d want = BruteOrder1(atm, r);
        const Vec3d got = Order1(hybrid, r);
        Vec3d mh, sh, mt, st;
        const uint64_t key = static_cast<uint64_t>(compared);
        Estimate(hybrid, r, 20, paths_per_batch, key, &mh, &sh);
        Estimate(tracking, r, 20, 2 * paths_per_batch, key, &mt, &st);
        for (int c = 0; c < 3; ++c) {
            SCOPED_TRACE(std::string(k.preset) + " altitude " + std::to_string(k.altitude) +
                         " mu " + std::to_string(k.mu) + " mu_s " + std::to_string(k.mu_s) +
                         " channel " + std::to_string(c));
            EXPECT_NEAR(got[c], want[c], 1e-2 * want[c] + 1e-9);
            const double se = std::hypot(sh[c], st[c]);
            EXPECT_NEAR(mh[c], mt[c], 4.5 * se + 1e-9) << "hybrid " << mh[c] << " +- " << sh[c]
                                                       << ", tracking " << mt[c] << " +- " << st[c];
            // Not vacuous: multiple scattering is a visible part of the answer.
            if (c == 1) {
                EXPECT_GT(mh[c], 1.2 * got[c]) << "order 1 " << got[c];
            }
        }
        std::printf(
            "%s alt %.0f mu %.2f mu_s %.2f: order 1 %.5g (brute %.5g), hybrid %.5g +- %.2g, "
            "tracking %.5g +- %.2g (green)\n",
            k.preset, k.altitude, k.mu, k.mu_s, got.y, want.y, mh.y, sh.y, mt.y, st.y);
        ++compared;
    }
    EXPECT_EQ(compared, 8);
}

TEST(ReferenceThick, EstimatorsAgreeOnTheThickPresets) {
    ExpectEstimatorsAgreeOnThickPresets(128);  // ~6 s CPU, mostly the brute-force order 1
}

TEST(ReferenceThickSlow, EstimatorsAgreeOnTheThickPresets) {
    if (!std::getenv("ATMOS_REFERENCE_SLOW")) GTEST_SKIP() << "ctest -L slow runs it";
    ExpectEstimatorsAgreeOnThickPresets(2048);  // ~1 min CPU
}

TEST(ReferenceThick, EstimatorsAgreeOnRandomAtmospheres) {
    ExpectEstimatorsAgree(10, 1);  // the fast subset
}

TEST(ReferenceThickSlow, EstimatorsAgreeOnRandomAtmospheres) {
    if (!std::getenv("ATMOS_REFERENCE_SLOW")) GTEST_SKIP() << "ctest -L slow runs it";
    ExpectEstimatorsAgree(60, 2);
}

}  // namespace
}  // namespace atmos
