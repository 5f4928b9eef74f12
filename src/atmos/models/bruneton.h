// atmos model `bruneton`: precomputed atmospheric scattering (Bruneton & Neyret
// 2008, in the 2017 reimplementation documented by Bruneton's 2017 implementation notes).
//
// Source: Bruneton 2017, functions.glsl: every section, Leenman's 2025 thesis
// sections 5.2 and 11.2.3 (the thesis used this implementation with 4 orders).
//
// Implements (Bruneton's 2017 implementation notes section named in each function's comment):
//   * transmittance to the top of the atmosphere T(r, mu) in a 2D table (256x64)
//     with the generic (r, mu) mapping and texel-centre coordinates;
//   * direct ground irradiance (64x16) and, per order, indirect irradiance;
//   * single Rayleigh and Mie scattering in a 4D (r, mu, mu_s, nu) table packed
//     in 3D (NU * MU_S, MU, R) = (8 * 32, 128, 32), mu split at the horizon;
//   * scattering density J_n and multiple scattering orders 2..N (default 4),
//     with the ground albedo in the higher orders;
//   * rendering: GetSkyRadiance (viewer in space moved to the top; rays that miss
//     the atmosphere: L = 0, T = 1), GetSkyRadianceToPoint (aerial perspective),
//     GetSunAndSkyIrradiance (lit ground); light shafts via shadow_length.
//   Mie storage: its own table (default) or combined (red in the alpha channel of
//   the scattering table, green and blue extrapolated, Bruneton's 2017 implementation notes
//   GetExtrapolatedSingleMieScattering).
//   The precomputation's steps are stage structs (models/bruneton_stages.h)
//   that RunStage runs on the CPU or, on the CUDA backend, on the device.
//
// Output: radiance per unit solar irradiance (1/sr): the tables are computed
// with solar irradiance 1 (the render loop multiplies by the atmosphere's), and
// the view ray's transmittance. Tables are float32 (GPU texture semantics,
// base/texture.h); geometry and mappings are double.
//
// Valid: any camera (ground, air, space), sun down to mu_s_min (the table's
// lower bound; below it the sky is taken as at mu_s_min, which is dark).
//
// Deviations: the scattering density integral uses the seed's 16 x 32 midpoint
// grid of incident directions, but laid out around the sun's azimuth instead of
// the view's (the incident radiance then depends on (r, mu_s) only and is
// computed once per (r, mu_s) instead of once per texel: same quadrature order,
// about 1000x fewer table lookups); the view-ray samples of single and multiple
// scattering (transmittance, densities, mapping of r_i and mu_i) are computed
// once per (r, mu) row and shared by the row's (mu_s, nu) texels. Both are exact
// rearrangements except for the rotated direction grid. Tables are per unit
// solar irradiance. The horizon handling: see docs/models/bruneton.md ("bruneton:
// horizon"). Low sun over the ground (mu_s < 0.01): single Mie integrated along
// the segment (`low-sun-mie=integrate`, 64 midpoint samples, the exponential in
// float, within 2 ulp; samples in the planet's shadow add exactly 0 and are
// skipped) in place of the seed's smoothstep fade (issue 15).
// Spectral runs: one precomputation and one lookup per ray for every channel
// of up to 16 batches (bruneton_wide.h, bruneton_wide_precompute.cpp), the
// batches' tables and values bit for bit.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "base/texture.h"
#include "models/evaluator_model.h"
#include "physics/density.h"
#include "physics/geometry.h"
#include "physics/phase.h"
#include "physics/vector_exp.h"
#include "physics/wide.h"

