// atmos model `atmosphere-plus`: the wide precomputation and the wide model
// (atmosphere_plus_wide.h, docs/models/atmosphere-plus.md "Wide channel batches").
//
// Each stage mirrors its three-channel stage (atmosphere_plus_stages.h) per
// channel, operation for operation, so channel 3b + c of a wide table is
// channel c of batch b's table bit for bit. What the channels share is
// computed once: the view ray of a texel, its nodes' positions and densities,
// and the sun rays' sample densities (optical depths are the coefficients
// times those, summed per channel in the three-channel order); the table rows
// and spans of every lookup; the gather's phase functions. The stages run one
// (altitude, view) column of the table per item, over its sun angles: the view
// ray, its optical depths and their exponentials, the gather's phase functions
// and each lookup's rows do not depend on the sun, so a column computes them
// once instead of once per texel. Host code (the wide path runs on the CPU).
#include "models/atmosphere_plus_wide.h"

#include <cmath>
#include <vector>

#include "atmos/error.h"
#include "models/atmosphere_plus_stages.h"
#include "models/order_check.h"
#include "render/stages.h"
#include "render/wide.h"

namespace atmos {

namespace {

// Channel c's extinction at densities d (Extinction's component c).
inline double WideExtinction(const WideCoefficients& w, int c, const Densities& d) {
    return w.rayleigh_scattering[c] * d.rayleigh + w.mie_extinction[c] * d.mie +
           w.absorption_extinction[c] * d.absorption;
}

// OpticalDepth (physics/transmittance.h) of every channel into tau[0, n): the
// samples' densities once (`densities`: 3 (samples + 1) doubles of scratch),
// then per channel the same sum in the same order. Channels are summed in
// blocks of 4 up to n rounded up (the coefficients past n are 0), kept in
// registers across the samples.
void WideOpticalDepth(const AtmosphereParameters& atm, const WideCoefficients& w,
                      const Vec3d& origin, const Vec3d& dir, double length, int samples,
                      double* densities, double* tau) {
    const double dx = length / samples;
    for (int i = 0; i <= samples; ++i) {
        const double t = i * dx;
        const double altitude = Length(origin + dir * t) - atm.bottom_radius;
        const Densities d = GetDensities(atm, altitude);
        densities[3 * i] = d.rayleigh;
        densities[3 * i + 1] = d.mie;
        densities[3 * i + 2] = d.absorption;
    }
    const int n = w.channels;
    for (int c0 = 0; c0 < n; c0 += 4) {
        double sum[4] = {0.0, 0.0, 0.0, 0.0};
        const double* rs = w.rayleigh_scattering + c0;
        const double* me = w.mie_extinction + c0;
        const double* ae = w.absorption_extinction + c0;
        for (int i = 0; i <= samples; ++i) {
            const double dr = densities[3 * i], dm = densities[3 * i + 1],
                         da = densities[3 * i + 2];
            const double weight = (i == 0 || i == samples) ? 0.5 : 1.0;
            for (int k = 0; k < 4; ++k) sum[k] += (rs[k] * dr + me[k] * dm + ae[k] * da) * weight;
        }
        for (int k = 0; k < 4 && c0 + k < n; ++k) tau[c0 + k] = sum[k] * dx;
    }
}

// The opening of a column stage: the column (x, y) of item `i` of the
// scattering table, its (h, mu) (AplusTexelParameters), the view ray of its
// texels (AplusTexelRayOf without the sun) and which batches have optically
// thick steps on it (RayHasThickSteps with the batch's extinction).
struct AplusWideColumn {
    int x = 0, y = 0;
    double h = 0.0, mu = 0.0;
    Vec3d p0, view;
    AtmosphereSegment seg;
    double ds = 0.0;
    bool thick[kMaxWideChannels / 3] = {};
    bool any_thick = false;
};
AplusWideColumn OpenColumn(int64_t i, const AtmosphereParameters& atm, const WideCoefficients& w,
                           const AplusSettings& s) {
    AplusWideColumn col;
    col.x = static_cast<int>(i % s.width);
    col.y = static_cast<int>(i / s.width);
    col.h = s.mapping.H(AplusUnitCoord(col.x, s.width));
    col.mu = s.mapping.Mu(col.h, AplusUnitCoord(col.y, s.height));
    col.p0 = Vec3d(0.0, 0.0, atm.bottom_radius + col.h);
    col.view = Vec3d(SafeSqrt(1.0 - col.mu * col.mu), 0.0, col.mu);
    col.seg = ClipToAtmosphere(col.p0, col.view, atm.bottom_radius, atm.top_radius);
    if (!col.seg.inside) return col;
    const int steps = s.transmittance_steps;
    col.ds = (col.seg.t_end - col.seg.t_start) / steps;
    const int batches = w.channels / 3;
    for (int k = 0; k <= steps; ++k) {
        const double alt =
            Length(col.p0 + col.view * (col.seg.t_start + k * col.ds)) - atm.bottom_radius;
        const Densities d = GetDensities(atm, alt);
        for (int b = 0; b < batches; ++b) {
            if (col.thick[b]) continue;
            const double e0 = WideExtinction(w, 3 * b, d), e1 = WideExtinction(w, 3 * b + 1, d),
                         e2 = WideExtinction(w, 3 * b + 2, d);
            if (Max(e0, Max(e1, e2)) * col.ds > kThickStepOpticalDepth) col.thick[b] = true;
        }
    }
    for (int b = 0; b < batches; ++b) col.any_thick = col.any_thick || col.thick[b];
    return col;
}

// AplusThickNodes (ExpLinearNodeWeights, PerExtinction) per channel, for the
// channels of the column's thick batches: Next(k, ext) gives node k's factor
// into weight[c].
struct WideThickNodes {
    double t[kMaxWideChannels], carry[kMaxWideChannels];
    WideThickNodes() {
        for (int c = 0; c < kMaxWideChannels; ++c) {
            t[c] = 1.0;
            carry[c] = 0.0;
        }
    }
    void Next(const AtmosphereParameters& atm, const WideCoefficients& w,
              const AplusWideColumn& col, int k, int steps, const double* ext, double* weight) {
        Densities next{0.0, 0.0, 0.0};
        if (k < steps) {
            const double alt = Length(col.p0 + col.view * (col.seg.t_start + (k + 1) * col.ds)) -
                               atm.bottom_radius;
            next = GetDensities(atm, alt);
        }
        for (int c = 0; c < w.channels; ++c) {
            if (!col.thick[c / 3]) continue;
            const double dtau =
                k < steps ? (ext[c] + WideExtinction(w, c, next)) * (0.5 * col.ds) : 0.0;
            double a, b;
            ExpLinearWeights(dtau, &a, &b);
            const double wc = carry[c] + t[c] * a;
            carry[c] = t[c] * b;
            t[c] *= exp(-dtau);
            weight[c] = ext[c] > 0.0 ? wc / ext[c] : 0.0;
        }
    }
};

// Texel (x, y, z) of a table of `channels` channels.
inline float* TexelOf(const TableOut& t, int x, int y, int z) {
    return t.data + ((static_cast<size_t>(z) * t.height + y) * t.width + x) *
                        static_cast<size_t>(t.channels);
}

// The sun directions of the table's depth (AplusTexelRayOf at each mu_s).
std::vector<Vec3d> SunDirections(const AplusSettings& s) {
    std::vector<Vec3d> suns(static_cast<size_t>(s.depth));
    for (int z = 0; z < s.depth; ++z) {
        const double mu_s = s.mapping.MuS(AplusUnitCoord(z, s.depth));
        suns[static_cast<size_t>(z)] = Vec3d(SafeSqrt(1.0 - mu_s * mu_s), 0.0, mu_s);
    }
    return suns;
}

// Writes a column's sums: Rayleigh (coefficient x sum) / 4 pi per channel, Mie
// (the batch's green channel) per batch, as AplusToVec4f of AplusValue.
void WriteColumn(const WideCoefficients& w, const AplusWideColumn& col, const AplusSettings& s,
                 const std::vector<double>& sums, const TableOut& out) {
    const int n = w.channels, nb = n / 3, channels = n + nb;
    for (int z = 0; z < s.depth; ++z) {
        float* texel = TexelOf(out, col.x, col.y, z);
        if (!col.seg.inside) {
            for (int c = 0; c < channels; ++c) texel[c] = 0.0f;
            continue;
        }
        const double* sum = sums.data() + static_cast<size_t>(z) * channels;
        for (int c = 0; c < n; ++c) {
            texel[c] = static_cast<float>(w.rayleigh_scattering[c] * sum[c] / (4.0 * kPi));
        }
        for (int b = 0; b < nb; ++b) {
            texel[n + b] = static_cast<float>(w.mie_scattering[3 * b + kAplusMieChannel] *
                                              sum[n + b] / (4.0 * kPi));
        }
    }
}

// AplusTransmittanceStage for every channel; one texel per item.
struct AplusWideTransmittanceStage {
    AtmosphereParameters atm;
    WideCoefficients w;
    AplusSettings s;
    TableOut out;

