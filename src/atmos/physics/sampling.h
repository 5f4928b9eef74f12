// atmos: importance sampling of phase functions and surfaces (host and device).
//
// Each sampler returns the cosine of the angle between the sampled direction
// and the axis it is sampled around; MakeDirection builds the direction.
#pragma once

#include "atmos/atmosphere.h"
#include "atmos/math.h"
#include "physics/phase.h"

namespace atmos {

// Rayleigh phase 3/(16 pi)(1 + mu^2), sampled exactly: the CDF
// F(mu) = (mu^3 + 3 mu + 4) / 8 = xi is the depressed cubic mu^3 + 3 mu + (4 - 8 xi) = 0,
// solved by Cardano's formula: with u = 4 xi - 2, A = cbrt(u + sqrt(u^2 + 1)),
// mu = A - 1 / A (the two cube roots multiply to -1).
ATMOS_HD inline double SampleRayleighCosine(double xi) {
    const double u = 4.0 * xi - 2.0;
    const double a = cbrt(u + Sqrt(u * u + 1.0));
    return Clamp(a - 1.0 / a, -1.0, 1.0);
}

// Henyey-Greenstein (forward peak at mu = 1 for g > 0), inverse CDF (e.g.
// Pharr et al., PBRT 3rd ed., 15.2.3, with our sign convention).
ATMOS_HD inline double SampleHenyeyGreensteinCosine(double g, double xi) {
    if (Abs(g) < 1e-4) return 1.0 - 2.0 * xi;
    const double s = (1.0 - g * g) / (1.0 - g + 2.0 * g * xi);
    return Clamp((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0);
}

// Cornette-Shanks / Henyey-Greenstein with the same g: the weight of a
// Cornette-Shanks sample drawn from Henyey-Greenstein, 3 (1 + mu^2) / (2 (2 + g^2)),
// bounded by 3 / (2 + g^2) <= 1.5.
ATMOS_HD inline double CornetteShanksOverHenyeyGreenstein(double g, double mu) {
    return 1.5 * (1.0 + mu * mu) / (2.0 + g * g);
}

// A tabulated phase function (atmosphere.h MiePhaseTable) sampled exactly by
// its inverse CDF: the interval i with cdf[i] <= xi < cdf[i + 1] (binary
// search), then inside it the phase is linear in mu, so the mass between mu[i]
// and mu is a quadratic in t = mu[i] - mu,
//   2 pi scale (v_i t + (v_{i+1} - v_i) t^2 / (2 h)) = xi - cdf[i]   (h = mu[i] - mu[i+1]),
// solved as t = 2 c / (v_i + sqrt(v_i^2 + 4 k c)) with c = (xi - cdf[i]) / (2 pi scale) and
// k = (v_{i+1} - v_i) / (2 h) (the form without cancellation; v > 0 keeps the root real).
// The density of the result is TabulatedPhase itself.
ATMOS_HD inline double SampleTabulatedPhaseCosine(const MiePhaseTable& t, double xi) {
    const int lo = BisectInterval(t.count, [&](int i) { return t.cdf[i] <= xi; });
    const double h = t.mu[lo] - t.mu[lo + 1];
    const double v0 = t.value[lo];
    const double k = (t.value[lo + 1] - v0) / (2.0 * h);
    const double c = Max(xi - t.cdf[lo], 0.0) / (2.0 * kPi * t.scale);
    const double disc = Max(v0 * v0 + 4.0 * k * c, 0.0);
    const double step = Clamp(2.0 * c / (v0 + Sqrt(disc)), 0.0, h);
    return Clamp(t.mu[lo] - step, -1.0, 1.0);
}

// The Mie phase (physics/phase.h MiePhase) sampled. Cornette-Shanks lobes: by
// the mixture of the lobes' Henyey-Greenstein functions: lobe 2 with
// probability w (then HG(g2)), else lobe 1 (HG(g)); one uniform number,
// rescaled after the choice, so that w = 0 draws exactly as HG(g) alone.
// Henyey-Greenstein lobes: the same mixture, which is then the phase itself;
// isotropic: mu = 1 - 2 xi; tabulated: SampleTabulatedPhaseCosine. So every
// kind but Cornette-Shanks is sampled exactly (weight 1).
ATMOS_HD inline double SampleMiePhaseCosine(const AtmosphereParameters& atm, double xi) {
    switch (atm.mie_phase_kind) {
        case MiePhaseKind::kIsotropic:
            return 1.0 - 2.0 * xi;
        case MiePhaseKind::kTabulated:
            return SampleTabulatedPhaseCosine(atm.mie_phase_table, xi);
        default:
            break;
    }
    const double w = atm.mie_phase_weight2;
    if (w == 0.0) return SampleHenyeyGreensteinCosine(atm.mie_phase_g, xi);
    if (xi < w) return SampleHenyeyGreensteinCosine(atm.mie_phase_g2, xi / w);
    return SampleHenyeyGreensteinCosine(atm.mie_phase_g, (xi - w) / (1.0 - w));
}

// The density of SampleMiePhaseCosine's directions (per steradian): for
// Cornette-Shanks (1 - w) HG(g, mu) + w HG(g2, mu) (one-sample MIS over the
// lobes, balance heuristic); for the other kinds the phase function itself.
ATMOS_HD inline double MiePhaseSamplingPdf(const AtmosphereParameters& atm, double mu) {
    if (atm.mie_phase_kind != MiePhaseKind::kCornetteShanks) return MiePhase(atm, mu);
    const double w = atm.mie_phase_weight2;
    const double p = HenyeyGreensteinPhase(atm.mie_phase_g, mu);
    if (w == 0.0) return p;
    return (1.0 - w) * p + w * HenyeyGreensteinPhase(atm.mie_phase_g2, mu);
}

// The weight MiePhase / MiePhaseSamplingPdf of a SampleMiePhaseCosine sample:
// with one Cornette-Shanks lobe CornetteShanksOverHenyeyGreenstein; with two a
// ratio of mixtures with the same weights, so at most the larger lobe ratio
// (<= 1.5); 1 for the kinds sampled exactly.
ATMOS_HD inline double MiePhaseOverSamplingPdf(const AtmosphereParameters& atm, double mu) {
    if (atm.mie_phase_kind != MiePhaseKind::kCornetteShanks) return 1.0;
    if (atm.mie_phase_weight2 == 0.0) {
        return CornetteShanksOverHenyeyGreenstein(atm.mie_phase_g, mu);
    }
    return MiePhase(atm, mu) / MiePhaseSamplingPdf(atm, mu);
}

// An orthonormal basis around unit n (Duff et al. 2017, "Building an
// orthonormal basis, revisited").
ATMOS_HD inline void OrthonormalBasis(const Vec3d& n, Vec3d* t, Vec3d* b) {
    const double sign = n.z >= 0.0 ? 1.0 : -1.0;
    const double a = -1.0 / (sign + n.z);
    const double c = n.x * n.y * a;
    *t = Vec3d(1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x);
    *b = Vec3d(c, sign + n.y * n.y * a, -n.y);
}

// The unit direction at angle acos(mu) from axis n, azimuth 2 pi xi.
ATMOS_HD inline Vec3d MakeDirection(const Vec3d& n, double mu, double xi) {
    Vec3d t, b;
    OrthonormalBasis(n, &t, &b);
    const double s = SafeSqrt(1.0 - mu * mu);
    const double phi = 2.0 * kPi * xi;
    return Normalize(t * (s * cos(phi)) + b * (s * sin(phi)) + n * mu);
}

// Cosine-weighted hemisphere around n: mu = sqrt(xi) (pdf mu / pi).
ATMOS_HD inline double SampleCosineHemisphereCosine(double xi) { return Sqrt(xi); }

}  // namespace atmos