namespace atmos {

// Table sizes and precomputation options (defaults: Bruneton's 2017 implementation notes).
struct BrunetonConfig {
    int transmittance_width = 256;  // mu
    int transmittance_height = 64;  // r
    int irradiance_width = 64;      // mu_s
    int irradiance_height = 16;     // r
    int scattering_r = 32;
    int scattering_mu = 128;  // even: half for rays hitting the ground
    int scattering_mu_s = 32;
    int scattering_nu = 8;
    int orders = 4;  // scattering orders (1 = single scattering only)
    int scattering_samples =
        100;  // intervals along view rays (Bruneton's 2017 implementation notes: 50)
    // Quadrature along view rays in single and multiple scattering: Simpson's
    // rule (default, issue 15) or the seed's trapezoid.
    int scattering_rule = 1;    // 0: trapezoid (Bruneton's 2017 implementation notes), 1: Simpson
    bool combined_mie = false;  // Mie red in the scattering table's alpha
    // Single Mie scattering of rays to the ground (aerial perspective) with the
    // sun low (mu_s < 0.01): 0: integrated along the segment (default), 1: the
    // seed's smoothstep(0, 0.01, mu_s) fade, 2: the two lookups subtracted as
    // for a high sun (the artefact the seed's fade hides; for study only).
    int low_sun_mie = 0;
    int low_sun_mie_steps = 64;  // midpoint samples of that integral
};

// The view-ray quadrature's weight of sample i of n (times the interval):
// the seed's trapezoid, or composite Simpson (odd n: Simpson's 3/8 rule on the
// last three intervals; n = 1: trapezoid).
ATMOS_HD inline double BrunetonQuadratureWeight(int rule, int i, int n) {
    if (rule == 0 || n < 2) return (i == 0 || i == n) ? 0.5 : 1.0;
    const int m = n % 2 == 0 ? n : n - 3;  // intervals of the 1/3 rule
    double w = 0.0;
    if (i <= m && m > 0) w += (i == 0 || i == m) ? 1.0 / 3.0 : (i % 2 == 1 ? 4.0 / 3.0 : 2.0 / 3.0);
    if (i >= m && m != n) w += (i == m || i == n) ? 3.0 / 8.0 : 9.0 / 8.0;
    return w;
}

// The mappings' constants, which depend on the atmosphere and the table sizes
// only: computed once (BrunetonLut's constructor) instead of per query, by the
// same operations as the seed's per-query code (bit-identical results).
struct BrunetonConstants {
    double bottom = 0.0, top = 0.0;
    double bottom2 = 0.0;  // bottom^2
    double H = 0.0;        // HorizonH()
    double H2 = 0.0;       // H^2
    // u_mu_s (ScatteringUMuS): d_min, d_max - d_min and A.
    double mu_s_d_min = 0.0, mu_s_d_range = 1.0, mu_s_big_a = 1.0;
    double irradiance_r_range = 1.0;  // top - bottom
    TexelCentreMap transmittance_u, transmittance_v, irradiance_u, irradiance_v;
    TexelCentreMap scattering_r, scattering_mu_half, scattering_mu_s;
};

// The mu_s part of GetScatteringTextureUvwzFromRMuMuSNu from the constants.
ATMOS_HD inline double BrunetonUMuS(const BrunetonConstants& k, double mu_s) {
    ATMOS_DASSERT(k.H > 0.0);
    const double d = DistanceToTopAtmosphereBoundary(k.bottom, mu_s, k.top);
    const double a = (d - k.mu_s_d_min) / k.mu_s_d_range;
    return k.scattering_mu_s(Max(1.0 - a / k.mu_s_big_a, 0.0) / (1.0 + a));
}

// A 4D lookup's texels and weights (BrunetonLut::Lookup4D: two trilinear
// lookups at u0 and u1), in two parts: the (mu, r) rows and the (nu, mu_s)
// columns. Computed once per query and shared by the tables of the same
// layout (scattering and single Mie); the precomputation's multiple
// scattering computes the rows once per view-ray sample for a row of texels.
struct Bruneton4DRows {
    size_t row[4];  // texel index of x = 0 in rows (y0,z0) (y1,z0) (y0,z1) (y1,z1)
    float fy, fz;   // along y and z
};
struct Bruneton4DColumns {
    TexelSpan xa, xb;  // along x at u0 and u1
    float lerp;        // between the two
};
ATMOS_HD inline Bruneton4DRows BrunetonSplitRows(int width, int height, int depth, double u_mu,
                                                 double u_r) {
    const TexelSpan y = SplitSpan(u_mu, height);
    const TexelSpan z = SplitSpan(u_r, depth);
    Bruneton4DRows s;
    s.fy = y.f;
    s.fz = z.f;
    const size_t w = static_cast<size_t>(width), h = static_cast<size_t>(height);
    s.row[0] = (z.i0 * h + y.i0) * w;
    s.row[1] = (z.i0 * h + y.i1) * w;
    s.row[2] = (z.i1 * h + y.i0) * w;
    s.row[3] = (z.i1 * h + y.i1) * w;
    return s;
}
// The nu coordinate: tex_x = floor(u_nu (NU - 1)) and lerp its fraction.
ATMOS_HD inline void BrunetonNuCoordinate(double nu, int nu_size, double* tex_x, float* lerp) {
    const double tex_coord_x = (nu + 1.0) / 2.0 * (nu_size - 1);
    *tex_x = floor(tex_coord_x);
    *lerp = static_cast<float>(tex_coord_x - *tex_x);
}
ATMOS_HD inline Bruneton4DColumns BrunetonSplitColumns(int width, int nu_size, double tex_x,
                                                       float lerp, double u_mu_s) {
    Bruneton4DColumns s;
    s.lerp = lerp;
    const double u0 = (tex_x + u_mu_s) / nu_size;
    const double u1 = (tex_x + 1.0 + u_mu_s) / nu_size;
    s.xa = SplitSpan(u0, width);
    s.xb = SplitSpan(u1, width);
    return s;
}
// Lookup4D of a C-channel table at (rows, columns): the operations of
// SampleTrilinear / SampleBilinear in their order (bit-identical).
template <int C>
ATMOS_HD inline void BrunetonSample4D(const float* data, const Bruneton4DRows& r,
                                      const Bruneton4DColumns& x, float out[C]) {
    for (int c = 0; c < C; ++c) {
        const float ta =
            BilinearChannel<C>(data, r.row[0], r.row[1], x.xa, r.fy, c) * (1.0f - r.fz) +
            BilinearChannel<C>(data, r.row[2], r.row[3], x.xa, r.fy, c) * r.fz;
        const float tb =
            BilinearChannel<C>(data, r.row[0], r.row[1], x.xb, r.fy, c) * (1.0f - r.fz) +
            BilinearChannel<C>(data, r.row[2], r.row[3], x.xb, r.fy, c) * r.fz;
        out[c] = ta * (1.0f - x.lerp) + tb * x.lerp;
    }
}

// The lookup functions of Bruneton's 2017 implementation notes over a set of tables (trivially
// copyable; used both by the precomputation, over its intermediate tables, and by the renderer,
// over the final ones). Every function is ATMOS_HD. Construct it from (atmosphere, config): the
// constructor computes `k`.
struct BrunetonLut {
    AtmosphereParameters atm;
    BrunetonConfig cfg;
    TableView transmittance_table;  // 3 channels
    TableView irradiance_table;     // 3 channels (indirect only, as the seed)
    TableView scattering_table;     // 3 channels (separate) or 4 (combined)
    TableView single_mie_table;     // 3 channels, separate storage only
    BrunetonConstants k;            // of atm and cfg

    BrunetonLut() = default;
    BrunetonLut(const AtmosphereParameters& atmosphere, const BrunetonConfig& config)
        : atm(atmosphere), cfg(config) {
        k.bottom = atm.bottom_radius;
        k.top = atm.top_radius;
        k.bottom2 = atm.bottom_radius * atm.bottom_radius;
        k.H = HorizonH();
        k.H2 = k.H * k.H;
        k.mu_s_d_min = atm.top_radius - atm.bottom_radius;
        k.mu_s_d_range = k.H - k.mu_s_d_min;
        const double D =
            DistanceToTopAtmosphereBoundary(atm.bottom_radius, atm.mu_s_min, atm.top_radius);
        k.mu_s_big_a = (D - k.mu_s_d_min) / k.mu_s_d_range;
        k.irradiance_r_range = atm.top_radius - atm.bottom_radius;
        k.transmittance_u = TexelCentreMap(cfg.transmittance_width);
        k.transmittance_v = TexelCentreMap(cfg.transmittance_height);
        k.irradiance_u = TexelCentreMap(cfg.irradiance_width);
        k.irradiance_v = TexelCentreMap(cfg.irradiance_height);
        k.scattering_r = TexelCentreMap(cfg.scattering_r);
        k.scattering_mu_half = TexelCentreMap(cfg.scattering_mu / 2);
        k.scattering_mu_s = TexelCentreMap(cfg.scattering_mu_s);
    }

    // Names every table (render/stages.h: a stage holding a lut copies these).
    template <typename V>
    void VisitTables(V& v) {
        v(transmittance_table);
        v(irradiance_table);
        v(scattering_table);
        v(single_mie_table);
    }

