// atmos model `transmittance-polynomial`: the view ray's transmittance from
// the polynomial-sigmoid fit of Leenman's 2025 thesis Eq. 42.
//
// Source: Leenman's 2025 thesis section 9.5, Eq. 42:
//   T(h, mu) = 1 / (1 + exp(-a1 - a2 h - a3 mu - a4 mu^2))
// (h the viewer's altitude, mu = cos theta_v), the transmittance of the whole
// ray to the top of the atmosphere.
// Implements: one set (a1..a4) per colour channel, fitted in Prepare() by
// least squares (Gauss-Newton on T itself, started from a weighted fit of
// logit T) to the numerically integrated transmittance of the given atmosphere
// (all media, ozone included) over h in [0, top - bottom] (h normalised by the
// thickness in the fit) and mu in [0, 1]. A segment's optical depth is
// -log T differences (SegmentFromToInfinity, i.e. Bruneton & Neyret's quotient
// of two upward transmittances for rays to the ground, as the thesis does for
// its fitted models), so the fit is only evaluated for mu >= 0, the domain it
// is fitted on. -log T = softplus(-z) is computed stably.
// Deviation: the thesis fits "once for Mie, and once for Rayleigh" on
// path-traced tables; here one fit per channel of the total transmittance
// (ozone included) to the numerical reference. Output: transmittance only.
#pragma once

#include "models/transmittance_common.h"
#include "physics/analytic_optical_depth.h"

namespace atmos {

struct PolynomialSigmoid {
    double a[3][4] = {};  // per channel: a1, a2 (per thickness), a3, a4
    double bottom = 6360e3;
    double thickness = 100e3;

    ATMOS_HD double Z(int c, double r, double mu) const {
        const double h = (r - bottom) / thickness;
        return a[c][0] + a[c][1] * h + a[c][2] * mu + a[c][3] * mu * mu;
    }
    // -log T = log(1 + exp(-z)).
    ATMOS_HD double OpticalDepth(int c, double r, double mu) const {
        const double z = Z(c, r, mu);
        return z > 0.0 ? log1p(Exp(-z)) : -z + log1p(Exp(z));
    }
};

struct PolynomialChannel {
    const PolynomialSigmoid* fit;
    int c;
    ATMOS_HD double operator()(double r, double mu) const { return fit->OpticalDepth(c, r, mu); }
};

struct PolynomialTransmittanceOptics {
    PolynomialSigmoid fit;

    ATMOS_HD Vec3d SegmentDepth(const Vec3d& origin, const Vec3d& dir, double t0, double t1) const {
        const auto [r, mu, d] = RaySegmentStartOf(origin, dir, t0, t1);
        Vec3d tau;
        for (int c = 0; c < 3; ++c)
            tau[c] = SegmentFromToInfinity(PolynomialChannel{&fit, c}, r, mu, d);
        return tau;
    }
};

// Least-squares fit of Eq. 42 to the atmosphere's numerical transmittance
// (host). `rms_error` receives the fit's RMS error in T.
PolynomialSigmoid FitPolynomialSigmoid(const AtmosphereParameters& atmosphere, double* rms_error);
inline PolynomialSigmoid FitPolynomialSigmoid(const AtmosphereParameters& atmosphere) {
    return FitPolynomialSigmoid(atmosphere, nullptr);
}

class TransmittancePolynomialModel
    : public OptionlessTransmittanceModel<TransmittancePolynomialModel,
                                          PolynomialTransmittanceOptics, PolynomialSigmoid,
                                          FitPolynomialSigmoid> {
  public:
    explicit TransmittancePolynomialModel(const NoOptions&) { Prepare(EarthAtmosphere()); }
    static ModelInfo StaticInfo();
};

}  // namespace atmos
