// atmos model `hillaire`: wide channel batches (physics/wide.h; docs/models/hillaire.md
// "Wide channel batches").
//
// One model for up to kMaxWideChannels channels (16 batches of three): its
// tables (transmittance, multiple scattering, and per frame sky-view and
// aerial perspective) hold every channel of every batch side by side (channel
// 3b + c of a texel is channel c of batch b's table, a texel's channels
// contiguous). Each march step, lookup and texel computes its geometry once
// (positions, radii, densities, sun cosines, table coordinates, texel spans,
// phase functions, the sphere's directions) and then runs the channels in
// loops over fixed-size arrays.
//
// Every function mirrors the HillaireEvaluator or stage function of the same
// name (models/hillaire.h, models/hillaire_stages.h) channel by channel, in the
// same operations and order (Vec3d arithmetic is per component): a wide
// channel equals the three-channel model's bit for bit
// (tests/wide_channels_test.cpp). The march steps' exponentials are ExpLane
// (physics/vector_exp.h) in both: one vector loop over the channels here.
#pragma once

#include <cstdint>

#include "models/hillaire.h"
#include "physics/wide.h"

namespace atmos {

// SampleTrilinearFixed<3> (base/texture.h) of an n-channel 3D table at the
// spans of its three axes, every channel with the same spans.
ATMOS_HD inline void HillaireWideTrilinear(const float* __restrict__ data, int n, int width,
                                           int height, const TexelSpan& x, const TexelSpan& y,
                                           const TexelSpan& z, float* __restrict__ out) {
    const size_t w = static_cast<size_t>(width), h = static_cast<size_t>(height);
    const size_t r00 = (z.i0 * h + y.i0) * w, r01 = (z.i0 * h + y.i1) * w;
    const size_t r10 = (z.i1 * h + y.i0) * w, r11 = (z.i1 * h + y.i1) * w;
    float a[kMaxWideChannels], b[kMaxWideChannels];
    WideBilinear(data, n, r00, r01, x, y.f, a);
    WideBilinear(data, n, r10, r11, x, y.f, b);
    for (int c = 0; c < n; ++c) out[c] = a[c] * (1.0f - z.f) + b[c] * z.f;
}

// The wide evaluator: `narrow` holds batch 0's atmosphere (the batches' common
// fields: radii, profiles, phase), the options and the frame geometry; its
// TableViews are the n-channel tables. The per-channel coefficients are w's.
struct HillaireWideEvaluator {
    HillaireEvaluator narrow;
    WideCoefficients w;

    template <typename V>
    void VisitTables(V& v) {
        narrow.VisitTables(v);
    }
    ATMOS_HD int Channels() const { return w.channels; }
    // Whether any batch has a lit ground (MaxComponent(atm.ground_albedo) > 0).
    ATMOS_HD bool AnyAlbedo() const {
        bool any = false;
        for (int b = 0; b < w.channels / 3; ++b) any = any || w.BatchMaxAlbedo(b) > 0.0;
        return any;
    }

    // HillaireEvaluator::Transmittance.
    ATMOS_HD void Transmittance(double r, double mu, double* out) const {
        double u, v;
        HillaireTransmittanceUv(narrow.atm, r, mu, &u, &v);
        float f[kMaxWideChannels];
        WideSampleBilinear(narrow.transmittance, u, v, f);
        const int n = w.channels;
        for (int c = 0; c < n; ++c) out[c] = static_cast<double>(f[c]);
    }

    // HillaireEvaluator::TransmittanceToGround.
    ATMOS_HD void TransmittanceToGround(double r, double mu, double d, double* out) const {
        const AtmosphereParameters& atm = narrow.atm;
        const double r_d =
            Clamp(Sqrt(d * d + 2.0 * r * mu * d + r * r), atm.bottom_radius, atm.top_radius);
        const double mu_d = ClampCosine((r * mu + d) / r_d);
        double a[kMaxWideChannels], b[kMaxWideChannels];
        Transmittance(r_d, -mu_d, a);
        Transmittance(r, -mu, b);
        const int n = w.channels;
        for (int c = 0; c < n; ++c) out[c] = b[c] > 0.0 ? Min(a[c] / b[c], 1.0) : 0.0;
    }

