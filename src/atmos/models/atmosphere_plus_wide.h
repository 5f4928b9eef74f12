// atmos model `atmosphere-plus`: wide channel batches (physics/wide.h,
// docs/models/atmosphere-plus.md "Wide channel batches").
//
// The tables of n = 3B channels (B batches of three) hold, per texel, the
// Rayleigh values of every channel (channel 3b + c: batch b's channel c) and
// then the Mie value of every batch (channel n + b: batch b's alpha, its green
// channel's), contiguous; the transmittance table holds the n channels. The
// precomputation (AplusPrecomputeWide, atmosphere_plus_wide.cpp) computes them
// for all channels at once and the per-pixel evaluator below reads them: the
// geometry once (segments, sample positions and densities, table rows, spans
// and weights, phase functions), then loops over the channels. Each channel is
// computed by the three-channel code's operations in its order, so a wide
// table's channel equals the batch's table bit for bit, and so do renders and
// samples (tests/wide_channels_test.cpp).
#pragma once

#include <vector>

#include "models/atmosphere_plus.h"
#include "physics/wide.h"

namespace atmos {

// The rows of one AplusSampleTableFixed lookup at (h, mu): the texel span in
// altitude and, per row, its weight, texel column, whether it is the ground
// row of a ray below the horizon, and its span in v. Independent of the sun
// (w), so a precomputation stage shares it across the table's depth.
struct AplusWideRows {
    float weight[2] = {0.0f, 0.0f};
    int xi[2] = {0, 0};
    bool ground[2] = {false, false};
    TexelSpan y[2];
};
ATMOS_HD inline AplusWideRows AplusWideRowsOf(const TableView& t, const AplusMapping& m, double h,
                                              double mu) {
    AplusWideRows r;
    const TexelSpan x = SplitSpan(GetTextureCoordFromUnitRange(m.U(h), t.width), t.width);
    for (int k = 0; k < 2; ++k) {
        r.weight[k] = k == 0 ? 1.0f - x.f : x.f;
        r.xi[k] = k == 0 ? x.i0 : x.i1;
        if (r.weight[k] == 0.0f) continue;
        const double h_row = m.H(t.width > 1 ? static_cast<double>(r.xi[k]) / (t.width - 1) : 0.0);
        if (h_row <= 0.0 && mu < 0.0) {
            r.ground[k] = true;
            continue;
        }
        r.y[k] = SplitSpan(GetTextureCoordFromUnitRange(m.V(h_row, mu), t.height), t.height);
    }
    return r;
}

// AplusSampleTableFixed of every channel of `t` (t.channels of them) at the
// rows `r` and the span `z` in w; `ground_row`: the value of a ground row (0
// for scattering, 1 for transmittance). Per channel the operations of
// AplusSampleTableFixed, in its order.
ATMOS_HD inline void AplusWideInterpolate(const TableView& t, const AplusWideRows& r,
                                          const TexelSpan& z, float ground_row,
                                          float* __restrict__ out) {
    const int n = t.channels;
    const size_t nn = static_cast<size_t>(n);
    const size_t plane = static_cast<size_t>(t.width) * t.height;
    for (int c = 0; c < n; ++c) out[c] = 0.0f;
    for (int k = 0; k < 2; ++k) {
        const float weight = r.weight[k];
        if (weight == 0.0f) continue;
        if (r.ground[k]) {
            for (int c = 0; c < n; ++c) out[c] = out[c] + ground_row * weight;
            continue;
        }
        const TexelSpan& y = r.y[k];
        const size_t y0 = static_cast<size_t>(y.i0) * t.width + r.xi[k];
        const size_t y1 = static_cast<size_t>(y.i1) * t.width + r.xi[k];
        const size_t z0 = static_cast<size_t>(z.i0) * plane, z1 = static_cast<size_t>(z.i1) * plane;
        const float* __restrict__ a0 = t.data + (z0 + y0) * nn;
        const float* __restrict__ b0 = t.data + (z0 + y1) * nn;
        const float fy = y.f;
        if (t.depth > 1) {
            const float* __restrict__ a1 = t.data + (z1 + y0) * nn;
            const float* __restrict__ b1 = t.data + (z1 + y1) * nn;
            const float fz = z.f;
            for (int c = 0; c < n; ++c) {
                const float l0 = a0[c] * (1.0f - fy) + b0[c] * fy;
                const float l1 = a1[c] * (1.0f - fy) + b1[c] * fy;
                const float row = l0 * (1.0f - fz) + l1 * fz;
                out[c] = out[c] + row * weight;
            }
        } else {
            for (int c = 0; c < n; ++c) {
                const float l0 = a0[c] * (1.0f - fy) + b0[c] * fy;
                out[c] = out[c] + l0 * weight;
            }
        }
    }
}

// The span in w of a scattering-table lookup with the sun at mu_s (AplusSample).
ATMOS_HD inline TexelSpan AplusWideSunSpan(const TableView& t, const AplusMapping& m, double mu_s) {
    return SplitSpan(GetTextureCoordFromUnitRange(m.W(mu_s), t.depth), t.depth);
}

// The per-pixel evaluator of n = w.channels channels (render/wide.h):
// AtmospherePlusEvaluator::Evaluate per channel. atm is batch 0's atmosphere
// (its common fields; the per-channel coefficients are w's).
struct AtmospherePlusWideEvaluator {
    AtmosphereParameters atm;
    WideCoefficients w;
    AplusMapping mapping;
    TableView scattering;     // n + n / 3 channels
    TableView transmittance;  // n channels
    bool modified_rayleigh = false;