    template <typename V>
    void VisitTables(V& v) {
        v(out);
    }
    void operator()(int64_t i) const {
        const int x = static_cast<int>(i % s.transmittance_width);
        const int y = static_cast<int>(i / s.transmittance_width);
        const double h = s.mapping.H(AplusUnitCoord(x, s.transmittance_width));
        const double mu = s.mapping.Mu(h, AplusUnitCoord(y, s.transmittance_height));
        const Vec3d p0(0.0, 0.0, atm.bottom_radius + h);
        const Vec3d dir(SafeSqrt(1.0 - mu * mu), 0.0, mu);
        const AtmosphereSegment seg = ClipToAtmosphere(p0, dir, atm.bottom_radius, atm.top_radius);
        const int n = w.channels;
        float* texel = TexelOf(out, x, y, 0);
        if (!seg.inside) {
            for (int c = 0; c < n; ++c) texel[c] = 1.0f;
            return;
        }
        std::vector<double> densities(3 * (static_cast<size_t>(s.transmittance_steps) + 1));
        double tau[kMaxWideChannels];
        WideOpticalDepth(atm, w, p0 + dir * seg.t_start, dir, seg.t_end - seg.t_start,
                         s.transmittance_steps, densities.data(), tau);
        for (int c = 0; c < n; ++c) texel[c] = static_cast<float>(exp(-tau[c]));
    }
};

// AplusSingleScatteringStage (AplusSingleScattering) for every channel; one
// column per item.
// One column of an order's table (stage.Integrate's sums over its depth,
// n Rayleigh channels then one Mie value per batch), written out.
template <typename Stage>
void IntegrateColumn(const Stage& stage, int64_t i) {
    const int n = stage.w.channels, nb = n / 3, channels = n + nb;
    const AplusWideColumn col = OpenColumn(i, stage.atm, stage.w, stage.s);
    std::vector<double> sums(static_cast<size_t>(stage.s.depth) * channels, 0.0);
    if (col.seg.inside) stage.Integrate(col, &sums);
    WriteColumn(stage.w, col, stage.s, sums, stage.out);
}

struct AplusWideSingleScatteringStage {
    AtmosphereParameters atm;
    WideCoefficients w;
    AplusSettings s;
    TableOut out;

