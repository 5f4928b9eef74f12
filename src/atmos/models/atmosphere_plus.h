// atmos model `atmosphere-plus`: the 3D-table model without azimuth.
//
// Source: J. Boody, "Atmosphere Plus" notes, Boody's Atmosphere Plus notes (sections 1.2-2.4); the
// earlier version, the earlier Atmosphere Plus notes (Boody), differs in constants only (R_p 6371
// km, Rayleigh (6.55, 17.3, 23.0)e-6 /m, Mie 2e-6 /m with extinction beta/0.9, g = -0.85 in a Mie
// phase written with +2g cos) and states the same cube-root mapping.
//
// Implements (factored form of section 2.3; Rayleigh in RGB, Mie in alpha):
//   transmittance  T = exp(-t), t = trapezoidal rule (1.9) of the extinction
//                  along the segment with `transmittance-steps` (seed: n = 30)
//                  intervals (1.10);
//   order 1        I1(P0,V,L) = beta/(4 pi) int p(h) T(Pc,P) T(P,Pa) ds   (2.1, 2.3)
//                  (trapezoidal rule over the view segment, the same n; a point
//                  whose sun ray hits the ground contributes 0);
//   order k        Ik(P0,V,L) = beta/(4 pi) int G(k-1)(P,V,L) p(h) T(P,Pa) ds (2.2, 2.3)
//                  G(k-1)(P,V,L) = int_4pi F(dot(w,V)) I(k-1)(P,w,L) dw by the 2D
//                  trapezoidal rule (1.9) over (Theta, Phi) with
//                  `gather-theta` x `gather-phi` intervals;
//   table          sum over k = 1..K (`orders`) in a width x height x depth
//                  table over (h, cos phi, cos delta) (2.4) in one of the four
//                  parameterizations (atmosphere_plus_mapping.h);
//   render         L = F_R(nu) I_R + F_M(nu) I_M, the phase functions applied
//                  per pixel (2.3) in the seed's normalisation (integral 4 pi;
//                  the 1/(4 pi) lives in the table), optionally the modified
//                  Rayleigh phase 0.8 (1.4 + 0.5 nu^2) of section 1.7.
//
// Output: radiance per unit solar irradiance (1/sr) like every model; the
// render loop multiplies by the atmosphere's solar_irradiance, which for the
// seed's preset (data/atmospheres/earth-atmosphere-plus.json) is the seed's
// spectral intensity of incident light I_I of section 1.2, so I_I is applied
// exactly once. Transmittance: of the view segment, from a 2D table T(h, mu)
// (same u, v mapping) computed with the same trapezoidal rule.
//
// Valid: any altitude (cameras above the atmosphere are moved to where the view
// ray enters it, section 2.4: h in [0, H_a]); any sun. The table has no
// sun-view azimuth: it is exact (up to interpolation) only when sun and view
// lie in the same vertical plane on the same side (azimuth 0); elsewhere the
// render-time phase functions stand in for the azimuth (2.4.5).
//
// Deviations (docs/models/atmosphere-plus.md): the gather G(k-1) is tabulated on the scattering
// table's grid and interpolated along the view ray (the seed's solver gathers at
// every ray sample; same integral, 72x cheaper); Mie "alpha" uses the green
// channel's beta_M and transmittance (the seed stores one wavelength-independent
// Mie value without saying which); extinction includes the atmosphere's ozone
// term (zero in the seed's preset); ground albedo is not used in the orders (the
// seed has none), the render adds the sun-lit ground only; the horizon-centric
// mapping uses the geometric horizon by default (atmosphere_plus_mapping.h);
// lookups interpolate between altitude rows, each row at its own v, and give
// rays below the horizon at the ground row zero length (AplusSampleTable).
// Defaults: horizon-centric mapping, 32 x 64 x 32 (the lowest measured table
// error per MiB, docs/models/atmosphere-plus.md), K = 5, 6 x 12 gather, n = 30.
// Precomputation: the stage structs of atmosphere_plus_stages.h through
// RunStage, on the CPU or (CUDA backend) on the device from the same code.
// Wide channel batches (a spectral run's up to 16 batches of three in one
// model): atmosphere_plus_wide.{h,cpp}, one column of a table per work item for
// every channel, bit for bit the batches' tables and values.
#pragma once