    // HillaireEvaluator::SunTransmittance, as floats (the table's values).
    ATMOS_HD void SunTransmittance(double r, double mu_s, float* out) const {
        const int n = w.channels;
        if (RayIntersectsGround(r, ClampCosine(mu_s), narrow.atm.bottom_radius)) {
            for (int c = 0; c < n; ++c) out[c] = 0.0f;
            return;
        }
        double u, v;
        HillaireTransmittanceUv(narrow.atm, r, mu_s, &u, &v);
        WideSampleBilinear(narrow.transmittance, u, v, out);
    }

    // HillaireEvaluator::MultipleScattering, as floats.
    ATMOS_HD void MultipleScattering(double r, double mu_s, float* out) const {
        const int n = w.channels;
        if (!narrow.use_multiple_scattering) {
            for (int c = 0; c < n; ++c) out[c] = 0.0f;
            return;
        }
        double u, v;
        HillaireMsUv(narrow.atm, r, mu_s, &u, &v);
        WideSampleBilinear(narrow.multiple_scattering, u, v, out);
    }

    // HillaireEvaluator::Integrate: adds to L[c], multiplies T[c].
    ATMOS_HD void Integrate(const Vec3d& origin, const Vec3d& dir, const Vec3d& sun, double ta,
                            double tb, int steps, double* __restrict__ L, double* __restrict__ T,
                            bool through_ground = false) const {
        if (!(tb > ta) || steps < 1) return;
        const AtmosphereParameters& atm = narrow.atm;
        const int n = w.channels;
        const double nu = Dot(dir, sun);
        const double phase_r = RayleighPhase(nu);
        const double phase_m = MiePhase(atm, nu);
        const double dt = (tb - ta) / steps;
        for (int i = 0; i < steps; ++i) {
            Vec3d p = origin + dir * (ta + (i + narrow.segment_offset) * dt);
            double r = Length(p);
            if (through_ground && r < atm.bottom_radius) {
                p = p * (atm.bottom_radius / r);
                r = atm.bottom_radius;
            }
            const double mu_s = ClampCosine(Dot(p, sun) / r);
            const Densities d = GetDensities(atm, r - atm.bottom_radius);
            float t_sun[kMaxWideChannels], psi[kMaxWideChannels];
            SunTransmittance(r, mu_s, t_sun);
            MultipleScattering(r, mu_s, psi);
            double S[kMaxWideChannels], sigma_t[kMaxWideChannels], step_t[kMaxWideChannels];
            for (int c = 0; c < n; ++c) {
                const double sigma_r = w.rayleigh_scattering[c] * d.rayleigh;
                const double sigma_m = w.mie_scattering[c] * d.mie;
                sigma_t[c] = w.rayleigh_scattering[c] * d.rayleigh + w.mie_extinction[c] * d.mie +
                             w.absorption_extinction[c] * d.absorption;
                S[c] = static_cast<double>(t_sun[c]) * (sigma_r * phase_r + sigma_m * phase_m) +
                       (sigma_r + sigma_m) * static_cast<double>(psi[c]);
                step_t[c] = -sigma_t[c] * dt;
            }
            ATMOS_SIMD
            for (int c = 0; c < n; ++c) step_t[c] = ExpLane(step_t[c]);
            for (int c = 0; c < n; ++c) {
                const double s_int =
                    sigma_t[c] > 0.0 ? (S[c] - S[c] * step_t[c]) / sigma_t[c] : S[c] * dt;
                L[c] += T[c] * s_int;
                T[c] *= step_t[c];
            }
        }
    }

