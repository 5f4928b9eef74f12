// atmos model `bruneton`: the precomputation of n channels at once (wide
// channel batches, issue 37; docs/models/bruneton.md "Wide channel batches").
//
// PrecomputeBruneton for every batch of a wide group in one pass: each stage
// computes a texel's (or a sample's, or a direction's) geometry once (ray
// distances, sample radii, table coordinates and texel spans, phase functions,
// direction sets, densities, thick-ray tests) and then loops over the n = 3 x
// batches channels on contiguous floats (channel 3b + c: batch b's channel c,
// the layout GatherChannels gives), with the per-channel coefficients of
// WideCoefficients. Each channel takes the operations of the three-channel
// CPU precomputation (bruneton_precompute.cpp: the texel stages of
// transmittance, irradiance, incident radiance, density and accumulation, and
// the vectorised rows of single and multiple scattering) in their order, so
// the tables equal the batches' gathered tables bit for bit
// (tests/bruneton_wide_precompute_test.cpp). CPU only: the device backend
// keeps the per-batch precomputation (BrunetonModel::PrepareWide).
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "atmos/error.h"
#include "base/cpu_features.h"
#include "base/library_progress.h"
#include "base/parallel.h"
#include "base/progress.h"
#include "models/bruneton.h"
#include "models/bruneton_stages.h"
#include "models/bruneton_wide.h"
#include "models/order_check.h"
#include "physics/vector_exp.h"
#include "render/stages.h"