#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "base/texture.h"
#include "models/atmosphere_plus_mapping.h"
#include "models/evaluator_model.h"
#include "physics/density.h"
#include "physics/exp_quadrature.h"
#include "physics/geometry.h"
#include "physics/phase.h"
#include "physics/transmittance.h"
#include "physics/wide.h"

namespace atmos {

// Boody's Atmosphere Plus notes section 1.7: phase functions normalised to 4 pi over the sphere.
ATMOS_HD inline double AplusRayleighPhase(double nu) { return 0.75 * (1.0 + nu * nu); }
ATMOS_HD inline double AplusModifiedRayleighPhase(double nu) {
    return 0.8 *
           (1.4 + 0.5 * nu * nu);  // Boody's Atmosphere Plus notes 1.7 (integrates to 5.013 pi)
}
ATMOS_HD inline double AplusMiePhase(double g, double nu) {
    return 4.0 * kPi *
           CornetteShanksPhase(
               g, nu);  // Boody's Atmosphere Plus notes 1.7 = 4 pi x Leenman's 2025 thesis Eq. 5
}
// The atmosphere's Mie phase (one or two lobes, MiePhase) on the same scale.
ATMOS_HD inline double AplusMiePhase(const AtmosphereParameters& atm, double nu) {
    return 4.0 * kPi * MiePhase(atm, nu);
}

// The Mie channel stored in alpha (see the header's deviations).
constexpr int kAplusMieChannel = 1;

ATMOS_HD inline double Channel(const Vec3d& v, int c) { return c == 0 ? v.x : c == 1 ? v.y : v.z; }

struct AplusValue {  // factored intensity: Rayleigh RGB + Mie
    Vec3d rayleigh;
    double mie = 0.0;
    ATMOS_HD AplusValue& operator+=(const AplusValue& o) {
        rayleigh += o.rayleigh;
        mie += o.mie;
        return *this;
    }
};
ATMOS_HD inline AplusValue operator*(const AplusValue& a, double s) {
    AplusValue r;
    r.rayleigh = a.rayleigh * s;
    r.mie = a.mie * s;
    return r;
}

// The exponential-linear rule's node factors W_i / sigma_t,i on a view segment
// whose optical depth is the trapezoid of the nodes' extinction (the seed's
// tau_view, so the rule's transmittance is the seed's): node i's factor needs
// the optical depth of the interval after it, i.e. node i + 1's extinction.
struct AplusThickNodes {
    ExpLinearNodeWeights rule;
    ATMOS_HD Vec3d Next(const AtmosphereParameters& atm, const Vec3d& p0, const Vec3d& dir,
                        double t0, double ds, int i, int steps, const Vec3d& ext) {
        Vec3d dtau;
        if (i < steps) {
            const double alt = Length(p0 + dir * (t0 + (i + 1) * ds)) - atm.bottom_radius;
            dtau = (ext + Extinction(atm, GetDensities(atm, alt))) * (0.5 * ds);
        }
        return PerExtinction(rule.Next(dtau), ext);
    }
};

// The view ray of a table texel (h, mu, mu_s), sun at azimuth 0: its start at
// altitude h, the view and sun directions, and its segment inside the
// atmosphere (Boody's Atmosphere Plus notes 2.1).
struct AplusTexelRay {
    Vec3d p0, view, sun;
    AtmosphereSegment seg;
};
ATMOS_HD inline AplusTexelRay AplusTexelRayOf(const AtmosphereParameters& atm, double h, double mu,
                                              double mu_s) {
    AplusTexelRay t;
    t.p0 = Vec3d(0.0, 0.0, atm.bottom_radius + h);
    t.view = Vec3d(SafeSqrt(1.0 - mu * mu), 0.0, mu);
    t.sun = Vec3d(SafeSqrt(1.0 - mu_s * mu_s), 0.0, mu_s);
    t.seg = ClipToAtmosphere(t.p0, t.view, atm.bottom_radius, atm.top_radius);
    return t;
}

// Boody's Atmosphere Plus notes sections 1.10, 2.1, 2.3: the factored single scattering I1 for an
// observer at altitude h looking along mu with the sun at mu_s (azimuth 0),
// trapezoidal rule with `steps` intervals along the view segment and
// `sun_steps` along each sun ray.
ATMOS_HD inline AplusValue AplusSingleScattering(const AtmosphereParameters& atm, double h,
                                                 double mu, double mu_s, int steps, int sun_steps) {
    AplusValue out;
    const auto [p0, view, sun, seg] = AplusTexelRayOf(atm, h, mu, mu_s);
    if (!seg.inside) return out;
    const double ds = (seg.t_end - seg.t_start) / steps;
    // Optically thick steps: the exponential-linear rule on the same nodes and
    // optical depths (physics/exp_quadrature.h; the trapezoid is not energy
    // conserving there).
    const bool thick = RayHasThickSteps(atm, p0, view, seg.t_start, ds, steps);
    AplusThickNodes nodes;
    Vec3d tau_view;  // P_a to the current node
    Vec3d prev_ext;
    Vec3d sum_r;
    double sum_m = 0.0;
    for (int i = 0; i <= steps; ++i) {
        const Vec3d p = p0 + view * (seg.t_start + i * ds);
        const double r = Length(p);
        const Densities d = GetDensities(atm, r - atm.bottom_radius);
        const Vec3d ext = Extinction(atm, d);
        if (i > 0) tau_view += (prev_ext + ext) * (0.5 * ds);
        prev_ext = ext;
        Vec3d thick_w;
        if (thick) thick_w = nodes.Next(atm, p0, view, seg.t_start, ds, i, steps, ext);
        const double mu_sun = ClampCosine(Dot(p, sun) / r);
        if (RayIntersectsGround(r, mu_sun, atm.bottom_radius)) continue;  // P_c on the ground
        const double length = DistanceToTopAtmosphereBoundary(r, mu_sun, atm.top_radius);
        const Vec3d tau_sun = OpticalDepth(atm, p, sun, length, sun_steps);
        if (thick) {
            const Vec3d t = Exp(-tau_sun) * thick_w;
            sum_r += t * d.rayleigh;
            sum_m += Channel(t, kAplusMieChannel) * d.mie;
            continue;
        }
        const Vec3d t = Exp(-(tau_view + tau_sun));
        const double w = (i == 0 || i == steps) ? 0.5 * ds : ds;
        sum_r += t * (d.rayleigh * w);
        sum_m += Channel(t, kAplusMieChannel) * d.mie * w;
    }
    out.rayleigh = atm.rayleigh_scattering * sum_r / (4.0 * kPi);
    out.mie = Channel(atm.mie_scattering, kAplusMieChannel) * sum_m / (4.0 * kPi);
    return out;
}

// Boody's Atmosphere Plus notes section 1.9: the 2D trapezoidal rule of f over [a, b] x [c, d] with
// n intervals in x and m in y (corner weight 1, edge 2, interior 4, times
// dx dy / 4).
template <typename T, typename F>
T AplusTrapezoid2D(const F& f, double a, double b, double c, double d, int n, int m) {
    const double dx = (b - a) / n, dy = (d - c) / m;
    T sum{};
    for (int i = 0; i <= m; ++i) {
        const double wy = (i == 0 || i == m) ? 1.0 : 2.0;
        for (int j = 0; j <= n; ++j) {
            const double wx = (j == 0 || j == n) ? 1.0 : 2.0;
            sum += f(a + j * dx, c + i * dy) * (wx * wy);
        }
    }
    return sum * (0.25 * dx * dy);
}

struct AplusSettings {
    AplusMapping mapping;  // default: horizon-centric (the lowest measured error)
    int width = 32, height = 64,
        depth = 32;  // Boody's Atmosphere Plus notes 2.4: (32, 256|128|64, 32)
    int transmittance_width = 64, transmittance_height = 256;
    // Numerics: the seed text gives n = 30 (1.10) only; K = 5 and the 6 x 12
    // gather (30 degree steps) are the constants of the seed author's solver
    // (atmosphere-plus repository, atmo_solver.c: ATMO_K, ATMO_GATHER_M/N_STEPS).
    int orders = 5;                  // K
    int transmittance_steps = 30;    // Boody's Atmosphere Plus notes 1.10: n = 30
    int gather_theta = 12;           // 2D trapezoid intervals over Theta in [0, pi] (author's: 6)
    int gather_phi = 24;             // ... over Phi in [0, 2 pi] (author's: 12; issue 15)
    bool modified_rayleigh = false;  // Boody's Atmosphere Plus notes 1.7
};

struct AplusTables {
    Table scattering;                   // width x height x depth x 4: sum of orders (R, G, B, Mie)
    Table transmittance;                // transmittance_width x transmittance_height x 1 x 3
    std::vector<Table> orders;          // per-order tables (kept only when asked)
    std::vector<double> order_seconds;  // precompute time of each order
    double transmittance_seconds = 0.0;
};

// Precomputes the tables through RunStage (atmosphere_plus_stages.h): on the
// CPU, or on the device on the CUDA backend. keep_orders keeps each order's
// table.
AplusTables AplusPrecompute(const AtmosphereParameters& atm, const AplusSettings& settings,
                            bool keep_orders = false);

// The tables of a wide precomputation (wide channel batches: physics/wide.h,
// models/atmosphere_plus_wide.h) for n = 3B channels of B batches: per texel
// the Rayleigh values of every channel (3b + c: batch b's channel c), then the
// Mie value (alpha) of every batch (n + b), contiguous.
struct AplusWideTables {
    Table scattering;     // width x height x depth x (n + n / 3)
    Table transmittance;  // transmittance_width x transmittance_height x 1 x n
};

// The tables for the batches' channels (MakeWideCoefficients: batch b gives
// channels 3b .. 3b + 2; the batches differ only in those coefficients), on
// the CPU (atmosphere_plus_wide.cpp): channel for channel what
// AplusPrecompute(batches[b], settings) computes, bit for bit, with the
// geometry shared by the channels and, in each (altitude, view) column of the
// table, by its sun angles. Each batch's orders are checked as AplusPrecompute
// checks them (a warning per batch whose orders stop decreasing).
AplusWideTables AplusPrecomputeWide(const std::vector<AtmosphereParameters>& batches,
                                    const AplusSettings& settings);

// Texel i of a table of `size` texels holds the value at i / (size - 1) (seed
// 000 2.4's x/(size-1); atmosphere_plus_mapping.h).
ATMOS_HD inline double AplusUnitCoord(int i, int size) {
    return size > 1 ? static_cast<double>(i) / (size - 1) : 0.0;
}

// The table's (h, mu, mu_s) of texel (x, y, z).
ATMOS_HD inline void AplusTexelParameters(const AplusMapping& m, int x, int y, int z, int width,
                                          int height, int depth, double* h, double* mu,
                                          double* mu_s) {
    *h = m.H(AplusUnitCoord(x, width));
    *mu = m.Mu(*h, AplusUnitCoord(y, height));
    *mu_s = m.MuS(AplusUnitCoord(z, depth));
}

// Samples a table laid out as the scattering table at (h, mu, mu_s): linear
// between the two altitude rows around h, and in each row bilinear in (v, w)
// with v computed from that row's altitude (the horizon-centric v depends on
// h). At the ground row (h = 0) a ray below the horizon has no length:
// `ground_row` (0 for scattering, 1 for transmittance) instead of the texel,
// which the horizon-centric mapping gives to the horizon there (s u(0) = 0).
ATMOS_HD inline Vec4f AplusSampleTable(const TableView& t, const AplusMapping& m, double h,
                                       double mu, double w, const Vec4f& ground_row) {
    int x0, z0;
    float fx, fz;
    TableView::Split(GetTextureCoordFromUnitRange(m.U(h), t.width), t.width, &x0, &fx);
    TableView::Split(w, t.depth, &z0, &fz);
    Vec4f out;
    for (int k = 0; k < 2; ++k) {
        const float weight = k == 0 ? 1.0f - fx : fx;
        if (weight == 0.0f) continue;
        const int x = Min(x0 + k, t.width - 1);
        const double h_row = m.H(t.width > 1 ? static_cast<double>(x) / (t.width - 1) : 0.0);
        if (h_row <= 0.0 && mu < 0.0) {
            out = out + ground_row * weight;
            continue;
        }
        int y0;
        float fy;
        TableView::Split(GetTextureCoordFromUnitRange(m.V(h_row, mu), t.height), t.height, &y0,
                         &fy);
        const auto layer = [&](int z) {
            return (t.Fetch(x, y0, z) * (1.0f - fy) + t.Fetch(x, y0 + 1, z) * fy);
        };
        const Vec4f row = t.depth > 1 ? layer(z0) * (1.0f - fz) + layer(z0 + 1) * fz : layer(0);
        out = out + row * weight;
    }
    return out;
}
ATMOS_HD inline Vec4f AplusSample(const TableView& t, const AplusMapping& m, double h, double mu,
                                  double mu_s) {
    return AplusSampleTable(t, m, h, mu, GetTextureCoordFromUnitRange(m.W(mu_s), t.depth), Vec4f());
}
ATMOS_HD inline Rgb AplusSampleTransmittance(const TableView& t, const AplusMapping& m, double h,
                                             double mu) {
    Vec4f one;
    one.x = one.y = one.z = 1.0f;
    return AplusSampleTable(t, m, h, mu, 0.5, one).rgb();
}

// AplusSampleTable for a table of C channels (TableView::channels == C): the
// same operations in the same order on the texels read directly (no per-texel
// clamps or channel tests; base/texture.h's TexelSpan), hence bit-identical
// (tests/atmosphere_plus_test.cpp holds it to the generic one).
template <int C>
ATMOS_HD inline void AplusSampleTableFixed(const TableView& t, const AplusMapping& m, double h,
                                           double mu, double w, const float ground_row[C],
                                           float out[C]) {
    ATMOS_DASSERT(t.channels == C);
    const TexelSpan x = SplitSpan(GetTextureCoordFromUnitRange(m.U(h), t.width), t.width);
    const TexelSpan z = SplitSpan(w, t.depth);
    const size_t plane = static_cast<size_t>(t.width) * t.height;
    for (int c = 0; c < C; ++c) out[c] = 0.0f;
    for (int k = 0; k < 2; ++k) {
        const float weight = k == 0 ? 1.0f - x.f : x.f;
        if (weight == 0.0f) continue;
        const int xi = k == 0 ? x.i0 : x.i1;
        const double h_row = m.H(t.width > 1 ? static_cast<double>(xi) / (t.width - 1) : 0.0);
        if (h_row <= 0.0 && mu < 0.0) {
            for (int c = 0; c < C; ++c) out[c] = out[c] + ground_row[c] * weight;
            continue;
        }
        const TexelSpan y =
            SplitSpan(GetTextureCoordFromUnitRange(m.V(h_row, mu), t.height), t.height);
        const size_t y0 = static_cast<size_t>(y.i0) * t.width + xi;
        const size_t y1 = static_cast<size_t>(y.i1) * t.width + xi;
        const size_t z0 = static_cast<size_t>(z.i0) * plane, z1 = static_cast<size_t>(z.i1) * plane;
        const float* d = t.data;
        for (int c = 0; c < C; ++c) {
            const float l0 = d[(z0 + y0) * C + c] * (1.0f - y.f) + d[(z0 + y1) * C + c] * y.f;
            float row = l0;
            if (t.depth > 1) {
                const float l1 = d[(z1 + y0) * C + c] * (1.0f - y.f) + d[(z1 + y1) * C + c] * y.f;
                row = l0 * (1.0f - z.f) + l1 * z.f;
            }
            out[c] = out[c] + row * weight;
        }
    }
}

// The per-pixel evaluator (trivially copyable; tables by view).
struct AtmospherePlusEvaluator {
    AtmosphereParameters atm;
    AplusMapping mapping;
    TableView scattering;
    TableView transmittance;
    bool modified_rayleigh = false;