    // HillaireEvaluator::GroundReflection.
    ATMOS_HD void GroundReflection(const Vec3d& g, const Vec3d& sun, double* out) const {
        const int n = w.channels;
        const Vec3d normal = Normalize(g);
        const double cos_sun = Dot(normal, sun);
        if (cos_sun <= 0.0) {
            for (int c = 0; c < n; ++c) out[c] = 0.0;
            return;
        }
        double t[kMaxWideChannels];
        Transmittance(narrow.atm.bottom_radius, cos_sun, t);
        for (int c = 0; c < n; ++c) out[c] = w.ground_albedo[c] * (cos_sun / kPi) * t[c];
    }

    // HillaireEvaluator::SkyViewTexel.
    ATMOS_HD void SkyViewTexel(double r, const Vec3d& sun, int march_steps, int i, int j,
                               double* L) const {
        const AtmosphereParameters& atm = narrow.atm;
        const int n = w.channels;
        const Vec3d camera(0.0, 0.0, r);
        double mu_v, cos_az;
        HillaireSkyViewParams(
            r, atm.bottom_radius, static_cast<double>(i) / (kHillaireSkyViewWidth - 1),
            static_cast<double>(j) / (kHillaireSkyViewHeight - 1), &mu_v, &cos_az);
        const double sin_v = SafeSqrt(1.0 - mu_v * mu_v);
        const Vec3d dir(sin_v * cos_az, sin_v * SafeSqrt(1.0 - cos_az * cos_az), mu_v);
        const AtmosphereSegment seg =
            ClipToAtmosphere(camera, dir, atm.bottom_radius, atm.top_radius);
        double T[kMaxWideChannels];
        for (int c = 0; c < n; ++c) {
            L[c] = 0.0;
            T[c] = 1.0;
        }
        if (seg.inside) Integrate(camera, dir, sun, seg.t_start, seg.t_end, march_steps, L, T);
    }

    // HillaireEvaluator::SkyView.
    ATMOS_HD void SkyView(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                          double* out) const {
        const AtmosphereParameters& atm = narrow.atm;
        const int n = w.channels;
        const double r = Length(camera);
        const Vec3d up = camera / r;
        const double mu_v = ClampCosine(Dot(dir, up));
        const Vec3d dir_h = dir - up * Dot(dir, up);
        const Vec3d sun_h = sun - up * Dot(sun, up);
        const double lh = Length(dir_h) * Length(sun_h);
        const double cos_az = lh > 1e-12 ? ClampCosine(Dot(dir_h, sun_h) / lh) : 1.0;
        double u, v;
        HillaireSkyViewUv(r, atm.bottom_radius, mu_v, cos_az, &u, &v);
        float o[kMaxWideChannels];
        if (narrow.sky_view.data != nullptr) {
            WideSampleBilinear(narrow.sky_view, u, v, o);
            for (int c = 0; c < n; ++c) out[c] = static_cast<double>(o[c]);
            return;
        }
        // The four texels of this lookup for this camera and sun (a 2 x 2
        // table of n channels), then the same bilinear blend.
        const TexelSpan sx = SplitSpan(u, kHillaireSkyViewWidth);
        const TexelSpan sy = SplitSpan(v, kHillaireSkyViewHeight);
        const double mu_s = ClampCosine(Dot(sun, camera) / r);
        const Vec3d sun_xz(SafeSqrt(1.0 - mu_s * mu_s), 0.0, mu_s);
        const double r_table = Max(r, atm.bottom_radius + kHillaireSkyViewMinAltitude);
        float texels[2 * 2 * kMaxWideChannels];
        for (int row = 0; row < 2; ++row) {
            for (int col = 0; col < 2; ++col) {
                const int i = col == 0 ? sx.i0 : sx.i1, j = row == 0 ? sy.i0 : sy.i1;
                float* t = texels + (row * 2 + col) * n;
                if ((col == 1 && sx.i1 == sx.i0) || (row == 1 && sy.i1 == sy.i0)) {
                    for (int c = 0; c < n; ++c) t[c] = 0.0f;  // not read
                    continue;
                }
                double L[kMaxWideChannels];
                SkyViewTexel(r_table, sun_xz, narrow.per_query_sky_view_steps, i, j, L);
                for (int c = 0; c < n; ++c) t[c] = static_cast<float>(L[c]);
            }
        }
        TexelSpan x2 = sx;
        x2.i0 = 0;
        x2.i1 = sx.i1 == sx.i0 ? 0 : 1;
        const size_t row1 = sy.i1 == sy.i0 ? 0 : 2;
        WideBilinear(texels, n, 0, row1, x2, sy.f, o);
        for (int c = 0; c < n; ++c) out[c] = static_cast<double>(o[c]);
    }

