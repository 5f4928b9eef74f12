// atmos model `atmosphere-plus`: its precomputation stages (render/stages.h),
// the one per-texel code of both backends (the CPU's ParallelFor and, in a
// CUDA build, src/atmos/cuda/atmosphere_plus_stages.cu).
//
// Source and equations: atmosphere_plus.h (Boody's Atmosphere Plus notes sections 1.9-2.4). Stages,
// each one texel per item (x fastest, then y, then z):
//  * AplusTransmittanceStage: T(h, mu) of the view segment, trapezoidal rule (1.9, 1.10);
//  * AplusSingleScatteringStage: order 1 (2.1, 2.3), AplusSingleScattering;
//  * AplusGatherStage: G(k-1)(P, V, L) = int_4pi F(dot(w, V)) I(k-1)(P, w, L) dw (2.2)
//    by the 2D trapezoidal rule over (Theta, Phi) (1.9);
//  * AplusOrderStage: order k from the gather table (2.2, 2.3);
//  * AplusAddStage: total += order (the sum over k, 2.4).
#pragma once

#include <cstdint>

#include "models/atmosphere_plus.h"
#include "render/stages.h"

namespace atmos {

ATMOS_HD inline Vec4f AplusToVec4f(const AplusValue& v) {
    return {static_cast<float>(v.rayleigh.x), static_cast<float>(v.rayleigh.y),
            static_cast<float>(v.rayleigh.z), static_cast<float>(v.mie)};
}

ATMOS_HD inline AplusValue AplusFromVec4f(const Vec4f& v) {
    AplusValue a;
    a.rayleigh =
        Vec3d(static_cast<double>(v.x), static_cast<double>(v.y), static_cast<double>(v.z));
    a.mie = static_cast<double>(v.w);
    return a;
}

// The texel (x, y, z) of item `i` of a width x height x depth table.
ATMOS_HD inline void AplusItemTexel(int64_t i, const AplusSettings& s, int* x, int* y, int* z) {
    *x = static_cast<int>(i % s.width);
    *y = static_cast<int>((i / s.width) % s.height);
    *z = static_cast<int>(i / (static_cast<int64_t>(s.width) * s.height));
}

// The opening of every per-texel stage: the texel of item `i` of the scattering
// table and the (h, mu, mu_s) it stands for (AplusTexelParameters).
struct AplusTexel {
    int x, y, z;
    double h, mu, mu_s;
};
ATMOS_HD inline AplusTexel AplusTexelOf(int64_t i, const AplusSettings& s) {
    AplusTexel t;
    AplusItemTexel(i, s, &t.x, &t.y, &t.z);
    AplusTexelParameters(s.mapping, t.x, t.y, t.z, s.width, s.height, s.depth, &t.h, &t.mu,
                         &t.mu_s);
    return t;
}

// Boody's Atmosphere Plus notes sections 2.2, 2.3: the factored order k from the gather table of
// order k-1: beta/(4 pi) int G(P, V, L) p(h) T(P, P_a) ds, trapezoidal rule
// with transmittance_steps intervals along the view segment.
ATMOS_HD inline AplusValue AplusOrderFromGather(const TableView& gather,
                                                const AtmosphereParameters& atm,
                                                const AplusSettings& s, double h, double mu,
                                                double mu_s) {
    AplusValue out;
    const auto [p0, view, sun, seg] = AplusTexelRayOf(atm, h, mu, mu_s);
    if (!seg.inside) return out;
    const int steps = s.transmittance_steps;
    const double ds = (seg.t_end - seg.t_start) / steps;
    const double top = atm.top_radius - atm.bottom_radius;
    // Optically thick steps: the exponential-linear rule (AplusThickNodes).
    const bool thick = RayHasThickSteps(atm, p0, view, seg.t_start, ds, steps);
    AplusThickNodes nodes;
    Vec3d tau_view, prev_ext, sum_r;
    double sum_m = 0.0;
    for (int i = 0; i <= steps; ++i) {
        const Vec3d p = p0 + view * (seg.t_start + i * ds);
        const double r = Length(p);
        const double hp = Clamp(r - atm.bottom_radius, 0.0, top);
        const Densities d = GetDensities(atm, r - atm.bottom_radius);
        const Vec3d ext = Extinction(atm, d);
        if (i > 0) tau_view += (prev_ext + ext) * (0.5 * ds);
        prev_ext = ext;
        const AplusValue gp = AplusFromVec4f(AplusSample(
            gather, s.mapping, hp, ClampCosine(Dot(p, view) / r), ClampCosine(Dot(p, sun) / r)));
        if (thick) {
            const Vec3d t = nodes.Next(atm, p0, view, seg.t_start, ds, i, steps, ext);
            sum_r += gp.rayleigh * t * d.rayleigh;
            sum_m += gp.mie * Channel(t, kAplusMieChannel) * d.mie;
            continue;
        }
        const Vec3d t = Exp(-tau_view);
        const double w = (i == 0 || i == steps) ? 0.5 * ds : ds;
        sum_r += gp.rayleigh * t * (d.rayleigh * w);
        sum_m += gp.mie * Channel(t, kAplusMieChannel) * d.mie * w;
    }
    out.rayleigh = atm.rayleigh_scattering * sum_r / (4.0 * kPi);
    out.mie = Channel(atm.mie_scattering, kAplusMieChannel) * sum_m / (4.0 * kPi);
    return out;
}

// Boody's Atmosphere Plus notes sections 1.9, 1.10: the transmittance table T(h, mu) of the view
// segment (to the top of the atmosphere or to the ground), trapezoidal rule.
// `out`: transmittance_width x transmittance_height x RGB.
struct AplusTransmittanceStage {
    AtmosphereParameters atm;
    AplusSettings s;
    TableOut out;