    // ---- helpers (Bruneton's 2017 implementation notes, "ClampRadius", distances) ----
    ATMOS_HD double ClampRadius(double r) const {
        return Clamp(r, atm.bottom_radius, atm.top_radius);
    }
    // Distance to the top boundary for a horizontal ray at ground level.
    ATMOS_HD double HorizonH() const {
        return Sqrt(atm.top_radius * atm.top_radius - atm.bottom_radius * atm.bottom_radius);
    }
    // Bruneton's 2017 implementation notes "DistanceToNearestAtmosphereBoundary".
    ATMOS_HD double DistanceToNearestAtmosphereBoundary(double r, double mu,
                                                        bool ray_r_mu_intersects_ground) const {
        return ray_r_mu_intersects_ground
                   ? DistanceToBottomAtmosphereBoundary(r, mu, atm.bottom_radius)
                   : DistanceToTopAtmosphereBoundary(r, mu, atm.top_radius);
    }

    // ---- transmittance (Bruneton's 2017 implementation notes, "Precomputation" / "Lookup" of
    // transmittance) ---- GetTransmittanceTextureUvFromRMu, with the constants of k.
    ATMOS_HD void TransmittanceUvFromRMu(double r, double mu, double* u, double* v) const {
        ATMOS_DASSERT(k.H > 0.0);
        const double rho = SafeSqrt(r * r - k.bottom2);
        const double d = DistanceToTopAtmosphereBoundary(r, mu, k.top);
        const double d_min = k.top - r;
        const double d_max = rho + k.H;
        const double x_mu = (d - d_min) / (d_max - d_min);
        const double x_r = rho / k.H;
        *u = k.transmittance_u(x_mu);
        *v = k.transmittance_v(x_r);
    }
    // The same, everything computed per call (the seed's form; tests hold the
    // hoisted one against it).
    ATMOS_HD void TransmittanceUvFromRMuGeneric(double r, double mu, double* u, double* v) const {
        const double H = HorizonH();
        const double rho = SafeSqrt(r * r - atm.bottom_radius * atm.bottom_radius);
        const double d = DistanceToTopAtmosphereBoundary(r, mu, atm.top_radius);
        const double d_min = atm.top_radius - r;
        const double d_max = rho + H;
        const double x_mu = (d - d_min) / (d_max - d_min);
        const double x_r = rho / H;
        *u = GetTextureCoordFromUnitRange(x_mu, cfg.transmittance_width);
        *v = GetTextureCoordFromUnitRange(x_r, cfg.transmittance_height);
    }
    // GetRMuFromTransmittanceTextureUv (the inverse).
    ATMOS_HD void RMuFromTransmittanceUv(double u, double v, double* r, double* mu) const {
        const double x_mu = GetUnitRangeFromTextureCoord(u, cfg.transmittance_width);
        const double x_r = GetUnitRangeFromTextureCoord(v, cfg.transmittance_height);
        const double H = HorizonH();
        const double rho = H * x_r;
        *r = Sqrt(rho * rho + atm.bottom_radius * atm.bottom_radius);
        const double d_min = atm.top_radius - *r;
        const double d_max = rho + H;
        const double d = d_min + x_mu * (d_max - d_min);
        const double m = d == 0.0 ? 1.0 : (H * H - rho * rho - d * d) / (2.0 * *r * d);
        *mu = ClampCosine(m);
    }
    // GetTransmittanceToTopAtmosphereBoundary: one lookup (fixed layout).
    ATMOS_HD Rgb TransmittanceToTop(double r, double mu) const {
        double u, v;
        TransmittanceUvFromRMu(ClampRadius(r), ClampCosine(mu), &u, &v);
        return SampleBilinearRgb(transmittance_table, u, v);
    }
    // The generic form (TableView::SampleBilinear, per-call constants).
    ATMOS_HD Rgb TransmittanceToTopGeneric(double r, double mu) const {
        double u, v;
        TransmittanceUvFromRMuGeneric(ClampRadius(r), ClampCosine(mu), &u, &v);
        return transmittance_table.SampleBilinear(u, v).rgb();
    }
    // GetTransmittance between (r, mu) and the point at distance d along the ray;
    // the caller says whether the ray (r, mu) hits the ground (Bruneton's 2017 implementation
    // notes: not recomputed here, because rounding makes that test unreliable at the horizon).
    ATMOS_HD Rgb Transmittance(double r, double mu, double d,
                               bool ray_r_mu_intersects_ground) const {
        const double r_d = ClampRadius(Sqrt(d * d + 2.0 * r * mu * d + r * r));
        const double mu_d = ClampCosine((r * mu + d) / r_d);
        Rgb t;
        if (ray_r_mu_intersects_ground) {
            t = TransmittanceToTop(r_d, -mu_d) / TransmittanceToTop(r, -mu);
        } else {
            t = TransmittanceToTop(r, mu) / TransmittanceToTop(r_d, mu_d);
        }
        return SafeRatio(t);
    }
    // GetTransmittanceToSun: the visible fraction of the sun's disc above the
    // horizon as a smoothstep (Bruneton's 2017 implementation notes, "Transmittance to the Sun").
    ATMOS_HD Rgb TransmittanceToSun(double r, double mu_s) const {
        const double f = SunAboveHorizon(r, mu_s);
        if (f <= 0.0) return Rgb(0.0f);
        return TransmittanceToTop(r, mu_s) * static_cast<float>(f);
    }
    // GetTransmittanceToSun's visible fraction of the sun's disc above the
    // horizon at (r, mu_s): 0 when the sun is below it, where the
    // transmittance to the sun is 0.
    ATMOS_HD double SunAboveHorizon(double r, double mu_s) const {
        const double sin_theta_h = atm.bottom_radius / r;
        const double cos_theta_h = -SafeSqrt(1.0 - sin_theta_h * sin_theta_h);
        const double a = sin_theta_h * atm.sun_angular_radius;
        return SmoothStep(-a, a, mu_s - cos_theta_h);
    }