    // HillaireEvaluator::AerialPerspective.
    ATMOS_HD bool AerialPerspective(const Vec3d& dir, double d, double* scatter,
                                    double* trans) const {
        const HillaireEvaluator& e = narrow;
        if (e.ap_scatter.data == nullptr) return false;
        const double a = Dot(dir, e.ap_camera.forward);
        if (a <= 0.0) return false;
        const double tan_y = e.ap_camera.tan_half_fov_y;
        const double u = 0.5 * (Dot(dir, e.ap_camera.right) / (a * tan_y * e.ap_aspect) + 1.0);
        const double v = 0.5 * (1.0 - Dot(dir, e.ap_camera.up) / (a * tan_y));
        const double d_last = HillaireApSliceDistance(kHillaireApSize - 1, e.ap_metres_per_slice);
        if (d > d_last) return false;
        const double d_first = HillaireApSliceDistance(0, e.ap_metres_per_slice);
        const double dd = Max(d, d_first);
        const double wz = Sqrt(dd / (kHillaireApSize * e.ap_metres_per_slice));
        const TexelSpan sx = SplitSpan(u, e.ap_scatter.width);
        const TexelSpan sy = SplitSpan(v, e.ap_scatter.height);
        const TexelSpan sz = SplitSpan(wz, e.ap_scatter.depth);
        const int n = w.channels;
        float fs[kMaxWideChannels], ft[kMaxWideChannels];
        HillaireWideTrilinear(e.ap_scatter.data, n, e.ap_scatter.width, e.ap_scatter.height, sx, sy,
                              sz, fs);
        HillaireWideTrilinear(e.ap_transmittance.data, n, e.ap_scatter.width, e.ap_scatter.height,
                              sx, sy, sz, ft);
        if (d < d_first) {
            const double f = d / d_first;
            for (int c = 0; c < n; ++c) {
                scatter[c] = static_cast<double>(fs[c]) * f;
                trans[c] = 1.0 - (1.0 - static_cast<double>(ft[c])) * f;
            }
        } else {
            for (int c = 0; c < n; ++c) {
                scatter[c] = static_cast<double>(fs[c]);
                trans[c] = static_cast<double>(ft[c]);
            }
        }
        return true;
    }