    template <typename V>
    void VisitTables(V& v) {
        v(out);
    }
    void operator()(int64_t i) const { IntegrateColumn(*this, i); }

    void Integrate(const AplusWideColumn& col, std::vector<double>* sums_out) const {
        const int n = w.channels, nb = n / 3, channels = n + nb;
        const int steps = s.transmittance_steps, sun_steps = s.transmittance_steps;
        const double ds = col.ds;
        const std::vector<Vec3d> suns = SunDirections(s);
        std::vector<double> densities(3 * (static_cast<size_t>(sun_steps) + 1));
        double tau_view[kMaxWideChannels], prev_ext[kMaxWideChannels], ext[kMaxWideChannels];
        double thick_w[kMaxWideChannels], tau_sun[kMaxWideChannels], t[kMaxWideChannels];
        for (int c = 0; c < n; ++c) tau_view[c] = 0.0;
        WideThickNodes nodes;
        for (int k = 0; k <= steps; ++k) {
            const Vec3d p = col.p0 + col.view * (col.seg.t_start + k * ds);
            const double r = Length(p);
            const Densities d = GetDensities(atm, r - atm.bottom_radius);
            for (int c = 0; c < n; ++c) ext[c] = WideExtinction(w, c, d);
            if (k > 0) {
                for (int c = 0; c < n; ++c) tau_view[c] += (prev_ext[c] + ext[c]) * (0.5 * ds);
            }
            for (int c = 0; c < n; ++c) prev_ext[c] = ext[c];
            if (col.any_thick) nodes.Next(atm, w, col, k, steps, ext, thick_w);
            const double weight = (k == 0 || k == steps) ? 0.5 * ds : ds;
            const double rayleigh_w = d.rayleigh * weight;
            for (int z = 0; z < s.depth; ++z) {
                const Vec3d& sun = suns[static_cast<size_t>(z)];
                const double mu_sun = ClampCosine(Dot(p, sun) / r);
                if (RayIntersectsGround(r, mu_sun, atm.bottom_radius)) continue;
                const double length = DistanceToTopAtmosphereBoundary(r, mu_sun, atm.top_radius);
                WideOpticalDepth(atm, w, p, sun, length, sun_steps, densities.data(), tau_sun);
                double* sum = sums_out->data() + static_cast<size_t>(z) * channels;
                if (!col.any_thick) {
                    for (int c = 0; c < n; ++c) t[c] = exp(-(tau_view[c] + tau_sun[c]));
                    for (int c = 0; c < n; ++c) sum[c] += t[c] * rayleigh_w;
                    for (int b = 0; b < nb; ++b) {
                        sum[n + b] += t[3 * b + kAplusMieChannel] * d.mie * weight;
                    }
                    continue;
                }
                for (int c = 0; c < n; ++c) {
                    if (col.thick[c / 3]) {
                        t[c] = exp(-tau_sun[c]) * thick_w[c];
                        sum[c] += t[c] * d.rayleigh;
                    } else {
                        t[c] = exp(-(tau_view[c] + tau_sun[c]));
                        sum[c] += t[c] * rayleigh_w;
                    }
                }
                for (int b = 0; b < nb; ++b) {
                    const double tm = t[3 * b + kAplusMieChannel];
                    sum[n + b] += col.thick[b] ? tm * d.mie : tm * d.mie * weight;
                }
            }
        }
    }
};

// Gather directions (Theta) whose incoming values a column keeps for a block
// of at most this many sun angles (the three-channel stage keeps them for
// gather-theta <= 48 and looks them up again otherwise: the same values).
constexpr int kAplusWideGatherZBlock = 32;

// AplusGatherStage for every channel; one column per item. The phase
// functions of each (Phi, Theta) node depend on the column's view only: once
// per column (per block of sun angles) instead of once per texel.
struct AplusWideGatherStage {
    AtmosphereParameters atm;
    WideCoefficients w;
    AplusSettings s;
    TableView prev;  // order k-1, n + n / 3 channels
    TableOut out;