    // ---- scattering table mapping (Bruneton's 2017 implementation notes, "Precomputation" of
    // single scattering) ---- The mu_s part of GetScatteringTextureUvwzFromRMuMuSNu (constants of
    // k).
    ATMOS_HD double ScatteringUMuS(double mu_s) const { return BrunetonUMuS(k, mu_s); }
    // The (mu, r) part: v = u_mu, w = u_r (constants of k).
    ATMOS_HD void ScatteringUMuR(double r, double mu, bool ray_r_mu_intersects_ground, double* u_mu,
                                 double* u_r) const {
        ATMOS_DASSERT(k.H > 0.0);
        const double rho = SafeSqrt(r * r - k.bottom2);
        *u_r = k.scattering_r(rho / k.H);
        const double r_mu = r * mu;
        const double discriminant = r_mu * r_mu - r * r + k.bottom2;
        if (ray_r_mu_intersects_ground) {
            const double d = -r_mu - SafeSqrt(discriminant);
            const double d_min = r - k.bottom;
            const double d_max = rho;
            const double x = d_max == d_min ? 0.0 : (d - d_min) / (d_max - d_min);
            *u_mu = 0.5 - 0.5 * k.scattering_mu_half(x);
        } else {
            const double d = -r_mu + SafeSqrt(discriminant + k.H2);
            const double d_min = k.top - r;
            const double d_max = rho + k.H;
            *u_mu = 0.5 + 0.5 * k.scattering_mu_half((d - d_min) / (d_max - d_min));
        }
    }
    // The generic forms of the two (per-call constants; for the tests).
    ATMOS_HD double ScatteringUMuSGeneric(double mu_s) const {
        const double H = HorizonH();
        const double d = DistanceToTopAtmosphereBoundary(atm.bottom_radius, mu_s, atm.top_radius);
        const double d_min = atm.top_radius - atm.bottom_radius;
        const double d_max = H;
        const double a = (d - d_min) / (d_max - d_min);
        const double D =
            DistanceToTopAtmosphereBoundary(atm.bottom_radius, atm.mu_s_min, atm.top_radius);
        const double A = (D - d_min) / (d_max - d_min);
        return GetTextureCoordFromUnitRange(Max(1.0 - a / A, 0.0) / (1.0 + a), cfg.scattering_mu_s);
    }
    ATMOS_HD void ScatteringUMuRGeneric(double r, double mu, bool ray_r_mu_intersects_ground,
                                        double* u_mu, double* u_r) const {
        const double H = HorizonH();
        const double rho = SafeSqrt(r * r - atm.bottom_radius * atm.bottom_radius);
        *u_r = GetTextureCoordFromUnitRange(rho / H, cfg.scattering_r);
        const double r_mu = r * mu;
        const double discriminant = r_mu * r_mu - r * r + atm.bottom_radius * atm.bottom_radius;
        const int half = cfg.scattering_mu / 2;
        if (ray_r_mu_intersects_ground) {
            // Distance to the ground, between r - bottom (mu = -1) and rho (horizon).
            const double d = -r_mu - SafeSqrt(discriminant);
            const double d_min = r - atm.bottom_radius;
            const double d_max = rho;
            const double x = d_max == d_min ? 0.0 : (d - d_min) / (d_max - d_min);
            *u_mu = 0.5 - 0.5 * GetTextureCoordFromUnitRange(x, half);
        } else {
            // Distance to the top, between top - r (mu = 1) and rho + H (horizon).
            const double d = -r_mu + SafeSqrt(discriminant + H * H);
            const double d_min = atm.top_radius - r;
            const double d_max = rho + H;
            *u_mu = 0.5 + 0.5 * GetTextureCoordFromUnitRange((d - d_min) / (d_max - d_min), half);
        }
    }
    // GetScatteringTextureUvwzFromRMuMuSNu: (u_nu, u_mu_s, u_mu, u_r).
    ATMOS_HD void ScatteringUvwz(double r, double mu, double mu_s, double nu,
                                 bool ray_r_mu_intersects_ground, double uvwz[4]) const {
        ScatteringUMuR(r, mu, ray_r_mu_intersects_ground, &uvwz[2], &uvwz[3]);
        uvwz[1] = ScatteringUMuS(mu_s);
        uvwz[0] = (nu + 1.0) / 2.0;
    }
    ATMOS_HD void ScatteringUvwzGeneric(double r, double mu, double mu_s, double nu,
                                        bool ray_r_mu_intersects_ground, double uvwz[4]) const {
        ScatteringUMuRGeneric(r, mu, ray_r_mu_intersects_ground, &uvwz[2], &uvwz[3]);
        uvwz[1] = ScatteringUMuSGeneric(mu_s);
        uvwz[0] = (nu + 1.0) / 2.0;
    }
    // GetRMuMuSNuFromScatteringTextureUvwz (the inverse).
    ATMOS_HD void RMuMuSNuFromScatteringUvwz(const double uvwz[4], double* r, double* mu,
                                             double* mu_s, double* nu,
                                             bool* ray_r_mu_intersects_ground) const {
        ATMOS_DASSERT(k.H > 0.0);
        const double H = k.H;  // HorizonH()
        const double rho = H * GetUnitRangeFromTextureCoord(uvwz[3], cfg.scattering_r);
        *r = Sqrt(rho * rho + atm.bottom_radius * atm.bottom_radius);
        const int half = cfg.scattering_mu / 2;
        if (uvwz[2] < 0.5) {
            const double d_min = *r - atm.bottom_radius;
            const double d_max = rho;
            const double d =
                d_min + (d_max - d_min) * GetUnitRangeFromTextureCoord(1.0 - 2.0 * uvwz[2], half);
            *mu = d == 0.0 ? -1.0 : ClampCosine(-(rho * rho + d * d) / (2.0 * *r * d));
            *ray_r_mu_intersects_ground = true;
        } else {
            const double d_min = atm.top_radius - *r;
            const double d_max = rho + H;
            const double d =
                d_min + (d_max - d_min) * GetUnitRangeFromTextureCoord(2.0 * uvwz[2] - 1.0, half);
            *mu = d == 0.0 ? 1.0 : ClampCosine((H * H - rho * rho - d * d) / (2.0 * *r * d));
            *ray_r_mu_intersects_ground = false;
        }
        const double x_mu_s = GetUnitRangeFromTextureCoord(uvwz[1], cfg.scattering_mu_s);
        // The seed's d_min = top - bottom, d_max = H and A from k (the same
        // operations, done once in the constructor).
        const double d_min = k.mu_s_d_min;
        const double A = k.mu_s_big_a;
        const double a = (A - x_mu_s * A) / (1.0 + x_mu_s * A);
        const double d = d_min + Min(a, A) * k.mu_s_d_range;
        *mu_s = d == 0.0 ? 1.0 : ClampCosine((H * H - d * d) / (2.0 * atm.bottom_radius * d));
        *nu = ClampCosine(uvwz[0] * 2.0 - 1.0);
    }
    // GetRMuMuSNuFromScatteringTextureFragCoord for texel (x, y, z) of the 3D
    // table (x = nu * MU_S + mu_s): texel centres, nu clamped to its range given
    // mu and mu_s.
    ATMOS_HD void RMuMuSNuFromTexel(int x, int y, int z, double* r, double* mu, double* mu_s,
                                    double* nu, bool* ray_r_mu_intersects_ground) const {
        const int nu_index = x / cfg.scattering_mu_s;
        const int mu_s_index = x % cfg.scattering_mu_s;
        const double uvwz[4] = {
            cfg.scattering_nu > 1 ? static_cast<double>(nu_index) / (cfg.scattering_nu - 1) : 0.5,
            (mu_s_index + 0.5) / cfg.scattering_mu_s, (y + 0.5) / cfg.scattering_mu,
            (z + 0.5) / cfg.scattering_r};
        RMuMuSNuFromScatteringUvwz(uvwz, r, mu, mu_s, nu, ray_r_mu_intersects_ground);
        *nu = ClampNu(*nu, *mu, *mu_s);
    }
    // Its parts for a row of texels (mu_s depends on x % MU_S only, nu before
    // its clamp on x / MU_S only): nu of texel column nu_index before the clamp,
    // and the clamp to the range that mu and mu_s allow.
    ATMOS_HD double TexelNuUnclamped(int nu_index) const {
        const double u =
            cfg.scattering_nu > 1 ? static_cast<double>(nu_index) / (cfg.scattering_nu - 1) : 0.5;
        return ClampCosine(u * 2.0 - 1.0);
    }
    ATMOS_HD static double ClampNu(double nu, double mu, double mu_s) {
        const double s = SafeSqrt((1.0 - mu * mu) * (1.0 - mu_s * mu_s));
        return Clamp(nu, mu * mu_s - s, mu * mu_s + s);
    }