    template <typename V>
    void VisitTables(V& v) {
        v(out);
    }
    ATMOS_HD void operator()(int64_t i) const {
        const int x = static_cast<int>(i % s.transmittance_width);
        const int y = static_cast<int>(i / s.transmittance_width);
        const double h = s.mapping.H(AplusUnitCoord(x, s.transmittance_width));
        const double mu = s.mapping.Mu(h, AplusUnitCoord(y, s.transmittance_height));
        const Vec3d p0(0.0, 0.0, atm.bottom_radius + h);
        const Vec3d dir(SafeSqrt(1.0 - mu * mu), 0.0, mu);
        const AtmosphereSegment seg = ClipToAtmosphere(p0, dir, atm.bottom_radius, atm.top_radius);
        Vec3d tr(1.0);
        if (seg.inside) {
            tr = Exp(-OpticalDepth(atm, p0 + dir * seg.t_start, dir, seg.t_end - seg.t_start,
                                   s.transmittance_steps));
        }
        const Rgb c(tr);
        out.Set(x, y, 0, {c.x, c.y, c.z, 0.0f});
    }
};
ATMOS_DEVICE_STAGE(AplusTransmittanceStage)

// Order 1 (Boody's Atmosphere Plus notes 2.1): AplusSingleScattering at every texel, n =
// transmittance_steps along the view and along each sun ray. `out`: the
// scattering table's layout (width x height x depth x 4).
struct AplusSingleScatteringStage {
    AtmosphereParameters atm;
    AplusSettings s;
    TableOut out;

    template <typename V>
    void VisitTables(V& v) {
        v(out);
    }
    ATMOS_HD void operator()(int64_t i) const {
        const auto [x, y, z, h, mu, mu_s] = AplusTexelOf(i, s);
        out.Set(x, y, z,
                AplusToVec4f(AplusSingleScattering(atm, h, mu, mu_s, s.transmittance_steps,
                                                   s.transmittance_steps)));
    }
};
ATMOS_DEVICE_STAGE(AplusSingleScatteringStage)

// Gather directions whose incoming values a texel keeps in a local array
// (16 bytes each: 784 bytes, so a device thread's stack frame stays under the
// default 1 KiB stack limit); more (--gather-theta > 48) are looked up again at
// every node, with the same result.
constexpr int kAplusGatherCachedThetas = 48;

// Boody's Atmosphere Plus notes 2.2, 2.3: the factored gather G(P, V, L) = int_4pi F(dot(w, V))
// I_prev(P, w, L) dw on the table's grid, by the 2D trapezoidal rule (1.9) over
// Theta in [0, pi] (gather_theta intervals) and Phi in [0, 2 pi] (gather_phi),
// dw = sin(Theta) dTheta dPhi. I_prev depends on w only through its zenith
// cosine (no azimuth): one lookup per Theta node. The sum is AplusTrapezoid2D's
// (corner weight 1, edge 2, interior 4, times dTheta dPhi / 4), in its order.
struct AplusGatherStage {
    AtmosphereParameters atm;
    AplusSettings s;
    TableView prev;  // order k-1
    TableOut out;

