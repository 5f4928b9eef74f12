// The reference path tracer's shared parts (model `reference`, reference.h):
// the majorant shells, the estimators' names, the converged optical depth
// (AdaptiveOpticalDepth) and the sun's transmittance table of the hybrid
// estimator. Depends on no other model.
#pragma once

#include <stdint.h>

#include <memory>

#include "atmos/atmosphere.h"
#include "base/texture.h"
#include "physics/density.h"
#include "physics/geometry.h"

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

// Russian roulette from the 4th vertex on: a path survives with probability
// q = min(1, max_c w_c) of its throughput w (and w /= q), so a path keeps
// going untouched while its throughput is at least 1 (conservative
// scattering) and is thinned only as absorption and the ground's albedo lower
// it (pbrt-v4's rule). A fixed cap below 1 (0.95 until 0.3.0) thins paths by
// 0.95 per vertex whatever their throughput: behind a conservatively
// scattering optical depth of tens (Venus's clouds, hundreds of vertices) the
// few survivors then carry weights of 10^6 and the estimate is unbiased but
// does not converge. Beyond kRouletteCapOrder vertices the cap 0.95 returns, so
// that every path ends (a closed, lossless medium would never let go of one).
constexpr int kRouletteCapOrder = 100000;
ATMOS_HD inline double RouletteSurvival(int order, double max_weight) {
    return Min(order < kRouletteCapOrder ? 1.0 : 0.95, max_weight);
}

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
    // The thesis's estimator (Leenman's 2025 thesis section 4), kept as a baseline.
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

// The integral of rate(densities) along the segment by the same rule
// (AdaptiveOpticalDepth: rate = the extinction; ReferenceHero: the scaled
// column densities).
template <typename Rate>
ATMOS_HD inline Vec3d AdaptiveIntegral(const AtmosphereParameters& atm, const Vec3d& origin,
                                       const Vec3d& dir, double length, const Rate& rate) {
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
            q.sigma = rate(GetDensities(atm, Length(origin + dir * q.t) - atm.bottom_radius));
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

struct ExtinctionRate {
    const AtmosphereParameters* atm;
    ATMOS_HD Vec3d operator()(const Densities& d) const { return Extinction(*atm, d); }
};

ATMOS_HD inline Vec3d AdaptiveOpticalDepth(const AtmosphereParameters& atm, const Vec3d& origin,
                                           const Vec3d& dir, double length) {
    return AdaptiveIntegral(atm, origin, dir, length, ExtinctionRate{&atm});
}

// The sun's transmittance from a point (r, mu_s) to space: 0 when the ray meets
// the ground (exact geometry), else exp(-tau) with tau = beta_R c_R + beta_M,ext
// c_M + beta_A c_A, the column densities c (m, density x length) bilinear in a
// table on Bruneton's 2017 implementation notes' transmittance parameterisation (x_r = rho / H,
// x_mu = (d - d_min) / (d_max - d_min)), filled by Simpson quadrature (BuildSunColumnTable). The
// columns do not depend on wavelength: every batch of a spectral run shares one table
// (SharedSunColumnTable); bilinear interpolation is linear, so tau is what a table of optical
// depths would give. Its error against exact quadrature is measured and bounded by a test
// (ReferenceHybrid.SunTableMatchesQuadrature).
struct SunTransmittanceTable {
    TableView columns;  // 3 channels: Rayleigh, Mie, absorption column to the top boundary
    double bottom = 0.0, top = 0.0;
    Vec3d rayleigh, mie_extinction, absorption;  // the coefficients (1/m) per channel
    // true: the table does not resolve this atmosphere (SunTableResolves
    // failed: e.g. an 8 km scale height on a planet of radius 1e9 m, whose
    // Bruneton's 2017 implementation notes parameterisation puts the whole atmosphere in one
    // texel): the evaluator integrates each sun ray by AdaptiveOpticalDepth instead.
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
        Vec3d c;
        if (!Columns(r, mu, &c)) return Vec3d(0.0);
        return Exp(-(rayleigh * c.x + mie_extinction * c.y + absorption * c.z));
    }

    // The table's Rayleigh, Mie and absorption columns (m) from (r, mu) to
    // the top boundary; false where the ray meets the ground.
    ATMOS_HD bool Columns(double r, double mu, Vec3d* column) const {
        if (RayIntersectsGround(r, mu, bottom)) return false;
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
        *column =
            Vec3d(static_cast<double>(v.x), static_cast<double>(v.y), static_cast<double>(v.z));
        return true;
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

}  // namespace atmos