    // 4D lookup as two 3D lookups (Bruneton's 2017 implementation notes GetScattering), from the
    // mapped coordinates; quadrilinear interpolation.
    ATMOS_HD static Vec4f Lookup4D(const TableView& table, int nu_size, const double uvwz[4]) {
        const double tex_coord_x = uvwz[0] * (nu_size - 1);
        const double tex_x = floor(tex_coord_x);
        const float lerp = static_cast<float>(tex_coord_x - tex_x);
        const double u0 = (tex_x + uvwz[1]) / nu_size;
        const double u1 = (tex_x + 1.0 + uvwz[1]) / nu_size;
        return table.SampleTrilinear(u0, uvwz[2], uvwz[3]) * (1.0f - lerp) +
               table.SampleTrilinear(u1, uvwz[2], uvwz[3]) * lerp;
    }
    // The texels and weights of the 4D lookup of table t (the scattering
    // layout) at uvwz: computed once, shared by the tables of that layout.
    ATMOS_HD void Split4D(const TableView& t, const double uvwz[4], Bruneton4DRows* rows,
                          Bruneton4DColumns* cols) const {
        *rows = BrunetonSplitRows(t.width, t.height, t.depth, uvwz[2], uvwz[3]);
        const double tex_coord_x = uvwz[0] * (cfg.scattering_nu - 1);
        const double tex_x = floor(tex_coord_x);
        *cols = BrunetonSplitColumns(t.width, cfg.scattering_nu, tex_x,
                                     static_cast<float>(tex_coord_x - tex_x), uvwz[1]);
    }
    // A 3-channel table (the precomputation's delta tables) through the
    // fixed-layout lookup (BrunetonSample4D, bit-identical to Lookup4D).
    ATMOS_HD Vec4f GetScattering(const TableView& table, double r, double mu, double mu_s,
                                 double nu, bool ray_r_mu_intersects_ground) const {
        double uvwz[4];
        ScatteringUvwz(ClampRadius(r), ClampCosine(mu), ClampCosine(mu_s), ClampCosine(nu),
                       ray_r_mu_intersects_ground, uvwz);
        if (table.channels != 3) return Lookup4D(table, cfg.scattering_nu, uvwz);
        Bruneton4DRows rows;
        Bruneton4DColumns cols;
        Split4D(table, uvwz, &rows, &cols);
        float o[3];
        BrunetonSample4D<3>(table.data, rows, cols, o);
        Vec4f v;
        v.x = o[0];
        v.y = o[1];
        v.z = o[2];
        return v;
    }

    // Bruneton's 2017 implementation notes GetExtrapolatedSingleMieScattering (combined storage).
    ATMOS_HD Rgb ExtrapolatedSingleMie(const Vec4f& s) const {
        if (s.x <= 0.0f) return Rgb(0.0f);
        const Vec3d ratio = atm.mie_scattering / atm.rayleigh_scattering *
                            (atm.rayleigh_scattering.x / atm.mie_scattering.x);
        return s.rgb() * (s.w / s.x) * Rgb(ratio);
    }
    // Bruneton's 2017 implementation notes GetCombinedScattering: Rayleigh + multiple scattering,
    // and the single Mie scattering (without phase functions). One split for both tables,
    // fixed-layout lookups.
    ATMOS_HD Rgb CombinedScattering(double r, double mu, double mu_s, double nu,
                                    bool ray_r_mu_intersects_ground, Rgb* single_mie) const {
        double uvwz[4];
        ScatteringUvwz(ClampRadius(r), ClampCosine(mu), ClampCosine(mu_s), ClampCosine(nu),
                       ray_r_mu_intersects_ground, uvwz);
        const TableView& t = scattering_table;
        Bruneton4DRows rows;
        Bruneton4DColumns cols;
        Split4D(t, uvwz, &rows, &cols);
        if (cfg.combined_mie) {
            float c[4];
            BrunetonSample4D<4>(t.data, rows, cols, c);
            Vec4f s;
            s.x = c[0];
            s.y = c[1];
            s.z = c[2];
            s.w = c[3];
            *single_mie = ExtrapolatedSingleMie(s);
            return s.rgb();
        }
        float s[3], m[3];
        BrunetonSample4D<3>(t.data, rows, cols, s);
        BrunetonSample4D<3>(single_mie_table.data, rows, cols, m);
        *single_mie = Rgb(m[0], m[1], m[2]);
        return Rgb(s[0], s[1], s[2]);
    }
    // The generic form (TableView::SampleTrilinear, per-call constants).
    ATMOS_HD Rgb CombinedScatteringGeneric(double r, double mu, double mu_s, double nu,
                                           bool ray_r_mu_intersects_ground, Rgb* single_mie) const {
        double uvwz[4];
        ScatteringUvwzGeneric(ClampRadius(r), ClampCosine(mu), ClampCosine(mu_s), ClampCosine(nu),
                              ray_r_mu_intersects_ground, uvwz);
        const Vec4f s = Lookup4D(scattering_table, cfg.scattering_nu, uvwz);
        if (cfg.combined_mie) {
            *single_mie = ExtrapolatedSingleMie(s);
        } else {
            *single_mie = Lookup4D(single_mie_table, cfg.scattering_nu, uvwz).rgb();
        }
        return s.rgb();
    }