    template <typename V>
    void VisitTables(V& v) {
        v(prev);
        v(out);
    }
    ATMOS_HD void operator()(int64_t i) const {
        const auto [x, y, z, h, mu, mu_s] = AplusTexelOf(i, s);
        const int n = s.gather_theta, m = s.gather_phi;
        const double d_theta = kPi / n;
        const double d_phi = 2.0 * kPi / m;
        const bool cached = n <= kAplusGatherCachedThetas;
        Vec4f incoming[kAplusGatherCachedThetas + 1];
        if (cached) {
            for (int j = 0; j <= n; ++j) {
                incoming[j] = AplusSample(prev, s.mapping, h, cos(j * d_theta), mu_s);
            }
        }
        const double sin_phi = SafeSqrt(1.0 - mu * mu);
        AplusValue sum;
        for (int k = 0; k <= m; ++k) {
            const double wy = (k == 0 || k == m) ? 1.0 : 2.0;
            const double phi = k * d_phi;
            for (int j = 0; j <= n; ++j) {
                const double wx = (j == 0 || j == n) ? 1.0 : 2.0;
                const double theta = j * d_theta;
                const AplusValue in = AplusFromVec4f(
                    cached ? incoming[j] : AplusSample(prev, s.mapping, h, cos(j * d_theta), mu_s));
                const double sin_t = sin(theta);
                // cos of the scattering angle dot(-w, -V) = dot(w, V), V = (sin phi, 0, mu).
                const double c = ClampCosine(sin_t * cos(phi) * sin_phi + cos(theta) * mu);
                AplusValue f;
                f.rayleigh = in.rayleigh * (AplusRayleighPhase(c) * sin_t);
                f.mie = in.mie * AplusMiePhase(atm, c) * sin_t;
                sum += f * (wx * wy);
            }
        }
        out.Set(x, y, z, AplusToVec4f(sum * (0.25 * d_theta * d_phi)));
    }
};
ATMOS_DEVICE_STAGE(AplusGatherStage)

// Order k (Boody's Atmosphere Plus notes 2.2) from the gather table of order k-1.
struct AplusOrderStage {
    AtmosphereParameters atm;
    AplusSettings s;
    TableView gather;
    TableOut out;

    template <typename V>
    void VisitTables(V& v) {
        v(gather);
        v(out);
    }
    ATMOS_HD void operator()(int64_t i) const {
        const auto [x, y, z, h, mu, mu_s] = AplusTexelOf(i, s);
        out.Set(x, y, z, AplusToVec4f(AplusOrderFromGather(gather, atm, s, h, mu, mu_s)));
    }
};
ATMOS_DEVICE_STAGE(AplusOrderStage)

// total += add, texel by texel (same size and channels): the sum of orders.
struct AplusAddStage {
    TableView add;
    TableOut total;

    template <typename V>
    void VisitTables(V& v) {
        v(add);
        v(total);
    }
    ATMOS_HD void operator()(int64_t i) const {
        const size_t c = static_cast<size_t>(total.channels);
        float* t = total.data + static_cast<size_t>(i) * c;
        const float* a = add.data + static_cast<size_t>(i) * c;
        for (size_t k = 0; k < c; ++k) t[k] += a[k];
    }
};
ATMOS_DEVICE_STAGE(AplusAddStage)

}  // namespace atmos
