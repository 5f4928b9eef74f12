// atmos: an energy-conserving quadrature of in-scattered light along a view
// ray whose steps are optically thick (issue 18 item 4).
//
// The in-scattered radiance of a segment is I = int_0^D T(s) J(s) ds with
// T = exp(-tau(s)) and J = sigma_t f, f = J / sigma_t the source function (the
// single-scattering albedo times phase-weighted incident light: smooth where the
// density is not). The trapezoidal and Simpson rules in s weight each node by
// its step length; with steps longer than a mean free path (sigma_t ds >> 1)
// they weight T J by ~ sigma_t ds where the exact integral of sigma_t T over the
// step is 1 - exp(-sigma_t ds) < 1: a dense layer then scatters more light than
// it receives, and precomputed orders grow instead of decaying (w sigma_t ds / 2
// per order at the first node: 45 for the 0.01 /m Mie layer at atmosphere-plus's
// 30 km steps). The exponential-linear rule integrates in optical depth instead:
// on each interval (optical depth dtau, transmittance T_i at its start) f is
// linear in tau and
//   int_0^dtau T_i e^-x (f_i (1 - x / dtau) + f_i+1 x / dtau) dx
//     = T_i (a(dtau) f_i + b(dtau) f_i+1),
//   b = (1 - (1 + dtau) e^-dtau) / dtau,  a = 1 - e^-dtau - b,
// exact for f linear in tau, both weights positive and a + b = 1 - e^-dtau: the
// weights of a ray sum to 1 - T(D) <= 1, so I <= (1 - T(D)) sup f, whatever the
// step (energy conserving). Thin steps: a, b -> dtau / 2 (the trapezoidal rule).
#pragma once

#include "atmos/atmosphere.h"
#include "physics/density.h"
#include "physics/geometry.h"

namespace atmos {

// A ray is "thick" for a rule with nodes every `ds` metres when a node's
// extinction times ds exceeds this: the trapezoidal rule then overestimates a
// step's exp(-tau) integral by ~8 %, Simpson's by ~0.5 % (both grow without
// bound beyond). Thinner rays keep their configured rule (earth's default
// tables never reach it: bit-identical).
constexpr double kThickStepOpticalDepth = 1.0;

// a(dtau) and b(dtau) above (series below 1e-3: no cancellation).
ATMOS_HD inline void ExpLinearWeights(double dtau, double* a, double* b) {
    if (dtau < 1e-3) {
        *a = dtau * (0.5 - dtau / 6.0);
        *b = dtau * (0.5 - dtau / 3.0);
        return;
    }
    const double e = exp(-dtau);
    *b = (1.0 - (1.0 + dtau) * e) / dtau;
    *a = (1.0 - e) - *b;
}

// The node weights W_i of the rule, node by node from the start of the ray:
// Next(dtau_i) returns W_i = T_i a(dtau_i) + T_i-1 b(dtau_i-1), where dtau_i is
// the optical depth of the interval after node i (pass 0 at the last node), so
// that I = sum_i W_i f_i. Per channel.
struct ExpLinearNodeWeights {
    Vec3d t = Vec3d(1.0);  // transmittance from the start to the current node
    Vec3d carry;           // T_i-1 b(dtau_i-1): the previous interval's share
    ATMOS_HD Vec3d Next(const Vec3d& dtau) {
        Vec3d w;
        for (int c = 0; c < 3; ++c) {
            double a, b;
            ExpLinearWeights(dtau[c], &a, &b);
            w[c] = carry[c] + t[c] * a;
            carry[c] = t[c] * b;
            t[c] *= exp(-dtau[c]);
        }
        return w;
    }
};

// Optical depth of the straight segment from `origin` along the unit `dir`
// between distances s0 and s1, trapezoidal rule in `steps` sub-intervals
// (the density's scale height may be shorter than one step of the outer rule).
ATMOS_HD inline Vec3d SegmentOpticalDepth(const AtmosphereParameters& atm, const Vec3d& origin,
                                          const Vec3d& dir, double s0, double s1, int steps) {
    const double h = (s1 - s0) / steps;
    Vec3d sum;
    for (int k = 0; k <= steps; ++k) {
        const double alt = Length(origin + dir * (s0 + k * h)) - atm.bottom_radius;
        sum += Extinction(atm, GetDensities(atm, alt)) * ((k == 0 || k == steps) ? 0.5 : 1.0);
    }
    return sum * h;
}

// W / sigma_t per channel (0 where sigma_t = 0: there J = 0 too): the factor of
// J (or of sigma_s times the light J carries) at a node.
ATMOS_HD inline Vec3d PerExtinction(const Vec3d& w, const Vec3d& sigma_t) {
    Vec3d out;
    for (int c = 0; c < 3; ++c) out[c] = sigma_t[c] > 0.0 ? w[c] / sigma_t[c] : 0.0;
    return out;
}

// Whether a ray with nodes at origin + dir * (t0 + i * ds) (i = 0..n) has a
// node whose extinction times ds exceeds kThickStepOpticalDepth.
ATMOS_HD inline bool RayHasThickSteps(const AtmosphereParameters& atm, const Vec3d& origin,
                                      const Vec3d& dir, double t0, double ds, int n) {
    for (int i = 0; i <= n; ++i) {
        const double alt = Length(origin + dir * (t0 + i * ds)) - atm.bottom_radius;
        if (MaxComponent(Extinction(atm, GetDensities(atm, alt))) * ds > kThickStepOpticalDepth) {
            return true;
        }
    }
    return false;
}
// The same for the ray from radius r (on the z axis) of zenith cosine mu, t0 = 0.
ATMOS_HD inline bool RayHasThickSteps(const AtmosphereParameters& atm, double r, double mu,
                                      double ds, int n) {
    return RayHasThickSteps(atm, Vec3d(0.0, 0.0, r), Vec3d(SafeSqrt(1.0 - mu * mu), 0.0, mu), 0.0,
                            ds, n);
}

// The node weights W_i / sigma_t,i of the rule along the ray from radius r
// (on the z axis) in the direction of zenith cosine mu, nodes at i * ds, node
// by node (i = 0, 1, ..., n in turn); each interval's optical depth by
// SegmentOpticalDepth with kThickRaySubsteps sub-intervals.
constexpr int kThickRaySubsteps = 8;
struct ThickRayWeights {
    ExpLinearNodeWeights rule;
    Vec3d origin, dir;
    double ds;
    int n;
    ATMOS_HD ThickRayWeights(double r, double mu, double ds_, int n_)
        : origin(0.0, 0.0, r), dir(SafeSqrt(1.0 - mu * mu), 0.0, mu), ds(ds_), n(n_) {}
    ATMOS_HD Vec3d Next(const AtmosphereParameters& atm, int i) {
        const Vec3d dtau =
            i < n ? SegmentOpticalDepth(atm, origin, dir, i * ds, (i + 1) * ds, kThickRaySubsteps)
                  : Vec3d();
        const Vec3d w = rule.Next(dtau);
        const double alt = Length(origin + dir * (i * ds)) - atm.bottom_radius;
        return PerExtinction(w, Extinction(atm, GetDensities(atm, alt)));
    }
};

}  // namespace atmos