    // ---- irradiance (Bruneton's 2017 implementation notes, "Ground irradiance") ----
    ATMOS_HD void IrradianceUvFromRMuS(double r, double mu_s, double* u, double* v) const {
        ATMOS_DASSERT(k.H > 0.0);
        const double x_r = (r - k.bottom) / k.irradiance_r_range;
        const double x_mu_s = mu_s * 0.5 + 0.5;
        *u = k.irradiance_u(x_mu_s);
        *v = k.irradiance_v(x_r);
    }
    ATMOS_HD void IrradianceUvFromRMuSGeneric(double r, double mu_s, double* u, double* v) const {
        const double x_r = (r - atm.bottom_radius) / (atm.top_radius - atm.bottom_radius);
        const double x_mu_s = mu_s * 0.5 + 0.5;
        *u = GetTextureCoordFromUnitRange(x_mu_s, cfg.irradiance_width);
        *v = GetTextureCoordFromUnitRange(x_r, cfg.irradiance_height);
    }
    ATMOS_HD void RMuSFromIrradianceUv(double u, double v, double* r, double* mu_s) const {
        const double x_mu_s = GetUnitRangeFromTextureCoord(u, cfg.irradiance_width);
        const double x_r = GetUnitRangeFromTextureCoord(v, cfg.irradiance_height);
        *r = atm.bottom_radius + x_r * (atm.top_radius - atm.bottom_radius);
        *mu_s = ClampCosine(2.0 * x_mu_s - 1.0);
    }
    // A 3-channel irradiance table (fixed layout).
    ATMOS_HD Rgb GetIrradiance(const TableView& table, double r, double mu_s) const {
        ATMOS_DASSERT(table.channels == 3);
        double u, v;
        IrradianceUvFromRMuS(ClampRadius(r), ClampCosine(mu_s), &u, &v);
        return SampleBilinearRgb(table, u, v);
    }
    ATMOS_HD Rgb GetIrradianceGeneric(const TableView& table, double r, double mu_s) const {
        double u, v;
        IrradianceUvFromRMuSGeneric(ClampRadius(r), ClampCosine(mu_s), &u, &v);
        return table.SampleBilinear(u, v).rgb();
    }
    // Bruneton's 2017 implementation notes ComputeDirectIrradiance (per unit solar irradiance): the
    // average cosine over the visible part of the sun's disc times T to the top.
    ATMOS_HD Rgb DirectIrradiance(double r, double mu_s) const {
        const double alpha_s = atm.sun_angular_radius;
        const double c =
            mu_s < -alpha_s
                ? 0.0
                : (mu_s > alpha_s ? mu_s : (mu_s + alpha_s) * (mu_s + alpha_s) / (4.0 * alpha_s));
        return TransmittanceToTop(r, mu_s) * static_cast<float>(c);
    }

    // ---- rendering (Bruneton's 2017 implementation notes, "Rendering") ----
    // GetSkyRadiance, per unit solar irradiance. `ray_hits_ground` is the
    // caller's (robust) answer to "does the view ray meet the ground".
    ATMOS_HD Rgb SkyRadiance(Vec3d camera, const Vec3d& view_ray, double shadow_length,
                             const Vec3d& sun_direction, bool ray_hits_ground,
                             Rgb* transmittance_out) const {
        double r = Length(camera);
        double rmu = Dot(camera, view_ray);
        const double disc = rmu * rmu - r * r + atm.top_radius * atm.top_radius;
        const double to_top = disc >= 0.0 ? -rmu - Sqrt(disc) : -1.0;
        if (r > atm.top_radius) {
            if (to_top > 0.0) {
                camera = camera + view_ray * to_top;
                r = atm.top_radius;
                rmu += to_top;
            } else {
                *transmittance_out = Rgb(1.0f);
                return Rgb(0.0f);
            }
        }
        r = ClampRadius(r);
        const double mu = ClampCosine(rmu / r);
        const double mu_s = ClampCosine(Dot(camera, sun_direction) / r);
        const double nu = ClampCosine(Dot(view_ray, sun_direction));
        *transmittance_out = ray_hits_ground ? Rgb(0.0f) : TransmittanceToTop(r, mu);
        Rgb single_mie, scattering;
        if (shadow_length == 0.0) {
            scattering = CombinedScattering(r, mu, mu_s, nu, ray_hits_ground, &single_mie);
        } else {
            // Light shafts (Bruneton's 2017 implementation notes; paper Eq. 18): omit the first l
            // metres.
            const double d = shadow_length;
            const double r_p = ClampRadius(Sqrt(d * d + 2.0 * r * mu * d + r * r));
            const double mu_p = (r * mu + d) / r_p;
            const double mu_s_p = (r * mu_s + d * nu) / r_p;
            scattering = CombinedScattering(r_p, mu_p, mu_s_p, nu, ray_hits_ground, &single_mie);
            const Rgb shadow_t = Transmittance(r, mu, shadow_length, ray_hits_ground);
            scattering = scattering * shadow_t;
            single_mie = single_mie * shadow_t;
        }
        return scattering * static_cast<float>(RayleighPhase(nu)) +
               single_mie * static_cast<float>(MiePhase(atm, nu));
    }

