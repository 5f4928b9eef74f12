// atmos model `hillaire`: its precomputation stages (render/stages.h), the one
// per-item code of both backends (the CPU's ParallelFor and, in a CUDA build,
// src/atmos/cuda/hillaire_stages.cu).
//
// Source and equations: hillaire.h (Hillaire 2020 sections 5.2-5.5, Eq. 1-11;
// Bruneton's 2017 implementation notes for the transmittance mapping). Each stage is one loop body
// of the former CPU code, unchanged in arithmetic:
//  * HillaireTransmittanceStage: one transmittance texel (Bruneton's 2017 implementation notes
//    ComputeTransmittanceToTopAtmosphereBoundaryTexture, midpoint rule);
//  * HillaireMultipleScatteringStage: one Psi_ms texel (paper Eq. 5-10);
//  * HillaireSkyViewStage: one sky-view texel (paper section 5.3, Eq. 11);
//  * HillaireAerialPerspectiveStage: one froxel column, its 32 slices by one
//    cumulative march (paper section 5.4).
// Per-frame stages take the model's evaluator without frame tables (only the
// transmittance and multiple-scattering tables are read).
#pragma once

#include <cstdint>

#include "atmos/view.h"
#include "models/hillaire.h"
#include "render/stages.h"

namespace atmos {

ATMOS_HD inline Vec4f HillaireTexel(const Vec3d& v) {
    return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z), 0.0f};
}

// Transmittance table (256 x 64 RGB): Bruneton's 2017 implementation notes
// ComputeTransmittanceToTopAtmosphereBoundaryTexture, optical depth by the
// midpoint rule with `steps` segments. Item: one texel (x fastest).
struct HillaireTransmittanceStage {
    AtmosphereParameters atm;
    int steps = 40;
    TableOut out;

    template <typename V>
    void VisitTables(V& v) {
        v(out);
    }
    ATMOS_HD void operator()(int64_t item) const {
        const int i = static_cast<int>(item % kHillaireTransmittanceWidth);
        const int j = static_cast<int>(item / kHillaireTransmittanceWidth);
        double r, mu;
        HillaireTransmittanceRMu(atm, static_cast<double>(i) / (kHillaireTransmittanceWidth - 1),
                                 static_cast<double>(j) / (kHillaireTransmittanceHeight - 1), &r,
                                 &mu);
        const double d = DistanceToTopAtmosphereBoundary(r, mu, atm.top_radius);
        const Vec3d dir(SafeSqrt(1.0 - mu * mu), 0.0, mu);
        const double dt = d / steps;
        Vec3d tau;
        for (int k = 0; k < steps; ++k) {
            const Vec3d p(dir.x * (k + 0.5) * dt, 0.0, r + dir.z * (k + 0.5) * dt);
            tau += Extinction(atm, GetDensities(atm, Length(p) - atm.bottom_radius));
        }
        out.Set(i, j, 0, HillaireTexel(Exp(-(tau * dt))));
    }
};
ATMOS_DEVICE_STAGE(HillaireTransmittanceStage)

// Multiple-scattering table Psi_ms (32 x 32 RGB; paper section 5.5.2, Eq. 5-10,
// see hillaire.h). `e`: the evaluator with the transmittance table and
// use_multiple_scattering = false. Item: one texel (x = mu_s fastest).
struct HillaireMultipleScatteringStage {
    HillaireEvaluator e;
    TableOut out;
    TableOut transfer;  // optional (no data: not written): f_ms per texel, RGB