    template <typename V>
    void VisitTables(V& v) {
        v(prev);
        v(out);
    }
    void operator()(int64_t i) const {
        const int n = w.channels, nb = n / 3, channels = n + nb;
        const int x = static_cast<int>(i % s.width);
        const int y = static_cast<int>(i / s.width);
        const double h = s.mapping.H(AplusUnitCoord(x, s.width));
        const double mu = s.mapping.Mu(h, AplusUnitCoord(y, s.height));
        const int nt = s.gather_theta, m = s.gather_phi;
        const double d_theta = kPi / nt;
        const double d_phi = 2.0 * kPi / m;
        const double sin_phi = SafeSqrt(1.0 - mu * mu);
        const size_t thetas = static_cast<size_t>(nt) + 1;
        std::vector<AplusWideRows> rows(thetas);
        for (int j = 0; j <= nt; ++j)
            rows[j] = AplusWideRowsOf(prev, s.mapping, h, cos(j * d_theta));
        const size_t cs = static_cast<size_t>(channels);
        std::vector<float> incoming;
        std::vector<double> sums;
        for (int z0 = 0; z0 < s.depth; z0 += kAplusWideGatherZBlock) {
            const int zn = Min(kAplusWideGatherZBlock, s.depth - z0);
            incoming.assign(static_cast<size_t>(zn) * thetas * cs, 0.0f);
            sums.assign(static_cast<size_t>(zn) * cs, 0.0);
            for (int zz = 0; zz < zn; ++zz) {
                const double mu_s = s.mapping.MuS(AplusUnitCoord(z0 + zz, s.depth));
                const TexelSpan span = AplusWideSunSpan(prev, s.mapping, mu_s);
                for (size_t j = 0; j < thetas; ++j) {
                    AplusWideInterpolate(prev, rows[j], span, 0.0f,
                                         incoming.data() + (zz * thetas + j) * cs);
                }
            }
            for (int k = 0; k <= m; ++k) {
                const double wy = (k == 0 || k == m) ? 1.0 : 2.0;
                const double phi = k * d_phi;
                for (int j = 0; j <= nt; ++j) {
                    const double wx = (j == 0 || j == nt) ? 1.0 : 2.0;
                    const double theta = j * d_theta;
                    const double sin_t = sin(theta);
                    const double c = ClampCosine(sin_t * cos(phi) * sin_phi + cos(theta) * mu);
                    const double rayleigh = AplusRayleighPhase(c) * sin_t;
                    const double mie = AplusMiePhase(atm, c);
                    const double wxy = wx * wy;
                    for (int zz = 0; zz < zn; ++zz) {
                        const float* __restrict__ in = incoming.data() + (zz * thetas + j) * cs;
                        double* __restrict__ sum = sums.data() + zz * cs;
                        for (int ch = 0; ch < n; ++ch) {
                            sum[ch] += static_cast<double>(in[ch]) * rayleigh * wxy;
                        }
                        for (int b = n; b < channels; ++b) {
                            sum[b] += static_cast<double>(in[b]) * mie * sin_t * wxy;
                        }
                    }
                }
            }
            const double scale = 0.25 * d_theta * d_phi;
            for (int zz = 0; zz < zn; ++zz) {
                float* texel = TexelOf(out, x, y, z0 + zz);
                const double* sum = sums.data() + zz * cs;
                for (int ch = 0; ch < channels; ++ch)
                    texel[ch] = static_cast<float>(sum[ch] * scale);
            }
        }
    }
};

// AplusOrderStage (AplusOrderFromGather) for every channel; one column per
// item. The view ray's optical depths and their exponentials, and each
// node's lookup rows, are the column's; per sun angle only the lookup's span
// in w, the interpolation and the sums.
struct AplusWideOrderStage {
    AtmosphereParameters atm;
    WideCoefficients w;
    AplusSettings s;
    TableView gather;  // n + n / 3 channels
    TableOut out;

