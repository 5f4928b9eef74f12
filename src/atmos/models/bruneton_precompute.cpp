// atmos model `bruneton`: the precomputation (seed 004, every "Precomputation"
// section, and the order loop of Bruneton's model: transmittance, direct
// irradiance, single scattering, then per order n >= 2 the scattering density,
// the indirect irradiance of order n - 1 and the multiple scattering of order n).
// All stages run through the project's one ParallelFor.
#include <chrono>
#include <cmath>
#include <ctime>
#include <vector>

#include "atmos/error.h"
#include "base/parallel.h"
#include "models/bruneton.h"
#include "physics/transmittance.h"

namespace atmos {

namespace {

using Clock = std::chrono::steady_clock;

// Wall and CPU time of one stage, added to a field of both.
struct Stopwatch {
    Clock::time_point wall = Clock::now();
    std::clock_t cpu = std::clock();
    void AddTo(BrunetonTimings* t, double BrunetonStageTimes::*field) const {
        t->wall.*field += std::chrono::duration<double>(Clock::now() - wall).count();
        t->cpu.*field += static_cast<double>(std::clock() - cpu) / CLOCKS_PER_SEC;
    }
};

// Seed 004: the number of intervals of each numerical integral.
constexpr int kTransmittanceSamples = 500;   // ComputeOpticalLengthToTopAtmosphereBoundary
constexpr int kMaxScatteringSamples = 1000;  // seed 004 uses 50 (the default)
constexpr int kDensityThetaSamples = 16;     // ComputeScatteringDensity: SAMPLE_COUNT
constexpr int kIrradianceSampleCount = 32;   // ComputeIndirectIrradiance: SAMPLE_COUNT
constexpr int kDirections = kDensityThetaSamples * 2 * kDensityThetaSamples;  // 512
constexpr int kLanes = 8;  // independent partial sums, so the inner loop vectorises

Vec4f ToVec4(const Rgb& c, float w = 0.0f) { return {c.x, c.y, c.z, w}; }

// Rows of the 3D scattering table: one (mu, r) pair = (y, z), NU * MU_S texels.
int RowCount(const BrunetonConfig& c) { return c.scattering_mu * c.scattering_r; }

// Trapezoid weights of seed 004 (0.5 at both ends).
double TrapezoidWeight(int i, int n) { return (i == 0 || i == n) ? 0.5 : 1.0; }

// ---- transmittance (seed 004 ComputeTransmittanceToTopAtmosphereBoundaryTexture) ----
void ComputeTransmittance(const BrunetonLut& lut, Table* out) {
    const int w = lut.cfg.transmittance_width;
    const int h = lut.cfg.transmittance_height;
    out->Resize(w, h, 1, 3);
    ParallelFor(h, 1, [&](int64_t yy) {
        const int y = static_cast<int>(yy);
        for (int x = 0; x < w; ++x) {
            double r, mu;
            lut.RMuFromTransmittanceUv((x + 0.5) / w, (y + 0.5) / h, &r, &mu);
            const Vec3d tau =
                OpticalDepthToTopAtmosphereBoundary(lut.atm, r, mu, kTransmittanceSamples);
            out->Set(x, y, 0, ToVec4(Rgb(Exp(-tau))));
        }
    });
}

// ---- direct irradiance (seed 004 ComputeDirectIrradianceTexture) ----
void ComputeDirectIrradianceTable(const BrunetonLut& lut, Table* out) {
    const int w = lut.cfg.irradiance_width;
    const int h = lut.cfg.irradiance_height;
    out->Resize(w, h, 1, 3);
    ParallelFor(h, 1, [&](int64_t yy) {
        const int y = static_cast<int>(yy);
        for (int x = 0; x < w; ++x) {
            double r, mu_s;
            lut.RMuSFromIrradianceUv((x + 0.5) / w, (y + 0.5) / h, &r, &mu_s);
            out->Set(x, y, 0, ToVec4(lut.DirectIrradiance(r, mu_s)));
        }
    });
}

// ---- single scattering (seed 004 ComputeSingleScattering(Texture)) ----
// Per row (r, mu): the view-ray samples (distance, transmittance from the
// camera, densities) are shared by the row's (mu_s, nu) texels; only the sun's
// transmittance depends on them.
void ComputeSingleScatteringTables(const BrunetonLut& lut, Table* rayleigh, Table* mie) {
    const BrunetonConfig& c = lut.cfg;
    const int width = c.scattering_nu * c.scattering_mu_s;
    rayleigh->Resize(width, c.scattering_mu, c.scattering_r, 3);
    mie->Resize(width, c.scattering_mu, c.scattering_r, 3);
    const AtmosphereParameters& atm = lut.atm;
    ParallelFor(RowCount(c), 1, [&](int64_t row) {
        const int y = static_cast<int>(row % c.scattering_mu);
        const int z = static_cast<int>(row / c.scattering_mu);
        double r, mu, mu_s, nu;
        bool ground;
        lut.RMuMuSNuFromTexel(0, y, z, &r, &mu, &mu_s, &nu, &ground);
        const int n = lut.cfg.scattering_samples;
        const double dx = lut.DistanceToNearestAtmosphereBoundary(r, mu, ground) / n;
        const size_t ns = static_cast<size_t>(n) + 1;
        std::vector<double> d_i(ns), r_i(ns);
        std::vector<Rgb> t_r(ns), t_m(ns);
        for (int i = 0; i <= n; ++i) {
            const double d = i * dx;
            d_i[i] = d;
            r_i[i] = lut.ClampRadius(Sqrt(d * d + 2.0 * r * mu * d + r * r));
            const Rgb t = lut.Transmittance(r, mu, d, ground);
            const double alt = r_i[i] - atm.bottom_radius;
            const float w = static_cast<float>(TrapezoidWeight(i, n));
            t_r[i] = t * static_cast<float>(GetProfileDensity(atm.rayleigh_density, alt)) * w;
            t_m[i] = t * static_cast<float>(GetProfileDensity(atm.mie_density, alt)) * w;
        }
        const Rgb beta_r = Rgb(atm.rayleigh_scattering * dx);
        const Rgb beta_m = Rgb(atm.mie_scattering * dx);
        for (int x = 0; x < width; ++x) {
            double r2, mu2;
            lut.RMuMuSNuFromTexel(x, y, z, &r2, &mu2, &mu_s, &nu, &ground);
            Rgb sum_r, sum_m;
            for (int i = 0; i <= n; ++i) {
                const double mu_s_d = ClampCosine((r * mu_s + d_i[i] * nu) / r_i[i]);
                const Rgb ts = lut.TransmittanceToSun(r_i[i], mu_s_d);
                sum_r += ts * t_r[i];
                sum_m += ts * t_m[i];
            }
            rayleigh->Set(x, y, z, ToVec4(sum_r * beta_r));
            mie->Set(x, y, z, ToVec4(sum_m * beta_m));
        }
    });
}

// The fixed grid of incident directions of the scattering density (seed 004
// ComputeScatteringDensity: 16 theta x 32 phi midpoints), in a frame whose x
// axis is the sun's azimuth.
struct DirectionGrid {
    float wx[kDirections], wy[kDirections], wz[kDirections];
    double solid_angle[kDirections];
    DirectionGrid() {
        const double dtheta = kPi / kDensityThetaSamples;
        const double dphi = kPi / kDensityThetaSamples;
        for (int l = 0; l < kDensityThetaSamples; ++l) {
            const double theta = (l + 0.5) * dtheta;
            for (int m = 0; m < 2 * kDensityThetaSamples; ++m) {
                const double phi = (m + 0.5) * dphi;
                const int k = l * 2 * kDensityThetaSamples + m;
                wx[k] = static_cast<float>(std::cos(phi) * std::sin(theta));
                wy[k] = static_cast<float>(std::sin(phi) * std::sin(theta));
                wz[k] = static_cast<float>(std::cos(theta));
                solid_angle[k] = dtheta * dphi * std::sin(theta);
            }
        }
    }
};

// Incident radiance L_i(r, mu_s, omega_i) after n - 1 bounces times d omega_i
// (seed 004 ComputeScatteringDensity, the inner part that does not depend on
// the view direction), for one (r, mu_s) pair: channel-major arrays.
struct IncidentRadiance {
    float l[3][kDirections];
};

struct DensityInputs {
    const TableView* single_rayleigh;
    const TableView* single_mie;
    const TableView* multiple;           // order n - 1 when n > 2
    const TableView* ground_irradiance;  // ground irradiance after n - 2 bounces
    int order;                           // n
};

void ComputeIncident(const BrunetonLut& lut, const DirectionGrid& grid, const DensityInputs& in,
                     double r, double mu_s, IncidentRadiance* out) {
    const AtmosphereParameters& atm = lut.atm;
    const double sin_s = SafeSqrt(1.0 - mu_s * mu_s);
    const Vec3d omega_s(sin_s, 0.0, mu_s);
    const double phase_g = atm.mie_phase_g;
    for (int l = 0; l < kDensityThetaSamples; ++l) {
        const int k0 = l * 2 * kDensityThetaSamples;
        const double theta = (l + 0.5) * kPi / kDensityThetaSamples;
        const double ct = std::cos(theta);  // the double value of wz
        const bool ground = RayIntersectsGround(r, ct, atm.bottom_radius);
        double distance_to_ground = 0.0;
        Rgb transmittance_to_ground(0.0f);
        if (ground) {
            distance_to_ground = DistanceToBottomAtmosphereBoundary(r, ct, atm.bottom_radius);
            transmittance_to_ground = lut.Transmittance(r, ct, distance_to_ground, true);
        }
        for (int m = 0; m < 2 * kDensityThetaSamples; ++m) {
            const int k = k0 + m;
            const double phi = (m + 0.5) * kPi / kDensityThetaSamples;
            const Vec3d omega_i(std::cos(phi) * std::sin(theta), std::sin(phi) * std::sin(theta),
                                ct);
            const double nu1 = ClampCosine(Dot(omega_s, omega_i));
            Rgb incident;
            if (in.order == 2) {
                const Rgb ray =
                    lut.GetScattering(*in.single_rayleigh, r, ct, mu_s, nu1, ground).rgb();
                const Rgb mie = lut.GetScattering(*in.single_mie, r, ct, mu_s, nu1, ground).rgb();
                incident = ray * static_cast<float>(RayleighPhase(nu1)) +
                           mie * static_cast<float>(CornetteShanksPhase(phase_g, nu1));
            } else {
                incident = lut.GetScattering(*in.multiple, r, ct, mu_s, nu1, ground).rgb();
            }
            if (ground && MaxComponent(atm.ground_albedo) > 0.0) {
                // Light whose (n - 1)-th bounce is on the ground (Lambertian).
                const Vec3d normal = Normalize(Vec3d(0.0, 0.0, r) + omega_i * distance_to_ground);
                const Rgb e = lut.GetIrradiance(*in.ground_irradiance, atm.bottom_radius,
                                                Dot(normal, omega_s));
                incident += transmittance_to_ground * Rgb(atm.ground_albedo * (1.0 / kPi)) * e;
            }
            const float w = static_cast<float>(grid.solid_angle[k]);
            out->l[0][k] = incident.x * w;
            out->l[1][k] = incident.y * w;
            out->l[2][k] = incident.z * w;
        }
    }
}

// Sum over the directions of L_i d omega times the Rayleigh and Mie phase
// functions without their constant factors (1 + x^2 and (1 + x^2) / den^1.5).
void PhaseSums(const DirectionGrid& grid, const IncidentRadiance& inc, float ox, float oy, float oz,
               float g, Rgb* sum_rayleigh, Rgb* sum_mie) {
    float ar[3][kLanes] = {}, am[3][kLanes] = {};
    const float g2 = 1.0f + g * g;
    const float g_2 = 2.0f * g;
    for (int k0 = 0; k0 < kDirections; k0 += kLanes) {
        for (int j = 0; j < kLanes; ++j) {
            const int k = k0 + j;
            const float x = ox * grid.wx[k] + oy * grid.wy[k] + oz * grid.wz[k];
            const float pr = 1.0f + x * x;
            const float den = g2 - g_2 * x;
            const float pm = pr / (den * sqrtf(den));
            ar[0][j] += pr * inc.l[0][k];
            ar[1][j] += pr * inc.l[1][k];
            ar[2][j] += pr * inc.l[2][k];
            am[0][j] += pm * inc.l[0][k];
            am[1][j] += pm * inc.l[1][k];
            am[2][j] += pm * inc.l[2][k];
        }
    }
    Rgb sr, sm;
    for (int ch = 0; ch < 3; ++ch) {
        double a = 0.0, b = 0.0;
        for (int j = 0; j < kLanes; ++j) {
            a += static_cast<double>(ar[ch][j]);
            b += static_cast<double>(am[ch][j]);
        }
        sr[ch] = static_cast<float>(a);
        sm[ch] = static_cast<float>(b);
    }
    *sum_rayleigh = sr;
    *sum_mie = sm;
}

// ---- scattering density J_n (seed 004 ComputeScatteringDensity(Texture)) ----
void ComputeScatteringDensityTable(const BrunetonLut& lut, const DensityInputs& in, Table* out) {
    const BrunetonConfig& c = lut.cfg;
    const AtmosphereParameters& atm = lut.atm;
    const int width = c.scattering_nu * c.scattering_mu_s;
    out->Resize(width, c.scattering_mu, c.scattering_r, 3);
    static const DirectionGrid grid;
    // 1. Incident radiance per (r, mu_s).
    std::vector<IncidentRadiance> incident(static_cast<size_t>(c.scattering_r) * c.scattering_mu_s);
    ParallelFor(static_cast<int64_t>(incident.size()), 1, [&](int64_t idx) {
        const int z = static_cast<int>(idx / c.scattering_mu_s);
        const int s = static_cast<int>(idx % c.scattering_mu_s);
        double r, mu, mu_s, nu;
        bool ground;
        lut.RMuMuSNuFromTexel(s, c.scattering_mu / 2, z, &r, &mu, &mu_s, &nu, &ground);
        ComputeIncident(lut, grid, in, r, mu_s, &incident[static_cast<size_t>(idx)]);
    });
    // 2. Per texel, the phase-weighted sums in the sun's frame.
    const double k_r = 3.0 / (16.0 * kPi);
    const double g = atm.mie_phase_g;
    const double k_m = 3.0 / (8.0 * kPi) * (1.0 - g * g) / (2.0 + g * g);
    ParallelFor(RowCount(c), 1, [&](int64_t row) {
        const int y = static_cast<int>(row % c.scattering_mu);
        const int z = static_cast<int>(row / c.scattering_mu);
        for (int x = 0; x < width; ++x) {
            double r, mu, mu_s, nu;
            bool ground;
            lut.RMuMuSNuFromTexel(x, y, z, &r, &mu, &mu_s, &nu, &ground);
            // The view direction omega with omega.z = mu and omega.omega_s = nu,
            // in the frame where omega_s = (sin_s, 0, mu_s).
            const double sin_s = SafeSqrt(1.0 - mu_s * mu_s);
            const double ox = sin_s == 0.0 ? 0.0 : (nu - mu * mu_s) / sin_s;
            const double oy = SafeSqrt(1.0 - ox * ox - mu * mu);
            Rgb sum_r, sum_m;
            const IncidentRadiance& inc = incident[static_cast<size_t>(z) * c.scattering_mu_s +
                                                   static_cast<size_t>(x % c.scattering_mu_s)];
            PhaseSums(grid, inc, static_cast<float>(ox), static_cast<float>(oy),
                      static_cast<float>(mu), static_cast<float>(g), &sum_r, &sum_m);
            const double alt = r - atm.bottom_radius;
            const Vec3d br =
                atm.rayleigh_scattering * (GetProfileDensity(atm.rayleigh_density, alt) * k_r);
            const Vec3d bm = atm.mie_scattering * (GetProfileDensity(atm.mie_density, alt) * k_m);
            out->Set(x, y, z, ToVec4(sum_r * Rgb(br) + sum_m * Rgb(bm)));
        }
    });
}

// ---- indirect irradiance of order n (seed 004 ComputeIndirectIrradiance(Texture)) ----
void ComputeIndirectIrradianceTable(const BrunetonLut& lut, const TableView& single_rayleigh,
                                    const TableView& single_mie, const TableView& multiple,
                                    int order, Table* out) {
    const int w = lut.cfg.irradiance_width;
    const int h = lut.cfg.irradiance_height;
    out->Resize(w, h, 1, 3);
    const int n = kIrradianceSampleCount;
    const double dphi = kPi / n;
    const double dtheta = kPi / n;
    ParallelFor(static_cast<int64_t>(w) * h, 4, [&](int64_t idx) {
        const int x = static_cast<int>(idx % w);
        const int y = static_cast<int>(idx / w);
        double r, mu_s;
        lut.RMuSFromIrradianceUv((x + 0.5) / w, (y + 0.5) / h, &r, &mu_s);
        const Vec3d omega_s(SafeSqrt(1.0 - mu_s * mu_s), 0.0, mu_s);
        Vec3d sum;
        for (int j = 0; j < n / 2; ++j) {
            const double theta = (j + 0.5) * dtheta;
            for (int i = 0; i < 2 * n; ++i) {
                const double phi = (i + 0.5) * dphi;
                const Vec3d omega(std::cos(phi) * std::sin(theta), std::sin(phi) * std::sin(theta),
                                  std::cos(theta));
                const double domega = dtheta * dphi * std::sin(theta);
                const double nu = ClampCosine(Dot(omega, omega_s));
                Rgb l;
                if (order == 1) {
                    l = lut.GetScattering(single_rayleigh, r, omega.z, mu_s, nu, false).rgb() *
                            static_cast<float>(RayleighPhase(nu)) +
                        lut.GetScattering(single_mie, r, omega.z, mu_s, nu, false).rgb() *
                            static_cast<float>(CornetteShanksPhase(lut.atm.mie_phase_g, nu));
                } else {
                    l = lut.GetScattering(multiple, r, omega.z, mu_s, nu, false).rgb();
                }
                sum += Vec3d(l) * (omega.z * domega);
            }
        }
        out->Set(x, y, 0, ToVec4(Rgb(sum)));
    });
}

// The 4D lookup of BrunetonLut::Lookup4D specialised for a 3-channel table
// (same texel-centre filtering and clamping, TableView::Split), with the mu_s
// mapping's constants hoisted: the inner loop of the multiple scattering step.
struct FastScatteringLookup {
    const float* data;
    int width, height, depth, nu_size;
    int mu_s_size;
    double bottom, top, d_min, d_range, big_a;
    FastScatteringLookup(const BrunetonLut& lut, const TableView& t)
        : data(t.data),
          width(t.width),
          height(t.height),
          depth(t.depth),
          nu_size(lut.cfg.scattering_nu),
          mu_s_size(lut.cfg.scattering_mu_s) {
        bottom = lut.atm.bottom_radius;
        top = lut.atm.top_radius;
        d_min = top - bottom;
        d_range = lut.HorizonH() - d_min;
        const double big_d = DistanceToTopAtmosphereBoundary(bottom, lut.atm.mu_s_min, top);
        big_a = (big_d - d_min) / d_range;
        inv_d_range = 1.0 / d_range;
        inv_big_a = 1.0 / big_a;
        half_texel = 0.5 / mu_s_size;
        texel_scale = 1.0 - 1.0 / mu_s_size;
    }
    double inv_d_range, inv_big_a, half_texel, texel_scale;
    // TableView::Split along x for the coordinate (tex_x + u_mu_s) / NU, i.e.
    // texel position (tex_x + u_mu_s) * MU_S - 0.5, clamped to the edges.
    void SplitX(double tex_x_plus_u, int* i0, float* f) const {
        double x = tex_x_plus_u * mu_s_size - 0.5;
        if (x < 0.0) x = 0.0;
        if (x > width - 1) x = width - 1;
        int i = static_cast<int>(x);
        if (i > width - 2) i = width - 2;
        *i0 = i;
        *f = static_cast<float>(x - i);
    }
    // Seed 004's u_mu_s (BrunetonLut::ScatteringUMuS).
    // Divisions by constants hoisted (the inner loop is division bound).
    double UMuS(double mu_s) const {
        const double d = DistanceToTopAtmosphereBoundary(bottom, mu_s, top);
        const double a = (d - d_min) * inv_d_range;
        return half_texel + Max(1.0 - a * inv_big_a, 0.0) / (1.0 + a) * texel_scale;
    }
    // The (mu, r) part of a lookup: four rows of texels and their weights.
    struct Rows {
        const float* row[4];
        float w[4];
    };
    void MakeRows(double u_mu, double u_r, Rows* out) const {
        int y0, z0;
        float fy, fz;
        TableView::Split(u_mu, height, &y0, &fy);
        TableView::Split(u_r, depth, &z0, &fz);
        const int y1 = Min(y0 + 1, height - 1), z1 = Min(z0 + 1, depth - 1);
        const int ys[2] = {y0, y1}, zs[2] = {z0, z1};
        const float wy[2] = {1.0f - fy, fy}, wz[2] = {1.0f - fz, fz};
        for (int k = 0; k < 2; ++k) {
            for (int j = 0; j < 2; ++j) {
                out->row[k * 2 + j] =
                    data + (static_cast<size_t>(zs[k]) * height + ys[j]) * width * 3;
                out->w[k * 2 + j] = wz[k] * wy[j];
            }
        }
    }
    // The (nu, mu_s) part, with tex_x = floor(u_nu (NU - 1)) and lerp its fraction
    // (BrunetonLut::Lookup4D).
    Rgb SampleRows(const Rows& rows, double tex_x, float lerp, double u_mu_s) const {
        int xa, xb;
        float fxa, fxb;
        SplitX(tex_x + u_mu_s, &xa, &fxa);
        SplitX(tex_x + 1.0 + u_mu_s, &xb, &fxb);
        const int x1a = Min(xa + 1, width - 1), x1b = Min(xb + 1, width - 1);
        const int xs[4] = {xa, x1a, xb, x1b};
        const float wx[4] = {(1.0f - fxa) * (1.0f - lerp), fxa * (1.0f - lerp), (1.0f - fxb) * lerp,
                             fxb * lerp};
        float acc[3] = {0.0f, 0.0f, 0.0f};
        for (int k = 0; k < 4; ++k) {
            for (int i = 0; i < 4; ++i) {
                const float w = rows.w[k] * wx[i];
                const float* p = rows.row[k] + static_cast<size_t>(xs[i]) * 3;
                acc[0] += w * p[0];
                acc[1] += w * p[1];
                acc[2] += w * p[2];
            }
        }
        return Rgb(acc[0], acc[1], acc[2]);
    }
};

// ---- multiple scattering of order n (seed 004 ComputeMultipleScattering(Texture)) ----
// Per row (r, mu): the samples' transmittance from the camera and the (mu, r)
// part of their table coordinates are shared by the row's texels.
void ComputeMultipleScatteringTable(const BrunetonLut& lut, const TableView& density, Table* out) {
    const BrunetonConfig& c = lut.cfg;
    const int width = c.scattering_nu * c.scattering_mu_s;
    out->Resize(width, c.scattering_mu, c.scattering_r, 3);
    const FastScatteringLookup fast(lut, density);
    ParallelFor(RowCount(c), 1, [&](int64_t row) {
        const int y = static_cast<int>(row % c.scattering_mu);
        const int z = static_cast<int>(row / c.scattering_mu);
        double r, mu, mu_s, nu;
        bool ground;
        lut.RMuMuSNuFromTexel(0, y, z, &r, &mu, &mu_s, &nu, &ground);
        const int n = lut.cfg.scattering_samples;
        const double dx = lut.DistanceToNearestAtmosphereBoundary(r, mu, ground) / n;
        const size_t ns = static_cast<size_t>(n) + 1;
        std::vector<double> d_i(ns), r_i(ns), u_mu(ns), u_r(ns);
        std::vector<Rgb> t_i(ns);
        std::vector<FastScatteringLookup::Rows> rows(ns);
        for (int i = 0; i <= n; ++i) {
            const double d = i * dx;
            d_i[i] = d;
            r_i[i] = lut.ClampRadius(Sqrt(d * d + 2.0 * r * mu * d + r * r));
            const double mu_i = ClampCosine((r * mu + d) / r_i[i]);
            lut.ScatteringUMuR(r_i[i], mu_i, ground, &u_mu[i], &u_r[i]);
            fast.MakeRows(u_mu[i], u_r[i], &rows[i]);
            t_i[i] = lut.Transmittance(r, mu, d, ground) *
                     static_cast<float>(TrapezoidWeight(i, n) * dx);
        }
        // Samples outer, texels inner: the four table rows of one sample stay in
        // the cache while the row's texels read them.
        std::vector<double> mu_s_x(static_cast<size_t>(width)), nu_x(mu_s_x.size());
        std::vector<double> tex_x(mu_s_x.size());
        std::vector<float> lerp(mu_s_x.size());
        std::vector<Rgb> sum(mu_s_x.size());
        for (int x = 0; x < width; ++x) {
            double r2, mu2;
            lut.RMuMuSNuFromTexel(x, y, z, &r2, &mu2, &mu_s, &nu, &ground);
            const size_t k = static_cast<size_t>(x);
            mu_s_x[k] = mu_s;
            nu_x[k] = nu;
            const double tex_coord_x = (nu + 1.0) / 2.0 * (c.scattering_nu - 1);
            tex_x[k] = std::floor(tex_coord_x);
            lerp[k] = static_cast<float>(tex_coord_x - tex_x[k]);
        }
        std::vector<double> u_mu_s(mu_s_x.size());
        for (int i = 0; i <= n; ++i) {
            const double inv_r_i = 1.0 / r_i[i];
            // First the mu_s coordinates of all texels (a vectorisable loop)...
            for (size_t k = 0; k < sum.size(); ++k) {
                const double mu_s_i = ClampCosine((r * mu_s_x[k] + d_i[i] * nu_x[k]) * inv_r_i);
                u_mu_s[k] = fast.UMuS(mu_s_i);
            }
            // ...then the lookups.
            for (size_t k = 0; k < sum.size(); ++k) {
                sum[k] += fast.SampleRows(rows[i], tex_x[k], lerp[k], u_mu_s[k]) * t_i[i];
            }
        }
        for (int x = 0; x < width; ++x) out->Set(x, y, z, ToVec4(sum[static_cast<size_t>(x)]));
    });
}

}  // namespace

void ValidateBrunetonConfig(const BrunetonConfig& c) {
    auto check = [](const char* name, int v, int lo, int hi) {
        if (v < lo || v > hi) Fail("bruneton: --", name, " ", v, " outside [", lo, ", ", hi, "]");
    };
    check("transmittance-width", c.transmittance_width, 2, 4096);
    check("transmittance-height", c.transmittance_height, 2, 4096);
    check("irradiance-width", c.irradiance_width, 2, 4096);
    check("irradiance-height", c.irradiance_height, 2, 4096);
    check("scattering-r", c.scattering_r, 2, 1024);
    check("scattering-mu", c.scattering_mu, 4, 4096);
    check("scattering-mu-s", c.scattering_mu_s, 2, 1024);
    check("scattering-nu", c.scattering_nu, 2, 1024);
    check("orders", c.orders, 1, 32);
    check("scattering-samples", c.scattering_samples, 1, kMaxScatteringSamples);
    if (c.scattering_mu % 2 != 0) {
        Fail("bruneton: --scattering-mu ", c.scattering_mu,
             " must be even (half of the table is for rays that hit the ground)");
    }
}

BrunetonLut MakeBrunetonLut(const AtmosphereParameters& atmosphere, const BrunetonConfig& config,
                            const BrunetonTables& tables) {
    BrunetonLut lut;
    lut.atm = atmosphere;
    lut.cfg = config;
    lut.transmittance_table = tables.transmittance.view();
    lut.irradiance_table = tables.irradiance.view();
    lut.scattering_table = tables.scattering.view();
    lut.single_mie_table = tables.single_mie.view();
    return lut;
}

void PrecomputeBruneton(const AtmosphereParameters& atmosphere, const BrunetonConfig& config,
                        BrunetonTables* tables, BrunetonTimings* timings,
                        const BrunetonOrderCallback& on_order) {
    ValidateBrunetonConfig(config);
    BrunetonTimings t;
    const Stopwatch start;
    BrunetonLut lut;
    lut.atm = atmosphere;
    lut.cfg = config;

    Stopwatch stage;
    ComputeTransmittance(lut, &tables->transmittance);
    lut.transmittance_table = tables->transmittance.view();
    stage.AddTo(&t, &BrunetonStageTimes::transmittance);

    stage = Stopwatch();
    Table delta_irradiance;
    ComputeDirectIrradianceTable(lut, &delta_irradiance);
    // The irradiance table holds the indirect irradiance only (the direct one is
    // computed at render time from the transmittance, seed 004).
    tables->irradiance.Resize(config.irradiance_width, config.irradiance_height, 1, 3);
    stage.AddTo(&t, &BrunetonStageTimes::direct_irradiance);

    stage = Stopwatch();
    Table delta_rayleigh, delta_mie;
    ComputeSingleScatteringTables(lut, &delta_rayleigh, &delta_mie);
    const int width = config.scattering_nu * config.scattering_mu_s;
    tables->scattering.Resize(width, config.scattering_mu, config.scattering_r,
                              config.combined_mie ? 4 : 3);
    if (config.combined_mie) {
        tables->single_mie = Table();
    } else {
        tables->single_mie = delta_mie;
    }
    {
        const size_t texels =
            static_cast<size_t>(width) * config.scattering_mu * config.scattering_r;
        const int ch = tables->scattering.channels();
        float* s = tables->scattering.data();
        const float* ray = delta_rayleigh.data();
        const float* mie = delta_mie.data();
        for (size_t i = 0; i < texels; ++i) {
            for (int c = 0; c < 3; ++c) s[i * ch + c] = ray[i * 3 + c];
            if (ch == 4) s[i * 4 + 3] = mie[i * 3];
        }
    }
    stage.AddTo(&t, &BrunetonStageTimes::single_scattering);
    if (on_order) on_order(1, *tables, nullptr);

    Table delta_multiple, delta_density;
    for (int order = 2; order <= config.orders; ++order) {
        stage = Stopwatch();
        const DensityInputs in{&delta_rayleigh.view(), &delta_mie.view(), &delta_multiple.view(),
                               &delta_irradiance.view(), order};
        ComputeScatteringDensityTable(lut, in, &delta_density);
        stage.AddTo(&t, &BrunetonStageTimes::scattering_density);

        stage = Stopwatch();
        ComputeIndirectIrradianceTable(lut, delta_rayleigh.view(), delta_mie.view(),
                                       delta_multiple.view(), order - 1, &delta_irradiance);
        {
            float* e = tables->irradiance.data();
            const float* de = delta_irradiance.data();
            for (size_t i = 0; i < tables->irradiance.size(); ++i) e[i] += de[i];
        }
        stage.AddTo(&t, &BrunetonStageTimes::indirect_irradiance);

        stage = Stopwatch();
        ComputeMultipleScatteringTable(lut, delta_density.view(), &delta_multiple);
        // Accumulate, divided by the Rayleigh phase function (the renderer
        // multiplies the whole table by it; seed 004 "Rendering").
        ParallelFor(RowCount(config), 4, [&](int64_t row) {
            const int y = static_cast<int>(row % config.scattering_mu);
            const int z = static_cast<int>(row / config.scattering_mu);
            for (int x = 0; x < width; ++x) {
                double r, mu, mu_s, nu;
                bool ground;
                lut.RMuMuSNuFromTexel(x, y, z, &r, &mu, &mu_s, &nu, &ground);
                const float inv_phase = static_cast<float>(1.0 / RayleighPhase(nu));
                const float* dm = delta_multiple.Texel(x, y, z);
                float* s = tables->scattering.Texel(x, y, z);
                for (int c = 0; c < 3; ++c) s[c] += dm[c] * inv_phase;
            }
        });
        stage.AddTo(&t, &BrunetonStageTimes::multiple_scattering);
        if (on_order) on_order(order, *tables, &delta_density);
    }
    start.AddTo(&t, &BrunetonStageTimes::total);
    if (timings) *timings = t;
}

}  // namespace atmos