    // Names every table (physics/ray.h: the device launch re-points these).
    template <typename V>
    void VisitTables(V& v) {
        v(scattering);
        v(transmittance);
    }

    // AplusSampleTransmittance on the fixed 3-channel lookup (bit-identical).
    ATMOS_HD Rgb Transmittance(double h, double mu) const {
        const float one[3] = {1.0f, 1.0f, 1.0f};
        float t[3];
        AplusSampleTableFixed<3>(transmittance, mapping, h, mu, 0.5, one, t);
        return Rgb(t[0], t[1], t[2]);
    }

    ATMOS_HD RayResult Evaluate(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                                bool want_ground) const {
        RayResult out;
        AtmosphereSegment seg;
        if (!BeginRay(camera, dir, atm.bottom_radius, atm.top_radius, &out, &seg)) {
            // A camera on the ground looking down (physics/ray.h): the ground at the camera.
            if (want_ground && GroundAtCamera(seg) && MaxComponent(atm.ground_albedo) > 0.0) {
                const double cos_sun = Dot(Normalize(camera), sun);
                if (cos_sun > 0.0) {
                    out.ground =
                        Rgb(atm.ground_albedo * (cos_sun / kPi)) * Transmittance(0.0, cos_sun);
                }
            }
            return out;
        }
        // Boody's Atmosphere Plus notes 2.4: P_0 is the camera, or where the ray enters the
        // atmosphere.
        const Vec3d p0 = camera + dir * seg.t_start;
        const double r = Length(p0);
        const double h = Clamp(r - atm.bottom_radius, 0.0, atm.top_radius - atm.bottom_radius);
        const double mu = ClampCosine(Dot(p0, dir) / r);
        const double mu_s = ClampCosine(Dot(p0, sun) / r);
        const double nu = ClampCosine(Dot(dir, sun));
        const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
        float s4[4];
        AplusSampleTableFixed<4>(scattering, mapping, h, mu,
                                 GetTextureCoordFromUnitRange(mapping.W(mu_s), scattering.depth),
                                 zero, s4);
        Vec4f s;
        s.x = s4[0];
        s.y = s4[1];
        s.z = s4[2];
        s.w = s4[3];
        // Boody's Atmosphere Plus notes 2.3: I_S / I_I = F_R(dot(L, -V)) I_R + F_M(dot(L, -V)) I_M,
        // with L = -sun and so dot(L, -V) = dot(sun, V) = nu.
        const double f_r =
            modified_rayleigh ? AplusModifiedRayleighPhase(nu) : AplusRayleighPhase(nu);
        const double f_m = AplusMiePhase(atm, nu);
        const Rgb sky = s.rgb() * static_cast<float>(f_r) + Rgb(s.w * static_cast<float>(f_m));
        out.sky = Max(sky, Rgb(0.0f));
        out.transmittance = Transmittance(h, mu);
        if (want_ground && seg.hits_ground && MaxComponent(atm.ground_albedo) > 0.0) {
            const Vec3d g = camera + dir * seg.t_end;
            const double cos_sun = Dot(Normalize(g), sun);
            if (cos_sun > 0.0) {
                const Rgb t_sun = Transmittance(0.0, cos_sun);
                out.ground = Rgb(atm.ground_albedo * (cos_sun / kPi)) * t_sun * out.transmittance;
            }
        }
        return out;
    }
};

// The same model without a table: the factored single scattering evaluated by
// direct integration at the pixel's exact (h, mu, mu_s) (azimuth omitted as in
// the table). The stand-in reference for the table error of order-1 tables
// (tests, docs/models/atmosphere-plus.md); host use only (slow).
struct AtmospherePlusDirectEvaluator {
    static constexpr bool kHostOnly = true;  // no device kernels (physics/ray.h)
    AtmosphereParameters atm;
    int steps = 30, sun_steps = 30;
    bool modified_rayleigh = false;