    template <typename V>
    void VisitTables(V& v) {
        v(gather);
        v(out);
    }
    void operator()(int64_t i) const { IntegrateColumn(*this, i); }

    void Integrate(const AplusWideColumn& col, std::vector<double>* sums_out) const {
        const int n = w.channels, nb = n / 3, channels = n + nb;
        const int steps = s.transmittance_steps;
        const double ds = col.ds;
        const double top = atm.top_radius - atm.bottom_radius;
        const std::vector<Vec3d> suns = SunDirections(s);
        double tau_view[kMaxWideChannels], prev_ext[kMaxWideChannels], ext[kMaxWideChannels];
        double thick_w[kMaxWideChannels], t[kMaxWideChannels], factor[kMaxWideChannels];
        double mie_t[kMaxWideChannels / 3];
        float g[kMaxWideChannels + kMaxWideChannels / 3];
        for (int c = 0; c < n; ++c) tau_view[c] = 0.0;
        WideThickNodes nodes;
        for (int k = 0; k <= steps; ++k) {
            const Vec3d p = col.p0 + col.view * (col.seg.t_start + k * ds);
            const double r = Length(p);
            const double hp = Clamp(r - atm.bottom_radius, 0.0, top);
            const Densities d = GetDensities(atm, r - atm.bottom_radius);
            for (int c = 0; c < n; ++c) ext[c] = WideExtinction(w, c, d);
            if (k > 0) {
                for (int c = 0; c < n; ++c) tau_view[c] += (prev_ext[c] + ext[c]) * (0.5 * ds);
            }
            for (int c = 0; c < n; ++c) prev_ext[c] = ext[c];
            const AplusWideRows rows =
                AplusWideRowsOf(gather, s.mapping, hp, ClampCosine(Dot(p, col.view) / r));
            if (col.any_thick) nodes.Next(atm, w, col, k, steps, ext, thick_w);
            const double weight = (k == 0 || k == steps) ? 0.5 * ds : ds;
            // Per channel: thin, sum += (g t) (rho_R w) with t = exp(-tau_view);
            // thick, sum += (g t) rho_R with t the rule's factor. Mie: thin
            // ((g t) rho_M) w, thick (g t) rho_M.
            const double rayleigh_w = d.rayleigh * weight;
            for (int c = 0; c < n; ++c) {
                const bool thick = col.thick[c / 3];
                t[c] = thick ? thick_w[c] : exp(-tau_view[c]);
                factor[c] = thick ? d.rayleigh : rayleigh_w;
            }
            for (int b = 0; b < nb; ++b) mie_t[b] = t[3 * b + kAplusMieChannel];
            for (int z = 0; z < s.depth; ++z) {
                const double mu_sun = ClampCosine(Dot(p, suns[static_cast<size_t>(z)]) / r);
                AplusWideInterpolate(gather, rows, AplusWideSunSpan(gather, s.mapping, mu_sun),
                                     0.0f, g);
                double* __restrict__ sum = sums_out->data() + static_cast<size_t>(z) * channels;
                for (int c = 0; c < n; ++c) sum[c] += static_cast<double>(g[c]) * t[c] * factor[c];
                for (int b = 0; b < nb; ++b) {
                    const double v = static_cast<double>(g[n + b]) * mie_t[b] * d.mie;
                    sum[n + b] += col.thick[b] ? v : v * weight;
                }
            }
        }
    }
};

// Sum of batch b's four channels of a wide scattering table, texel by texel
// in the order of TableSum over the batch's own table (R, G, B, Mie).
double BatchTableSum(const Table& table, int n, int b) {
    const size_t texels = static_cast<size_t>(table.width()) * table.height() * table.depth();
    const size_t channels = static_cast<size_t>(table.channels());
    const float* data = table.data();
    double sum = 0.0;
    for (size_t i = 0; i < texels; ++i) {
        const float* texel = data + i * channels;
        sum += static_cast<double>(texel[3 * b]);
        sum += static_cast<double>(texel[3 * b + 1]);
        sum += static_cast<double>(texel[3 * b + 2]);
        sum += static_cast<double>(texel[n + b]);
    }
    return sum;
}

}  // namespace

AplusWideTables AplusPrecomputeWide(const std::vector<AtmosphereParameters>& batches,
                                    const AplusSettings& settings_in) {
    const WideCoefficients w = MakeWideCoefficients(batches);
    const AtmosphereParameters& atm = batches[0];
    AplusSettings s = settings_in;
    s.mapping.bottom_radius = atm.bottom_radius;
    s.mapping.height = atm.top_radius - atm.bottom_radius;
    AtmospherePlusModel::OptionRows().Check("atmosphere-plus", s);
    const int n = w.channels, nb = n / 3, channels = n + nb;
    AplusWideTables out;
    out.transmittance = Table(s.transmittance_width, s.transmittance_height, 1, n);
    RunStage("atmosphere-plus/wide-transmittance",
             static_cast<int64_t>(s.transmittance_width) * s.transmittance_height, 64,
             AplusWideTransmittanceStage{atm, w, s, out.transmittance.out()});

    const int64_t columns = static_cast<int64_t>(s.width) * s.height;
    const int64_t texels = columns * s.depth;
    Table order(s.width, s.height, s.depth, channels);
    RunStage("atmosphere-plus/wide-order-1", columns, 1,
             AplusWideSingleScatteringStage{atm, w, s, order.out()});
    out.scattering = order;
    std::vector<ScatteringOrders> sums(static_cast<size_t>(nb));
    for (int b = 0; b < nb; ++b) sums[b].Add(1, BatchTableSum(order, n, b));
    for (int k = 2; k <= s.orders; ++k) {
        Table gather(s.width, s.height, s.depth, channels);
        RunStage("atmosphere-plus/wide-gather", columns, 1,
                 AplusWideGatherStage{atm, w, s, order.view(), gather.out()});
        Table next(s.width, s.height, s.depth, channels);
        RunStage("atmosphere-plus/wide-order-k", columns, 1,
                 AplusWideOrderStage{atm, w, s, gather.view(), next.out()});
        RunStage("atmosphere-plus/sum", texels, 4096,
                 AplusAddStage{next.view(), out.scattering.out(true)});
        order = std::move(next);
        for (int b = 0; b < nb; ++b) sums[b].Add(k, BatchTableSum(order, n, b));
    }
    for (const ScatteringOrders& o : sums) o.WarnIfDiverging("atmosphere-plus", 3);
    return out;
}

void AtmospherePlusModel::PrepareWide(const std::vector<AtmosphereParameters>& batches,
                                      const BatchPrepare&) {
    const WideCoefficients w = MakeWideCoefficients(batches);  // checks the batches
    for (const AtmosphereParameters& a : batches) WarnOutsideValidityDomain(Info(), a);
    wide_prepared_ = false;
    wide_tables_ = AplusPrecomputeWide(batches, settings_);
    wide_atm_ = batches[0];
    wide_ = w;
    wide_mapping_ = settings_.mapping;
    wide_mapping_.bottom_radius = wide_atm_.bottom_radius;
    wide_mapping_.height = wide_atm_.top_radius - wide_atm_.bottom_radius;
    wide_prepared_ = true;
}

namespace {
AtmospherePlusWideEvaluator MakeWideEvaluator(bool prepared, const AtmosphereParameters& atm,
                                              const WideCoefficients& w,
                                              const AplusMapping& mapping,
                                              const AplusWideTables& tables,
                                              bool modified_rayleigh) {
    if (!prepared) {
        Fail("model atmosphere-plus: PrepareWide() must run before RenderWide() / SampleWide()");
    }
    AtmospherePlusWideEvaluator e;
    e.atm = atm;
    e.w = w;
    e.mapping = mapping;
    e.scattering = tables.scattering.view();
    e.transmittance = tables.transmittance.view();
    e.modified_rayleigh = modified_rayleigh;
    return e;
}
}  // namespace

void AtmospherePlusModel::RenderWide(const RenderRequest& request,
                                     std::vector<float>* values) const {
    const AtmospherePlusWideEvaluator e = MakeWideEvaluator(
        wide_prepared_, wide_atm_, wide_, wide_mapping_, wide_tables_, settings_.modified_rayleigh);
    RenderWideImage(e, MakeWidePixelSetup(request, wide_atm_, e.w), values);
}

std::vector<float> AtmospherePlusModel::SampleWide(const std::vector<SampleQuery>& queries) const {
    const AtmospherePlusWideEvaluator e = MakeWideEvaluator(
        wide_prepared_, wide_atm_, wide_, wide_mapping_, wide_tables_, settings_.modified_rayleigh);
    return SampleAllWide(e, wide_atm_.bottom_radius, queries);
}

}  // namespace atmos