    // GetSkyRadianceToPoint: scattering between the camera and `point` (aerial
    // perspective) as the difference of two lookups, and the transmittance.
    ATMOS_HD Rgb SkyRadianceToPoint(Vec3d camera, const Vec3d& point, double shadow_length,
                                    const Vec3d& sun_direction, bool ray_hits_ground,
                                    Rgb* transmittance_out) const {
        const Vec3d view_ray = Normalize(point - camera);
        double r = Length(camera);
        double rmu = Dot(camera, view_ray);
        const double disc = rmu * rmu - r * r + atm.top_radius * atm.top_radius;
        const double to_top = disc >= 0.0 ? -rmu - Sqrt(disc) : -1.0;
        if (r > atm.top_radius && to_top > 0.0) {
            camera = camera + view_ray * to_top;
            r = atm.top_radius;
            rmu += to_top;
        }
        r = ClampRadius(r);
        const double mu = ClampCosine(rmu / r);
        const double mu_s = ClampCosine(Dot(camera, sun_direction) / r);
        const double nu = ClampCosine(Dot(view_ray, sun_direction));
        double d = Length(point - camera);
        *transmittance_out = Transmittance(r, mu, d, ray_hits_ground);
        Rgb single_mie;
        Rgb scattering = CombinedScattering(r, mu, mu_s, nu, ray_hits_ground, &single_mie);
        // Second lookup at the point, or shadow_length before it (paper Eq. 17).
        d = Max(d - shadow_length, 0.0);
        const double r_p = ClampRadius(Sqrt(d * d + 2.0 * r * mu * d + r * r));
        const double mu_p = (r * mu + d) / r_p;
        const double mu_s_p = (r * mu_s + d * nu) / r_p;
        Rgb single_mie_p;
        const Rgb scattering_p =
            CombinedScattering(r_p, mu_p, mu_s_p, nu, ray_hits_ground, &single_mie_p);
        Rgb shadow_t = *transmittance_out;
        if (shadow_length > 0.0) shadow_t = Transmittance(r, mu, d, ray_hits_ground);
        scattering = scattering - shadow_t * scattering_p;
        single_mie = single_mie - shadow_t * single_mie_p;
        if (cfg.combined_mie) {
            Vec4f s;
            s.x = scattering.x;
            s.y = scattering.y;
            s.z = scattering.z;
            s.w = single_mie.x;
            single_mie = ExtrapolatedSingleMie(s);
        }
        // Bruneton's 2017 implementation notes fades single Mie out below mu_s = 0.01 ("hack to
        // avoid rendering artifacts when the sun is below the horizon": the two lookups'
        // interpolation errors do not cancel in the difference, and the Mie phase's forward peak
        // magnifies them). That fade also removes the real sunset glow over the ground (issue 15),
        // so by default the faded part is replaced by the single Mie integral along the segment
        // itself (to the point, or shadow_length before it), which has no
        // difference to go wrong.
        const double fade = SmoothStep(0.0, 0.01, mu_s);
        if (cfg.low_sun_mie != 2 && fade < 1.0) {
            single_mie = single_mie * static_cast<float>(fade);
            if (cfg.low_sun_mie == 0) {
                single_mie += SegmentSingleMie(r, mu, mu_s, nu, d) * static_cast<float>(1.0 - fade);
            }
        }
        return Max(scattering, Rgb(0.0f)) * static_cast<float>(RayleighPhase(nu)) +
               Max(single_mie, Rgb(0.0f)) * static_cast<float>(MiePhase(atm, nu));
    }

    // Single Mie scattering (without the phase function) between the camera at
    // (r, mu, mu_s, nu) and the point at distance d: the midpoint rule in
    // cfg.low_sun_mie_steps samples, the view ray's transmittance from the
    // optical depths of the constituents accumulated along the segment (each
    // channel's from them), the sun's from the table (GetTransmittanceToSun,
    // as in the precomputed single scattering). The exponential is ExpLaneF
    // (physics/vector_exp.h, float, within 2 ulp), which the wide evaluator
    // runs as one vector loop over its channels. Samples where the sun is
    // below the horizon add nothing and are skipped.
    ATMOS_HD Rgb SegmentSingleMie(double r, double mu, double mu_s, double nu, double d) const {
        const int n = cfg.low_sun_mie_steps;
        const double dt = d / n;
        double depth_r = 0.0, depth_m = 0.0, depth_o = 0.0;
        Vec3d sum;
        for (int i = 0; i < n; ++i) {
            const double t = (i + 0.5) * dt;
            const double r_t = ClampRadius(Sqrt(t * t + 2.0 * r * mu * t + r * r));
            const Densities rho = GetDensities(atm, r_t - atm.bottom_radius);
            const double mid_r = depth_r + rho.rayleigh * (0.5 * dt);
            const double mid_m = depth_m + rho.mie * (0.5 * dt);
            const double mid_o = depth_o + rho.absorption * (0.5 * dt);
            depth_r += rho.rayleigh * dt;
            depth_m += rho.mie * dt;
            depth_o += rho.absorption * dt;
            // A sample in the planet's shadow adds exactly 0 (a zero
            // transmittance to the sun times finite factors): skipped.
            const double mu_s_t = ClampCosine((r * mu_s + t * nu) / r_t);
            const double f = SunAboveHorizon(r_t, mu_s_t);
            if (f <= 0.0) continue;
            const Rgb ts = TransmittanceToTop(r_t, mu_s_t) * static_cast<float>(f);
            const double m = rho.mie * dt;
            for (int c = 0; c < 3; ++c) {
                const double tau = atm.rayleigh_scattering[c] * mid_r +
                                   atm.mie_extinction[c] * mid_m +
                                   atm.absorption_extinction[c] * mid_o;
                const float e = ExpLaneF(static_cast<float>(-tau));
                sum[c] += static_cast<double>(ts[c]) * static_cast<double>(e) * m;
            }
        }
        return Rgb(sum * atm.mie_scattering);
    }

    // GetSunAndSkyIrradiance (per unit solar irradiance) at `point` with
    // `normal`: returns the sun's, writes the sky's (horizontal-surface table
    // times (1 + n.up) / 2, the paper's approximation).
    ATMOS_HD Rgb SunAndSkyIrradiance(const Vec3d& point, const Vec3d& normal,
                                     const Vec3d& sun_direction, Rgb* sky_irradiance) const {
        const double r = ClampRadius(Length(point));
        const double mu_s = ClampCosine(Dot(point, sun_direction) / Length(point));
        *sky_irradiance = GetIrradiance(irradiance_table, r, mu_s) *
                          static_cast<float>((1.0 + Dot(normal, point) / Length(point)) * 0.5);
        return TransmittanceToSun(r, mu_s) *
               static_cast<float>(Max(Dot(normal, sun_direction), 0.0));
    }