    // HillaireEvaluator::Evaluate for every channel.
    ATMOS_HD void EvaluateWide(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                               bool want_ground, WideRayResult* out) const {
        const AtmosphereParameters& atm = narrow.atm;
        const int n = w.channels;
        out->Reset(n);
        const AtmosphereSegment seg =
            ClipToAtmosphere(camera, dir, atm.bottom_radius, atm.top_radius);
        out->hits_ground = seg.hits_ground;
        double g[kMaxWideChannels];
        if (!seg.inside) {
            // A camera on the ground looking down (physics/ray.h): the ground at the camera.
            if (want_ground && GroundAtCamera(seg) && AnyAlbedo()) {
                GroundReflection(camera, sun, g);
                StoreGround(g, nullptr, out);
            }
            return;
        }
        const double r = Length(camera);
        double L[kMaxWideChannels], T[kMaxWideChannels];
        for (int c = 0; c < n; ++c) {
            L[c] = 0.0;
            T[c] = 1.0;
        }
        if ((narrow.sky_view.data != nullptr || narrow.per_query_sky_view_steps > 0) &&
            r <= atm.top_radius) {
            const double mu = ClampCosine(Dot(dir, camera) / r);
            if (!seg.hits_ground) {
                SkyView(camera, dir, sun, L);
                Transmittance(r, mu, T);
            } else {
                double wt = 1.0;
                if (narrow.ground_from_ap && AerialPerspective(dir, seg.t_end, L, T)) {
                    const double d0 =
                        HillaireApSliceDistance(kHillaireApBlendSlice, narrow.ap_metres_per_slice);
                    const double d1 =
                        HillaireApSliceDistance(kHillaireApSize - 1, narrow.ap_metres_per_slice);
                    wt = Clamp((seg.t_end - d0) / (d1 - d0), 0.0, 1.0);
                }
                if (wt > 0.0) {
                    double Ls[kMaxWideChannels], Ts[kMaxWideChannels];
                    SkyView(camera, dir, sun, Ls);
                    TransmittanceToGround(r, mu, seg.t_end, Ts);
                    for (int c = 0; c < n; ++c) {
                        L[c] = L[c] * (1.0 - wt) + Ls[c] * wt;
                        T[c] = T[c] * (1.0 - wt) + Ts[c] * wt;
                    }
                }
            }
        } else {
            Integrate(camera, dir, sun, seg.t_start, seg.t_end, narrow.steps, L, T);
        }
        for (int c = 0; c < n; ++c) {
            out->sky[c] = static_cast<float>(L[c]);
            out->transmittance[c] = static_cast<float>(T[c]);
        }
        if (want_ground && seg.hits_ground && AnyAlbedo()) {
            GroundReflection(camera + dir * seg.t_end, sun, g);
            StoreGround(g, T, out);
        }
    }

    // out->ground of the batches with a lit ground: g (times t when given).
    ATMOS_HD void StoreGround(const double* g, const double* t, WideRayResult* out) const {
        for (int b = 0; b < w.channels / 3; ++b) {
            if (!(w.BatchMaxAlbedo(b) > 0.0)) continue;
            for (int c = 3 * b; c < 3 * b + 3; ++c) {
                out->ground[c] = static_cast<float>(t ? g[c] * t[c] : g[c]);
            }
        }
    }
};

// ---- The precomputation and per-frame tables, n channels -------------------
// The stages of hillaire_stages.h, per item the same arithmetic per channel.
// They run on the CPU (ParallelFor), as the wide path does.

// HillaireTransmittanceStage: `out` is 256 x 64 x n.
struct HillaireWideTransmittanceStage {
    AtmosphereParameters atm;  // the common fields (batch 0)
    WideCoefficients w;
    int steps = 40;
    float* out = nullptr;

    ATMOS_HD void operator()(int64_t item) const {
        const int n = w.channels;
        const int i = static_cast<int>(item % kHillaireTransmittanceWidth);
        const int j = static_cast<int>(item / kHillaireTransmittanceWidth);
        double r, mu;
        HillaireTransmittanceRMu(atm, static_cast<double>(i) / (kHillaireTransmittanceWidth - 1),
                                 static_cast<double>(j) / (kHillaireTransmittanceHeight - 1), &r,
                                 &mu);
        const double d = DistanceToTopAtmosphereBoundary(r, mu, atm.top_radius);
        const Vec3d dir(SafeSqrt(1.0 - mu * mu), 0.0, mu);
        const double dt = d / steps;
        double tau[kMaxWideChannels];
        for (int c = 0; c < n; ++c) tau[c] = 0.0;
        for (int k = 0; k < steps; ++k) {
            const Vec3d p(dir.x * (k + 0.5) * dt, 0.0, r + dir.z * (k + 0.5) * dt);
            const Densities rho = GetDensities(atm, Length(p) - atm.bottom_radius);
            for (int c = 0; c < n; ++c) {
                tau[c] += w.rayleigh_scattering[c] * rho.rayleigh + w.mie_extinction[c] * rho.mie +
                          w.absorption_extinction[c] * rho.absorption;
            }
        }
        float* texel = out + static_cast<size_t>(item) * n;
        for (int c = 0; c < n; ++c) texel[c] = static_cast<float>(Exp(-(tau[c] * dt)));
    }
};

// HillaireMultipleScatteringStage: `e` reads the wide transmittance table
// (use_multiple_scattering false); `out` (Psi_ms) and `transfer` (f_ms, may be
// null) are 32 x 32 x n.
struct HillaireWideMultipleScatteringStage {
    HillaireWideEvaluator e;
    float* out = nullptr;
    float* transfer = nullptr;

