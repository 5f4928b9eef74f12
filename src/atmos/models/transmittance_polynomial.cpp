#include "models/transmittance_polynomial.h"

#include <cmath>
#include <vector>

#include "atmos/error.h"
#include "physics/analytic_fit.h"
#include "physics/transmittance.h"

namespace atmos {

namespace {

struct Sample {
    double f[4];  // 1, h / thickness, mu, mu^2
    double t;     // reference transmittance of one channel
};

double Sigmoid(double z) { return 1.0 / (1.0 + std::exp(-z)); }

double SumSquares(const std::vector<Sample>& s, const double* a) {
    double sum = 0.0;
    for (const Sample& x : s) {
        const double z = a[0] * x.f[0] + a[1] * x.f[1] + a[2] * x.f[2] + a[3] * x.f[3];
        const double r = Sigmoid(z) - x.t;
        sum += r * r;
    }
    return sum;
}

// Least squares of sigmoid(a . f) against t.
void FitChannel(const std::vector<Sample>& samples, double* a) {
    // Start: logit(t) = a . f weighted by (t (1 - t))^2, the first-order
    // equivalent of the residual in t.
    double ata[16] = {0.0}, atb[4] = {0.0};
    for (const Sample& s : samples) {
        const double t = std::min(std::max(s.t, 1e-6), 1.0 - 1e-6);
        const double w = (t * (1.0 - t)) * (t * (1.0 - t));
        const double y = std::log(t / (1.0 - t));
        for (int p = 0; p < 4; ++p) {
            atb[p] += w * s.f[p] * y;
            for (int q = 0; q < 4; ++q) ata[p * 4 + q] += w * s.f[p] * s.f[q];
        }
    }
    if (!SolveLinearSystem(4, ata, atb)) Fail("transmittance-polynomial: singular fit");
    for (int p = 0; p < 4; ++p) a[p] = atb[p];
    // Levenberg-Marquardt on the residual in t.
    double lambda = 1e-3;
    double best = SumSquares(samples, a);
    for (int iter = 0; iter < 50; ++iter) {
        double jtj[16] = {0.0}, jtr[4] = {0.0};
        for (const Sample& s : samples) {
            const double z = a[0] * s.f[0] + a[1] * s.f[1] + a[2] * s.f[2] + a[3] * s.f[3];
            const double g = Sigmoid(z);
            const double r = g - s.t;
            const double dg = g * (1.0 - g);
            for (int p = 0; p < 4; ++p) {
                jtr[p] -= dg * s.f[p] * r;
                for (int q = 0; q < 4; ++q) jtj[p * 4 + q] += dg * dg * s.f[p] * s.f[q];
            }
        }
        for (int p = 0; p < 4; ++p) jtj[p * 4 + p] *= 1.0 + lambda;
        if (!SolveLinearSystem(4, jtj, jtr)) break;
        double trial[4];
        for (int p = 0; p < 4; ++p) trial[p] = a[p] + jtr[p];
        const double e = SumSquares(samples, trial);
        if (e < best) {
            const bool converged = best - e < 1e-14 * (1.0 + best);
            best = e;
            for (int p = 0; p < 4; ++p) a[p] = trial[p];
            lambda = std::max(lambda * 0.3, 1e-9);
            if (converged) break;
        } else {
            lambda *= 10.0;
            if (lambda > 1e8) break;
        }
    }
}

}  // namespace

PolynomialSigmoid FitPolynomialSigmoid(const AtmosphereParameters& atm, double* rms_error) {
    PolynomialSigmoid fit;
    fit.bottom = atm.bottom_radius;
    fit.thickness = atm.top_radius - atm.bottom_radius;
    constexpr int kHeights = 24, kAngles = 48;
    std::vector<Sample> channels[3];
    for (int i = 0; i < kHeights; ++i) {
        const double hn = i / (kHeights - 1.0);
        const double r = atm.bottom_radius + hn * fit.thickness * 0.999;
        for (int j = 0; j < kAngles; ++j) {
            const double mu = j / (kAngles - 1.0);
            const Vec3d tau = OpticalDepthToTopAtmosphereBoundary(atm, r, mu, 256);
            for (int c = 0; c < 3; ++c) {
                channels[c].push_back({{1.0, hn, mu, mu * mu}, std::exp(-tau[c])});
            }
        }
    }
    double total = 0.0;
    size_t count = 0;
    for (int c = 0; c < 3; ++c) {
        FitChannel(channels[c], fit.a[c]);
        total += SumSquares(channels[c], fit.a[c]);
        count += channels[c].size();
    }
    if (rms_error) *rms_error = std::sqrt(total / static_cast<double>(count));
    return fit;
}

ModelInfo TransmittancePolynomialModel::StaticInfo() {
    ModelInfo info;
    info.name = "transmittance-polynomial";
    info.title = "Polynomial-sigmoid transmittance fit (Leenman's 2025 thesis Eq. 42)";
    info.citation = "Leenman's 2025 thesis section 9.5 (Eq. 42)";
    info.summary =
        "view-ray transmittance 1/(1+exp(-a1-a2 h-a3 mu-a4 mu^2)) per channel, least squares "
        "in Prepare()";
    info.capabilities = TransmittanceCapabilities();
    info.capabilities.precomputed = true;
    // Measured: the zenith transmittance from the ground against its own at Earth
    // (docs/models/transmittance.md "Validity domain"): +0.6 % at 19.4 column
    // heights, +1.5 % at 26.4, +2.5 % at 35.1, -2.9 % at 27.7 on a 10x planet, 0 on
    // the giant planet.
    info.domain.max_shell_heights = 25.0;
    info.domain.shell_heights_reason =
        "its fit samples the whole shell: zenith transmittance +2.5 % at 35 heights, 0 on a "
        "1e9 m shell";
    return info;
}

}  // namespace atmos
