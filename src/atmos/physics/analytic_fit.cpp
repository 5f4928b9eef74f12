#include "physics/analytic_fit.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "atmos/error.h"

namespace atmos {

double NumericalExpLength(double r, double mu, double H, double bottom, double top, int samples) {
    const double d = DistanceToTopAtmosphereBoundary(r, mu, top);
    const double dt = d / samples;
    double sum = 0.0;
    for (int i = 0; i < samples; ++i) {
        const double t = (i + 0.5) * dt;
        const double ri = std::sqrt(t * t + 2.0 * r * mu * t + r * r);
        sum += std::exp(-(ri - bottom) / H);
    }
    return sum * dt;
}

bool SolveLinearSystem(int n, double* a, double* b) {
    for (int col = 0; col < n; ++col) {
        int pivot = col;
        for (int row = col + 1; row < n; ++row) {
            if (std::fabs(a[row * n + col]) > std::fabs(a[pivot * n + col])) pivot = row;
        }
        if (std::fabs(a[pivot * n + col]) < 1e-300) return false;
        if (pivot != col) {
            for (int k = 0; k < n; ++k) std::swap(a[col * n + k], a[pivot * n + k]);
            std::swap(b[col], b[pivot]);
        }
        for (int row = col + 1; row < n; ++row) {
            const double f = a[row * n + col] / a[col * n + col];
            for (int k = col; k < n; ++k) a[row * n + k] -= f * a[col * n + k];
            b[row] -= f * b[col];
        }
    }
    for (int row = n - 1; row >= 0; --row) {
        double s = b[row];
        for (int k = row + 1; k < n; ++k) s -= a[row * n + k] * b[k];
        b[row] = s / a[row * n + row];
    }
    return true;
}

OneilScale OriginalOneilScale(double H, double bottom, double top) {
    OneilScale s;
    s.scale_height = H;
    s.thickness = top - bottom;
    return s;
}

OneilScale FitOneilScale(double H, double bottom, double top) {
    OneilScale s = OriginalOneilScale(H, bottom, top);
    const double thickness = top - bottom;
    // Data: y = log(l / (H exp(-h/H))) at x = 1 - mu.
    std::vector<double> xs, ys;
    const double heights[4] = {0.0, 0.25 * H, 0.5 * H, H};
    for (double h : heights) {
        if (h > 0.5 * thickness) continue;
        for (int j = 0; j < 64; ++j) {
            const double mu = j / 63.0;
            const double l = NumericalExpLength(bottom + h, mu, H, bottom, top, 1000);
            xs.push_back(1.0 - mu);
            ys.push_back(std::log(l / (H * std::exp(-h / H))));
        }
    }
    // Weighted least squares of the degree-4 polynomial (normal equations);
    // Lawson's iteration (weights times the absolute residual) then moves the
    // least-squares solution toward the smallest maximum error in log space,
    // i.e. the smallest maximum relative error of the optical length. The best
    // maximum error seen is kept, so the result is never worse than plain
    // least squares.
    std::vector<double> w(xs.size(), 1.0 / static_cast<double>(xs.size()));
    double best_max = 1e300;
    for (int iter = 0; iter < 60; ++iter) {
        double ata[25] = {0.0};
        double atb[5] = {0.0};
        for (size_t i = 0; i < xs.size(); ++i) {
            const double x = xs[i];
            const double powers[5] = {1.0, x, x * x, x * x * x, x * x * x * x};
            for (int p = 0; p < 5; ++p) {
                atb[p] += w[i] * powers[p] * ys[i];
                for (int q = 0; q < 5; ++q) ata[p * 5 + q] += w[i] * powers[p] * powers[q];
            }
        }
        if (!SolveLinearSystem(5, ata, atb)) {
            if (iter == 0) Fail("oneil: the scale() refit is singular");
            break;
        }
        OneilScale trial = s;
        for (int p = 0; p < 5; ++p) trial.c[p] = atb[p];
        double max_error = 0.0, weight_sum = 0.0;
        for (size_t i = 0; i < xs.size(); ++i) {
            const double e = std::fabs(trial.Polynomial(xs[i]) - ys[i]);
            max_error = std::max(max_error, e);
            w[i] *= e;
            weight_sum += w[i];
        }
        if (max_error < best_max) {
            best_max = max_error;
            s = trial;
        }
        if (weight_sum <= 0.0) break;
        for (double& wi : w) wi /= weight_sum;
    }
    return s;
}

double OneilScaleMaxRelativeError(const OneilScale& scale, double h, double bottom, double top,
                                  double mu_min) {
    double worst = 0.0;
    for (int j = 0; j < 256; ++j) {
        const double mu = mu_min + (1.0 - mu_min) * j / 255.0;
        const double r = bottom + h;
        const double reference = NumericalExpLength(r, mu, scale.scale_height, bottom, top);
        const double approx = scale.LengthToInfinity(r, mu, bottom);
        worst = std::max(worst, std::fabs(approx / reference - 1.0));
    }
    return worst;
}

}  // namespace atmos