    ATMOS_HD RayResult Evaluate(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                                bool) const {
        RayResult out;
        AtmosphereSegment seg;
        if (!BeginRay(camera, dir, atm.bottom_radius, atm.top_radius, &out, &seg)) return out;
        const Vec3d p0 = camera + dir * seg.t_start;
        const double r = Length(p0);
        const double h = Clamp(r - atm.bottom_radius, 0.0, atm.top_radius - atm.bottom_radius);
        const double nu = ClampCosine(Dot(dir, sun));
        const AplusValue v = AplusSingleScattering(atm, h, ClampCosine(Dot(p0, dir) / r),
                                                   ClampCosine(Dot(p0, sun) / r), steps, sun_steps);
        const double f_r =
            modified_rayleigh ? AplusModifiedRayleighPhase(nu) : AplusRayleighPhase(nu);
        out.sky = Rgb(v.rayleigh * f_r + Vec3d(v.mie * AplusMiePhase(atm, nu)));
        out.transmittance = Rgb(Exp(-OpticalDepth(atm, p0, dir, seg.t_end - seg.t_start, steps)));
        return out;
    }
};

class AtmospherePlusModel : public EvaluatorModel<AtmospherePlusModel> {
  public:
    static const OptionTable<AplusSettings>& OptionRows();
    explicit AtmospherePlusModel(const AplusSettings& options);
    static ModelInfo StaticInfo();
    const ModelInfo& Info() const override { return info_; }
    void Prepare(const AtmosphereParameters& atmosphere) override;
    AtmospherePlusEvaluator MakeEvaluator() const;
    const AtmosphereParameters& atmosphere() const { return atm_; }
    const AplusSettings& settings() const { return settings_; }
    const AplusTables& tables() const { return tables_; }