    template <typename V>
    void VisitTables(V& v) {
        e.VisitTables(v);
        v(out);
        v(transfer);
    }
    ATMOS_HD void operator()(int64_t index) const {
        const AtmosphereParameters& atm = e.atm;
        const double p_u = IsotropicPhase();
        constexpr int kDirs = kHillaireMsSqrtDirections * kHillaireMsSqrtDirections;
        const int i = static_cast<int>(index % kHillaireMsSize);  // mu_s
        const int j = static_cast<int>(index / kHillaireMsSize);  // altitude
        const double mu_s = -1.0 + 2.0 * i / (kHillaireMsSize - 1);
        const double r =
            atm.bottom_radius + (atm.top_radius - atm.bottom_radius) * j / (kHillaireMsSize - 1);
        const Vec3d x(0.0, 0.0, r);
        const Vec3d sun(SafeSqrt(1.0 - mu_s * mu_s), 0.0, mu_s);
        Vec3d l_2nd, f_ms;
        for (int k = 0; k < kDirs; ++k) {
            // Stratified uniform directions on the sphere (8 x 8 cells, centres).
            const double a = (k / kHillaireMsSqrtDirections + 0.5) / kHillaireMsSqrtDirections;
            const double b = (k % kHillaireMsSqrtDirections + 0.5) / kHillaireMsSqrtDirections;
            const double phi = 2.0 * kPi * a;
            const double cos_theta = 1.0 - 2.0 * b;
            const double sin_theta = SafeSqrt(1.0 - cos_theta * cos_theta);
            const Vec3d dir(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
            const AtmosphereSegment seg =
                ClipToAtmosphere(x, dir, atm.bottom_radius, atm.top_radius);
            Vec3d L, F, T(1.0);
            if (seg.inside) {
                const double dt = (seg.t_end - seg.t_start) / kHillaireMsSteps;
                for (int s = 0; s < kHillaireMsSteps; ++s) {
                    const Vec3d p = x + dir * (seg.t_start + (s + e.segment_offset) * dt);
                    const double rp = Length(p);
                    const Densities d = GetDensities(atm, rp - atm.bottom_radius);
                    const Vec3d sigma_s =
                        atm.rayleigh_scattering * d.rayleigh + atm.mie_scattering * d.mie;
                    const Vec3d sigma_t = Extinction(atm, d);
                    const Vec3d t_sun = e.SunTransmittance(rp, ClampCosine(Dot(p, sun) / rp));
                    const Vec3d S = sigma_s * t_sun * p_u;
                    const Vec3d step_t = ExpLane(-sigma_t * dt);  // as Integrate
                    for (int c = 0; c < 3; ++c) {
                        const double w = sigma_t[c] > 0.0 ? (1.0 - step_t[c]) / sigma_t[c] : dt;
                        L[c] += T[c] * S[c] * w;
                        F[c] += T[c] * sigma_s[c] * w;
                    }
                    T *= step_t;
                }
            }
            if (seg.hits_ground) L += T * e.GroundReflection(x + dir * seg.t_end, sun);
            l_2nd += L;
            f_ms += F;
        }
        // Uniform sampling of the sphere: int f p_u dw = mean of f.
        l_2nd = l_2nd / static_cast<double>(kDirs);
        f_ms = f_ms / static_cast<double>(kDirs);
        Vec3d psi;
        for (int c = 0; c < 3; ++c) psi[c] = l_2nd[c] / Max(1.0 - f_ms[c], 1e-6);
        out.Set(i, j, 0, HillaireTexel(psi));
        if (transfer.data) transfer.Set(i, j, 0, HillaireTexel(f_ms));
    }
};
ATMOS_DEVICE_STAGE(HillaireMultipleScatteringStage)

// Sky-view table (192 x 108 RGB; paper section 5.3) for a camera at radius
// `r` (already raised to kHillaireSkyViewMinAltitude) on the z axis and the sun
// `sun` in the x-z plane: each texel one ray march of `steps` segments,
// without ground reflection. Item: one texel (x fastest).
struct HillaireSkyViewStage {
    HillaireEvaluator e;
    double r = 0.0;
    Vec3d sun;
    int steps = 30;
    TableOut out;

    template <typename V>
    void VisitTables(V& v) {
        e.VisitTables(v);
        v(out);
    }
    ATMOS_HD void operator()(int64_t item) const {
        const int i = static_cast<int>(item % kHillaireSkyViewWidth);
        const int j = static_cast<int>(item / kHillaireSkyViewWidth);
        out.Set(i, j, 0, HillaireTexel(e.SkyViewTexel(r, sun, steps, i, j)));
    }
};
ATMOS_DEVICE_STAGE(HillaireSkyViewStage)

// Aerial-perspective volume (32 x 32 x 32 RGB in-scatter and transmittance;
// paper section 5.4): one cumulative march per froxel column through the
// slice centres, `steps_per_slice` segments per slice. The froxel's ray
// ignores the ground (points below it are taken at the ground): a ground ray's
// value is interpolated between froxel rays, and a neighbour that stopped at
// its own ground hit would bias it (hillaire.h). Item: one column (x fastest).
struct HillaireAerialPerspectiveStage {
    HillaireEvaluator e;
    Camera camera;
    Vec3d sun;
    double aspect = 1.0;
    double metres_per_slice = 4000.0;
    int steps_per_slice = 4;
    TableOut scatter, transmittance;

    template <typename V>
    void VisitTables(V& v) {
        e.VisitTables(v);
        v(scatter);
        v(transmittance);
    }
    ATMOS_HD void operator()(int64_t index) const {
        const AtmosphereParameters& atm = e.atm;
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
        Vec3d L, T(1.0);
        double t_prev = 0.0;
        for (int k = 0; k < kHillaireApSize; ++k) {
            const double t_k = HillaireApSliceDistance(k, metres_per_slice);
            if (crosses) {
                const double ta = Clamp(t_prev, t_in, t_out);
                const double tb = Clamp(t_k, t_in, t_out);
                e.Integrate(origin, dir, sun, ta, tb, steps_per_slice, &L, &T, true);
            }
            t_prev = t_k;
            scatter.Set(i, j, k, HillaireTexel(L));
            transmittance.Set(i, j, k, HillaireTexel(T));
        }
    }
};
ATMOS_DEVICE_STAGE(HillaireAerialPerspectiveStage)

}  // namespace atmos
