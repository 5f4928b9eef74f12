// atmos model `bruneton`: the precomputation's stages (render/stages.h), one
// struct per stage of Bruneton's 2017 implementation notes' precomputation, each doing one texel
// (or, for the incident radiance of the scattering density, one direction) per item, so that the
// CPU (ParallelFor) and the device (one thread per item, src/atmos/cuda/bruneton_stages.cu) run the
// same code.
//
// Source: Bruneton 2017, functions.glsl, every "Precomputation"
// section; the functions each stage implements are named in its comment.
//
// Two stages have a faster CPU form that shares per-row work in std::vectors
// (bruneton_precompute.cpp: single and multiple scattering, one (r, mu) row of
// the scattering table at a time). Those rows are built from the same helpers
// (BrunetonSingleScatteringSample / BrunetonMultipleScatteringSample below),
// in the same order of operations, so the per-texel stage reproduces them to
// rounding; the CPU backend uses the rows, the CUDA backend the stages, and
// tests/bruneton_stages_test.cpp compares the two on the CPU.
#pragma once

#include <cstdint>

#include "models/bruneton.h"
#include "physics/exp_quadrature.h"
#include "physics/transmittance.h"
#include "render/stages.h"

namespace atmos {

// Bruneton's 2017 implementation notes: the number of intervals of each numerical integral.
constexpr int kBrunetonTransmittanceSamples = 500;  // ComputeOpticalLengthToTopAtmosphereBoundary
constexpr int kBrunetonDensityThetaSamples = 16;    // ComputeScatteringDensity: SAMPLE_COUNT
constexpr int kBrunetonIrradianceSamples = 32;      // ComputeIndirectIrradiance: SAMPLE_COUNT
// The incident directions of the scattering density: 16 theta x 32 phi.
constexpr int kBrunetonDirections = kBrunetonDensityThetaSamples * 2 * kBrunetonDensityThetaSamples;
constexpr int kBrunetonLanes = 8;  // independent partial sums (the CPU vectorises them)

ATMOS_HD inline Vec4f BrunetonVec4(const Rgb& c, float w = 0.0f) { return {c.x, c.y, c.z, w}; }

// Texel (x, y, z) of a table `width` x `height` x depth from a flat item index.
ATMOS_HD inline void BrunetonTexelOf(int64_t item, int width, int height, int* x, int* y, int* z) {
    *x = static_cast<int>(item % width);
    const int64_t row = item / width;
    *y = static_cast<int>(row % height);
    *z = static_cast<int>(row / height);
}

// The opening of the per-texel stages of the scattering tables: the texel of
// `item` in a `width` x `height` x depth table and the (r, mu, mu_s, nu) it
// stands for, with whether its view ray hits the ground (Bruneton's 2017 implementation notes
// GetRMuMuSNuFromScatteringTextureFragCoord).
struct BrunetonScatteringTexel {
    int x, y, z;
    double r, mu, mu_s, nu;
    bool ground;
};
ATMOS_HD inline BrunetonScatteringTexel BrunetonScatteringTexelOf(const BrunetonLut& lut,
                                                                  int64_t item, int width,
                                                                  int height) {
    BrunetonScatteringTexel t;
    BrunetonTexelOf(item, width, height, &t.x, &t.y, &t.z);
    lut.RMuMuSNuFromTexel(t.x, t.y, t.z, &t.r, &t.mu, &t.mu_s, &t.nu, &t.ground);
    return t;
}

// The view ray of a scattering texel: n = scattering_samples steps of dx to
// the nearest boundary, and whether any is optically thick (RayHasThickSteps).
struct BrunetonViewSteps {
    int n;
    double dx;
    bool thick;
};
ATMOS_HD inline BrunetonViewSteps BrunetonViewStepsOf(const BrunetonLut& lut, double r, double mu,
                                                      bool ground) {
    const int n = lut.cfg.scattering_samples;
    const double dx = lut.DistanceToNearestAtmosphereBoundary(r, mu, ground) / n;
    return {n, dx, RayHasThickSteps(lut.atm, r, mu, dx, n)};
}

// The lookup `lut` with no tables: the mappings only (a stage that needs no
// table of the lut then copies none to the device).
inline BrunetonLut BrunetonMappingsOnly(const BrunetonLut& lut) {
    return BrunetonLut(lut.atm, lut.cfg);
}

// ---- transmittance (Bruneton's 2017 implementation notes
// ComputeTransmittanceToTopAtmosphereBoundaryTexture) ---- Item: texel x + W * y of the W x H table
// (3 channels).
struct BrunetonTransmittanceStage {
    BrunetonLut lut;  // mappings only
    TableOut out;
    template <typename V>
    void VisitTables(V& v) {
        lut.VisitTables(v);
        v(out);
    }
    ATMOS_HD void operator()(int64_t item) const {
        int x, y, z;
        BrunetonTexelOf(item, out.width, out.height, &x, &y, &z);
        double r, mu;
        lut.RMuFromTransmittanceUv((x + 0.5) / out.width, (y + 0.5) / out.height, &r, &mu);
        const Vec3d tau =
            OpticalDepthToTopAtmosphereBoundary(lut.atm, r, mu, kBrunetonTransmittanceSamples);
        out.Set(x, y, 0, BrunetonVec4(Rgb(Exp(-tau))));
    }
};
ATMOS_DEVICE_STAGE(BrunetonTransmittanceStage)

// ---- direct irradiance (Bruneton's 2017 implementation notes ComputeDirectIrradianceTexture) ----
// Item: texel of the irradiance table; reads the transmittance table.
struct BrunetonDirectIrradianceStage {
    BrunetonLut lut;  // with the transmittance table
    TableOut out;
    template <typename V>
    void VisitTables(V& v) {
        lut.VisitTables(v);
        v(out);
    }
    ATMOS_HD void operator()(int64_t item) const {
        int x, y, z;
        BrunetonTexelOf(item, out.width, out.height, &x, &y, &z);
        double r, mu_s;
        lut.RMuSFromIrradianceUv((x + 0.5) / out.width, (y + 0.5) / out.height, &r, &mu_s);
        out.Set(x, y, 0, BrunetonVec4(lut.DirectIrradiance(r, mu_s)));
    }
};
ATMOS_DEVICE_STAGE(BrunetonDirectIrradianceStage)

// ---- single scattering (Bruneton's 2017 implementation notes ComputeSingleScattering(Texture))
// ---- Sample i of n along the view ray (r, mu): what does not depend on (mu_s, nu), i.e. what one
// (r, mu) row of the table shares: the distance d_i, the radius r_i, and the transmittance from the
// camera times the Rayleigh and Mie densities and the trapezoid weight (Bruneton's 2017
// implementation notes ComputeSingleScatteringIntegrand and the sum of ComputeSingleScattering). On
// a ray with optically thick steps (RayHasThickSteps) `thick` is the node's ThickRayWeights factor
// W_i / sigma_t,i instead (physics/exp_quadrature.h: the seed's rule is not energy conserving
// there).
struct BrunetonSingleSample {
    double d, r;
    Rgb t_rayleigh, t_mie;
};
ATMOS_HD inline BrunetonSingleSample BrunetonSingleScatteringSample(const BrunetonLut& lut,
                                                                    double r, double mu,
                                                                    bool ground, double dx, int i,
                                                                    int n,
                                                                    const Vec3d* thick = nullptr) {
    const AtmosphereParameters& atm = lut.atm;
    BrunetonSingleSample s;
    const double d = i * dx;
    s.d = d;
    s.r = lut.ClampRadius(Sqrt(d * d + 2.0 * r * mu * d + r * r));
    if (thick) {  // W_i / sigma_t,i / dx: the caller multiplies by beta dx
        const double alt = s.r - atm.bottom_radius;
        s.t_rayleigh = Rgb(*thick * (GetProfileDensity(atm.rayleigh_density, alt) / dx));
        s.t_mie = Rgb(*thick * (GetProfileDensity(atm.mie_density, alt) / dx));
        return s;
    }
    const Rgb t = lut.Transmittance(r, mu, d, ground);
    const double alt = s.r - atm.bottom_radius;
    const float w = static_cast<float>(BrunetonQuadratureWeight(lut.cfg.scattering_rule, i, n));
    s.t_rayleigh = t * static_cast<float>(GetProfileDensity(atm.rayleigh_density, alt)) * w;
    s.t_mie = t * static_cast<float>(GetProfileDensity(atm.mie_density, alt)) * w;
    return s;
}
// The (mu_s, nu) part of sample s: the transmittance to the sun at the sample.
ATMOS_HD inline void BrunetonSingleScatteringAdd(const BrunetonLut& lut,
                                                 const BrunetonSingleSample& s, double r,
                                                 double mu_s, double nu, Rgb* sum_rayleigh,
                                                 Rgb* sum_mie) {
    const double mu_s_d = ClampCosine((r * mu_s + s.d * nu) / s.r);
    const Rgb ts = lut.TransmittanceToSun(s.r, mu_s_d);
    *sum_rayleigh += ts * s.t_rayleigh;
    *sum_mie += ts * s.t_mie;
}

// Item: texel of the scattering table (NU * MU_S x MU x R); writes the single
// Rayleigh and Mie scattering (3 channels each, without phase functions).
struct BrunetonSingleScatteringStage {
    BrunetonLut lut;  // with the transmittance table
    TableOut rayleigh, mie;
    template <typename V>
    void VisitTables(V& v) {
        lut.VisitTables(v);
        v(rayleigh);
        v(mie);
    }
    ATMOS_HD void operator()(int64_t item) const {
        const auto [x, y, z, r, mu, mu_s, nu, ground] =
            BrunetonScatteringTexelOf(lut, item, rayleigh.width, rayleigh.height);
        const auto [n, dx, thick] = BrunetonViewStepsOf(lut, r, mu, ground);
        ThickRayWeights weights(r, mu, dx, n);
        Rgb sum_r, sum_m;
        for (int i = 0; i <= n; ++i) {
            Vec3d w;
            if (thick) w = weights.Next(lut.atm, i);
            const BrunetonSingleSample s =
                BrunetonSingleScatteringSample(lut, r, mu, ground, dx, i, n, thick ? &w : nullptr);
            BrunetonSingleScatteringAdd(lut, s, r, mu_s, nu, &sum_r, &sum_m);
        }
        rayleigh.Set(x, y, z, BrunetonVec4(sum_r * Rgb(lut.atm.rayleigh_scattering * dx)));
        mie.Set(x, y, z, BrunetonVec4(sum_m * Rgb(lut.atm.mie_scattering * dx)));
    }
};
ATMOS_DEVICE_STAGE(BrunetonSingleScatteringStage)

// The scattering table after order 1: single Rayleigh (and, with combined
// storage, single Mie red in alpha, Bruneton's 2017 implementation notes "Precomputation" of the
// scattering texture); with separate storage the single Mie table is a copy of
// the single Mie scattering. Item: texel.
struct BrunetonCombineStage {
    TableView rayleigh, mie;
    TableOut scattering;  // 3 or 4 channels
    TableOut single_mie;  // separate storage; empty (no data) when combined
    template <typename V>
    void VisitTables(V& v) {
        v(rayleigh);
        v(mie);
        v(scattering);
        v(single_mie);
    }
    ATMOS_HD void operator()(int64_t item) const {
        const size_t i = static_cast<size_t>(item);
        const float* ray = rayleigh.data + i * 3;
        const float* m = mie.data + i * 3;
        float* s = scattering.data + i * static_cast<size_t>(scattering.channels);
        s[0] = ray[0];
        s[1] = ray[1];
        s[2] = ray[2];
        if (scattering.channels == 4) s[3] = m[0];
        if (single_mie.data) {
            float* sm = single_mie.data + i * 3;
            sm[0] = m[0];
            sm[1] = m[1];
            sm[2] = m[2];
        }
    }
};
ATMOS_DEVICE_STAGE(BrunetonCombineStage)

// ---- scattering density J_n (Bruneton's 2017 implementation notes
// ComputeScatteringDensity(Texture)) ---- The fixed grid of incident directions (16 theta x 32 phi
// midpoints) in a frame whose x axis is the sun's azimuth, as one table: 1 channel, width 4 * 512:
// x, y, z of each direction, then its solid angle (float), structure of arrays
// (MakeBrunetonDirectionTable, built once on the host).
struct BrunetonDirections {
    const float* wx;
    const float* wy;
    const float* wz;
    const float* solid_angle;
    ATMOS_HD explicit BrunetonDirections(const TableView& t)
        : wx(t.data),
          wy(t.data + kBrunetonDirections),
          wz(t.data + 2 * kBrunetonDirections),
          solid_angle(t.data + 3 * kBrunetonDirections) {}
};

// Incident radiance L_i(r, mu_s, omega_k) after n - 1 bounces times its solid
// angle (the part of ComputeScatteringDensity that does not depend on the view
// direction), for one (r, mu_s) pair and direction k, in the sun's frame.
// Table: 1 channel, width 3 * 512 (red of every direction, then green, then
// blue), height MU_S, depth R. Item: k + 512 * (s + MU_S * z).
struct BrunetonIncidentStage {
    BrunetonLut lut;                        // with the transmittance table
    TableView single_rayleigh, single_mie;  // order 2
    TableView multiple;                     // order n - 1 when n > 2
    TableView ground_irradiance;            // ground irradiance after n - 2 bounces
    TableView directions;                   // MakeBrunetonDirectionTable
    int order = 2;                          // n
    TableOut incident;
    template <typename V>
    void VisitTables(V& v) {
        lut.VisitTables(v);
        v(single_rayleigh);
        v(single_mie);
        v(multiple);
        v(ground_irradiance);
        v(directions);
        v(incident);
    }
    ATMOS_HD void operator()(int64_t item) const {
        const int k = static_cast<int>(item % kBrunetonDirections);
        const int64_t rest = item / kBrunetonDirections;
        const int s = static_cast<int>(rest % lut.cfg.scattering_mu_s);
        const int z = static_cast<int>(rest / lut.cfg.scattering_mu_s);
        const AtmosphereParameters& atm = lut.atm;
        double r, mu, mu_s, nu;
        bool unused;
        lut.RMuMuSNuFromTexel(s, lut.cfg.scattering_mu / 2, z, &r, &mu, &mu_s, &nu, &unused);
        const double sin_s = SafeSqrt(1.0 - mu_s * mu_s);
        const Vec3d omega_s(sin_s, 0.0, mu_s);
        const int l = k / (2 * kBrunetonDensityThetaSamples);
        const int m = k % (2 * kBrunetonDensityThetaSamples);
        const double theta = (l + 0.5) * kPi / kBrunetonDensityThetaSamples;
        const double phi = (m + 0.5) * kPi / kBrunetonDensityThetaSamples;
        const double ct = cos(theta);
        const bool ground = RayIntersectsGround(r, ct, atm.bottom_radius);
        const Vec3d omega_i(cos(phi) * sin(theta), sin(phi) * sin(theta), ct);
        const double nu1 = ClampCosine(Dot(omega_s, omega_i));
        Rgb inc;
        if (order == 2) {
            const Rgb ray = lut.GetScattering(single_rayleigh, r, ct, mu_s, nu1, ground).rgb();
            const Rgb mie = lut.GetScattering(single_mie, r, ct, mu_s, nu1, ground).rgb();
            inc = ray * static_cast<float>(RayleighPhase(nu1)) +
                  mie * static_cast<float>(MiePhase(atm, nu1));
        } else {
            inc = lut.GetScattering(multiple, r, ct, mu_s, nu1, ground).rgb();
        }
        if (ground && MaxComponent(atm.ground_albedo) > 0.0) {
            // Light whose (n - 1)-th bounce is on the ground (Lambertian).
            const double distance_to_ground =
                DistanceToBottomAtmosphereBoundary(r, ct, atm.bottom_radius);
            const Rgb transmittance_to_ground = lut.Transmittance(r, ct, distance_to_ground, true);
            const Vec3d normal = Normalize(Vec3d(0.0, 0.0, r) + omega_i * distance_to_ground);
            const Rgb e =
                lut.GetIrradiance(ground_irradiance, atm.bottom_radius, Dot(normal, omega_s));
            inc += transmittance_to_ground * Rgb(atm.ground_albedo * (1.0 / kPi)) * e;
        }
        const float w = BrunetonDirections(directions).solid_angle[k];
        incident.Texel(k, s, z)[0] = inc.x * w;
        incident.Texel(kBrunetonDirections + k, s, z)[0] = inc.y * w;
        incident.Texel(2 * kBrunetonDirections + k, s, z)[0] = inc.z * w;
    }
};
ATMOS_DEVICE_STAGE(BrunetonIncidentStage)

// Sum over the directions of L_i d omega times the Rayleigh and Mie phase
// functions without their constant factors (1 + x^2 and (1 + x^2) / den^1.5;
// Bruneton's 2017 implementation notes ComputeScatteringDensity, the inner sum), for the view
// direction (ox, oy, oz) in the sun's frame. `l` points to the 3 * 512 floats of one (r, mu_s) pair
// of the incident table.
ATMOS_HD inline void BrunetonPhaseSums(const BrunetonDirections& grid, const float* l, float ox,
                                       float oy, float oz, float g, Rgb* sum_rayleigh,
                                       Rgb* sum_mie) {
    const float* l0 = l;
    const float* l1 = l + kBrunetonDirections;
    const float* l2 = l + 2 * kBrunetonDirections;
    float ar[3][kBrunetonLanes] = {}, am[3][kBrunetonLanes] = {};
    const float g2 = 1.0f + g * g;
    const float g_2 = 2.0f * g;
    for (int k0 = 0; k0 < kBrunetonDirections; k0 += kBrunetonLanes) {
        for (int j = 0; j < kBrunetonLanes; ++j) {
            const int k = k0 + j;
            const float x = ox * grid.wx[k] + oy * grid.wy[k] + oz * grid.wz[k];
            const float pr = 1.0f + x * x;
            const float den = g2 - g_2 * x;
            const float pm = pr / (den * Sqrt(den));
            ar[0][j] += pr * l0[k];
            ar[1][j] += pr * l1[k];
            ar[2][j] += pr * l2[k];
            am[0][j] += pm * l0[k];
            am[1][j] += pm * l1[k];
            am[2][j] += pm * l2[k];
        }
    }
    Rgb sr, sm;
    for (int ch = 0; ch < 3; ++ch) {
        double a = 0.0, b = 0.0;
        for (int j = 0; j < kBrunetonLanes; ++j) {
            a += static_cast<double>(ar[ch][j]);
            b += static_cast<double>(am[ch][j]);
        }
        sr[ch] = static_cast<float>(a);
        sm[ch] = static_cast<float>(b);
    }
    *sum_rayleigh = sr;
    *sum_mie = sm;
}

// BrunetonPhaseSums for any Mie phase function (physics/phase.h MiePhase, in
// double per direction): the Rayleigh sums as there (1 + x^2), the Mie sums
// with the normalised phase itself.
ATMOS_HD inline void BrunetonPhaseSumsGeneric(const BrunetonDirections& grid, const float* l,
                                              float ox, float oy, float oz,
                                              const AtmosphereParameters& atm, Rgb* sum_rayleigh,
                                              Rgb* sum_mie) {
    const float* l0 = l;
    const float* l1 = l + kBrunetonDirections;
    const float* l2 = l + 2 * kBrunetonDirections;
    double ar[3] = {}, am[3] = {};
    for (int k = 0; k < kBrunetonDirections; ++k) {
        const double x = static_cast<double>(ox * grid.wx[k] + oy * grid.wy[k] + oz * grid.wz[k]);
        const double pr = 1.0 + x * x;
        const double pm = MiePhase(atm, x);
        const double v0 = static_cast<double>(l0[k]);
        const double v1 = static_cast<double>(l1[k]);
        const double v2 = static_cast<double>(l2[k]);
        ar[0] += pr * v0;
        ar[1] += pr * v1;
        ar[2] += pr * v2;
        am[0] += pm * v0;
        am[1] += pm * v1;
        am[2] += pm * v2;
    }
    for (int ch = 0; ch < 3; ++ch) {
        (*sum_rayleigh)[ch] = static_cast<float>(ar[ch]);
        (*sum_mie)[ch] = static_cast<float>(am[ch]);
    }
}

// J_n per texel of the scattering table: the phase-weighted sums of the
// incident table times the scattering coefficients (3 channels).
struct BrunetonDensityStage {
    BrunetonLut lut;       // mappings only
    TableView incident;    // BrunetonIncidentStage
    TableView directions;  // MakeBrunetonDirectionTable
    TableOut density;
    template <typename V>
    void VisitTables(V& v) {
        lut.VisitTables(v);
        v(incident);
        v(directions);
        v(density);
    }
    ATMOS_HD void operator()(int64_t item) const {
        const auto [x, y, z, r, mu, mu_s, nu, ground] =
            BrunetonScatteringTexelOf(lut, item, density.width, density.height);
        const AtmosphereParameters& atm = lut.atm;
        // The view direction omega with omega.z = mu and omega.omega_s = nu, in
        // the frame where omega_s = (sin_s, 0, mu_s).
        const double sin_s = SafeSqrt(1.0 - mu_s * mu_s);
        const double ox = sin_s == 0.0 ? 0.0 : (nu - mu * mu_s) / sin_s;
        const double oy = SafeSqrt(1.0 - ox * ox - mu * mu);
        const double g = atm.mie_phase_g;
        const int s = x % lut.cfg.scattering_mu_s;
        const float* l =
            incident.data + (static_cast<size_t>(z) * incident.height + static_cast<size_t>(s)) *
                                static_cast<size_t>(incident.width);
        Rgb sum_r, sum_m;
        if (atm.mie_phase_kind != MiePhaseKind::kCornetteShanks) {
            // Any other phase function (Henyey-Greenstein, isotropic, tabulated):
            // the sums with MiePhase itself (normalised, so no k_m).
            BrunetonPhaseSumsGeneric(BrunetonDirections(directions), l, static_cast<float>(ox),
                                     static_cast<float>(oy), static_cast<float>(mu), atm, &sum_r,
                                     &sum_m);
            const double alt = r - atm.bottom_radius;
            const Vec3d br = atm.rayleigh_scattering *
                             (GetProfileDensity(atm.rayleigh_density, alt) * (3.0 / (16.0 * kPi)));
            const Vec3d bm = atm.mie_scattering * GetProfileDensity(atm.mie_density, alt);
            density.Set(x, y, z, BrunetonVec4(sum_r * Rgb(br) + sum_m * Rgb(bm)));
            return;
        }
        BrunetonPhaseSums(BrunetonDirections(directions), l, static_cast<float>(ox),
                          static_cast<float>(oy), static_cast<float>(mu), static_cast<float>(g),
                          &sum_r, &sum_m);
        const double k_r = 3.0 / (16.0 * kPi);
        const double k_m = 3.0 / (8.0 * kPi) * (1.0 - g * g) / (2.0 + g * g);
        const double alt = r - atm.bottom_radius;
        const Vec3d br =
            atm.rayleigh_scattering * (GetProfileDensity(atm.rayleigh_density, alt) * k_r);
        const double rho_m = GetProfileDensity(atm.mie_density, alt);
        const double w2 = atm.mie_phase_weight2;
        if (w2 == 0.0) {
            const Vec3d bm = atm.mie_scattering * (rho_m * k_m);
            density.Set(x, y, z, BrunetonVec4(sum_r * Rgb(br) + sum_m * Rgb(bm)));
            return;
        }
        // A second Cornette-Shanks lobe (MiePhase): its own phase sums, the
        // lobes weighted 1 - w2 and w2.
        const double g2 = atm.mie_phase_g2;
        Rgb unused, sum_m2;
        BrunetonPhaseSums(BrunetonDirections(directions), l, static_cast<float>(ox),
                          static_cast<float>(oy), static_cast<float>(mu), static_cast<float>(g2),
                          &unused, &sum_m2);
        const double k_m2 = 3.0 / (8.0 * kPi) * (1.0 - g2 * g2) / (2.0 + g2 * g2);
        const Vec3d bm = atm.mie_scattering * (rho_m * (1.0 - w2) * k_m);
        const Vec3d bm2 = atm.mie_scattering * (rho_m * w2 * k_m2);
        density.Set(x, y, z, BrunetonVec4(sum_r * Rgb(br) + sum_m * Rgb(bm) + sum_m2 * Rgb(bm2)));
    }
};
ATMOS_DEVICE_STAGE(BrunetonDensityStage)

// ---- indirect irradiance of order n (Bruneton's 2017 implementation notes
// ComputeIndirectIrradiance(Texture)) ---- Item: texel of the irradiance table; `order` is n (1:
// from the single scattering tables, else from the multiple scattering of order n).
struct BrunetonIndirectIrradianceStage {
    BrunetonLut lut;  // mappings only
    TableView single_rayleigh, single_mie, multiple;
    int order = 1;
    TableOut out;
    template <typename V>
    void VisitTables(V& v) {
        lut.VisitTables(v);
        v(single_rayleigh);
        v(single_mie);
        v(multiple);
        v(out);
    }
    ATMOS_HD void operator()(int64_t item) const {
        int x, y, z;
        BrunetonTexelOf(item, out.width, out.height, &x, &y, &z);
        const int n = kBrunetonIrradianceSamples;
        const double dphi = kPi / n;
        const double dtheta = kPi / n;
        double r, mu_s;
        lut.RMuSFromIrradianceUv((x + 0.5) / out.width, (y + 0.5) / out.height, &r, &mu_s);
        const Vec3d omega_s(SafeSqrt(1.0 - mu_s * mu_s), 0.0, mu_s);
        Vec3d sum;
        for (int j = 0; j < n / 2; ++j) {
            const double theta = (j + 0.5) * dtheta;
            for (int i = 0; i < 2 * n; ++i) {
                const double phi = (i + 0.5) * dphi;
                const Vec3d omega(cos(phi) * sin(theta), sin(phi) * sin(theta), cos(theta));
                const double domega = dtheta * dphi * sin(theta);
                const double nu = ClampCosine(Dot(omega, omega_s));
                Rgb l;
                if (order == 1) {
                    l = lut.GetScattering(single_rayleigh, r, omega.z, mu_s, nu, false).rgb() *
                            static_cast<float>(RayleighPhase(nu)) +
                        lut.GetScattering(single_mie, r, omega.z, mu_s, nu, false).rgb() *
                            static_cast<float>(MiePhase(lut.atm, nu));
                } else {
                    l = lut.GetScattering(multiple, r, omega.z, mu_s, nu, false).rgb();
                }
                sum += Vec3d(l) * (omega.z * domega);
            }
        }
        out.Set(x, y, 0, BrunetonVec4(Rgb(sum)));
    }
};
ATMOS_DEVICE_STAGE(BrunetonIndirectIrradianceStage)

// total += delta, texel by texel (the irradiance table after each order).
struct BrunetonAddStage {
    TableView delta;
    TableOut total;
    template <typename V>
    void VisitTables(V& v) {
        v(delta);
        v(total);
    }
    ATMOS_HD void operator()(int64_t item) const {
        const size_t i = static_cast<size_t>(item) * 3;
        float* t = total.data + i;
        t[0] += delta.data[i];
        t[1] += delta.data[i + 1];
        t[2] += delta.data[i + 2];
    }
};
ATMOS_DEVICE_STAGE(BrunetonAddStage)

// ---- multiple scattering of order n (Bruneton's 2017 implementation notes
// ComputeMultipleScattering(Texture)) ---- The density J_n's 4D lookup: the renderer's
// (BrunetonLut::CombinedScattering: BrunetonSplitRows, BrunetonSplitColumns, BrunetonSample4D and
// BrunetonUMuS), in its two parts so that a row of texels shares the (mu, r) rows.
struct BrunetonFastLookup {
    const float* data;
    int width, height, depth, nu_size;
    BrunetonConstants k;
    ATMOS_HD BrunetonFastLookup(const BrunetonLut& lut, const TableView& t)
        : data(t.data),
          width(t.width),
          height(t.height),
          depth(t.depth),
          nu_size(lut.cfg.scattering_nu),
          k(lut.k) {}
    ATMOS_HD double UMuS(double mu_s) const { return BrunetonUMuS(k, mu_s); }
    using Rows = Bruneton4DRows;
    ATMOS_HD void MakeRows(double u_mu, double u_r, Rows* out) const {
        *out = BrunetonSplitRows(width, height, depth, u_mu, u_r);
    }
    ATMOS_HD Rgb SampleRows(const Rows& rows, double tex_x, float lerp, double u_mu_s) const {
        float o[3];
        BrunetonSample4D<3>(data, rows, BrunetonSplitColumns(width, nu_size, tex_x, lerp, u_mu_s),
                            o);
        return Rgb(o[0], o[1], o[2]);
    }
};

// Sample i of n along the view ray (r, mu) of the multiple scattering integral
// (Bruneton's 2017 implementation notes ComputeMultipleScattering): what one (r, mu) row shares:
// distance, radius, the (mu, r) rows of the density lookup, and the transmittance from the camera
// times the trapezoid weight and dx (on a ray with optically thick steps: `thick`, the node's W_i /
// sigma_t,i, as for single scattering).
struct BrunetonMultipleSample {
    double d, r, inv_r;
    BrunetonFastLookup::Rows rows;
    Rgb t;
};
ATMOS_HD inline BrunetonMultipleSample BrunetonMultipleScatteringSample(
    const BrunetonLut& lut, const BrunetonFastLookup& fast, double r, double mu, bool ground,
    double dx, int i, int n, const Vec3d* thick = nullptr) {
    BrunetonMultipleSample s;
    const double d = i * dx;
    s.d = d;
    s.r = lut.ClampRadius(Sqrt(d * d + 2.0 * r * mu * d + r * r));
    s.inv_r = 1.0 / s.r;
    const double mu_i = ClampCosine((r * mu + d) / s.r);
    double u_mu, u_r;
    lut.ScatteringUMuR(s.r, mu_i, ground, &u_mu, &u_r);
    fast.MakeRows(u_mu, u_r, &s.rows);
    if (thick) {
        s.t = Rgb(*thick);
        return s;
    }
    s.t = lut.Transmittance(r, mu, d, ground) *
          static_cast<float>(BrunetonQuadratureWeight(lut.cfg.scattering_rule, i, n) * dx);
    return s;
}
// The (mu_s, nu) part of sample s: the mu_s coordinate at the sample (the
// CPU's rows compute it for a whole row first, a loop that vectorises)...
ATMOS_HD inline double BrunetonMultipleScatteringUMuS(const BrunetonFastLookup& fast,
                                                      const BrunetonMultipleSample& s, double r,
                                                      double mu_s, double nu) {
    return fast.UMuS(ClampCosine((r * mu_s + s.d * nu) * s.inv_r));
}
// ...then the density J_n at the sample times the weighted transmittance.
ATMOS_HD inline Rgb BrunetonMultipleScatteringTerm(const BrunetonFastLookup& fast,
                                                   const BrunetonMultipleSample& s, double tex_x,
                                                   float lerp, double u_mu_s) {
    return fast.SampleRows(s.rows, tex_x, lerp, u_mu_s) * s.t;
}

// Item: texel of the scattering table; writes the multiple scattering of order
// n from the density J_n (3 channels).
struct BrunetonMultipleScatteringStage {
    BrunetonLut lut;  // with the transmittance table
    TableView density;
    TableOut out;
    template <typename V>
    void VisitTables(V& v) {
        lut.VisitTables(v);
        v(density);
        v(out);
    }
    ATMOS_HD void operator()(int64_t item) const {
        const auto [x, y, z, r, mu, mu_s, nu, ground] =
            BrunetonScatteringTexelOf(lut, item, out.width, out.height);
        const auto [n, dx, thick] = BrunetonViewStepsOf(lut, r, mu, ground);
        const BrunetonFastLookup fast(lut, density);
        double tex_x;
        float lerp;
        BrunetonNuCoordinate(nu, lut.cfg.scattering_nu, &tex_x, &lerp);
        ThickRayWeights weights(r, mu, dx, n);
        Rgb sum;
        for (int i = 0; i <= n; ++i) {
            Vec3d w;
            if (thick) w = weights.Next(lut.atm, i);
            const BrunetonMultipleSample s = BrunetonMultipleScatteringSample(
                lut, fast, r, mu, ground, dx, i, n, thick ? &w : nullptr);
            const double u_mu_s = BrunetonMultipleScatteringUMuS(fast, s, r, mu_s, nu);
            sum += BrunetonMultipleScatteringTerm(fast, s, tex_x, lerp, u_mu_s);
        }
        out.Set(x, y, z, BrunetonVec4(sum));
    }
};
ATMOS_DEVICE_STAGE(BrunetonMultipleScatteringStage)

// scattering += delta_multiple / RayleighPhase(nu): the renderer multiplies the
// whole table by the Rayleigh phase function (Bruneton's 2017 implementation notes "Rendering").
// Item: texel.
struct BrunetonAccumulateStage {
    BrunetonLut lut;  // mappings only
    TableView delta;
    TableOut scattering;  // 3 or 4 channels (alpha untouched)
    template <typename V>
    void VisitTables(V& v) {
        lut.VisitTables(v);
        v(delta);
        v(scattering);
    }
    ATMOS_HD void operator()(int64_t item) const {
        const auto [x, y, z, r, mu, mu_s, nu, ground] =
            BrunetonScatteringTexelOf(lut, item, scattering.width, scattering.height);
        const float inv_phase = static_cast<float>(1.0 / RayleighPhase(nu));
        const float* dm = delta.data + static_cast<size_t>(item) * 3;
        float* s = scattering.Texel(x, y, z);
        for (int c = 0; c < 3; ++c) s[c] += dm[c] * inv_phase;
    }
};
ATMOS_DEVICE_STAGE(BrunetonAccumulateStage)

// ---- host side (bruneton_precompute.cpp) ----

// The direction grid of the scattering density (BrunetonDirections).
Table MakeBrunetonDirectionTable();

// The CPU's row forms of the single and multiple scattering stages: one (r, mu)
// row at a time, the samples' row-shared parts computed once per row (same
// helpers as the stages). Tables are resized. The CPU backend runs the
// vectorised rows (a loop over the row's texels per view-ray sample on plain
// arrays, `#pragma omp simd`): single scattering bit-identical to the scalar
// rows, multiple scattering interpolating the density along (mu, r) once per
// sample before x (float rounding apart). The scalar rows (per texel the
// stages' helpers in their order) stay for the tests.
void ComputeBrunetonSingleScatteringRows(const BrunetonLut& lut, Table* rayleigh, Table* mie);
void ComputeBrunetonMultipleScatteringRows(const BrunetonLut& lut, const TableView& density,
                                           Table* out);
void ComputeBrunetonSingleScatteringRowsScalar(const BrunetonLut& lut, Table* rayleigh, Table* mie);
void ComputeBrunetonMultipleScatteringRowsScalar(const BrunetonLut& lut, const TableView& density,
                                                 Table* out);

// The (mu_s, nu) of each texel of the scattering table's row (y, z) (x = nu *
// MU_S + mu_s): RMuMuSNuFromTexel's values, the mapping done once per mu_s
// column; the arrays hold NU * MU_S values.
void BrunetonRowMuSNu(const BrunetonLut& lut, int y, int z, int width, double* mu_s_x,
                      double* nu_x);

// PrecomputeBruneton with the choice of per-texel stages made explicit:
// `texel_stages` runs every stage through its stage struct (what the CUDA
// backend does, and does on the CPU backend too); otherwise the CPU's row forms
// replace the single and multiple scattering stages. PrecomputeBruneton passes
// texel_stages = (CurrentBackend() == Backend::kCuda). `scalar_rows`: the
// CPU's scalar rows instead of the vectorised ones (tests, benchmarks).
void PrecomputeBrunetonWith(const AtmosphereParameters& atmosphere, const BrunetonConfig& config,
                            bool texel_stages, BrunetonTables* tables,
                            const BrunetonOrderCallback& on_order = nullptr,
                            bool scalar_rows = false);

}  // namespace atmos