namespace atmos {

namespace {

using Clock = std::chrono::steady_clock;
constexpr int kWideBatches = kMaxWideChannels / 3;

// Runs body(i) for i < count (ParallelFor) and logs it as a CPU stage.
template <typename F>
void RunWide(const char* name, int64_t count, int64_t grain, const F& body) {
    RunCpuStage(name, count, grain, body);
}

size_t Texels(const Table& t) { return static_cast<size_t>(t.width()) * t.height() * t.depth(); }

// Extinction (physics/density.h) of channel c at densities rho.
inline double WideExtinction(const WideCoefficients& w, int c, const Densities& rho) {
    return w.rayleigh_scattering[c] * rho.rayleigh + w.mie_extinction[c] * rho.mie +
           w.absorption_extinction[c] * rho.absorption;
}

// RayHasThickSteps(batch b's atmosphere, r, mu, ds, n) for every batch b: the
// nodes' densities once, each channel's extinction (MaxComponent(e) * ds >
// 1 is "some channel's e * ds > 1": the product rounds monotonically).
bool WideThickBatches(const AtmosphereParameters& atm, const WideCoefficients& w, double r,
                      double mu, double ds, int n, bool thick[kWideBatches]) {
    const int batches = w.channels / 3;
    for (int b = 0; b < batches; ++b) thick[b] = false;
    const Vec3d origin(0.0, 0.0, r);
    const Vec3d dir(SafeSqrt(1.0 - mu * mu), 0.0, mu);
    int count = 0;
    for (int i = 0; i <= n && count < batches; ++i) {
        const double alt = Length(origin + dir * (0.0 + i * ds)) - atm.bottom_radius;
        const Densities rho = GetDensities(atm, alt);
        for (int b = 0; b < batches; ++b) {
            if (thick[b]) continue;
            for (int c = 3 * b; c < 3 * b + 3; ++c) {
                if (WideExtinction(w, c, rho) * ds > kThickStepOpticalDepth) {
                    thick[b] = true;
                    ++count;
                    break;
                }
            }
        }
    }
    return count > 0;
}

// BrunetonLut::GetScattering of an n-channel table of the scattering layout.
inline void WideGetScattering(const BrunetonLut& lut, const TableView& table, double r, double mu,
                              double mu_s, double nu, bool ground, float* out) {
    double uvwz[4];
    lut.ScatteringUvwz(lut.ClampRadius(r), ClampCosine(mu), ClampCosine(mu_s), ClampCosine(nu),
                       ground, uvwz);
    Bruneton4DRows rows;
    Bruneton4DColumns cols;
    lut.Split4D(table, uvwz, &rows, &cols);
    BrunetonWideSample4D(table.data, table.channels, rows, cols, out);
}

// ---- transmittance (BrunetonTransmittanceStage: OpticalDepth's trapezoid,
// the densities once per sample) ----
void WideTransmittance(const BrunetonLut& lut, const WideCoefficients& w, Table* out) {
    const BrunetonConfig& cfg = lut.cfg;
    const AtmosphereParameters& atm = lut.atm;
    const int width = cfg.transmittance_width, height = cfg.transmittance_height;
    const int n = w.channels;
    out->Resize(width, height, 1, n);
    RunWide("bruneton wide transmittance", static_cast<int64_t>(width) * height, width,
            [&](int64_t item) {
                const int x = static_cast<int>(item % width);
                const int y = static_cast<int>(item / width);
                double r, mu;
                lut.RMuFromTransmittanceUv((x + 0.5) / width, (y + 0.5) / height, &r, &mu);
                // OpticalDepthToTopAtmosphereBoundary -> OpticalDepth.
                const int samples = kBrunetonTransmittanceSamples;
                const double d = DistanceToTopAtmosphereBoundary(r, mu, atm.top_radius);
                const Vec3d origin(0.0, 0.0, r);
                const Vec3d dir(SafeSqrt(1.0 - mu * mu), 0.0, mu);
                const double dx = d / samples;
                double sum[kMaxWideChannels];
                for (int c = 0; c < n; ++c) sum[c] = 0.0;
                for (int i = 0; i <= samples; ++i) {
                    const double t = i * dx;
                    const double altitude = Length(origin + dir * t) - atm.bottom_radius;
                    const double wi = (i == 0 || i == samples) ? 0.5 : 1.0;
                    const Densities rho = GetDensities(atm, altitude);
                    for (int c = 0; c < n; ++c) sum[c] += WideExtinction(w, c, rho) * wi;
                }
                float* o = out->Texel(x, y);
                for (int c = 0; c < n; ++c) o[c] = static_cast<float>(Exp(-(sum[c] * dx)));
            });
}

// ---- direct irradiance (BrunetonDirectIrradianceStage) ----
void WideDirectIrradiance(const BrunetonWideEvaluator& ev, Table* out) {
    const BrunetonLut& lut = ev.lut;
    const int width = lut.cfg.irradiance_width, height = lut.cfg.irradiance_height;
    const int n = ev.w.channels;
    out->Resize(width, height, 1, n);
    RunWide("bruneton wide direct irradiance", static_cast<int64_t>(width) * height, width,
            [&](int64_t item) {
                const int x = static_cast<int>(item % width);
                const int y = static_cast<int>(item / width);
                double r, mu_s;
                lut.RMuSFromIrradianceUv((x + 0.5) / width, (y + 0.5) / height, &r, &mu_s);
                const double alpha_s = lut.atm.sun_angular_radius;
                const double c =
                    mu_s < -alpha_s
                        ? 0.0
                        : (mu_s > alpha_s ? mu_s
                                          : (mu_s + alpha_s) * (mu_s + alpha_s) / (4.0 * alpha_s));
                float* o = out->Texel(x, y);
                ev.TransmittanceToTop(r, mu_s, o);
                const float f = static_cast<float>(c);
                for (int ch = 0; ch < n; ++ch) o[ch] = o[ch] * f;
            });
}

// The per-texel geometry of one view-ray sample of a row, in functions of
// plain arguments (inside the row lambdas GCC leaves these loops scalar; here
// they vectorise, lane by lane the same IEEE operations).
//
// Single scattering: each texel's sun-disc factor f and transmittance texel
// span along mu (ComputeBrunetonSingleScatteringRows' inner loop).
__attribute__((noinline)) void SunColumns(int width, double r, const double* mu_s_x,
                                          const double* nu_x, double s_d, double s_r,
                                          double cos_theta_h, double e0, double e_range, double rr,
                                          double top2, double u_off, double d_min, double d_range,
                                          double u_scale, int t_width, float* f_x, int* i0_x,
                                          int* i1_x, float* fx_x) {
    ATMOS_SIMD_WIDE
    for (int k = 0; k < width; ++k) {
        const double mu_s_d = ClampCosine((r * mu_s_x[k] + s_d * nu_x[k]) / s_r);
        const double t = Clamp(((mu_s_d - cos_theta_h) - e0) / e_range, 0.0, 1.0);
        f_x[k] = static_cast<float>(t * t * (3.0 - 2.0 * t));
        const double d = Max(-s_r * mu_s_d + SafeSqrt(rr * (mu_s_d * mu_s_d - 1.0) + top2), 0.0);
        const double u = u_off + ((d - d_min) / d_range) * u_scale;
        const TexelSpan tx = SplitSpan(u, t_width);
        i0_x[k] = tx.i0;
        i1_x[k] = tx.i1;
        fx_x[k] = tx.f;
    }
}
// Multiple scattering: each texel's mu_s coordinate at the sample and its two
// nu slices' spans (ComputeBrunetonMultipleScatteringRows' inner loop).
__attribute__((noinline)) void DensityColumns(int width, double r, const double* mu_s_x,
                                              const double* nu_x, const double* tex_x, double s_d,
                                              double inv_r, double bottom, double bb, double top2,
                                              double mu_s_d_min, double inv_d_range,
                                              double inv_big_a, TexelCentreMap mu_s_map,
                                              double inv_nu, int* a0_x, int* a1_x, int* b0_x,
                                              int* b1_x, float* fa_x, float* fb_x) {
    ATMOS_SIMD_WIDE
    for (int k = 0; k < width; ++k) {
        const double ms = ClampCosine((r * mu_s_x[k] + s_d * nu_x[k]) * inv_r);
        const double d = Max(-bottom * ms + SafeSqrt(bb * (ms * ms - 1.0) + top2), 0.0);
        const double a = (d - mu_s_d_min) * inv_d_range;
        const double u_mu_s = mu_s_map(Max(1.0 - a * inv_big_a, 0.0) / (1.0 + a));
        const TexelSpan sa = SplitSpan((tex_x[k] + u_mu_s) * inv_nu, width);
        const TexelSpan sb = SplitSpan((tex_x[k] + 1.0 + u_mu_s) * inv_nu, width);
        a0_x[k] = sa.i0;
        a1_x[k] = sa.i1;
        b0_x[k] = sb.i0;
        b1_x[k] = sb.i1;
        fa_x[k] = sa.f;
        fb_x[k] = sb.f;
    }
}

// ---- single scattering (ComputeBrunetonSingleScatteringRows per channel) ----
void WideSingleScattering(const BrunetonWideEvaluator& ev,
                          const std::vector<AtmosphereParameters>& batches, Table* rayleigh,
                          Table* mie) {
    const BrunetonLut& lut = ev.lut;
    const WideCoefficients& w = ev.w;
    const BrunetonConfig& c = lut.cfg;
    const AtmosphereParameters& atm = lut.atm;
    const BrunetonConstants& kc = lut.k;
    const int n = w.channels;
    const size_t nn = static_cast<size_t>(n);
    const int width = c.scattering_nu * c.scattering_mu_s;
    rayleigh->Resize(width, c.scattering_mu, c.scattering_r, n);
    mie->Resize(width, c.scattering_mu, c.scattering_r, n);
    const TableView& tt = lut.transmittance_table;
    const float* const tdata = tt.data;
    const int t_width = tt.width;
    const double top2 = kc.top * kc.top;
    RunWide(
        "bruneton wide single scattering (rows)",
        static_cast<int64_t>(c.scattering_mu) * c.scattering_r, 1, [&](int64_t row) {
            const int y = static_cast<int>(row % c.scattering_mu);
            const int z = static_cast<int>(row / c.scattering_mu);
            double r_texel, mu, mu_s0, nu0;
            bool ground;
            lut.RMuMuSNuFromTexel(0, y, z, &r_texel, &mu, &mu_s0, &nu0, &ground);
            const double r = r_texel;  // a local whose address is not taken (the loops vectorise)
            const int steps = c.scattering_samples;
            const double dx = lut.DistanceToNearestAtmosphereBoundary(r, mu, ground) / steps;
            // The samples (BrunetonSingleScatteringSample): per sample the
            // distance and radius, per channel the weighted transmittance
            // times each density.
            bool thick[kWideBatches];
            const bool any_thick = WideThickBatches(atm, w, r, mu, dx, steps, thick);
            std::vector<ThickRayWeights> weights;
            if (any_thick) weights.assign(w.channels / 3, ThickRayWeights(r, mu, dx, steps));
            const size_t ns = static_cast<size_t>(steps) + 1;
            std::vector<double> sd(ns), srad(ns);
            std::vector<float> st(2 * ns * nn);  // t_rayleigh, then t_mie, per sample
            for (int i = 0; i <= steps; ++i) {
                const size_t si = static_cast<size_t>(i);
                const double d = i * dx;
                sd[si] = d;
                srad[si] = lut.ClampRadius(Sqrt(d * d + 2.0 * r * mu * d + r * r));
                const double alt = srad[si] - atm.bottom_radius;
                const double rho_r = GetProfileDensity(atm.rayleigh_density, alt);
                const double rho_m = GetProfileDensity(atm.mie_density, alt);
                float* tr = st.data() + si * nn;
                float* tm = st.data() + (ns + si) * nn;
                float t[kMaxWideChannels];
                ev.Transmittance(r, mu, d, ground, t);
                const float wq =
                    static_cast<float>(BrunetonQuadratureWeight(c.scattering_rule, i, steps));
                const float fr = static_cast<float>(rho_r), fm = static_cast<float>(rho_m);
                for (int ch = 0; ch < n; ++ch) {
                    tr[ch] = t[ch] * fr * wq;
                    tm[ch] = t[ch] * fm * wq;
                }
                if (!any_thick) continue;
                for (int b = 0; b < n / 3; ++b) {
                    if (!thick[b]) continue;
                    // W_i / sigma_t,i / dx (the caller multiplies by beta dx).
                    const Vec3d wt =
                        weights[static_cast<size_t>(b)].Next(batches[static_cast<size_t>(b)], i);
                    const Rgb vr = Rgb(wt * (rho_r / dx));
                    const Rgb vm = Rgb(wt * (rho_m / dx));
                    for (int k = 0; k < 3; ++k) {
                        tr[3 * b + k] = vr[k];
                        tm[3 * b + k] = vm[k];
                    }
                }
            }
            const size_t wz = static_cast<size_t>(width);
            std::vector<double> texel(2 * wz);
            double* const mu_s_x = texel.data();
            double* const nu_x = mu_s_x + wz;
            BrunetonRowMuSNu(lut, y, z, width, mu_s_x, nu_x);
            std::vector<float> acc(2 * wz * nn, 0.0f);  // Rayleigh, then Mie, [texel][channel]
            float* const acc_r = acc.data();
            float* const acc_m = acc_r + wz * nn;
            std::vector<float> fxf(2 * wz);
            float* const f_x = fxf.data();
            float* const fx_x = f_x + wz;
            std::vector<int> span(2 * wz);
            int* const i0_x = span.data();
            int* const i1_x = i0_x + wz;
            for (size_t si = 0; si < ns; ++si) {
                // GetTransmittanceToSun's terms of the radius (as the rows).
                const double s_r = srad[si];
                const double sin_theta_h = atm.bottom_radius / s_r;
                const double cos_theta_h = -SafeSqrt(1.0 - sin_theta_h * sin_theta_h);
                const double a = sin_theta_h * atm.sun_angular_radius;
                const double e0 = -a;
                const double e_range = a - e0;
                const double rr = s_r * s_r;
                const double rho = SafeSqrt(rr - kc.bottom2);
                const double d_min = kc.top - s_r;
                const double d_range = (rho + kc.H) - d_min;
                const double u_off = kc.transmittance_u.offset, u_scale = kc.transmittance_u.scale;
                const TexelSpan ty = SplitSpan(kc.transmittance_v(rho / kc.H), tt.height);
                const size_t row0 = static_cast<size_t>(ty.i0) * t_width;
                const size_t row1 = static_cast<size_t>(ty.i1) * t_width;
                const float fy = ty.f;
                const double s_d = sd[si];
                // The texels' geometry (vectorised over the row)...
                SunColumns(width, r, mu_s_x, nu_x, s_d, s_r, cos_theta_h, e0, e_range, rr, top2,
                           u_off, d_min, d_range, u_scale, t_width, f_x, i0_x, i1_x, fx_x);
                // ...then the channels (vectorised over them). A texel whose
                // sun is below the horizon (f = 0) adds 0 to its sums: skipped.
                const float* const tr = st.data() + si * nn;
                const float* const tm = st.data() + (ns + si) * nn;
                for (size_t k = 0; k < wz; ++k) {
                    const float f = f_x[k];
                    if (f == 0.0f) continue;
                    const float fx = fx_x[k];
                    const float* a0 = tdata + (row0 + i0_x[k]) * nn;
                    const float* a1 = tdata + (row0 + i1_x[k]) * nn;
                    const float* b0 = tdata + (row1 + i0_x[k]) * nn;
                    const float* b1 = tdata + (row1 + i1_x[k]) * nn;
                    float* const ar = acc_r + k * nn;
                    float* const am = acc_m + k * nn;
                    ATMOS_SIMD_WIDE
                    for (int ch = 0; ch < n; ++ch) {
                        const float ta = a0[ch] * (1.0f - fx) + a1[ch] * fx;
                        const float tb = b0[ch] * (1.0f - fx) + b1[ch] * fx;
                        const float ts = (ta * (1.0f - fy) + tb * fy) * f;
                        ar[ch] += ts * tr[ch];
                        am[ch] += ts * tm[ch];
                    }
                }
            }
            float beta_r[kMaxWideChannels], beta_m[kMaxWideChannels];
            for (int ch = 0; ch < n; ++ch) {
                beta_r[ch] = static_cast<float>(w.rayleigh_scattering[ch] * dx);
                beta_m[ch] = static_cast<float>(w.mie_scattering[ch] * dx);
            }
            for (int x = 0; x < width; ++x) {
                float* const o_r = rayleigh->Texel(x, y, z);
                float* const o_m = mie->Texel(x, y, z);
                const float* const ar = acc_r + static_cast<size_t>(x) * nn;
                const float* const am = acc_m + static_cast<size_t>(x) * nn;
                for (int ch = 0; ch < n; ++ch) {
                    o_r[ch] = ar[ch] * beta_r[ch];
                    o_m[ch] = am[ch] * beta_m[ch];
                }
            }
        });
}

// ---- incident radiance (BrunetonIncidentStage): per (r, mu_s) pair, the
// 512 directions' geometry once, each channel's radiance; the table holds
// channel c's 512 directions at c * 512 .. c * 512 + 511 of its row ----
struct WideIncidentInputs {
    TableView single_rayleigh, single_mie, multiple, ground_irradiance;
    const float* solid_angle = nullptr;
    int order = 2;
};
// Where channel c's direction k lies in a (r, mu_s) pair's n x 512 incident
// floats: channels in pairs (c, c + 1), each pair's directions in blocks of
// kBrunetonLanes, a block holding the pair's two channels' lanes one after
// the other, so that one 16-float load holds both channels' lanes of a block
// (the density's sums, DensitySums).
inline size_t IncidentIndex(int c, int k) {
    constexpr int blocks = kBrunetonDirections / kBrunetonLanes;
    return ((static_cast<size_t>(c / 2) * blocks + static_cast<size_t>(k / kBrunetonLanes)) * 2 +
            static_cast<size_t>(c % 2)) *
               kBrunetonLanes +
           static_cast<size_t>(k % kBrunetonLanes);
}

void WideIncident(const BrunetonWideEvaluator& ev, const WideIncidentInputs& in, Table* incident) {
    const BrunetonLut& lut = ev.lut;
    const WideCoefficients& w = ev.w;
    const AtmosphereParameters& atm = lut.atm;
    const BrunetonConfig& cfg = lut.cfg;
    const int n = w.channels;
    // Channel pairs' blocks (IncidentIndex), an odd channel count's last pair
    // half empty.
    incident->Resize((n + (n & 1)) * kBrunetonDirections, cfg.scattering_mu_s, cfg.scattering_r, 1);
    bool any_albedo = false;
    for (int b = 0; b < n / 3; ++b) any_albedo = any_albedo || w.BatchMaxAlbedo(b) > 0.0;
    RunWide("bruneton wide incident radiance",
            static_cast<int64_t>(cfg.scattering_mu_s) * cfg.scattering_r, 1, [&](int64_t item) {
                const int s = static_cast<int>(item % cfg.scattering_mu_s);
                const int z = static_cast<int>(item / cfg.scattering_mu_s);
                double r, mu, mu_s, nu;
                bool unused;
                lut.RMuMuSNuFromTexel(s, cfg.scattering_mu / 2, z, &r, &mu, &mu_s, &nu, &unused);
                const double sin_s = SafeSqrt(1.0 - mu_s * mu_s);
                const Vec3d omega_s(sin_s, 0.0, mu_s);
                float* const out = incident->Texel(0, s, z);
                float inc[kMaxWideChannels], a[kMaxWideChannels], b[kMaxWideChannels];
                for (int k = 0; k < kBrunetonDirections; ++k) {
                    const int l = k / (2 * kBrunetonDensityThetaSamples);
                    const int m = k % (2 * kBrunetonDensityThetaSamples);
                    const double theta = (l + 0.5) * kPi / kBrunetonDensityThetaSamples;
                    const double phi = (m + 0.5) * kPi / kBrunetonDensityThetaSamples;
                    const double ct = cos(theta);
                    const bool ground = RayIntersectsGround(r, ct, atm.bottom_radius);
                    const Vec3d omega_i(cos(phi) * sin(theta), sin(phi) * sin(theta), ct);
                    const double nu1 = ClampCosine(Dot(omega_s, omega_i));
                    if (in.order == 2) {
                        double uvwz[4];
                        lut.ScatteringUvwz(lut.ClampRadius(r), ClampCosine(ct), ClampCosine(mu_s),
                                           ClampCosine(nu1), ground, uvwz);
                        Bruneton4DRows rows;
                        Bruneton4DColumns cols;
                        lut.Split4D(in.single_rayleigh, uvwz, &rows, &cols);
                        BrunetonWideSample4D(in.single_rayleigh.data, n, rows, cols, a);
                        BrunetonWideSample4D(in.single_mie.data, n, rows, cols, b);
                        const float pr = static_cast<float>(RayleighPhase(nu1));
                        const float pm = static_cast<float>(MiePhase(atm, nu1));
                        for (int c = 0; c < n; ++c) inc[c] = a[c] * pr + b[c] * pm;
                    } else {
                        WideGetScattering(lut, in.multiple, r, ct, mu_s, nu1, ground, inc);
                    }
                    if (ground && any_albedo) {
                        // Light whose (n - 1)-th bounce is on the ground.
                        const double distance_to_ground =
                            DistanceToBottomAtmosphereBoundary(r, ct, atm.bottom_radius);
                        ev.Transmittance(r, ct, distance_to_ground, true, a);
                        const Vec3d normal =
                            Normalize(Vec3d(0.0, 0.0, r) + omega_i * distance_to_ground);
                        double u, v;
                        lut.IrradianceUvFromRMuS(lut.ClampRadius(atm.bottom_radius),
                                                 ClampCosine(Dot(normal, omega_s)), &u, &v);
                        WideSampleBilinear(in.ground_irradiance, u, v, b);
                        for (int bt = 0; bt < n / 3; ++bt) {
                            if (!(w.BatchMaxAlbedo(bt) > 0.0)) continue;
                            for (int c = 3 * bt; c < 3 * bt + 3; ++c) {
                                inc[c] += a[c] *
                                          static_cast<float>(w.ground_albedo[c] * (1.0 / kPi)) *
                                          b[c];
                            }
                        }
                    }
                    const float wk = in.solid_angle[k];
                    for (int c = 0; c < n; ++c) out[IncidentIndex(c, k)] = inc[c] * wk;
                }
            });
}

// Sixteen float lanes (the GCC / Clang vector extension: each operation is the
// scalar one per lane, IEEE, no contraction under -ffp-contract=off): lanes
// 0-7 and 8-15 are BrunetonPhaseSums' lanes j of a pair of channels.
// Lanes16 never crosses this file (anonymous namespace), so GCC's note that a
// 64-byte vector returned without AVX-512 has another ABI (builds without it)
// does not apply.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
typedef float Lanes16 __attribute__((vector_size(2 * kBrunetonLanes * sizeof(float))));
static_assert(kBrunetonLanes == 8, "a pair's block is 2 x 8 floats");
constexpr int kPhaseBlocks = kBrunetonDirections / kBrunetonLanes;
constexpr size_t kPairFloats = 2 * static_cast<size_t>(kBrunetonDirections);

inline Lanes16 Load16(const float* p) {
    Lanes16 v;
    std::memcpy(&v, p, sizeof(v));
    return v;
}
inline void Store16(float* p, const Lanes16& v) { std::memcpy(p, &v, sizeof(v)); }

// BrunetonPhaseSums' lane sums of every channel: ar[8c + j] (and, with kTwo,
// am[8c + j]) = the sum over the directions k = j, j + 8, ... in order of
// p[k] x l_c[k] (q[k] x l_c[k]), in float from 0, where l is a pair's incident
// radiance in IncidentIndex's layout and p2 (q2) holds each block of eight
// directions' phase values twice (16 floats). kPairs channel pairs at a time,
// with independent accumulators.
template <bool kTwo, int kPairs>
__attribute__((always_inline)) inline void PhaseSumsBody(const float* __restrict__ l, int pairs,
                                                         const float* __restrict__ p2,
                                                         const float* __restrict__ q2,
                                                         float* __restrict__ ar,
                                                         float* __restrict__ am) {
    int pp = 0;
    for (; pp + kPairs <= pairs; pp += kPairs) {
        const float* b[kPairs];
        Lanes16 r[kPairs], m[kPairs];
        for (int i = 0; i < kPairs; ++i) {
            b[i] = l + static_cast<size_t>(pp + i) * kPairFloats;
            r[i] = Lanes16{};
            m[i] = Lanes16{};
        }
        for (int kb = 0; kb < kPhaseBlocks; ++kb) {
            const size_t o = static_cast<size_t>(kb) * 2 * kBrunetonLanes;
            const Lanes16 p = Load16(p2 + o);
            if (kTwo) {
                const Lanes16 q = Load16(q2 + o);
                for (int i = 0; i < kPairs; ++i) {
                    const Lanes16 a = Load16(b[i] + o);
                    r[i] += p * a;
                    m[i] += q * a;
                }
            } else {
                for (int i = 0; i < kPairs; ++i) r[i] += p * Load16(b[i] + o);
            }
        }
        for (int i = 0; i < kPairs; ++i) {
            Store16(ar + static_cast<size_t>(pp + i) * 2 * kBrunetonLanes, r[i]);
            if (kTwo) Store16(am + static_cast<size_t>(pp + i) * 2 * kBrunetonLanes, m[i]);
        }
    }
    for (; pp < pairs; ++pp) {
        const float* b0 = l + static_cast<size_t>(pp) * kPairFloats;
        Lanes16 r0 = {}, m0 = {};
        for (int kb = 0; kb < kPhaseBlocks; ++kb) {
            const size_t o = static_cast<size_t>(kb) * 2 * kBrunetonLanes;
            const Lanes16 a = Load16(b0 + o);
            r0 += Load16(p2 + o) * a;
            if (kTwo) m0 += Load16(q2 + o) * a;
        }
        Store16(ar + static_cast<size_t>(pp) * 2 * kBrunetonLanes, r0);
        if (kTwo) Store16(am + static_cast<size_t>(pp) * 2 * kBrunetonLanes, m0);
    }
}

// PhaseSumsBody for this machine: with AVX-512 (32 registers of 16 floats)
// four pairs at a time, else two (a Lanes16 is then two 8-float registers).
// The same operations per lane either way, so the same bits.
template <bool kTwo>
void PhaseSumsPortable(const float* l, int pairs, const float* p2, const float* q2, float* ar,
                       float* am) {
    PhaseSumsBody<kTwo, 2>(l, pairs, p2, q2, ar, am);
}
#if ATMOS_HOST_AVX512_DISPATCH
template <bool kTwo>
__attribute__((target("avx512f"))) void PhaseSumsAvx512(const float* l, int pairs, const float* p2,
                                                        const float* q2, float* ar, float* am) {
    PhaseSumsBody<kTwo, 4>(l, pairs, p2, q2, ar, am);
}
#endif
template <bool kTwo>
void PhaseSums(const float* l, int pairs, const float* p2, const float* q2, float* ar, float* am) {
#if ATMOS_HOST_AVX512_DISPATCH
    if (HostUsesAvx512()) {
        PhaseSumsAvx512<kTwo>(l, pairs, p2, q2, ar, am);
        return;
    }
#endif
    PhaseSumsPortable<kTwo>(l, pairs, p2, q2, ar, am);
}

// Each block of eight values of v (kBrunetonDirections) twice: 16 floats.
inline void DoubleBlocks(const float* v, float* v2) {
    for (int kb = 0; kb < kPhaseBlocks; ++kb) {
        std::memcpy(v2 + 2 * kBrunetonLanes * kb, v + kBrunetonLanes * kb,
                    kBrunetonLanes * sizeof(float));
        std::memcpy(v2 + 2 * kBrunetonLanes * kb + kBrunetonLanes, v + kBrunetonLanes * kb,
                    kBrunetonLanes * sizeof(float));
    }
}

// ---- scattering density J_n (BrunetonDensityStage): per texel the phase
// functions of the 512 directions once, then each channel's sums in the
// lanes and order of BrunetonPhaseSums (or BrunetonPhaseSumsGeneric) ----
void WideDensity(const BrunetonWideEvaluator& ev, const TableView& incident,
                 const TableView& directions, Table* density) {
    const BrunetonLut& lut = ev.lut;
    const WideCoefficients& w = ev.w;
    const AtmosphereParameters& atm = lut.atm;
    const BrunetonConfig& cfg = lut.cfg;
    const int n = w.channels;
    const int pairs = (n + 1) / 2;
    const int width = cfg.scattering_nu * cfg.scattering_mu_s;
    density->Resize(width, cfg.scattering_mu, cfg.scattering_r, n);
    const BrunetonDirections grid(directions);
    constexpr int kd = kBrunetonDirections;
    constexpr int lanes = kBrunetonLanes;
    const bool cornette_shanks = atm.mie_phase_kind == MiePhaseKind::kCornetteShanks;
    const double g = atm.mie_phase_g, g2d = atm.mie_phase_g2, w2 = atm.mie_phase_weight2;
    RunWide(
        "bruneton wide scattering density",
        // Per (r, mu_s) pair (z, s): its texels (every mu and nu) read the
        // same incident radiance (n * 512 floats), which then stays in cache.
        static_cast<int64_t>(cfg.scattering_mu_s) * cfg.scattering_r, 1, [&](int64_t pair) {
            const int s_pair = static_cast<int>(pair % cfg.scattering_mu_s);
            const int z = static_cast<int>(pair / cfg.scattering_mu_s);
            alignas(64) float pr[kd], pm[kd], pm2[kd];
            alignas(64) float pr2[2 * kd], pm2x[2 * kd], pm22[2 * kd];
            // The lane sums of each channel (8 floats per channel, pairs' halves).
            std::vector<float> sums(static_cast<size_t>(3 * pairs) * 2 * lanes);
            float* const ar = sums.data();
            float* const am = ar + static_cast<size_t>(pairs) * 2 * lanes;
            float* const am2 = am + static_cast<size_t>(pairs) * 2 * lanes;
            std::vector<double> prd, pmd;
            if (!cornette_shanks) {
                prd.resize(kd);
                pmd.resize(kd);
            }
            for (int texel = 0; texel < cfg.scattering_mu * cfg.scattering_nu; ++texel) {
                const int y = texel / cfg.scattering_nu;
                const int x = (texel % cfg.scattering_nu) * cfg.scattering_mu_s + s_pair;
                double r, mu, mu_s, nu;
                bool ground;
                lut.RMuMuSNuFromTexel(x, y, z, &r, &mu, &mu_s, &nu, &ground);
                const double sin_s = SafeSqrt(1.0 - mu_s * mu_s);
                const double oxd = sin_s == 0.0 ? 0.0 : (nu - mu * mu_s) / sin_s;
                const double oyd = SafeSqrt(1.0 - oxd * oxd - mu * mu);
                const float ox = static_cast<float>(oxd), oy = static_cast<float>(oyd),
                            oz = static_cast<float>(mu);
                const int s = x % cfg.scattering_mu_s;
                const float* const l = incident.data + (static_cast<size_t>(z) * incident.height +
                                                        static_cast<size_t>(s)) *
                                                           static_cast<size_t>(incident.width);
                const double alt = r - atm.bottom_radius;
                float* const o = density->Texel(x, y, z);
                if (!cornette_shanks) {
                    // BrunetonPhaseSumsGeneric: double sums in direction order.
                    for (int k = 0; k < kd; ++k) {
                        const double xk = static_cast<double>(ox * grid.wx[k] + oy * grid.wy[k] +
                                                              oz * grid.wz[k]);
                        prd[k] = 1.0 + xk * xk;
                        pmd[k] = MiePhase(atm, xk);
                    }
                    const double rho_r = GetProfileDensity(atm.rayleigh_density, alt);
                    const double rho_m = GetProfileDensity(atm.mie_density, alt);
                    for (int c = 0; c < n; ++c) {
                        double ar_d = 0.0, am_d = 0.0;
                        for (int k = 0; k < kd; ++k) {
                            const double v = static_cast<double>(l[IncidentIndex(c, k)]);
                            ar_d += prd[k] * v;
                            am_d += pmd[k] * v;
                        }
                        const float br = static_cast<float>(w.rayleigh_scattering[c] *
                                                            (rho_r * (3.0 / (16.0 * kPi))));
                        const float bm = static_cast<float>(w.mie_scattering[c] * rho_m);
                        o[c] = static_cast<float>(ar_d) * br + static_cast<float>(am_d) * bm;
                    }
                    continue;
                }
                // BrunetonPhaseSums' phase functions, per direction.
                const float gf = static_cast<float>(g);
                const float gp = 1.0f + gf * gf, gm = 2.0f * gf;
                const float g2f = static_cast<float>(g2d);
                const float g2p = 1.0f + g2f * g2f, g2m = 2.0f * g2f;
                ATMOS_SIMD_WIDE
                for (int k = 0; k < kd; ++k) {
                    const float xk = ox * grid.wx[k] + oy * grid.wy[k] + oz * grid.wz[k];
                    const float p = 1.0f + xk * xk;
                    const float den = gp - gm * xk;
                    pr[k] = p;
                    pm[k] = p / (den * Sqrt(den));
                }
                DoubleBlocks(pr, pr2);
                DoubleBlocks(pm, pm2x);
                PhaseSums<true>(l, pairs, pr2, pm2x, ar, am);
                if (w2 != 0.0) {  // the second lobe's (BrunetonPhaseSums with g2)
                    ATMOS_SIMD_WIDE
                    for (int k = 0; k < kd; ++k) {
                        const float xk = ox * grid.wx[k] + oy * grid.wy[k] + oz * grid.wz[k];
                        const float p = 1.0f + xk * xk;
                        const float den2 = g2p - g2m * xk;
                        pm2[k] = p / (den2 * Sqrt(den2));
                    }
                    DoubleBlocks(pm2, pm22);
                    PhaseSums<false>(l, pairs, pm22, nullptr, am2, nullptr);
                }
                const double k_r = 3.0 / (16.0 * kPi);
                const double k_m = 3.0 / (8.0 * kPi) * (1.0 - g * g) / (2.0 + g * g);
                const double rho_r = GetProfileDensity(atm.rayleigh_density, alt);
                const double rho_m = GetProfileDensity(atm.mie_density, alt);
                const double k_m2 = 3.0 / (8.0 * kPi) * (1.0 - g2d * g2d) / (2.0 + g2d * g2d);
                // Each channel's lanes summed in double in lane order (as
                // BrunetonPhaseSums).
                const auto lane_sum = [&](const float* v, int c) {
                    const float* vc = v + static_cast<size_t>(c) * lanes;
                    double sum = 0.0;
                    for (int j = 0; j < lanes; ++j) sum += static_cast<double>(vc[j]);
                    return static_cast<float>(sum);
                };
                for (int c = 0; c < n; ++c) {
                    const float sum_r = lane_sum(ar, c), sum_m = lane_sum(am, c);
                    const float br = static_cast<float>(w.rayleigh_scattering[c] * (rho_r * k_r));
                    if (w2 == 0.0) {
                        const float bm = static_cast<float>(w.mie_scattering[c] * (rho_m * k_m));
                        o[c] = sum_r * br + sum_m * bm;
                        continue;
                    }
                    const float sum_m2 = lane_sum(am2, c);
                    const float bm =
                        static_cast<float>(w.mie_scattering[c] * (rho_m * (1.0 - w2) * k_m));
                    const float bm2 = static_cast<float>(w.mie_scattering[c] * (rho_m * w2 * k_m2));
                    o[c] = sum_r * br + sum_m * bm + sum_m2 * bm2;
                }
            }
        });
}

// ---- indirect irradiance of order n (BrunetonIndirectIrradianceStage) ----
void WideIndirectIrradiance(const BrunetonWideEvaluator& ev, int order,
                            const TableView& single_rayleigh, const TableView& single_mie,
                            const TableView& multiple, Table* out) {
    const BrunetonLut& lut = ev.lut;
    const int n = ev.w.channels;
    const int width = out->width(), height = out->height();
    RunWide("bruneton wide indirect irradiance", static_cast<int64_t>(width) * height, 4,
            [&](int64_t item) {
                const int x = static_cast<int>(item % width);
                const int y = static_cast<int>(item / width);
                const int steps = kBrunetonIrradianceSamples;
                const double dphi = kPi / steps;
                const double dtheta = kPi / steps;
                double r, mu_s;
                lut.RMuSFromIrradianceUv((x + 0.5) / width, (y + 0.5) / height, &r, &mu_s);
                const Vec3d omega_s(SafeSqrt(1.0 - mu_s * mu_s), 0.0, mu_s);
                double sum[kMaxWideChannels];
                for (int c = 0; c < n; ++c) sum[c] = 0.0;
                float a[kMaxWideChannels], b[kMaxWideChannels];
                for (int j = 0; j < steps / 2; ++j) {
                    const double theta = (j + 0.5) * dtheta;
                    for (int i = 0; i < 2 * steps; ++i) {
                        const double phi = (i + 0.5) * dphi;
                        const Vec3d omega(cos(phi) * sin(theta), sin(phi) * sin(theta), cos(theta));
                        const double domega = dtheta * dphi * sin(theta);
                        const double nu = ClampCosine(Dot(omega, omega_s));
                        if (order == 1) {
                            double uvwz[4];
                            lut.ScatteringUvwz(lut.ClampRadius(r), ClampCosine(omega.z),
                                               ClampCosine(mu_s), ClampCosine(nu), false, uvwz);
                            Bruneton4DRows rows;
                            Bruneton4DColumns cols;
                            lut.Split4D(single_rayleigh, uvwz, &rows, &cols);
                            BrunetonWideSample4D(single_rayleigh.data, n, rows, cols, a);
                            BrunetonWideSample4D(single_mie.data, n, rows, cols, b);
                            const float pr = static_cast<float>(RayleighPhase(nu));
                            const float pm = static_cast<float>(MiePhase(lut.atm, nu));
                            for (int c = 0; c < n; ++c) a[c] = a[c] * pr + b[c] * pm;
                        } else {
                            WideGetScattering(lut, multiple, r, omega.z, mu_s, nu, false, a);
                        }
                        const double wgt = omega.z * domega;
                        for (int c = 0; c < n; ++c) sum[c] += static_cast<double>(a[c]) * wgt;
                    }
                }
                float* const o = out->Texel(x, y);
                for (int c = 0; c < n; ++c) o[c] = static_cast<float>(sum[c]);
            });
}

// ---- multiple scattering of order n (ComputeBrunetonMultipleScatteringRows
// per channel) ----
void WideMultipleScattering(const BrunetonWideEvaluator& ev,
                            const std::vector<AtmosphereParameters>& batches,
                            const TableView& density, Table* out) {
    const BrunetonLut& lut = ev.lut;
    const WideCoefficients& w = ev.w;
    const BrunetonConfig& c = lut.cfg;
    const AtmosphereParameters& atm = lut.atm;
    const BrunetonConstants& kc = lut.k;
    const int n = w.channels;
    const size_t nn = static_cast<size_t>(n);
    const int width = c.scattering_nu * c.scattering_mu_s;
    out->Resize(width, c.scattering_mu, c.scattering_r, n);
    const int nu_size = c.scattering_nu;
    const double top2 = kc.top * kc.top;
    const double bb = kc.bottom * kc.bottom;
    const double inv_d_range = 1.0 / kc.mu_s_d_range;
    const double inv_big_a = 1.0 / kc.mu_s_big_a;
    const double inv_nu = 1.0 / nu_size;
    // One view-ray row (y, z): its samples (BrunetonMultipleScatteringSample:
    // distance, 1 / radius, the density's (mu, r) rows, each channel's weighted
    // transmittance), its texels' (mu_s, nu) and nu coordinates, and the sums.
    struct Row {
        int y = 0;
        double r = 0.0;
        std::vector<double> sd, sinv, texel;  // texel: mu_s, nu, tex_x per texel
        std::vector<Bruneton4DRows> srows;
        std::vector<float> st, lerp_x, sums;
    };
    const size_t wz = static_cast<size_t>(width);
    const int steps = c.scattering_samples;
    const size_t ns = static_cast<size_t>(steps) + 1;
    const auto make_row = [&](int y, int z, Row* row) {
        double r_texel, mu, mu_s0, nu0;
        bool ground;
        lut.RMuMuSNuFromTexel(0, y, z, &r_texel, &mu, &mu_s0, &nu0, &ground);
        const double r = r_texel;
        row->y = y;
        row->r = r;
        const double dx = lut.DistanceToNearestAtmosphereBoundary(r, mu, ground) / steps;
        bool thick[kWideBatches];
        const bool any_thick = WideThickBatches(atm, w, r, mu, dx, steps, thick);
        std::vector<ThickRayWeights> weights;
        if (any_thick) weights.assign(w.channels / 3, ThickRayWeights(r, mu, dx, steps));
        row->sd.resize(ns);
        row->sinv.resize(ns);
        row->srows.resize(ns);
        row->st.resize(ns * nn);
        for (int i = 0; i <= steps; ++i) {
            const size_t si = static_cast<size_t>(i);
            const double d = i * dx;
            row->sd[si] = d;
            const double s_r = lut.ClampRadius(Sqrt(d * d + 2.0 * r * mu * d + r * r));
            row->sinv[si] = 1.0 / s_r;
            const double mu_i = ClampCosine((r * mu + d) / s_r);
            double u_mu, u_r;
            lut.ScatteringUMuR(s_r, mu_i, ground, &u_mu, &u_r);
            row->srows[si] =
                BrunetonSplitRows(density.width, density.height, density.depth, u_mu, u_r);
            float* t = row->st.data() + si * nn;
            ev.Transmittance(r, mu, d, ground, t);
            const float wq =
                static_cast<float>(BrunetonQuadratureWeight(c.scattering_rule, i, steps) * dx);
            for (int ch = 0; ch < n; ++ch) t[ch] = t[ch] * wq;
            if (!any_thick) continue;
            for (int b = 0; b < n / 3; ++b) {
                if (!thick[b]) continue;
                const Vec3d wt =
                    weights[static_cast<size_t>(b)].Next(batches[static_cast<size_t>(b)], i);
                const Rgb v = Rgb(wt);
                for (int k = 0; k < 3; ++k) t[3 * b + k] = v[k];
            }
        }
        row->texel.resize(3 * wz);
        double* const mu_s_x = row->texel.data();
        double* const nu_x = mu_s_x + wz;
        double* const tex_x = nu_x + wz;
        row->lerp_x.resize(wz);
        BrunetonRowMuSNu(lut, y, z, width, mu_s_x, nu_x);
        for (size_t k = 0; k < wz; ++k) {
            BrunetonNuCoordinate(nu_x[k], nu_size, &tex_x[k], &row->lerp_x[k]);
        }
        row->sums.assign(wz * nn, 0.0f);  // [texel][channel]
    };
    // Blocks of kRowBlock rows of one r (neighbouring mu): sample i of each row
    // in turn, so that the rows' samples, which often read the same density
    // rows, find them in cache (the density table is 176 MB at 42 channels).
    // Each texel still sums its samples in order.
    constexpr int kRowBlock = 8;
    const int blocks = (c.scattering_mu + kRowBlock - 1) / kRowBlock;
    RunWide("bruneton wide multiple scattering (rows)",
            static_cast<int64_t>(blocks) * c.scattering_r, 1, [&](int64_t item) {
                const int z = static_cast<int>(item / blocks);
                const int y0 = static_cast<int>(item % blocks) * kRowBlock;
                const int y1 = Min(y0 + kRowBlock, c.scattering_mu);
                std::vector<Row> rows(static_cast<size_t>(y1 - y0));
                for (int y = y0; y < y1; ++y) make_row(y, z, &rows[static_cast<size_t>(y - y0)]);
                std::vector<float> prow(wz * nn);  // the interpolated row
                float* const p = prow.data();
                std::vector<float> ff(2 * wz);
                float* const fa_x = ff.data();
                float* const fb_x = fa_x + wz;
                std::vector<int> span(4 * wz);
                int* const a0_x = span.data();
                int* const a1_x = a0_x + wz;
                int* const b0_x = a1_x + wz;
                int* const b1_x = b0_x + wz;
                const int count = width * n;
                for (size_t si = 0; si < ns; ++si) {
                    for (Row& row : rows) {
                        const Bruneton4DRows& dr = row.srows[si];
                        const float* q0 = density.data + dr.row[0] * nn;
                        const float* q1 = density.data + dr.row[1] * nn;
                        const float* q2 = density.data + dr.row[2] * nn;
                        const float* q3 = density.data + dr.row[3] * nn;
                        const float fy = dr.fy, fz = dr.fz;
                        ATMOS_SIMD_WIDE
                        for (int j = 0; j < count; ++j) {
                            p[j] = (q0[j] * (1.0f - fy) + q1[j] * fy) * (1.0f - fz) +
                                   (q2[j] * (1.0f - fy) + q3[j] * fy) * fz;
                        }
                        const double* const mu_s_x = row.texel.data();
                        const double* const nu_x = mu_s_x + wz;
                        const double* const tex_x = nu_x + wz;
                        DensityColumns(width, row.r, mu_s_x, nu_x, tex_x, row.sd[si], row.sinv[si],
                                       kc.bottom, bb, top2, kc.mu_s_d_min, inv_d_range, inv_big_a,
                                       kc.scattering_mu_s, inv_nu, a0_x, a1_x, b0_x, b1_x, fa_x,
                                       fb_x);
                        const float* const t = row.st.data() + si * nn;
                        const float* const lerp_x = row.lerp_x.data();
                        for (size_t k = 0; k < wz; ++k) {
                            const float* pa0 = p + static_cast<size_t>(a0_x[k]) * nn;
                            const float* pa1 = p + static_cast<size_t>(a1_x[k]) * nn;
                            const float* pb0 = p + static_cast<size_t>(b0_x[k]) * nn;
                            const float* pb1 = p + static_cast<size_t>(b1_x[k]) * nn;
                            const float fa = fa_x[k], fb = fb_x[k], l = lerp_x[k];
                            float* const s = row.sums.data() + k * nn;
                            ATMOS_SIMD_WIDE
                            for (int ch = 0; ch < n; ++ch) {
                                const float ta = pa0[ch] * (1.0f - fa) + pa1[ch] * fa;
                                const float tb = pb0[ch] * (1.0f - fb) + pb1[ch] * fb;
                                const float v = ta * (1.0f - l) + tb * l;
                                s[ch] += v * t[ch];
                            }
                        }
                    }
                }
                for (const Row& row : rows) {
                    for (int x = 0; x < width; ++x) {
                        float* const o = out->Texel(x, row.y, z);
                        const float* const s = row.sums.data() + static_cast<size_t>(x) * nn;
                        for (int ch = 0; ch < n; ++ch) o[ch] = s[ch];
                    }
                }
            });
}

// scattering += delta / RayleighPhase(nu) (BrunetonAccumulateStage).
void WideAccumulate(const BrunetonLut& lut, const Table& delta, Table* scattering) {
    const BrunetonConfig& cfg = lut.cfg;
    const int n = delta.channels();
    const int width = scattering->width();
    RunWide("bruneton wide accumulate", static_cast<int64_t>(cfg.scattering_mu) * cfg.scattering_r,
            1, [&](int64_t row) {
                const int y = static_cast<int>(row % cfg.scattering_mu);
                const int z = static_cast<int>(row / cfg.scattering_mu);
                for (int x = 0; x < width; ++x) {
                    double r, mu, mu_s, nu;
                    bool ground;
                    lut.RMuMuSNuFromTexel(x, y, z, &r, &mu, &mu_s, &nu, &ground);
                    const float inv_phase = static_cast<float>(1.0 / RayleighPhase(nu));
                    const float* dm =
                        delta.view().data +
                        ((static_cast<size_t>(z) * cfg.scattering_mu + y) * width + x) *
                            static_cast<size_t>(n);
                    float* s = scattering->Texel(x, y, z);
                    for (int c = 0; c < n; ++c) s[c] += dm[c] * inv_phase;
                }
            });
}

// TableSum of batch b's three channels (the batch's own table's sum: texel by
// texel, channel by channel).
double BatchSum(const Table& t, int b) {
    const size_t texels = Texels(t);
    const size_t n = static_cast<size_t>(t.channels());
    const float* d = t.data() + 3 * static_cast<size_t>(b);
    double sum = 0.0;
    for (size_t i = 0; i < texels; ++i) {
        for (size_t c = 0; c < 3; ++c) sum += static_cast<double>(d[i * n + c]);
    }
    return sum;
}

}  // namespace

void PrecomputeBrunetonWide(const std::vector<AtmosphereParameters>& batches,
                            const BrunetonConfig& config, BrunetonTables* tables) {
    ValidateBrunetonConfig(config);
    if (config.combined_mie) {
        Fail("model bruneton: the wide precomputation needs mie-storage=separate");
    }
    const WideCoefficients w = MakeWideCoefficients(batches);
    const int n = w.channels;
    const int nb = n / 3;
    BrunetonWideEvaluator ev;
    ev.lut = BrunetonLut(batches[0], config);
    ev.w = w;
    const BrunetonLut mappings = ev.lut;
    Progress progress("bruneton precompute", 1 + 4 * static_cast<int64_t>(config.orders - 1),
                      LibraryProgressEnabled());

    WideTransmittance(mappings, w, &tables->transmittance);
    ev.lut.transmittance_table = tables->transmittance.view();

    Table delta_irradiance;
    WideDirectIrradiance(ev, &delta_irradiance);
    // The irradiance table holds the indirect irradiance only.
    tables->irradiance.Resize(config.irradiance_width, config.irradiance_height, 1, n);

    // Separate Mie storage: the scattering table after order 1 is the single
    // Rayleigh scattering and the single Mie table the single Mie scattering
    // (BrunetonCombineStage's copies), so the delta tables are those tables:
    // the single Rayleigh scattering is read (orders 2's incident radiance and
    // order 1's irradiance) before the first accumulation changes it.
    WideSingleScattering(ev, batches, &tables->scattering, &tables->single_mie);
    progress.Add(1);
    const Table directions = MakeBrunetonDirectionTable();
    const BrunetonDirections grid(directions.view());
    Table incident, delta_multiple, delta_density;
    std::vector<ScatteringOrders> sums(static_cast<size_t>(nb));
    for (int order = 2; order <= config.orders; ++order) {
        WideIncidentInputs in;
        in.order = order;
        in.solid_angle = grid.solid_angle;
        if (order == 2) {
            in.single_rayleigh = tables->scattering.view();
            in.single_mie = tables->single_mie.view();
        } else {
            in.multiple = delta_multiple.view();
        }
        in.ground_irradiance = delta_irradiance.view();
        WideIncident(ev, in, &incident);
        progress.Add(1);
        WideDensity(ev, incident.view(), directions.view(), &delta_density);
        progress.Add(1);

        Table irradiance_order(config.irradiance_width, config.irradiance_height, 1, n);
        WideIndirectIrradiance(ev, order - 1, tables->scattering.view(), tables->single_mie.view(),
                               delta_multiple.view(), &irradiance_order);
        delta_irradiance = std::move(irradiance_order);
        {
            float* t = tables->irradiance.data();
            const float* d = delta_irradiance.data();
            const size_t count = tables->irradiance.size();
            for (size_t i = 0; i < count; ++i) t[i] += d[i];
        }
        progress.Add(1);

        WideMultipleScattering(ev, batches, delta_density.view(), &delta_multiple);
        progress.Add(1);
        for (int b = 0; b < nb; ++b) {
            sums[static_cast<size_t>(b)].Add(order, BatchSum(delta_multiple, b));
        }
        WideAccumulate(mappings, delta_multiple, &tables->scattering);
    }
    for (ScatteringOrders& s : sums) s.WarnIfDiverging("bruneton", 3);
}

}  // namespace atmos