    ATMOS_HD void operator()(int64_t index) const {
        const AtmosphereParameters& atm = e.narrow.atm;
        const WideCoefficients& w = e.w;
        const int n = w.channels;
        const double p_u = IsotropicPhase();
        constexpr int kDirs = kHillaireMsSqrtDirections * kHillaireMsSqrtDirections;
        const int i = static_cast<int>(index % kHillaireMsSize);  // mu_s
        const int j = static_cast<int>(index / kHillaireMsSize);  // altitude
        const double mu_s = -1.0 + 2.0 * i / (kHillaireMsSize - 1);
        const double r =
            atm.bottom_radius + (atm.top_radius - atm.bottom_radius) * j / (kHillaireMsSize - 1);
        const Vec3d x(0.0, 0.0, r);
        const Vec3d sun(SafeSqrt(1.0 - mu_s * mu_s), 0.0, mu_s);
        double l_2nd[kMaxWideChannels], f_ms[kMaxWideChannels];
        for (int c = 0; c < n; ++c) l_2nd[c] = f_ms[c] = 0.0;
        for (int k = 0; k < kDirs; ++k) {
            const double a = (k / kHillaireMsSqrtDirections + 0.5) / kHillaireMsSqrtDirections;
            const double b = (k % kHillaireMsSqrtDirections + 0.5) / kHillaireMsSqrtDirections;
            const double phi = 2.0 * kPi * a;
            const double cos_theta = 1.0 - 2.0 * b;
            const double sin_theta = SafeSqrt(1.0 - cos_theta * cos_theta);
            const Vec3d dir(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
            const AtmosphereSegment seg =
                ClipToAtmosphere(x, dir, atm.bottom_radius, atm.top_radius);
            double L[kMaxWideChannels], F[kMaxWideChannels], T[kMaxWideChannels];
            for (int c = 0; c < n; ++c) {
                L[c] = F[c] = 0.0;
                T[c] = 1.0;
            }
            if (seg.inside) {
                const double dt = (seg.t_end - seg.t_start) / kHillaireMsSteps;
                for (int s = 0; s < kHillaireMsSteps; ++s) {
                    const Vec3d p = x + dir * (seg.t_start + (s + e.narrow.segment_offset) * dt);
                    const double rp = Length(p);
                    const Densities d = GetDensities(atm, rp - atm.bottom_radius);
                    float t_sun[kMaxWideChannels];
                    e.SunTransmittance(rp, ClampCosine(Dot(p, sun) / rp), t_sun);
                    double sigma_s[kMaxWideChannels], sigma_t[kMaxWideChannels],
                        step_t[kMaxWideChannels];
                    for (int c = 0; c < n; ++c) {
                        sigma_s[c] =
                            w.rayleigh_scattering[c] * d.rayleigh + w.mie_scattering[c] * d.mie;
                        sigma_t[c] = w.rayleigh_scattering[c] * d.rayleigh +
                                     w.mie_extinction[c] * d.mie +
                                     w.absorption_extinction[c] * d.absorption;
                        step_t[c] = -sigma_t[c] * dt;
                    }
                    ATMOS_SIMD
                    for (int c = 0; c < n; ++c) step_t[c] = ExpLane(step_t[c]);
                    for (int c = 0; c < n; ++c) {
                        const double S = sigma_s[c] * static_cast<double>(t_sun[c]) * p_u;
                        const double wt = sigma_t[c] > 0.0 ? (1.0 - step_t[c]) / sigma_t[c] : dt;
                        L[c] += T[c] * S * wt;
                        F[c] += T[c] * sigma_s[c] * wt;
                        T[c] *= step_t[c];
                    }
                }
            }
            if (seg.hits_ground) {
                double g[kMaxWideChannels];
                e.GroundReflection(x + dir * seg.t_end, sun, g);
                for (int c = 0; c < n; ++c) L[c] += T[c] * g[c];
            }
            for (int c = 0; c < n; ++c) {
                l_2nd[c] += L[c];
                f_ms[c] += F[c];
            }
        }
        float* texel = out + static_cast<size_t>(index) * n;
        for (int c = 0; c < n; ++c) {
            const double l = l_2nd[c] / static_cast<double>(kDirs);
            const double f = f_ms[c] / static_cast<double>(kDirs);
            texel[c] = static_cast<float>(l / Max(1.0 - f, 1e-6));
            if (transfer) transfer[static_cast<size_t>(index) * n + c] = static_cast<float>(f);
        }
    }
};

// HillaireSkyViewStage: `out` is 192 x 108 x n; `e` without frame tables.
struct HillaireWideSkyViewStage {
    HillaireWideEvaluator e;
    double r = 0.0;
    Vec3d sun;
    int steps = 30;
    float* out = nullptr;

