// atmos model `bruneton`: the wide evaluator (physics/wide.h, docs/models/bruneton.md
// "Wide channel batches").
//
// The tables hold the channels of every batch side by side (channel 3b + c of a
// texel is channel c of batch b's table); the lookups compute their
// coordinates, texel spans and weights once per query and interpolate every
// channel with them. Each function mirrors the BrunetonLut function of the
// same name (models/bruneton.h) for the evaluator's case (no light shafts,
// separate Mie storage), per channel in the same operations and order, so a
// channel equals the three-channel evaluator's bit for bit.
#pragma once

#include "models/bruneton.h"
#include "physics/wide.h"

namespace atmos {

// BrunetonSample4D of an n-channel table, every channel with the same rows
// and columns.
ATMOS_HD inline void BrunetonWideSample4D(const float* __restrict__ data, int n,
                                          const Bruneton4DRows& r, const Bruneton4DColumns& x,
                                          float* __restrict__ out) {
    const size_t nn = static_cast<size_t>(n);
    const float* a00 = data + (r.row[0] + x.xa.i0) * nn;
    const float* a01 = data + (r.row[0] + x.xa.i1) * nn;
    const float* a10 = data + (r.row[1] + x.xa.i0) * nn;
    const float* a11 = data + (r.row[1] + x.xa.i1) * nn;
    const float* a20 = data + (r.row[2] + x.xa.i0) * nn;
    const float* a21 = data + (r.row[2] + x.xa.i1) * nn;
    const float* a30 = data + (r.row[3] + x.xa.i0) * nn;
    const float* a31 = data + (r.row[3] + x.xa.i1) * nn;
    const float* b00 = data + (r.row[0] + x.xb.i0) * nn;
    const float* b01 = data + (r.row[0] + x.xb.i1) * nn;
    const float* b10 = data + (r.row[1] + x.xb.i0) * nn;
    const float* b11 = data + (r.row[1] + x.xb.i1) * nn;
    const float* b20 = data + (r.row[2] + x.xb.i0) * nn;
    const float* b21 = data + (r.row[2] + x.xb.i1) * nn;
    const float* b30 = data + (r.row[3] + x.xb.i0) * nn;
    const float* b31 = data + (r.row[3] + x.xb.i1) * nn;
    const float fa = x.xa.f, fb = x.xb.f, fy = r.fy, fz = r.fz, l = x.lerp;
    for (int c = 0; c < n; ++c) {
        // BilinearChannel: along x, then y.
        const float pa0 = (a00[c] * (1.0f - fa) + a01[c] * fa) * (1.0f - fy) +
                          (a10[c] * (1.0f - fa) + a11[c] * fa) * fy;
        const float pa1 = (a20[c] * (1.0f - fa) + a21[c] * fa) * (1.0f - fy) +
                          (a30[c] * (1.0f - fa) + a31[c] * fa) * fy;
        const float pb0 = (b00[c] * (1.0f - fb) + b01[c] * fb) * (1.0f - fy) +
                          (b10[c] * (1.0f - fb) + b11[c] * fb) * fy;
        const float pb1 = (b20[c] * (1.0f - fb) + b21[c] * fb) * (1.0f - fy) +
                          (b30[c] * (1.0f - fb) + b31[c] * fb) * fy;
        const float ta = pa0 * (1.0f - fz) + pa1 * fz;
        const float tb = pb0 * (1.0f - fz) + pb1 * fz;
        out[c] = ta * (1.0f - l) + tb * l;
    }
}

// The per-pixel evaluator of n = w.channels channels. lut.atm is batch 0's
// atmosphere (its common fields; the per-channel coefficients are w's) and its
// tables have n channels.
struct BrunetonWideEvaluator {
    BrunetonLut lut;
    WideCoefficients w;

    template <typename V>
    void VisitTables(V& v) {
        lut.VisitTables(v);
    }
    ATMOS_HD int Channels() const { return w.channels; }

