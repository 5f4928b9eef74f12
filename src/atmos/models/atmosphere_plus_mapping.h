// atmos model `atmosphere-plus`: the four texture parameterizations of Boody's Atmosphere Plus
// notes section 2.4 (altitude h, view-zenith cosine mu = cos(phi), sun-zenith cosine mu_s =
// cos(delta)) <-> texture coordinates (u, v, w) in [0, 1].
//
//   linear     (2.4.1): u = h/H_a, v = (mu+1)/2, w = (mu_s+1)/2
//   nonlinear  (2.4.2): u = sqrt(h/H_a), v, w = (sign(c)|c|^(1/3) + 1)/2
//                       (the earlier Atmosphere Plus notes (Boody) writes the same map as 0.5(1 +
//                       sign(c)|c|^(1/3)))
//   power      (2.4.3): u = (h/H_a)^(1/p_u), v, w = (sign(c)|c|^(1/p)+1)/2
//   horizon    (2.4.4): u as power; v split at the horizon cosine c_h:
//                       sky:     v = (1 - s u)((mu - c_h)/(1 - c_h))^(1/p_a) + s u
//                       surface: v = s u (1 - ((mu - c_h)/(-1 - c_h))^(1/p_s))
//                       w: the power map with p_w (the seed leaves w open)
//
// The horizon cosine: the seed writes c_h = -1 + R_p/(R_p+h), which is not the
// tangent direction of the triangle it describes (centre, tangent point,
// observer); the geometric value is c_h = -sqrt(1 - (R_p/(R_p+h))^2). Both are
// offered (HorizonAngle); the geometric one is the default (a deviation, see
// docs/models/atmosphere-plus.md).
//
// A texture coordinate t in [0, 1] is the seed's x/(size-1): texel x holds the
// value at t = x/(size-1) (the sampler maps t onto texel centres).
#pragma once

#include "atmos/math.h"

namespace atmos {

enum class AplusParameterization { kLinear = 0, kNonlinear = 1, kPower = 2, kHorizon = 3 };
enum class AplusHorizonAngle { kGeometric = 0, kSeed = 1 };

// x^p and x^(1/p) for x >= 0, with exact fast paths for the seed's powers
// 1, 2 and 3 (per-pixel lookups call these several times).
ATMOS_HD inline double AplusPow(double x, double p) {
    return p == 1.0 ? x : p == 2.0 ? x * x : p == 3.0 ? x * x * x : Pow(x, p);
}
ATMOS_HD inline double AplusRoot(double x, double p) {
    return p == 1.0 ? x : p == 2.0 ? Sqrt(x) : p == 3.0 ? cbrt(x) : Pow(x, 1.0 / p);
}
// sign(c) |c|^(1/p) -> maps [-1, 1] onto [-1, 1] (Boody's Atmosphere Plus notes 2.4.3).
ATMOS_HD inline double AplusSignedRoot(double c, double p) {
    const double a = AplusRoot(Abs(c), p);
    return c < 0.0 ? -a : a;
}
// Inverse: sign(x) |x|^p.
ATMOS_HD inline double AplusSignedPow(double x, double p) {
    const double a = AplusPow(Abs(x), p);
    return x < 0.0 ? -a : a;
}

struct AplusMapping {
    AplusParameterization kind = AplusParameterization::kHorizon;
    AplusHorizonAngle horizon_angle = AplusHorizonAngle::kGeometric;
    double bottom_radius = 6360e3;  // R_p
    double height = 100e3;          // H_a = R_a - R_p
    double p_u = 2.0, p_v = 3.0, p_w = 3.0;
    double p_a = 3.0, p_s = 3.0, s = 0.5;

    // Effective powers of the u, v (power maps) and w coordinates.
    ATMOS_HD double PowerU() const {
        return kind == AplusParameterization::kLinear      ? 1.0
               : kind == AplusParameterization::kNonlinear ? 2.0
                                                           : p_u;
    }
    ATMOS_HD double PowerV() const {
        return kind == AplusParameterization::kLinear      ? 1.0
               : kind == AplusParameterization::kNonlinear ? 3.0
                                                           : p_v;
    }
    ATMOS_HD double PowerW() const {
        return kind == AplusParameterization::kLinear      ? 1.0
               : kind == AplusParameterization::kNonlinear ? 3.0
                                                           : p_w;
    }

    // Boody's Atmosphere Plus notes 2.4.4: cosine of the horizon's view-zenith angle at altitude h.
    ATMOS_HD double HorizonCosine(double h) const {
        const double ratio = bottom_radius / (bottom_radius + Max(h, 0.0));
        if (horizon_angle == AplusHorizonAngle::kSeed) return -1.0 + ratio;
        return -SafeSqrt(1.0 - ratio * ratio);
    }

    ATMOS_HD double U(double h) const {
        const double x = Clamp(h / height, 0.0, 1.0);
        return AplusRoot(x, PowerU());
    }
    ATMOS_HD double H(double u) const {
        const double x = Clamp(u, 0.0, 1.0);
        return AplusPow(x, PowerU()) * height;
    }

    ATMOS_HD double V(double h, double mu) const {
        mu = Clamp(mu, -1.0, 1.0);
        if (kind != AplusParameterization::kHorizon) {
            return 0.5 * (AplusSignedRoot(mu, PowerV()) + 1.0);
        }
        const double c_h = HorizonCosine(h);
        const double su = s * U(h);
        if (mu >= c_h) {
            const double x = Clamp((mu - c_h) / (1.0 - c_h), 0.0, 1.0);
            return (1.0 - su) * AplusRoot(x, p_a) + su;
        }
        const double x = Clamp((mu - c_h) / (-1.0 - c_h), 0.0, 1.0);
        return su * (1.0 - AplusRoot(x, p_s));
    }
    ATMOS_HD double Mu(double h, double v) const {
        v = Clamp(v, 0.0, 1.0);
        if (kind != AplusParameterization::kHorizon) {
            return Clamp(AplusSignedPow(2.0 * v - 1.0, PowerV()), -1.0, 1.0);
        }
        const double c_h = HorizonCosine(h);
        const double su = s * U(h);
        if (v >= su) {
            const double x = su < 1.0 ? (v - su) / (1.0 - su) : 0.0;
            return Clamp(AplusPow(x, p_a) * (1.0 - c_h) + c_h, -1.0, 1.0);
        }
        const double x = 1.0 - v / su;
        return Clamp(AplusPow(x, p_s) * (-1.0 - c_h) + c_h, -1.0, 1.0);
    }

    ATMOS_HD double W(double mu_s) const {
        return 0.5 * (AplusSignedRoot(Clamp(mu_s, -1.0, 1.0), PowerW()) + 1.0);
    }
    ATMOS_HD double MuS(double w) const {
        return Clamp(AplusSignedPow(2.0 * Clamp(w, 0.0, 1.0) - 1.0, PowerW()), -1.0, 1.0);
    }
};

}  // namespace atmos
