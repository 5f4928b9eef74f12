// atmos model `bruneton`: the precomputation (Bruneton's 2017 implementation notes, every
// "Precomputation" section, and the order loop of Bruneton's model: transmittance, direct
// irradiance, single scattering, then per order n >= 2 the scattering density,
// the indirect irradiance of order n - 1 and the multiple scattering of order n).
// Every stage runs through RunStage (render/stages.h: the CPU's ParallelFor or
// the device) from the stage structs of models/bruneton_stages.h; on the CPU
// backend single and multiple scattering use their row forms (faster on the CPU).
#include <chrono>
#include <cmath>
#include <vector>

#include "atmos/error.h"
#include "base/library_progress.h"
#include "base/parallel.h"
#include "base/progress.h"
#include "models/bruneton.h"
#include "models/bruneton_stages.h"
#include "models/order_check.h"
#include "physics/vector_exp.h"
#include "render/stages.h"

namespace atmos {

namespace {

using Clock = std::chrono::steady_clock;

// Rows of the 3D scattering table: one (mu, r) pair = (y, z), NU * MU_S texels.
int RowCount(const BrunetonConfig& c) { return c.scattering_mu * c.scattering_r; }

// The row forms in the stage log (render/stages.h), like RunStage's CPU runs.
void LogRows(const char* name, int64_t rows, Clock::time_point start) {
    if (!CurrentStageLog()) return;
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    LogStage({name, rows, "cpu", ms, ms});
}

// Runs row(r) for every row r of the scattering table (ParallelFor) and logs
// the run under `name` (LogRows).
template <typename F>
void ForEachRow(const char* name, const BrunetonConfig& c, F row) {
    const Clock::time_point start = Clock::now();
    ParallelFor(RowCount(c), 1, row);
    LogRows(name, RowCount(c), start);
}

int64_t TexelCount(const Table& t) {
    return static_cast<int64_t>(t.width()) * t.height() * t.depth();
}

// One (r, mu) row of the scattering table: its texel row (y, z), the view ray
// (r, mu; whether it hits the ground), the interval dx, and the samples along
// it that the row's texels share, sample i made by make(r, mu, ground, dx, i,
// n, thick) (thick: the node's ThickRayWeights factor on a ray with optically
// thick steps, else nullptr).
template <typename Sample>
struct RowSamples {
    int y = 0, z = 0;
    double r = 0.0, mu = 0.0, dx = 0.0;
    bool ground = false;
    std::vector<Sample> samples;
};
template <typename Sample, typename Make>
RowSamples<Sample> MakeRowSamples(const BrunetonLut& lut, int64_t row, const Make& make) {
    const BrunetonConfig& c = lut.cfg;
    RowSamples<Sample> s;
    s.y = static_cast<int>(row % c.scattering_mu);
    s.z = static_cast<int>(row / c.scattering_mu);
    double mu_s, nu;
    lut.RMuMuSNuFromTexel(0, s.y, s.z, &s.r, &s.mu, &mu_s, &nu, &s.ground);
    const int n = c.scattering_samples;
    s.dx = lut.DistanceToNearestAtmosphereBoundary(s.r, s.mu, s.ground) / n;
    s.samples.resize(static_cast<size_t>(n) + 1);
    const bool thick = RayHasThickSteps(lut.atm, s.r, s.mu, s.dx, n);
    ThickRayWeights weights(s.r, s.mu, s.dx, n);
    for (int i = 0; i <= n; ++i) {
        Vec3d w;
        if (thick) w = weights.Next(lut.atm, i);
        s.samples[static_cast<size_t>(i)] =
            make(s.r, s.mu, s.ground, s.dx, i, n, thick ? &w : nullptr);
    }
    return s;
}
RowSamples<BrunetonSingleSample> SingleScatteringRow(const BrunetonLut& lut, int64_t row) {
    return MakeRowSamples<BrunetonSingleSample>(
        lut, row,
        [&lut](double r, double mu, bool ground, double dx, int i, int n, const Vec3d* thick) {
            return BrunetonSingleScatteringSample(lut, r, mu, ground, dx, i, n, thick);
        });
}
RowSamples<BrunetonMultipleSample> MultipleScatteringRow(const BrunetonLut& lut,
                                                         const BrunetonFastLookup& fast,
                                                         int64_t row) {
    return MakeRowSamples<BrunetonMultipleSample>(
        lut, row,
        [&lut, &fast](double r, double mu, bool ground, double dx, int i, int n,
                      const Vec3d* thick) {
            return BrunetonMultipleScatteringSample(lut, fast, r, mu, ground, dx, i, n, thick);
        });
}

}  // namespace

void ValidateBrunetonConfig(const BrunetonConfig& c) {
    BrunetonModel::OptionRows().Check("bruneton", c);
}

BrunetonLut MakeBrunetonLut(const AtmosphereParameters& atmosphere, const BrunetonConfig& config,
                            const BrunetonTables& tables) {
    BrunetonLut lut(atmosphere, config);
    lut.transmittance_table = tables.transmittance.view();
    lut.irradiance_table = tables.irradiance.view();
    lut.scattering_table = tables.scattering.view();
    lut.single_mie_table = tables.single_mie.view();
    return lut;
}

Table MakeBrunetonDirectionTable() {
    Table t(4 * kBrunetonDirections, 1, 1, 1);
    float* p = t.data();
    const double dtheta = kPi / kBrunetonDensityThetaSamples;
    const double dphi = kPi / kBrunetonDensityThetaSamples;
    for (int l = 0; l < kBrunetonDensityThetaSamples; ++l) {
        const double theta = (l + 0.5) * dtheta;
        for (int m = 0; m < 2 * kBrunetonDensityThetaSamples; ++m) {
            const double phi = (m + 0.5) * dphi;
            const int k = l * 2 * kBrunetonDensityThetaSamples + m;
            p[k] = static_cast<float>(std::cos(phi) * std::sin(theta));
            p[kBrunetonDirections + k] = static_cast<float>(std::sin(phi) * std::sin(theta));
            p[2 * kBrunetonDirections + k] = static_cast<float>(std::cos(theta));
            p[3 * kBrunetonDirections + k] = static_cast<float>(dtheta * dphi * std::sin(theta));
        }
    }
    return t;
}

// Per row (r, mu): the view-ray samples (distance, transmittance from the
// camera, densities) are shared by the row's (mu_s, nu) texels; only the sun's
// transmittance depends on them (BrunetonSingleScatteringStage per texel).
void ComputeBrunetonSingleScatteringRowsScalar(const BrunetonLut& lut, Table* rayleigh,
                                               Table* mie) {
    const BrunetonConfig& c = lut.cfg;
    const int width = c.scattering_nu * c.scattering_mu_s;
    rayleigh->Resize(width, c.scattering_mu, c.scattering_r, 3);
    mie->Resize(width, c.scattering_mu, c.scattering_r, 3);
    ForEachRow("bruneton single scattering (scalar rows)", c, [&](int64_t row) {
        const RowSamples<BrunetonSingleSample> rs = SingleScatteringRow(lut, row);
        const int y = rs.y, z = rs.z;
        const double r = rs.r, dx = rs.dx;
        const std::vector<BrunetonSingleSample>& samples = rs.samples;
        double mu_s, nu;
        bool ground;
        const Rgb beta_r = Rgb(lut.atm.rayleigh_scattering * dx);
        const Rgb beta_m = Rgb(lut.atm.mie_scattering * dx);
        for (int x = 0; x < width; ++x) {
            double r2, mu2;
            lut.RMuMuSNuFromTexel(x, y, z, &r2, &mu2, &mu_s, &nu, &ground);
            Rgb sum_r, sum_m;
            for (const BrunetonSingleSample& s : samples) {
                BrunetonSingleScatteringAdd(lut, s, r, mu_s, nu, &sum_r, &sum_m);
            }
            rayleigh->Set(x, y, z, BrunetonVec4(sum_r * beta_r));
            mie->Set(x, y, z, BrunetonVec4(sum_m * beta_m));
        }
    });
}

// Per row (r, mu): the samples' transmittance from the camera and the (mu, r)
// part of their table coordinates are shared by the row's texels
// (BrunetonMultipleScatteringStage per texel).
void ComputeBrunetonMultipleScatteringRowsScalar(const BrunetonLut& lut, const TableView& density,
                                                 Table* out) {
    const BrunetonConfig& c = lut.cfg;
    const int width = c.scattering_nu * c.scattering_mu_s;
    out->Resize(width, c.scattering_mu, c.scattering_r, 3);
    const BrunetonFastLookup fast(lut, density);
    ForEachRow("bruneton multiple scattering (scalar rows)", c, [&](int64_t row) {
        const RowSamples<BrunetonMultipleSample> rs = MultipleScatteringRow(lut, fast, row);
        const int y = rs.y, z = rs.z;
        const double r = rs.r;
        const std::vector<BrunetonMultipleSample>& samples = rs.samples;
        double mu_s, nu;
        bool ground;
        // Samples outer, texels inner: the four table rows of one sample stay in
        // the cache while the row's texels read them.
        const size_t w = static_cast<size_t>(width);
        std::vector<double> mu_s_x(w), nu_x(w), tex_x(w);
        std::vector<float> lerp(w);
        std::vector<Rgb> sum(w);
        for (int x = 0; x < width; ++x) {
            double r2, mu2;
            lut.RMuMuSNuFromTexel(x, y, z, &r2, &mu2, &mu_s, &nu, &ground);
            const size_t k = static_cast<size_t>(x);
            mu_s_x[k] = mu_s;
            nu_x[k] = nu;
            BrunetonNuCoordinate(nu, c.scattering_nu, &tex_x[k], &lerp[k]);
        }
        std::vector<double> u_mu_s(w);
        for (const BrunetonMultipleSample& s : samples) {
            // First the mu_s coordinates of all texels (a vectorisable loop)...
            for (size_t k = 0; k < w; ++k) {
                u_mu_s[k] = BrunetonMultipleScatteringUMuS(fast, s, r, mu_s_x[k], nu_x[k]);
            }
            // ...then the lookups.
            for (size_t k = 0; k < w; ++k) {
                sum[k] += BrunetonMultipleScatteringTerm(fast, s, tex_x[k], lerp[k], u_mu_s[k]);
            }
        }
        for (int x = 0; x < width; ++x) {
            out->Set(x, y, z, BrunetonVec4(sum[static_cast<size_t>(x)]));
        }
    });
}

// ---- vectorised rows (issue 19 item 2) ----
// The same per-row sample data as the scalar rows above; then, per view-ray
// sample, one loop over the row's texels on plain arrays (structure of arrays:
// one array per texel quantity, one per channel), which `#pragma omp simd`
// (ATMOS_SIMD_WIDE) turns into vector code: the per-sample constants hoisted out of
// the loop, the table lookups written out for the fixed 3-channel layout.

// The row's (mu_s, nu) per texel, x = nu * MU_S + mu_s: RMuMuSNuFromTexel's
// values, its mapping done once per mu_s column.
void BrunetonRowMuSNu(const BrunetonLut& lut, int y, int z, int width, double* mu_s_x,
                      double* nu_x) {
    const int mu_s_size = lut.cfg.scattering_mu_s;
    double r, mu = 0.0, nu;
    bool ground;
    for (int x = 0; x < mu_s_size; ++x) {
        lut.RMuMuSNuFromTexel(x, y, z, &r, &mu, &mu_s_x[x], &nu, &ground);
    }
    for (int x = mu_s_size; x < width; ++x) mu_s_x[x] = mu_s_x[x % mu_s_size];
    for (int x = 0; x < width; ++x) {
        nu_x[x] = BrunetonLut::ClampNu(lut.TexelNuUnclamped(x / mu_s_size), mu, mu_s_x[x]);
    }
}

// Single scattering: per sample, the transmittance to the sun at every texel of
// the row (BrunetonSingleScatteringAdd: GetTransmittanceToSun, i.e. the sun
// disc's smoothstep and TransmittanceToTop's lookup) with the sample's radius
// terms (the horizon angle, rho, the table row v) computed once. Every
// operation of the scalar form, in its order: the tables are bit-identical.
void ComputeBrunetonSingleScatteringRows(const BrunetonLut& lut, Table* rayleigh, Table* mie) {
    const BrunetonConfig& c = lut.cfg;
    const AtmosphereParameters& atm = lut.atm;
    const BrunetonConstants& kc = lut.k;
    const int width = c.scattering_nu * c.scattering_mu_s;
    rayleigh->Resize(width, c.scattering_mu, c.scattering_r, 3);
    mie->Resize(width, c.scattering_mu, c.scattering_r, 3);
    const TableView& tt = lut.transmittance_table;
    ATMOS_DASSERT(tt.channels == 3);
    const float* const tdata = tt.data;
    const int t_width = tt.width;
    const double top2 = kc.top * kc.top;
    ForEachRow("bruneton single scattering (rows)", c, [&](int64_t row) {
        const RowSamples<BrunetonSingleSample> rs = SingleScatteringRow(lut, row);
        const int y = rs.y, z = rs.z;
        const double r = rs.r, dx = rs.dx;
        const std::vector<BrunetonSingleSample>& samples = rs.samples;
        const size_t wz = static_cast<size_t>(width);
        std::vector<double> texel(2 * wz);
        double* const mu_s_x = texel.data();
        double* const nu_x = mu_s_x + wz;
        BrunetonRowMuSNu(lut, y, z, width, mu_s_x, nu_x);
        std::vector<float> acc(6 * wz, 0.0f);  // Rayleigh R, G, B, then Mie R, G, B
        float* const sr0 = acc.data();
        float* const sr1 = sr0 + wz;
        float* const sr2 = sr1 + wz;
        float* const sm0 = sr2 + wz;
        float* const sm1 = sm0 + wz;
        float* const sm2 = sm1 + wz;
        for (const BrunetonSingleSample& s : samples) {
            // GetTransmittanceToSun's terms of the radius s.r.
            const double sin_theta_h = atm.bottom_radius / s.r;
            const double cos_theta_h = -SafeSqrt(1.0 - sin_theta_h * sin_theta_h);
            const double a = sin_theta_h * atm.sun_angular_radius;
            const double e0 = -a;
            const double e_range = a - e0;
            // TransmittanceUvFromRMu's terms of the radius (s.r is clamped).
            const double sr = s.r;
            const double rr = sr * sr;
            const double rho = SafeSqrt(rr - kc.bottom2);
            const double d_min = kc.top - sr;
            const double d_range = (rho + kc.H) - d_min;
            const double u_off = kc.transmittance_u.offset, u_scale = kc.transmittance_u.scale;
            const TexelSpan ty = SplitSpan(kc.transmittance_v(rho / kc.H), tt.height);
            const int row0 = ty.i0 * t_width, row1 = ty.i1 * t_width;
            const float fy = ty.f;
            const float tr0 = s.t_rayleigh.x, tr1 = s.t_rayleigh.y, tr2 = s.t_rayleigh.z;
            const float tm0 = s.t_mie.x, tm1 = s.t_mie.y, tm2 = s.t_mie.z;
            const double sd = s.d;
            ATMOS_SIMD_WIDE
            for (int k = 0; k < width; ++k) {
                const double mu_s_d = ClampCosine((r * mu_s_x[k] + sd * nu_x[k]) / sr);
                const double t = Clamp(((mu_s_d - cos_theta_h) - e0) / e_range, 0.0, 1.0);
                const float f = static_cast<float>(t * t * (3.0 - 2.0 * t));
                const double d =
                    Max(-sr * mu_s_d + SafeSqrt(rr * (mu_s_d * mu_s_d - 1.0) + top2), 0.0);
                const double u = u_off + ((d - d_min) / d_range) * u_scale;
                const TexelSpan tx = SplitSpan(u, t_width);
                const int i0 = tx.i0, i1 = tx.i1;
                const float fx = tx.f;
                const float* a0 = tdata + (row0 + i0) * 3;
                const float* a1 = tdata + (row0 + i1) * 3;
                const float* b0 = tdata + (row1 + i0) * 3;
                const float* b1 = tdata + (row1 + i1) * 3;
                float ts[3];
                for (int ch = 0; ch < 3; ++ch) {
                    const float ta = a0[ch] * (1.0f - fx) + a1[ch] * fx;
                    const float tb = b0[ch] * (1.0f - fx) + b1[ch] * fx;
                    ts[ch] = (ta * (1.0f - fy) + tb * fy) * f;
                }
                sr0[k] += ts[0] * tr0;
                sr1[k] += ts[1] * tr1;
                sr2[k] += ts[2] * tr2;
                sm0[k] += ts[0] * tm0;
                sm1[k] += ts[1] * tm1;
                sm2[k] += ts[2] * tm2;
            }
        }
        const Rgb beta_r = Rgb(atm.rayleigh_scattering * dx);
        const Rgb beta_m = Rgb(atm.mie_scattering * dx);
        for (int x = 0; x < width; ++x) {
            rayleigh->Set(x, y, z, BrunetonVec4(Rgb(sr0[x], sr1[x], sr2[x]) * beta_r));
            mie->Set(x, y, z, BrunetonVec4(Rgb(sm0[x], sm1[x], sm2[x]) * beta_m));
        }
    });
}

// Multiple scattering: per sample, the density's two (mu, r) row pairs are
// interpolated along mu and r once for the whole table row (one contiguous
// loop), then each texel interpolates that row along x at its two nu slices
// (its mu_s coordinate computed in the same loop). The scalar form (the
// renderer's 4D lookup) interpolates along x first: the same trilinear
// interpolation in another order, so the tables differ by float rounding
// (tests/bruneton_stages_test.cpp states the bound).
void ComputeBrunetonMultipleScatteringRows(const BrunetonLut& lut, const TableView& density,
                                           Table* out) {
    const BrunetonConfig& c = lut.cfg;
    const BrunetonConstants& kc = lut.k;
    const int width = c.scattering_nu * c.scattering_mu_s;
    out->Resize(width, c.scattering_mu, c.scattering_r, 3);
    ATMOS_DASSERT(density.channels == 3 && density.width == width);
    const BrunetonFastLookup fast(lut, density);
    const int nu_size = c.scattering_nu;
    const double top2 = kc.top * kc.top;
    const double bb = kc.bottom * kc.bottom;
    // Reciprocals of the mappings' divisors: one multiplication each in the loop
    // (the coordinates differ from the renderer's divisions by at most 1 ulp).
    const double inv_d_range = 1.0 / kc.mu_s_d_range;
    const double inv_big_a = 1.0 / kc.mu_s_big_a;
    const double inv_nu = 1.0 / nu_size;
    ForEachRow("bruneton multiple scattering (rows)", c, [&](int64_t row) {
        const RowSamples<BrunetonMultipleSample> rs = MultipleScatteringRow(lut, fast, row);
        const int y = rs.y, z = rs.z;
        const double r = rs.r;
        const std::vector<BrunetonMultipleSample>& samples = rs.samples;
        const size_t wz = static_cast<size_t>(width);
        std::vector<double> texel(3 * wz);
        double* const mu_s_x = texel.data();
        double* const nu_x = mu_s_x + wz;
        double* const tex_x = nu_x + wz;
        std::vector<float> lerp_x(wz);
        BrunetonRowMuSNu(lut, y, z, width, mu_s_x, nu_x);
        for (size_t k = 0; k < wz; ++k) {
            BrunetonNuCoordinate(nu_x[k], nu_size, &tex_x[k], &lerp_x[k]);
        }
        const float* const lerp = lerp_x.data();
        std::vector<float> buf(6 * wz, 0.0f);  // the sums R, G, B
        float* const s0 = buf.data();
        float* const s1 = s0 + wz;
        float* const s2 = s1 + wz;
        float* const p = s2 + wz;  // the interpolated row, 3 channels interleaved
        const int n3 = 3 * width;
        for (const BrunetonMultipleSample& s : samples) {
            const float* q0 = density.data + s.rows.row[0] * 3;
            const float* q1 = density.data + s.rows.row[1] * 3;
            const float* q2 = density.data + s.rows.row[2] * 3;
            const float* q3 = density.data + s.rows.row[3] * 3;
            const float fy = s.rows.fy, fz = s.rows.fz;
            ATMOS_SIMD_WIDE
            for (int j = 0; j < n3; ++j) {
                p[j] = (q0[j] * (1.0f - fy) + q1[j] * fy) * (1.0f - fz) +
                       (q2[j] * (1.0f - fy) + q3[j] * fy) * fz;
            }
            const double rd = r;
            const double sd = s.d, inv_r = s.inv_r;
            const float t0 = s.t.x, t1 = s.t.y, t2 = s.t.z;
            ATMOS_SIMD_WIDE
            for (int k = 0; k < width; ++k) {
                // BrunetonUMuS of the sample's mu_s.
                const double ms = ClampCosine((rd * mu_s_x[k] + sd * nu_x[k]) * inv_r);
                const double d = Max(-kc.bottom * ms + SafeSqrt(bb * (ms * ms - 1.0) + top2), 0.0);
                const double a = (d - kc.mu_s_d_min) * inv_d_range;
                const double u_mu_s = kc.scattering_mu_s(Max(1.0 - a * inv_big_a, 0.0) / (1.0 + a));
                // BrunetonSplitColumns: the two nu slices.
                const TexelSpan sa = SplitSpan((tex_x[k] + u_mu_s) * inv_nu, width);
                const TexelSpan sb = SplitSpan((tex_x[k] + 1.0 + u_mu_s) * inv_nu, width);
                const int a0 = sa.i0, a1 = sa.i1, b0 = sb.i0, b1 = sb.i1;
                const float fa = sa.f, fb = sb.f;
                const float l = lerp[k];
                float v[3];
                for (int ch = 0; ch < 3; ++ch) {
                    const float ta = p[a0 * 3 + ch] * (1.0f - fa) + p[a1 * 3 + ch] * fa;
                    const float tb = p[b0 * 3 + ch] * (1.0f - fb) + p[b1 * 3 + ch] * fb;
                    v[ch] = ta * (1.0f - l) + tb * l;
                }
                s0[k] += v[0] * t0;
                s1[k] += v[1] * t1;
                s2[k] += v[2] * t2;
            }
        }
        for (int x = 0; x < width; ++x) out->Set(x, y, z, BrunetonVec4(Rgb(s0[x], s1[x], s2[x])));
    });
}

void PrecomputeBruneton(const AtmosphereParameters& atmosphere, const BrunetonConfig& config,
                        BrunetonTables* tables, const BrunetonOrderCallback& on_order) {
    PrecomputeBrunetonWith(atmosphere, config, IsDeviceBackend(CurrentBackend()), tables, on_order);
}

void PrecomputeBrunetonWith(const AtmosphereParameters& atmosphere, const BrunetonConfig& config,
                            bool texel_stages, BrunetonTables* tables,
                            const BrunetonOrderCallback& on_order, bool scalar_rows) {
    ValidateBrunetonConfig(config);
    BrunetonLut lut(atmosphere, config);
    const BrunetonLut mappings = BrunetonMappingsOnly(lut);
    const int width = config.scattering_nu * config.scattering_mu_s;
    // A progress bar (CLI, over a second): one step for order 1, four per
    // further order (incident radiance, density, irradiance, multiple scattering).
    Progress progress("bruneton precompute", 1 + 4 * static_cast<int64_t>(config.orders - 1),
                      LibraryProgressEnabled());
    // On a device backend all tables stay on the device between the stages;
    // the host gets the final tables, and the tables on_order reads, by Download.
    StageSession session;
    const auto download = [&](Table* delta_density) {
        session.Download(&tables->transmittance);
        session.Download(&tables->irradiance);
        session.Download(&tables->scattering);
        session.Download(&tables->single_mie);
        if (delta_density) session.Download(delta_density);
    };

    tables->transmittance.Resize(config.transmittance_width, config.transmittance_height, 1, 3);
    RunStage("bruneton transmittance", TexelCount(tables->transmittance),
             config.transmittance_width,
             BrunetonTransmittanceStage{mappings, tables->transmittance.out()});
    lut.transmittance_table = tables->transmittance.view();

    Table delta_irradiance(config.irradiance_width, config.irradiance_height, 1, 3);
    RunStage("bruneton direct irradiance", TexelCount(delta_irradiance), config.irradiance_width,
             BrunetonDirectIrradianceStage{lut, delta_irradiance.out()});
    // The irradiance table holds the indirect irradiance only (the direct one is
    // computed at render time from the transmittance, Bruneton's 2017 implementation notes).
    tables->irradiance.Resize(config.irradiance_width, config.irradiance_height, 1, 3);

    Table delta_rayleigh, delta_mie;
    if (texel_stages) {
        delta_rayleigh.Resize(width, config.scattering_mu, config.scattering_r, 3);
        delta_mie.Resize(width, config.scattering_mu, config.scattering_r, 3);
        RunStage("bruneton single scattering", TexelCount(delta_rayleigh), width,
                 BrunetonSingleScatteringStage{lut, delta_rayleigh.out(), delta_mie.out()});
    } else if (scalar_rows) {
        ComputeBrunetonSingleScatteringRowsScalar(lut, &delta_rayleigh, &delta_mie);
    } else {
        ComputeBrunetonSingleScatteringRows(lut, &delta_rayleigh, &delta_mie);
    }
    tables->scattering.Resize(width, config.scattering_mu, config.scattering_r,
                              config.combined_mie ? 4 : 3);
    if (config.combined_mie) {
        tables->single_mie = Table();
    } else {
        tables->single_mie.Resize(width, config.scattering_mu, config.scattering_r, 3);
    }
    RunStage("bruneton combine", TexelCount(delta_rayleigh), width,
             BrunetonCombineStage{delta_rayleigh.view(), delta_mie.view(), tables->scattering.out(),
                                  config.combined_mie ? TableOut() : tables->single_mie.out()});
    progress.Add(1);
    if (on_order) {
        download(nullptr);
        on_order(1, *tables, nullptr);
    }

    const Table directions = MakeBrunetonDirectionTable();
    Table incident, delta_multiple, delta_density;
    // Each order's multiple scattering is summed: orders that stop decreasing
    // are reported (models/order_check.h; orders >= 2 share their units).
    ScatteringOrders sums;
    for (int order = 2; order <= config.orders; ++order) {
        // 1. Incident radiance per (r, mu_s, direction); 2. per texel, its
        // phase-weighted sums in the sun's frame.
        incident.Resize(3 * kBrunetonDirections, config.scattering_mu_s, config.scattering_r, 1);
        BrunetonIncidentStage inc;
        inc.lut = lut;
        inc.single_rayleigh = delta_rayleigh.view();
        inc.single_mie = delta_mie.view();
        inc.multiple = delta_multiple.view();
        inc.ground_irradiance = delta_irradiance.view();
        inc.directions = directions.view();
        inc.order = order;
        inc.incident = incident.out();
        if (order == 2) {
            inc.multiple = TableView();
        } else {
            inc.single_rayleigh = TableView();
            inc.single_mie = TableView();
        }
        if (MaxComponent(atmosphere.ground_albedo) <= 0.0) inc.ground_irradiance = TableView();
        RunStage("bruneton incident radiance",
                 static_cast<int64_t>(kBrunetonDirections) * config.scattering_mu_s *
                     config.scattering_r,
                 kBrunetonDirections, inc);
        progress.Add(1);
        delta_density.Resize(width, config.scattering_mu, config.scattering_r, 3);
        RunStage("bruneton scattering density", TexelCount(delta_density), width,
                 BrunetonDensityStage{mappings, incident.view(), directions.view(),
                                      delta_density.out()});
        progress.Add(1);

        BrunetonIndirectIrradianceStage irr;
        irr.lut = mappings;
        irr.order = order - 1;
        if (irr.order == 1) {
            irr.single_rayleigh = delta_rayleigh.view();
            irr.single_mie = delta_mie.view();
        } else {
            irr.multiple = delta_multiple.view();
        }
        irr.out = delta_irradiance.out();
        RunStage("bruneton indirect irradiance", TexelCount(delta_irradiance), 4, irr);
        RunStage("bruneton add irradiance", TexelCount(delta_irradiance), config.irradiance_width,
                 BrunetonAddStage{delta_irradiance.view(), tables->irradiance.out(true)});
        progress.Add(1);

        if (texel_stages) {
            delta_multiple.Resize(width, config.scattering_mu, config.scattering_r, 3);
            RunStage(
                "bruneton multiple scattering", TexelCount(delta_multiple), width,
                BrunetonMultipleScatteringStage{lut, delta_density.view(), delta_multiple.out()});
        } else if (scalar_rows) {
            ComputeBrunetonMultipleScatteringRowsScalar(lut, delta_density.view(), &delta_multiple);
        } else {
            ComputeBrunetonMultipleScatteringRows(lut, delta_density.view(), &delta_multiple);
        }
        progress.Add(1);
        session.Download(&delta_multiple);
        sums.Add(order, TableSum(delta_multiple));
        // Accumulate, divided by the Rayleigh phase function (the renderer
        // multiplies the whole table by it; Bruneton's 2017 implementation notes "Rendering").
        RunStage(
            "bruneton accumulate", TexelCount(delta_multiple), width,
            BrunetonAccumulateStage{mappings, delta_multiple.view(), tables->scattering.out(true)});
        if (on_order) {
            download(&delta_density);
            on_order(order, *tables, &delta_density);
        }
    }
    download(nullptr);
    sums.WarnIfDiverging("bruneton", 3);
}

}  // namespace atmos