    // TransmittanceToTop.
    ATMOS_HD void TransmittanceToTop(double r, double mu, float* out) const {
        double u, v;
        lut.TransmittanceUvFromRMu(lut.ClampRadius(r), ClampCosine(mu), &u, &v);
        WideSampleBilinear(lut.transmittance_table, u, v, out);
    }
    // Transmittance (with SafeRatio).
    ATMOS_HD void Transmittance(double r, double mu, double d, bool ray_r_mu_intersects_ground,
                                float* out) const {
        const double r_d = lut.ClampRadius(Sqrt(d * d + 2.0 * r * mu * d + r * r));
        const double mu_d = ClampCosine((r * mu + d) / r_d);
        float a[kMaxWideChannels], b[kMaxWideChannels];
        if (ray_r_mu_intersects_ground) {
            TransmittanceToTop(r_d, -mu_d, a);
            TransmittanceToTop(r, -mu, b);
        } else {
            TransmittanceToTop(r, mu, a);
            TransmittanceToTop(r_d, mu_d, b);
        }
        const int n = w.channels;
        for (int c = 0; c < n; ++c) {
            const float t = a[c] / b[c];
            out[c] = IsFinite(t) ? Clamp(t, 0.0f, 1.0f) : 0.0f;
        }
    }
    // TransmittanceToSun.
    ATMOS_HD void TransmittanceToSun(double r, double mu_s, float* out) const {
        TransmittanceToSunWith(lut.SunAboveHorizon(r, mu_s), r, mu_s, out);
    }
    // TransmittanceToSun with f = lut.SunAboveHorizon(r, mu_s).
    ATMOS_HD void TransmittanceToSunWith(double f, double r, double mu_s, float* out) const {
        const int n = w.channels;
        if (f <= 0.0) {
            for (int c = 0; c < n; ++c) out[c] = 0.0f;
            return;
        }
        TransmittanceToTop(r, mu_s, out);
        const float ff = static_cast<float>(f);
        for (int c = 0; c < n; ++c) out[c] = out[c] * ff;
    }
    // CombinedScattering, separate Mie storage.
    ATMOS_HD void CombinedScattering(double r, double mu, double mu_s, double nu,
                                     bool ray_r_mu_intersects_ground, float* scattering,
                                     float* single_mie) const {
        double uvwz[4];
        lut.ScatteringUvwz(lut.ClampRadius(r), ClampCosine(mu), ClampCosine(mu_s), ClampCosine(nu),
                           ray_r_mu_intersects_ground, uvwz);
        const TableView& t = lut.scattering_table;
        Bruneton4DRows rows;
        Bruneton4DColumns cols;
        lut.Split4D(t, uvwz, &rows, &cols);
        BrunetonWideSample4D(t.data, w.channels, rows, cols, scattering);
        BrunetonWideSample4D(lut.single_mie_table.data, w.channels, rows, cols, single_mie);
    }
    // SkyRadiance without light shafts.
    ATMOS_HD void SkyRadiance(Vec3d camera, const Vec3d& view_ray, const Vec3d& sun_direction,
                              bool ray_hits_ground, float* transmittance_out, float* out) const {
        const AtmosphereParameters& atm = lut.atm;
        const int n = w.channels;
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
                for (int c = 0; c < n; ++c) {
                    transmittance_out[c] = 1.0f;
                    out[c] = 0.0f;
                }
                return;
            }
        }
        r = lut.ClampRadius(r);
        const double mu = ClampCosine(rmu / r);
        const double mu_s = ClampCosine(Dot(camera, sun_direction) / r);
        const double nu = ClampCosine(Dot(view_ray, sun_direction));
        if (ray_hits_ground) {
            for (int c = 0; c < n; ++c) transmittance_out[c] = 0.0f;
        } else {
            TransmittanceToTop(r, mu, transmittance_out);
        }
        float scattering[kMaxWideChannels], single_mie[kMaxWideChannels];
        CombinedScattering(r, mu, mu_s, nu, ray_hits_ground, scattering, single_mie);
        const float pr = static_cast<float>(RayleighPhase(nu));
        const float pm = static_cast<float>(MiePhase(atm, nu));
        for (int c = 0; c < n; ++c) out[c] = scattering[c] * pr + single_mie[c] * pm;
    }
    // SegmentSingleMie: the constituents' optical depths once per sample, then
    // every channel's exponent, exponential (one vector loop) and sum.
    ATMOS_HD void SegmentSingleMie(double r, double mu, double mu_s, double nu, double d,
                                   float* out) const {
        const AtmosphereParameters& atm = lut.atm;
        const int n = w.channels;
        const int steps = lut.cfg.low_sun_mie_steps;
        const double dt = d / steps;
        double depth_r = 0.0, depth_m = 0.0, depth_o = 0.0;
        double sum[kMaxWideChannels];
        for (int c = 0; c < n; ++c) sum[c] = 0.0;
        float ts[kMaxWideChannels];
        float e[kMaxWideChannels];
        for (int i = 0; i < steps; ++i) {
            const double t = (i + 0.5) * dt;
            const double r_t = lut.ClampRadius(Sqrt(t * t + 2.0 * r * mu * t + r * r));
            const Densities rho = GetDensities(atm, r_t - atm.bottom_radius);
            const double mid_r = depth_r + rho.rayleigh * (0.5 * dt);
            const double mid_m = depth_m + rho.mie * (0.5 * dt);
            const double mid_o = depth_o + rho.absorption * (0.5 * dt);
            depth_r += rho.rayleigh * dt;
            depth_m += rho.mie * dt;
            depth_o += rho.absorption * dt;
            // In the planet's shadow: adds exactly 0, skipped (as BrunetonLut).
            const double mu_s_t = ClampCosine((r * mu_s + t * nu) / r_t);
            const double f = lut.SunAboveHorizon(r_t, mu_s_t);
            if (f <= 0.0) continue;
            TransmittanceToSunWith(f, r_t, mu_s_t, ts);
            const double m = rho.mie * dt;
            ATMOS_SIMD_WIDE
            for (int c = 0; c < n; ++c) {
                const double tau = w.rayleigh_scattering[c] * mid_r + w.mie_extinction[c] * mid_m +
                                   w.absorption_extinction[c] * mid_o;
                e[c] = ExpLaneF(static_cast<float>(-tau));
            }
            for (int c = 0; c < n; ++c) {
                sum[c] += static_cast<double>(ts[c]) * static_cast<double>(e[c]) * m;
            }
        }
        for (int c = 0; c < n; ++c) out[c] = static_cast<float>(sum[c] * w.mie_scattering[c]);
    }
    // SkyRadianceToPoint without light shafts, separate Mie storage.
    ATMOS_HD void SkyRadianceToPoint(Vec3d camera, const Vec3d& point, const Vec3d& sun_direction,
                                     bool ray_hits_ground, float* transmittance_out,
                                     float* out) const {
        const AtmosphereParameters& atm = lut.atm;
        const int n = w.channels;
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
        r = lut.ClampRadius(r);
        const double mu = ClampCosine(rmu / r);
        const double mu_s = ClampCosine(Dot(camera, sun_direction) / r);
        const double nu = ClampCosine(Dot(view_ray, sun_direction));
        double d = Length(point - camera);
        Transmittance(r, mu, d, ray_hits_ground, transmittance_out);
        float scattering[kMaxWideChannels], single_mie[kMaxWideChannels];
        CombinedScattering(r, mu, mu_s, nu, ray_hits_ground, scattering, single_mie);
        d = Max(d - 0.0, 0.0);
        const double r_p = lut.ClampRadius(Sqrt(d * d + 2.0 * r * mu * d + r * r));
        const double mu_p = (r * mu + d) / r_p;
        const double mu_s_p = (r * mu_s + d * nu) / r_p;
        float scattering_p[kMaxWideChannels], single_mie_p[kMaxWideChannels];
        CombinedScattering(r_p, mu_p, mu_s_p, nu, ray_hits_ground, scattering_p, single_mie_p);
        for (int c = 0; c < n; ++c) {
            scattering[c] = scattering[c] - transmittance_out[c] * scattering_p[c];
            single_mie[c] = single_mie[c] - transmittance_out[c] * single_mie_p[c];
        }
        const double fade = BrunetonLut::SmoothStep(0.0, 0.01, mu_s);
        if (lut.cfg.low_sun_mie != 2 && fade < 1.0) {
            const float f = static_cast<float>(fade);
            for (int c = 0; c < n; ++c) single_mie[c] = single_mie[c] * f;
            if (lut.cfg.low_sun_mie == 0) {
                float segment[kMaxWideChannels];
                SegmentSingleMie(r, mu, mu_s, nu, d, segment);
                const float g = static_cast<float>(1.0 - fade);
                for (int c = 0; c < n; ++c) single_mie[c] += segment[c] * g;
            }
        }
        const float pr = static_cast<float>(RayleighPhase(nu));
        const float pm = static_cast<float>(MiePhase(atm, nu));
        for (int c = 0; c < n; ++c) {
            out[c] = Max(scattering[c], 0.0f) * pr + Max(single_mie[c], 0.0f) * pm;
        }
    }
    // SunAndSkyIrradiance: writes the sun's to sun_out, the sky's to sky_out.
    ATMOS_HD void SunAndSkyIrradiance(const Vec3d& point, const Vec3d& normal,
                                      const Vec3d& sun_direction, float* sun_out,
                                      float* sky_out) const {
        const int n = w.channels;
        const double r = lut.ClampRadius(Length(point));
        const double mu_s = ClampCosine(Dot(point, sun_direction) / Length(point));
        double u, v;
        lut.IrradianceUvFromRMuS(lut.ClampRadius(r), ClampCosine(mu_s), &u, &v);
        WideSampleBilinear(lut.irradiance_table, u, v, sky_out);
        const float k = static_cast<float>((1.0 + Dot(normal, point) / Length(point)) * 0.5);
        for (int c = 0; c < n; ++c) sky_out[c] = sky_out[c] * k;
        TransmittanceToSun(r, mu_s, sun_out);
        const float s = static_cast<float>(Max(Dot(normal, sun_direction), 0.0));
        for (int c = 0; c < n; ++c) sun_out[c] = sun_out[c] * s;
    }

    // BrunetonEvaluator::Evaluate for every channel.
    ATMOS_HD void EvaluateWide(const Vec3d& camera, const Vec3d& dir, const Vec3d& sun,
                               bool want_ground, WideRayResult* out) const {
        const int n = w.channels;
        out->Reset(n);
        const AtmosphereParameters& atm = lut.atm;
        const AtmosphereSegment seg =
            ClipToAtmosphere(camera, dir, atm.bottom_radius, atm.top_radius);
        out->hits_ground = seg.hits_ground;
        if (!seg.inside && !seg.hits_ground) return;
        if (!seg.hits_ground) {
            SkyRadiance(camera, dir, sun, false, out->transmittance, out->sky);
            return;
        }
        const Vec3d ground = seg.inside ? camera + dir * seg.t_end : camera;
        if (seg.inside) SkyRadianceToPoint(camera, ground, sun, true, out->transmittance, out->sky);
        if (!want_ground) return;
        bool any = false;
        for (int b = 0; b < n / 3; ++b) any = any || w.BatchMaxAlbedo(b) > 0.0;
        if (!any) return;
        const Vec3d normal = Normalize(ground);
        float sun_irradiance[kMaxWideChannels], sky_irradiance[kMaxWideChannels];
        SunAndSkyIrradiance(ground, normal, sun, sun_irradiance, sky_irradiance);
        for (int b = 0; b < n / 3; ++b) {
            // A batch whose albedo is 0 has no ground term (the three-channel
            // evaluator's test), not 0 x its irradiance.
            if (!(w.BatchMaxAlbedo(b) > 0.0)) continue;
            for (int c = 3 * b; c < 3 * b + 3; ++c) {
                out->ground[c] = static_cast<float>(w.ground_albedo[c] * (1.0 / kPi)) *
                                 (sun_irradiance[c] + sky_irradiance[c]) * out->transmittance[c];
            }
        }
    }
};

}  // namespace atmos