    ATMOS_HD void operator()(int64_t item) const {
        const int n = e.w.channels;
        const int i = static_cast<int>(item % kHillaireSkyViewWidth);
        const int j = static_cast<int>(item / kHillaireSkyViewWidth);
        double L[kMaxWideChannels];
        e.SkyViewTexel(r, sun, steps, i, j, L);
        float* texel = out + static_cast<size_t>(item) * n;
        for (int c = 0; c < n; ++c) texel[c] = static_cast<float>(L[c]);
    }
};

// HillaireAerialPerspectiveStage: `scatter` and `transmittance` are
// 32 x 32 x 32 x n; item: one froxel column.
struct HillaireWideAerialPerspectiveStage {
    HillaireWideEvaluator e;
    Camera camera;
    Vec3d sun;
    double aspect = 1.0;
    double metres_per_slice = 4000.0;
    int steps_per_slice = 4;
    float* scatter = nullptr;
    float* transmittance = nullptr;

    ATMOS_HD void operator()(int64_t index) const {
        const AtmosphereParameters& atm = e.narrow.atm;
        const int n = e.w.channels;
        const Vec3d origin = camera.position;
        const int i = static_cast<int>(index % kHillaireApSize);
        const int j = static_cast<int>(index / kHillaireApSize);
        const double u = (i + 0.5) / kHillaireApSize;
        const double v = (j + 0.5) / kHillaireApSize;
        const double tan_y = camera.tan_half_fov_y;
        const Vec3d dir =
            Normalize(camera.forward + camera.right * ((2.0 * u - 1.0) * tan_y * aspect) +
                      camera.up * ((1.0 - 2.0 * v) * tan_y));
        double t_in = 0.0, t_out = 0.0;
        const bool crosses =
            IntersectSphere(origin, dir, atm.top_radius, &t_in, &t_out) && t_out > 0.0;
        t_in = Max(t_in, 0.0);
        double L[kMaxWideChannels], T[kMaxWideChannels];
        for (int c = 0; c < n; ++c) {
            L[c] = 0.0;
            T[c] = 1.0;
        }
        double t_prev = 0.0;
        for (int k = 0; k < kHillaireApSize; ++k) {
            const double t_k = HillaireApSliceDistance(k, metres_per_slice);
            if (crosses) {
                const double ta = Clamp(t_prev, t_in, t_out);
                const double tb = Clamp(t_k, t_in, t_out);
                e.Integrate(origin, dir, sun, ta, tb, steps_per_slice, L, T, true);
            }
            t_prev = t_k;
            const size_t texel =
                ((static_cast<size_t>(k) * kHillaireApSize + j) * kHillaireApSize + i) * n;
            for (int c = 0; c < n; ++c) {
                scatter[texel + c] = static_cast<float>(L[c]);
                transmittance[texel + c] = static_cast<float>(T[c]);
            }
        }
    }
};

}  // namespace atmos