    // `atmos bake`: scattering.exr (W*D x H, RGBA), transmittance.exr (RGB) and
    // atmosphere-plus.json (sizes, mapping, numerics, the atmosphere).
    bool CanBake() const override { return true; }
    void Bake(const std::string& directory) const override;
    int64_t TableBytes() const override;
    void LoadBaked(const std::string& directory, const AtmosphereParameters& atmosphere) override;

    // Wide channel batches (models/atmosphere_plus_wide.h): PrepareWide
    // computes the n-channel tables itself (AplusPrecomputeWide; the spectral
    // run's per-batch prepare function is not used).
    void PrepareWide(const std::vector<AtmosphereParameters>& batches,
                     const BatchPrepare& prepare_batch = {}) override;
    void RenderWide(const RenderRequest& request, std::vector<float>* values) const override;
    std::vector<float> SampleWide(const std::vector<SampleQuery>& queries) const override;
    // The tables of the last PrepareWide (empty before).
    const AplusWideTables& wide_tables() const { return wide_tables_; }

  private:
    ModelInfo info_;
    AplusSettings settings_;
    AtmosphereParameters atm_;
    AplusTables tables_;
    // PrepareWide's: batch 0's atmosphere, the per-channel coefficients, the
    // mapping (its radii set) and the tables.
    bool wide_prepared_ = false;
    AtmosphereParameters wide_atm_;
    WideCoefficients wide_;
    AplusMapping wide_mapping_;
    AplusWideTables wide_tables_;
};

}  // namespace atmos
