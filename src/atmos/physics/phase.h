// atmos: phase functions, normalised to integrate to 1 over the sphere (1/sr).
//
// nu is the cosine of the scattering angle: the angle between the direction the
// light travels before and after scattering, i.e. nu = dot(view, sun) for a view
// direction pointing away from the camera and a direction pointing to the sun
// (Bruneton's 2017 implementation notes convention). Sources:
//   Rayleigh:         3/(16 pi) (1 + nu^2)                     Bruneton's 2017 implementation notes
//   RayleighPhaseFunction Cornette-Shanks:  3/(8 pi) (1-g^2)(1+nu^2) / ((2+g^2)(1+g^2-2 g nu)^1.5)
//                                                               Leenman's 2025 thesis Eq. 5,
//                                                               Bruneton's 2017 implementation
//                                                               notes
//   Henyey-Greenstein: 1/(4 pi) (1-g^2) / (1+g^2-2 g nu)^1.5    Henyey & Greenstein 1941
//                     (Leenman's 2025 thesis Eq. 6 writes +2g cos theta with theta measured
//                      from the backward direction; here nu = +cos of the angle
//                      between propagation directions, so forward peaks at nu = 1)
//   Mie:              (1 - w) CS(g) + w CS(g2)                 MiePhase (two lobes), or
//                     (1 - w) HG(g) + w HG(g2), isotropic or tabulated (mie_phase_kind)
//   isotropic:        1/(4 pi)                                  Leenman's 2025 thesis Eq. 7
//   tabulated:        values at scattering angles, linear in nu between them, normalised
//                     so that the integral over the sphere is 1 (atmosphere.h MiePhaseTable)
#pragma once

#include "atmos/atmosphere.h"
#include "atmos/math.h"

namespace atmos {

ATMOS_HD inline double RayleighPhase(double nu) { return 3.0 / (16.0 * kPi) * (1.0 + nu * nu); }

ATMOS_HD inline double CornetteShanksPhase(double g, double nu) {
    const double k = 3.0 / (8.0 * kPi) * (1.0 - g * g) / (2.0 + g * g);
    const double denom = 1.0 + g * g - 2.0 * g * nu;
    return k * (1.0 + nu * nu) / (denom * Sqrt(denom));
}

ATMOS_HD inline double HenyeyGreensteinPhase(double g, double nu) {
    const double denom = 1.0 + g * g - 2.0 * g * nu;
    return (1.0 - g * g) / (4.0 * kPi * denom * Sqrt(denom));
}

// One lobe of a lobed Mie phase function: Henyey-Greenstein for that kind,
// Cornette-Shanks otherwise.
ATMOS_HD inline double MieLobe(MiePhaseKind kind, double g, double nu) {
    return kind == MiePhaseKind::kHenyeyGreenstein ? HenyeyGreensteinPhase(g, nu)
                                                   : CornetteShanksPhase(g, nu);
}

// A lobed Mie phase function, one lobe or two: (1 - w) P(g, nu) + w P(g2, nu)
// (AtmosphereParameters::mie_phase_weight2). A convex combination of
// normalised lobes, so normalised. With w = 0 it is P(g, nu) exactly (the
// second lobe is not evaluated).
ATMOS_HD inline double MieLobes(MiePhaseKind kind, double g, double g2, double w, double nu) {
    const double p = MieLobe(kind, g, nu);
    if (w == 0.0) return p;
    return (1.0 - w) * p + w * MieLobe(kind, g2, nu);
}

// The Cornette-Shanks form: one lobe or two.
ATMOS_HD inline double MiePhase(double g, double g2, double w, double nu) {
    return MieLobes(MiePhaseKind::kCornetteShanks, g, g2, w, nu);
}

ATMOS_HD inline double IsotropicPhase() { return 1.0 / (4.0 * kPi); }

// Bisection over n >= 2 nodes: the i (0 <= i <= n - 2) with left(i) true and
// left(i + 1) false, for a predicate that holds at node 0 and, once false,
// stays false (left(n - 1) is taken as false).
template <typename LeftOf>
ATMOS_HD inline int BisectInterval(int n, const LeftOf& left) {
    int lo = 0, hi = n - 1;
    while (hi - lo > 1) {
        const int mid = (lo + hi) / 2;
        if (left(mid)) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// The interval of a tabulated phase function that holds nu: the i with
// mu[i] >= nu >= mu[i + 1] (0 <= i <= count - 2; mu decreases from 1 to -1).
ATMOS_HD inline int MiePhaseTableInterval(const MiePhaseTable& t, double nu) {
    return BisectInterval(t.count, [&](int i) { return t.mu[i] >= nu; });
}

// A tabulated phase function (atmosphere.h MiePhaseTable): the values linear in
// nu between the nodes, times the table's normalisation (1/sr).
ATMOS_HD inline double TabulatedPhase(const MiePhaseTable& t, double nu) {
    nu = Clamp(nu, -1.0, 1.0);
    const int i = MiePhaseTableInterval(t, nu);
    const double h = t.mu[i] - t.mu[i + 1];
    const double f = h > 0.0 ? (t.mu[i] - nu) / h : 0.0;
    return t.scale * (t.value[i] + (t.value[i + 1] - t.value[i]) * f);
}

// Any Mie phase function (AtmosphereParameters::mie_phase_kind): Cornette-Shanks
// or Henyey-Greenstein lobes (1 - w) P(g) + w P(g2) (w = 0: P(g) alone, the
// second lobe not evaluated), isotropic, or tabulated.
ATMOS_HD inline double MiePhase(MiePhaseKind kind, double g, double g2, double w,
                                const MiePhaseTable& table, double nu) {
    switch (kind) {
        case MiePhaseKind::kIsotropic:
            return IsotropicPhase();
        case MiePhaseKind::kTabulated:
            return TabulatedPhase(table, nu);
        case MiePhaseKind::kHenyeyGreenstein:
        case MiePhaseKind::kCornetteShanks:
        default:
            return MieLobes(kind, g, g2, w, nu);
    }
}

ATMOS_HD inline double MiePhase(const AtmosphereParameters& atm, double nu) {
    return MiePhase(atm.mie_phase_kind, atm.mie_phase_g, atm.mie_phase_g2, atm.mie_phase_weight2,
                    atm.mie_phase_table, nu);
}

}  // namespace atmos