    ATMOS_HD static double SmoothStep(double e0, double e1, double x) {
        const double t = Clamp((x - e0) / (e1 - e0), 0.0, 1.0);
        return t * t * (3.0 - 2.0 * t);
    }
    // min(t, 1) and 0 for a non-finite ratio (0 / 0 at T = 0).
    ATMOS_HD static Rgb SafeRatio(const Rgb& t) {
        Rgb out;
        for (int i = 0; i < 3; ++i) out[i] = IsFinite(t[i]) ? Clamp(t[i], 0.0f, 1.0f) : 0.0f;
        return out;
    }
};

// The per-pixel evaluator: sky radiance (to space, or to the ground point),
// the lit ground, and the transmittance.
struct BrunetonEvaluator {
    BrunetonLut lut;

    // Names every table (physics/ray.h: the device launch re-points these).
    template <typename V>
    void VisitTables(V& v) {
        lut.VisitTables(v);
    }

    ATMOS_HD RayResult Evaluate(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                                bool want_ground) const {
        RayResult out;
        out.transmittance = Rgb(1.0f);
        const AtmosphereParameters& atm = lut.atm;
        const AtmosphereSegment seg =
            ClipToAtmosphere(camera, dir, atm.bottom_radius, atm.top_radius);
        out.hits_ground = seg.hits_ground;
        if (!seg.inside && !seg.hits_ground) return out;  // misses the atmosphere: L = 0, T = 1
        if (!seg.hits_ground) {
            out.sky = lut.SkyRadiance(camera, dir, 0.0, sun, false, &out.transmittance);
            return out;
        }
        // A camera on the ground looking down sees the ground at its feet (zero
        // length: no scattering, T = 1).
        const Vec3d ground = seg.inside ? camera + dir * seg.t_end : camera;
        if (seg.inside) {
            out.sky = lut.SkyRadianceToPoint(camera, ground, 0.0, sun, true, &out.transmittance);
        }
        if (want_ground && MaxComponent(atm.ground_albedo) > 0.0) {
            const Vec3d normal = Normalize(ground);
            Rgb sky_irradiance;
            const Rgb sun_irradiance =
                lut.SunAndSkyIrradiance(ground, normal, sun, &sky_irradiance);
            out.ground = Rgb(atm.ground_albedo * (1.0 / kPi)) * (sun_irradiance + sky_irradiance) *
                         out.transmittance;
        }
        return out;
    }
};

// Host-owned tables of one precomputation.
struct BrunetonTables {
    Table transmittance;  // W x H, 3 channels
    Table irradiance;     // W x H, 3 channels
    Table scattering;     // NU*MU_S x MU x R, 3 or 4 channels
    Table single_mie;     // same size, 3 channels (separate storage), else empty
};

// Called with the tables as they stand after each scattering order (1..N), and
// that order's scattering density J_n (nullptr for order 1): for tests.
using BrunetonOrderCallback =
    std::function<void(int order, const BrunetonTables& tables, const Table* density)>;

// The whole precomputation of Bruneton's 2017 implementation notes, stage by stage through RunStage
// (models/bruneton_stages.h): on the CPU (ParallelFor) or, on the CUDA backend,
// on the device. Tables are per unit solar irradiance. Throws atmos::Error for
// an invalid configuration. Each stage's time is in the stage log
// (StageLogScope, render/stages.h).
void PrecomputeBruneton(const AtmosphereParameters& atmosphere, const BrunetonConfig& config,
                        BrunetonTables* tables, const BrunetonOrderCallback& on_order = nullptr);

// The precomputation of every batch of a wide group at once, on the CPU
// (bruneton_wide_precompute.cpp): tables of n = 3 x batches.size() channels,
// channel 3b + c = channel c of batch b's PrecomputeBruneton tables (the CPU
// backend's), bit for bit; each texel's geometry computed once for all
// channels. Separate Mie storage only; the batches as MakeWideCoefficients
// takes them. Each stage's time is in the stage log ("bruneton wide ...").
void PrecomputeBrunetonWide(const std::vector<AtmosphereParameters>& batches,
                            const BrunetonConfig& config, BrunetonTables* tables);

// Checks sizes and orders; throws atmos::Error naming the bad option.
void ValidateBrunetonConfig(const BrunetonConfig& config);

// A lookup over `tables`.
BrunetonLut MakeBrunetonLut(const AtmosphereParameters& atmosphere, const BrunetonConfig& config,
                            const BrunetonTables& tables);

class BrunetonModel : public EvaluatorModel<BrunetonModel> {
  public:
    static const OptionTable<BrunetonConfig>& OptionRows();
    explicit BrunetonModel(const BrunetonConfig& options);
    static ModelInfo StaticInfo();
    const ModelInfo& Info() const override { return info_; }
    void Prepare(const AtmosphereParameters& atmosphere) override;
    BrunetonEvaluator MakeEvaluator() const;
    const AtmosphereParameters& atmosphere() const { return atm_; }

    bool CanBake() const override { return true; }
    void Bake(const std::string& directory) const override;
    int64_t TableBytes() const override;
    void LoadBaked(const std::string& directory, const AtmosphereParameters& atmosphere) override;
    // The irradiance table (Bruneton's 2017 implementation notes "Ground irradiance": indirect
    // only).
    bool TableSkyIrradiance(double altitude_m, double mu_s, Rgb* out) const override;

    // Wide channel batches (models/bruneton_wide.h; separate Mie storage only).
    void PrepareWide(const std::vector<AtmosphereParameters>& batches,
                     const BatchPrepare& prepare_batch = {}) override;
    void RenderWide(const RenderRequest& request, std::vector<float>* values) const override;
    std::vector<float> SampleWide(const std::vector<SampleQuery>& queries) const override;
    // The n-channel tables of the last PrepareWide (channel 3b + c: batch b's c).
    const BrunetonTables& wide_tables() const { return wide_tables_; }

    const BrunetonConfig& config() const { return config_; }
    const BrunetonTables& tables() const { return tables_; }

  private:
    ModelInfo info_;
    BrunetonConfig config_;
    AtmosphereParameters atm_;
    BrunetonTables tables_;
    bool prepared_ = false;
    // PrepareWide's: batch 0's atmosphere, the per-channel coefficients, the
    // n-channel tables.
    AtmosphereParameters wide_atm_;
    WideCoefficients wide_;
    bool wide_prepared_ = false;
    BrunetonTables wide_tables_;
};

}  // namespace atmos