    template <typename V>
    void VisitTables(V& v) {
        v(scattering);
        v(transmittance);
    }
    ATMOS_HD int Channels() const { return w.channels; }

    // AtmospherePlusEvaluator::Transmittance for every channel.
    ATMOS_HD void Transmittance(double h, double mu, float* out) const {
        const AplusWideRows r = AplusWideRowsOf(transmittance, mapping, h, mu);
        AplusWideInterpolate(transmittance, r, SplitSpan(0.5, transmittance.depth), 1.0f, out);
    }

    // The lit ground's radiance (cos_sun / pi times each batch's albedo with
    // any albedo, times the sun's transmittance to the ground and, when
    // given, the view's transmittance).
    ATMOS_HD void Ground(double cos_sun, const float* t_view, WideRayResult* out) const {
        const int n = w.channels;
        float t_sun[kMaxWideChannels];
        Transmittance(0.0, cos_sun, t_sun);
        for (int b = 0; b < n / 3; ++b) {
            if (!(w.BatchMaxAlbedo(b) > 0.0)) continue;
            for (int c = 3 * b; c < 3 * b + 3; ++c) {
                const float g = static_cast<float>(w.ground_albedo[c] * (cos_sun / kPi)) * t_sun[c];
                out->ground[c] = t_view ? g * t_view[c] : g;
            }
        }
    }
    ATMOS_HD bool AnyAlbedo() const {
        bool any = false;
        for (int b = 0; b < w.channels / 3; ++b) any = any || w.BatchMaxAlbedo(b) > 0.0;
        return any;
    }

    ATMOS_HD void EvaluateWide(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                               bool want_ground, WideRayResult* out) const {
        const int n = w.channels;
        out->Reset(n);
        const AtmosphereSegment seg =
            ClipToAtmosphere(camera, dir, atm.bottom_radius, atm.top_radius);
        out->hits_ground = seg.hits_ground;
        if (!seg.inside) {
            if (want_ground && GroundAtCamera(seg) && AnyAlbedo()) {
                const double cos_sun = Dot(Normalize(camera), sun);
                if (cos_sun > 0.0) Ground(cos_sun, nullptr, out);
            }
            return;
        }
        const Vec3d p0 = camera + dir * seg.t_start;
        const double r = Length(p0);
        const double h = Clamp(r - atm.bottom_radius, 0.0, atm.top_radius - atm.bottom_radius);
        const double mu = ClampCosine(Dot(p0, dir) / r);
        const double mu_s = ClampCosine(Dot(p0, sun) / r);
        const double nu = ClampCosine(Dot(dir, sun));
        float s[kMaxWideChannels + kMaxWideChannels / 3];
        AplusWideInterpolate(scattering, AplusWideRowsOf(scattering, mapping, h, mu),
                             AplusWideSunSpan(scattering, mapping, mu_s), 0.0f, s);
        const double f_r =
            modified_rayleigh ? AplusModifiedRayleighPhase(nu) : AplusRayleighPhase(nu);
        const double f_m = AplusMiePhase(atm, nu);
        const float fr = static_cast<float>(f_r), fm = static_cast<float>(f_m);
        for (int b = 0; b < n / 3; ++b) {
            const float mie = s[n + b] * fm;
            for (int c = 3 * b; c < 3 * b + 3; ++c) out->sky[c] = Max(s[c] * fr + mie, 0.0f);
        }
        Transmittance(h, mu, out->transmittance);
        if (want_ground && seg.hits_ground && AnyAlbedo()) {
            const Vec3d g = camera + dir * seg.t_end;
            const double cos_sun = Dot(Normalize(g), sun);
            if (cos_sun > 0.0) Ground(cos_sun, out->transmittance, out);
        }
    }
};

}  // namespace atmos
