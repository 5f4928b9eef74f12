// atmos model `hosek-wilkie`: the fit to any atmosphere (hosek_wilkie_fit.h).
//
// The Levenberg-Marquardt below is atmos's own (about 60 lines): NLopt, the
// one optimisation library atmos links (the validate study's aerosol fit),
// has no least-squares solver that uses the residuals' Jacobian, and the
// problems here are tiny (9 or 60 unknowns, normal equations accumulated
// directly), so a dependency (Eigen's unsupported LM, Ceres) would buy nothing.
#include "models/hosek_wilkie_fit.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "io/output_path.h"
#include "models/hosek_wilkie.h"
#include "render/progressive.h"

namespace atmos {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double SecondsSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Solves (A + lambda D) x = b, D = diag(max(A_ii, floor)), by Cholesky of the
// system scaled to a unit diagonal (Jacobi: the parameters' scales differ by
// orders of magnitude, which would otherwise cost the factorisation its
// precision); false when the matrix is not positive definite.
bool SolveDamped(const std::vector<double>& a, const std::vector<double>& b, int n, double lambda,
                 std::vector<double>* x) {
    double max_diag = 0.0;
    for (int i = 0; i < n; ++i) max_diag = std::max(max_diag, a[i * n + i]);
    const double floor = 1e-12 * std::max(max_diag, 1e-300);
    std::vector<double> scale(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
        const double d = std::max(a[i * n + i], floor) * (1.0 + lambda);
        scale[i] = 1.0 / std::sqrt(d);
    }
    std::vector<double> l(static_cast<size_t>(n * n));
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) l[i * n + j] = a[i * n + j] * scale[i] * scale[j];
        l[i * n + i] = 1.0;  // (A_ii + lambda D_ii) scaled
        if (a[i * n + i] < floor)
            l[i * n + i] = (a[i * n + i] + lambda * floor) * scale[i] * scale[i];
    }
    for (int j = 0; j < n; ++j) {
        double d = l[j * n + j];
        for (int k = 0; k < j; ++k) d -= l[j * n + k] * l[j * n + k];
        if (!(d > 0.0)) return false;
        d = std::sqrt(d);
        l[j * n + j] = d;
        for (int i = j + 1; i < n; ++i) {
            double s = l[i * n + j];
            for (int k = 0; k < j; ++k) s -= l[i * n + k] * l[j * n + k];
            l[i * n + j] = s / d;
        }
    }
    x->resize(static_cast<size_t>(n));
    std::vector<double>& y = *x;
    for (int i = 0; i < n; ++i) {
        double s = b[i] * scale[i];
        for (int k = 0; k < i; ++k) s -= l[i * n + k] * y[k];
        y[i] = s / l[i * n + i];
    }
    for (int i = n - 1; i >= 0; --i) {
        double s = y[i];
        for (int k = i + 1; k < n; ++k) s -= l[k * n + i] * y[k];
        y[i] = s / l[i * n + i];
    }
    for (int i = 0; i < n; ++i) y[i] *= scale[i];
    return true;
}

// Levenberg-Marquardt (Marquardt's diagonal scaling) on cost(x, A, g) =
// 1/2 sum r^2, which also fills A = J^T J and g = J^T r when they are given; a
// cost that is not finite rejects the step; project(x) puts a trial point back
// inside the bounds (a projected step). Returns the final cost; x holds
// the minimiser found.
template <typename Cost, typename Project>
double LevenbergMarquardt(const Cost& cost, const Project& project, int n, int iterations,
                          std::vector<double>* x, int* evaluations) {
    std::vector<double> a(static_cast<size_t>(n * n)), g(static_cast<size_t>(n)), step, trial;
    double c = cost(*x, &a, &g);
    ++*evaluations;
    if (!std::isfinite(c)) return c;
    double lambda = 1e-3;
    int small = 0;
    for (int it = 0; it < iterations && lambda < 1e12; ++it) {
        std::vector<double> minus_g(g);
        for (double& v : minus_g) v = -v;
        if (!SolveDamped(a, minus_g, n, lambda, &step)) {
            lambda *= 8.0;
            continue;
        }
        trial = *x;
        for (int i = 0; i < n; ++i) trial[i] += step[i];
        project(&trial);
        const double ct = cost(trial, nullptr, nullptr);
        ++*evaluations;
        if (std::isfinite(ct) && ct < c) {
            const bool tiny = c - ct <= 1e-12 * c;
            *x = trial;
            c = cost(*x, &a, &g);
            ++*evaluations;
            lambda = std::max(lambda / 4.0, 1e-12);
            small = tiny ? small + 1 : 0;
            if (small >= 3 || c == 0.0) break;
        } else {
            lambda *= 8.0;
        }
    }
    return c;
}

void NoBounds(std::vector<double>*) {}

// One sample's geometry as the model computes it (hosek_wilkie.h).
struct Sample {
    double cos_theta, gamma, cos_gamma;
};

Sample Geometry(const SampleQuery& q) {
    const double sv = std::sqrt(std::max(0.0, 1.0 - q.mu * q.mu));
    const double ss = std::sqrt(std::max(0.0, 1.0 - q.mu_s * q.mu_s));
    const double cg = std::max(
        -1.0, std::min(1.0, sv * ss * std::cos(q.azimuth_deg * kPi / 180.0) + q.mu * q.mu_s));
    return {std::max(q.mu, 0.0), std::acos(cg), cg};
}

// The form (eq. 8-9) at one sample and its gradient in A B C D E F G I H L_M.
double FormAndGradient(const double v[10], const Sample& s, double grad[10]) {
    const double A = v[0], B = v[1], C = v[2], D = v[3], E = v[4], F = v[5], G = v[6], I = v[7],
                 H = v[8], L = v[9];
    const double inv = 1.0 / (s.cos_theta + 0.01);
    const double t1 = std::exp(B * inv);
    const double p = 1.0 + A * t1;
    const double eg = std::exp(E * s.gamma);
    const double cg2 = s.cos_gamma * s.cos_gamma;
    const double q = 1.0 + H * H - 2.0 * H * s.cos_gamma;
    if (!(q > 1e-12)) return kInf;
    const double sq = std::sqrt(q);
    const double chi = (1.0 + cg2) / (q * sq);
    const double su = std::sqrt(s.cos_theta);
    const double qq = C + D * eg + F * cg2 + G * chi + I * su;
    if (grad != nullptr) {
        grad[0] = t1 * qq * L;
        grad[1] = A * t1 * inv * qq * L;
        grad[2] = p * L;
        grad[3] = p * eg * L;
        grad[4] = p * D * s.gamma * eg * L;
        grad[5] = p * cg2 * L;
        grad[6] = p * chi * L;
        grad[7] = p * su * L;
        grad[8] = p * G * (-3.0 * (1.0 + cg2) * (H - s.cos_gamma) / (q * q * sq)) * L;
        grad[9] = p * qq;
    }
    return p * qq * L;
}

// The Bernstein weights at `elevation`, exactly as the model cooks them.
void Bernstein(double elevation, double b[6]) {
    for (int j = 0; j < 6; ++j) {
        double unit[6][10] = {};
        unit[j][0] = 1.0;
        b[j] = HosekWilkieCook(unit, elevation).v[0];
    }
}

// The samples of one elevation and channel with a positive reference value.
struct Slice {
    std::vector<Sample> s;
    std::vector<double> y;
    std::vector<double> w;  // 1 / y: the residual (m - y) w is the relative error
    double mean = 0.0;      // over the slice's whole grid (the hemisphere's mean)
};

void CheckRange(const char* field, int v, int lo, int hi) {
    if (v < lo || v > hi) {
        Fail("fit: ", field, " must be in [", lo, ", ", hi, "], got ", v);
    }
}

}  // namespace

void ResolveHosekWilkieFitConfig(const HosekWilkieFitConfig& c) {
    CheckRange("--sun-elevations", c.sun_elevations, 8, 200);
    CheckRange("--view-zeniths", c.view_zeniths, 4, 256);
    CheckRange("--view-azimuths", c.view_azimuths, 4, 512);
    CheckRange("--iterations", c.iterations, 1, 10000);
    const ModelSpec spec = ParseModelSpec(c.reference);
    for (const ModelInfo& info : ListModels()) {
        if (info.name == spec.name && !info.capabilities.radiance) {
            Fail("fit: --reference ", spec.name, " gives no sky radiance (`atmos list ", spec.name,
                 "`)");
        }
    }
}

bool FitsHosekWilkieForm(const std::string& model) {
    try {
        const std::unique_ptr<Model> m = CreateModel(ParseModelSpec(model));
        return dynamic_cast<const HosekWilkieModel*>(m.get()) != nullptr;
    } catch (const Error&) {
        return false;
    }
}

HosekWilkieFitData HosekWilkieFitGrid(const HosekWilkieFitConfig& c, bool shifted) {
    // The fit's grid: x = (k + 1) / K, cos(theta) and azimuth at the strata's
    // midpoints; the shifted grid: the points halfway between those (K - 1
    // elevations, Z - 1 zeniths, A - 1 azimuths), where the fit interpolates.
    HosekWilkieFitData d;
    const int s = shifted ? 1 : 0;
    d.elevations = c.sun_elevations - s;
    d.zeniths = c.view_zeniths - s;
    d.azimuths = c.view_azimuths - s;
    const double o = shifted ? 1.0 : 0.5;
    for (int k = 0; k < d.elevations; ++k) {
        const double x = (k + 1.0 + 0.5 * s) / c.sun_elevations;
        const double elevation = 0.5 * kPi * x * x * x;
        d.elevation.push_back(elevation);
        for (int i = 0; i < d.zeniths; ++i) {
            for (int j = 0; j < d.azimuths; ++j) {
                SampleQuery q;
                q.altitude_m = 0.0;
                q.mu = (i + o) / c.view_zeniths;
                q.mu_s = std::sin(elevation);
                q.azimuth_deg = 180.0 * (j + o) / c.view_azimuths;
                d.queries.push_back(q);
            }
        }
    }
    return d;
}

void SampleHosekWilkieFitData(const Model& reference, const MonteCarloSettings& monte_carlo,
                              HosekWilkieFitData* data) {
    const std::vector<SampleAnswer> a =
        reference.Info().capabilities.stochastic
            ? SampleMonteCarlo(reference, data->queries, monte_carlo)
            : reference.Sample(data->queries);
    data->value.resize(data->queries.size() * 3);
    for (size_t q = 0; q < a.size(); ++q) {
        data->value[q * 3 + 0] = a[q].radiance.x;
        data->value[q * 3 + 1] = a[q].radiance.y;
        data->value[q * 3 + 2] = a[q].radiance.z;
    }
}

void HosekWilkieFitError(const double ctrl[3][6][10], const HosekWilkieFitData& data, double rms[3],
                         double* rms_all, double max_abs[3]) {
    const int per = data.zeniths * data.azimuths;
    double sum_all = 0.0;
    int n_all = 0;
    for (int c = 0; c < 3; ++c) {
        double sum = 0.0, worst = 0.0;
        int n = 0;
        for (int k = 0; k < data.elevations; ++k) {
            const HosekWilkieConfig v = HosekWilkieCook(ctrl[c], data.elevation[k]);
            for (int s = 0; s < per; ++s) {
                const size_t q = static_cast<size_t>(k * per + s);
                const double y = data.value[q * 3 + c];
                if (!(y > 0.0)) continue;
                const Sample g = Geometry(data.queries[q]);
                const double m = std::max(HosekWilkieRadiance(v, g.cos_theta, g.gamma), 0.0);
                const double r = m / y - 1.0;
                sum += r * r;
                worst = std::max(worst, std::abs(r));
                ++n;
            }
        }
        rms[c] = n > 0 ? std::sqrt(sum / n) : 0.0;
        max_abs[c] = worst;
        sum_all += sum;
        n_all += n;
    }
    *rms_all = n_all > 0 ? std::sqrt(sum_all / n_all) : 0.0;
}

HosekWilkieFitResult FitHosekWilkieForm(const HosekWilkieFitData& data,
                                        const HosekWilkieFitConfig& config) {
    HosekWilkieFitResult result;
    HosekWilkieFitReport& rep = result.report;
    const int K = data.elevations, per = data.zeniths * data.azimuths;
    if (K < 6 || static_cast<int>(data.value.size()) != 3 * K * per) {
        Fail("fit: hosek-wilkie needs at least 6 sun elevations of samples");
    }
    std::vector<std::array<double, 6>> basis(static_cast<size_t>(K));
    for (int k = 0; k < K; ++k) Bernstein(data.elevation[k], basis[k].data());
    // The published RGB channel's control points at T = 3, albedo 0: the start.
    const HosekWilkieData& published = HosekWilkieDataset(HosekWilkieColour::kRgb);
    rep.samples = K * per;
    for (int c = 0; c < 3; ++c) {
        std::vector<Slice> slices(static_cast<size_t>(K));
        for (int k = 0; k < K; ++k) {
            Slice& sl = slices[k];
            double sum = 0.0;
            for (int s = 0; s < per; ++s) {
                const size_t q = static_cast<size_t>(k * per + s);
                const double y = data.value[q * 3 + c];
                sum += std::isfinite(y) ? std::max(y, 0.0) : 0.0;
                if (!(y > 0.0) || !std::isfinite(y)) {
                    ++rep.skipped;
                    continue;
                }
                sl.s.push_back(Geometry(data.queries[q]));
                sl.y.push_back(y);
            }
            sl.mean = sum / per;
            for (double y : sl.y) sl.w.push_back(1.0 / y);
            if (sl.s.size() < 10 || !(sl.mean > 0.0)) {
                Fail("fit: the reference's radiance (channel ", c, ", sun elevation ",
                     data.elevation[k] * 180.0 / kPi,
                     " deg) is not positive at enough views to fit");
            }
        }
        double start[6][10];
        HosekWilkieBlend(published, c, 3.0, 0.0, start);
        // Stage 1: nine parameters per elevation, L_M = the slice's mean.
        std::vector<std::array<double, 10>> params(static_cast<size_t>(K));
        double stage1_sum = 0.0;
        int stage1_n = 0;
        std::vector<double> previous;
        for (int k = K - 1; k >= 0; --k) {
            const Slice& sl = slices[k];
            const double L = sl.mean;
            auto cost = [&](const std::vector<double>& x, std::vector<double>* a,
                            std::vector<double>* g) {
                double v[10];
                for (int p = 0; p < 9; ++p) v[p] = x[p];
                v[9] = L;
                if (a != nullptr) {
                    std::fill(a->begin(), a->end(), 0.0);
                    std::fill(g->begin(), g->end(), 0.0);
                }
                double total = 0.0;
                double grad[10];
                for (size_t i = 0; i < sl.s.size(); ++i) {
                    const double m = FormAndGradient(v, sl.s[i], a != nullptr ? grad : nullptr);
                    const double r = (m - sl.y[i]) * sl.w[i];
                    if (!std::isfinite(r)) return kInf;
                    total += 0.5 * r * r;
                    if (a == nullptr) continue;
                    for (int p = 0; p < 9; ++p) grad[p] *= sl.w[i];
                    for (int p = 0; p < 9; ++p) {
                        (*g)[p] += grad[p] * r;
                        for (int q = 0; q < 9; ++q) (*a)[p * 9 + q] += grad[p] * grad[q];
                    }
                }
                return total;
            };
            const HosekWilkieConfig init = HosekWilkieCook(start, data.elevation[k]);
            std::vector<double> x0(init.v, init.v + 9);
            double c0 =
                LevenbergMarquardt(cost, NoBounds, 9, config.iterations, &x0, &rep.evaluations);
            if (!previous.empty()) {
                std::vector<double> x1 = previous;
                const double c1 =
                    LevenbergMarquardt(cost, NoBounds, 9, config.iterations, &x1, &rep.evaluations);
                // The neighbour's branch unless the published start is clearly
                // better: parameters that vary smoothly with elevation.
                if (std::isfinite(c1) && !(0.5 * c1 >= c0)) {
                    x0 = x1;
                    c0 = c1;
                }
            }
            if (!std::isfinite(c0)) {
                Fail("fit: the form could not be fitted at sun elevation ",
                     data.elevation[k] * 180.0 / kPi, " deg (channel ", c, ")");
            }
            previous = x0;
            for (int p = 0; p < 9; ++p) params[k][p] = x0[p];
            params[k][9] = L;
            stage1_sum += 2.0 * c0;
            stage1_n += static_cast<int>(sl.s.size());
        }
        rep.stage1_rms[c] = std::sqrt(stage1_sum / std::max(stage1_n, 1));
        // Stage 2: each parameter's control points by linear least squares
        // (L_M weighted by 1 / L_M: relative error).
        double ctrl[6][10];
        for (int p = 0; p < 10; ++p) {
            std::vector<double> a(36, 0.0), b(6, 0.0), x;
            for (int k = 0; k < K; ++k) {
                const double w = p == 9 ? 1.0 / params[k][9] : 1.0;
                for (int i = 0; i < 6; ++i) {
                    b[i] += w * w * basis[k][i] * params[k][p];
                    for (int j = 0; j < 6; ++j) a[i * 6 + j] += w * w * basis[k][i] * basis[k][j];
                }
            }
            if (!SolveDamped(a, b, 6, 1e-12, &x)) Fail("fit: the Bezier fit is singular");
            for (int i = 0; i < 6; ++i) ctrl[i][p] = p == 9 ? std::max(x[i], 0.0) : x[i];
        }
        // Stage 2b: L_M and C, D, F, G, I enter the form only as the products
        // L_M C, ..., L_M I, which stage 1 determines whatever its choice of
        // L_M; alternating least squares gives quintic L_M and quintic C..I
        // whose products match them (relative to the slice's mean).
        {
            constexpr int kLin[5] = {2, 3, 5, 6, 7};
            for (int sweep = 0; sweep < 200; ++sweep) {
                // A curve c minimising sum_k sum_j (w_k (s_jk B_k c - t_jk))^2.
                auto solve = [&](int p, bool for_l) {
                    std::vector<double> a(36, 0.0), b(6, 0.0), x;
                    for (int k = 0; k < K; ++k) {
                        const double w = 1.0 / params[k][9];
                        double lk = 0.0, vk[10] = {};
                        for (int i = 0; i < 6; ++i) {
                            lk += basis[k][i] * ctrl[i][9];
                            for (int q = 0; q < 10; ++q) vk[q] += basis[k][i] * ctrl[i][q];
                        }
                        for (int j = 0; j < (for_l ? 5 : 1); ++j) {
                            const int q = for_l ? kLin[j] : p;
                            const double sk = w * (for_l ? vk[q] : lk);
                            const double tk = w * params[k][q] * params[k][9];
                            for (int i = 0; i < 6; ++i) {
                                b[i] += sk * basis[k][i] * tk;
                                for (int m = 0; m < 6; ++m) {
                                    a[i * 6 + m] += sk * sk * basis[k][i] * basis[k][m];
                                }
                            }
                        }
                    }
                    if (!SolveDamped(a, b, 6, 1e-12, &x)) return;
                    for (int i = 0; i < 6; ++i) ctrl[i][for_l ? 9 : p] = x[i];
                };
                for (int p : kLin) solve(p, false);
                solve(9, true);
                // Keep the scale (the products do not fix it): L_M's last point.
                const double s5 = ctrl[5][9] != 0.0 ? params[K - 1][9] / ctrl[5][9] : 1.0;
                if (std::isfinite(s5) && s5 > 0.0) {
                    for (int i = 0; i < 6; ++i) {
                        ctrl[i][9] *= s5;
                        for (int p : kLin) ctrl[i][p] /= s5;
                    }
                }
            }
            for (int i = 0; i < 6; ++i) ctrl[i][9] = std::max(ctrl[i][9], 0.0);
        }
        // Stage 3: all 60 control points on every sample (first L_M's alone,
        // the linear ones solved for at each trial, then all).
        bool only_lm = true;
        auto joint = [&](const std::vector<double>& x, std::vector<double>* a,
                         std::vector<double>* g) {
            double cp[6][10];
            for (int i = 0; i < 6; ++i) {
                for (int p = 0; p < 10; ++p) cp[i][p] = x[i * 10 + p];
                if (cp[i][9] < 0.0) return kInf;
            }
            if (a != nullptr) {
                std::fill(a->begin(), a->end(), 0.0);
                std::fill(g->begin(), g->end(), 0.0);
            }
            double total = 0.0;
            double grad[10];
            for (int k = 0; k < K; ++k) {
                const Slice& sl = slices[k];
                const HosekWilkieConfig v = HosekWilkieCook(cp, data.elevation[k]);
                double gk[10][10] = {}, hk[10] = {};
                for (size_t i = 0; i < sl.s.size(); ++i) {
                    const double m = FormAndGradient(v.v, sl.s[i], a != nullptr ? grad : nullptr);
                    const double r = (m - sl.y[i]) * sl.w[i];
                    if (!std::isfinite(r)) return kInf;
                    total += 0.5 * r * r;
                    if (a == nullptr) continue;
                    for (int p = 0; p < 10; ++p) grad[p] *= sl.w[i];
                    for (int p = 0; p < 10; ++p) {
                        hk[p] += grad[p] * r;
                        for (int q = 0; q < 10; ++q) gk[p][q] += grad[p] * grad[q];
                    }
                }
                if (a == nullptr) continue;
                const std::array<double, 6>& bk = basis[k];
                for (int i = 0; i < 6; ++i) {
                    for (int p = 0; p < 10; ++p) {
                        (*g)[i * 10 + p] += bk[i] * hk[p];
                        for (int j = 0; j < 6; ++j) {
                            for (int q = 0; q < 10; ++q) {
                                (*a)[(i * 10 + p) * 60 + j * 10 + q] += bk[i] * bk[j] * gk[p][q];
                            }
                        }
                    }
                }
            }
            if (a != nullptr) {
                // Pin the last L_M control point (F L_M is unchanged by scaling
                // L_M by s and C, D, F, G, I by 1 / s, a direction without
                // information that only slows the solver) and, in the first
                // pass, all but L_M's.
                for (int i = 0; i < 60; ++i) {
                    if (i != 59 && (!only_lm || i % 10 == 9)) continue;
                    for (int j = 0; j < 60; ++j) (*a)[i * 60 + j] = (*a)[j * 60 + i] = 0.0;
                    (*a)[i * 60 + i] = 1.0;
                    (*g)[i] = 0.0;
                }
            }
            return total;
        };
        // A trial point: L_M's control points kept >= 0, then the 30 control
        // points of C, D, F, G, I (in which the form is linear once the others
        // are fixed) solved for exactly by linear least squares: the
        // alternation that makes the joint fit converge in tens of steps.
        constexpr int kLinear[5] = {2, 3, 5, 6, 7};
        auto keep_lm_positive = [&](std::vector<double>* x) {
            for (int i = 0; i < 6; ++i) (*x)[i * 10 + 9] = std::max((*x)[i * 10 + 9], 0.0);
            double cp[6][10];
            for (int i = 0; i < 6; ++i) {
                for (int p = 0; p < 10; ++p) cp[i][p] = (*x)[i * 10 + p];
            }
            std::vector<double> m(900, 0.0), rhs(30, 0.0), sol;
            for (int k = 0; k < K; ++k) {
                const Slice& sl = slices[k];
                const HosekWilkieConfig v = HosekWilkieCook(cp, data.elevation[k]);
                double gk[5][5] = {}, hk[5] = {};
                for (size_t i = 0; i < sl.s.size(); ++i) {
                    const Sample& sm = sl.s[i];
                    // The form's features: the gradient in C, D, F, G, I.
                    double grad[10];
                    if (!std::isfinite(FormAndGradient(v.v, sm, grad))) return;
                    double f[5];
                    for (int p = 0; p < 5; ++p) f[p] = grad[kLinear[p]] * sl.w[i];
                    for (int p = 0; p < 5; ++p) {
                        hk[p] += f[p] * sl.y[i] * sl.w[i];
                        for (int q = 0; q < 5; ++q) gk[p][q] += f[p] * f[q];
                    }
                }
                const std::array<double, 6>& bk = basis[k];
                for (int i = 0; i < 6; ++i) {
                    for (int p = 0; p < 5; ++p) {
                        rhs[i * 5 + p] += bk[i] * hk[p];
                        for (int j = 0; j < 6; ++j) {
                            for (int q = 0; q < 5; ++q) {
                                m[(i * 5 + p) * 30 + j * 5 + q] += bk[i] * bk[j] * gk[p][q];
                            }
                        }
                    }
                }
            }
            if (!SolveDamped(m, rhs, 30, 1e-12, &sol)) return;
            for (int i = 0; i < 6; ++i) {
                for (int p = 0; p < 5; ++p) (*x)[i * 10 + kLinear[p]] = sol[i * 5 + p];
            }
        };
        // Two starts: stage 2's control points, and the published ones with
        // L_M scaled by the data's best constant factor; the better end kept.
        std::vector<double> x(60), y(60);
        double ratio = 0.0, ratio2 = 0.0;
        for (int k = 0; k < K; ++k) {
            const HosekWilkieConfig v = HosekWilkieCook(start, data.elevation[k]);
            for (size_t i = 0; i < slices[k].s.size(); ++i) {
                const double u = FormAndGradient(v.v, slices[k].s[i], nullptr) / slices[k].y[i];
                if (!std::isfinite(u)) continue;
                ratio += u;
                ratio2 += u * u;
            }
        }
        const double scale = ratio2 > 0.0 ? ratio / ratio2 : 1.0;
        for (int i = 0; i < 6; ++i) {
            for (int p = 0; p < 10; ++p) {
                x[i * 10 + p] = ctrl[i][p];
                y[i * 10 + p] = p == 9 ? std::max(start[i][p] * scale, 0.0) : start[i][p];
            }
        }
        only_lm = true;
        const int first = std::max(1, config.iterations / 4);
        LevenbergMarquardt(joint, keep_lm_positive, 60, first, &x, &rep.evaluations);
        LevenbergMarquardt(joint, keep_lm_positive, 60, first, &y, &rep.evaluations);
        only_lm = false;
        double cj = LevenbergMarquardt(joint, keep_lm_positive, 60, config.iterations, &x,
                                       &rep.evaluations);
        const double cy = LevenbergMarquardt(joint, keep_lm_positive, 60, config.iterations, &y,
                                             &rep.evaluations);
        if (std::isfinite(cy) && !(cy >= cj)) {
            x = y;
            cj = cy;
        }
        if (!std::isfinite(cj)) {
            Fail("fit: the Bezier form could not be fitted (channel ", c,
                 "): no start gives finite radiance");
        }
        for (int i = 0; i < 6; ++i) {
            for (int p = 0; p < 10; ++p) result.coefficients.ctrl[c][i][p] = x[i * 10 + p];
        }
    }
    HosekWilkieFitError(result.coefficients.ctrl, data, rep.relative_rms, &rep.relative_rms_all,
                        rep.max_relative);
    return result;
}

HosekWilkieFitResult RunHosekWilkieFit(const HosekWilkieFitConfig& config,
                                       const std::string& atmosphere_name,
                                       const AtmosphereParameters& atmosphere) {
    ResolveHosekWilkieFitConfig(config);
    std::unique_ptr<Model> reference = CreateModel(ParseModelSpec(config.reference));
    auto t0 = std::chrono::steady_clock::now();
    reference->Prepare(atmosphere);
    const double prepare_s = SecondsSince(t0);
    t0 = std::chrono::steady_clock::now();
    HosekWilkieFitData data = HosekWilkieFitGrid(config, false);
    SampleHosekWilkieFitData(*reference, config.reference_monte_carlo, &data);
    HosekWilkieFitData holdout;
    if (config.holdout) {
        holdout = HosekWilkieFitGrid(config, true);
        SampleHosekWilkieFitData(*reference, config.reference_monte_carlo, &holdout);
    }
    const double sample_s = SecondsSince(t0);
    t0 = std::chrono::steady_clock::now();
    HosekWilkieFitResult result = FitHosekWilkieForm(data, config);
    HosekWilkieFitReport& rep = result.report;
    rep.fit_seconds = SecondsSince(t0);
    rep.prepare_seconds = prepare_s;
    rep.sample_seconds = sample_s;
    if (config.holdout) {
        double rms[3], worst[3];
        HosekWilkieFitError(result.coefficients.ctrl, holdout, rms, &rep.holdout_rms_all, worst);
    }
    if (config.score_published) {
        // The published form at the reference's wavelengths (colour=spectral:
        // 680, 550, 440 nm, per unit solar irradiance), albedo the atmosphere's.
        for (int t2 = 2; t2 <= 20; ++t2) {
            const double T = 0.5 * t2;
            std::unique_ptr<Model> hw = CreateModel(
                ParseModelSpec("hosek-wilkie:colour=spectral:turbidity=" + std::to_string(T)));
            hw->Prepare(atmosphere);
            const std::vector<SampleAnswer> a = hw->Sample(data.queries);
            double sum = 0.0, ratio[3] = {}, ratio2[3] = {};
            int n = 0;
            for (size_t q = 0; q < a.size(); ++q) {
                const double m[3] = {a[q].radiance.x, a[q].radiance.y, a[q].radiance.z};
                for (int c = 0; c < 3; ++c) {
                    const double y = data.value[q * 3 + c];
                    if (!(y > 0.0)) continue;
                    const double u = m[c] / y;
                    sum += (u - 1.0) * (u - 1.0);
                    ratio[c] += u;
                    ratio2[c] += u * u;
                    ++n;
                }
            }
            const double rms = std::sqrt(sum / std::max(n, 1));
            // With each channel's best factor s = sum u / sum u^2: the residual
            // sum (s u - 1)^2 = N_c - (sum u)^2 / sum u^2.
            double shape = 0.0;
            const int nc = n / 3;
            for (int c = 0; c < 3; ++c) {
                shape += ratio2[c] > 0.0 ? nc - ratio[c] * ratio[c] / ratio2[c] : nc;
            }
            const double shape_rms = std::sqrt(std::max(shape, 0.0) / std::max(n, 1));
            if (rep.published_rms_all < 0.0 || rms < rep.published_rms_all) {
                rep.published_rms_all = rms;
                rep.published_turbidity = T;
            }
            if (rep.published_shape_rms_all < 0.0 || shape_rms < rep.published_shape_rms_all) {
                rep.published_shape_rms_all = shape_rms;
                rep.published_shape_turbidity = T;
            }
        }
    }
    HosekWilkieCoefficients& co = result.coefficients;
    co.reference = config.reference;
    co.atmosphere = atmosphere_name;
    nlohmann::ordered_json fit;
    fit["atmosphere_parameters"] = nlohmann::ordered_json::parse(AtmosphereToJson(atmosphere));
    if (reference->Info().capabilities.stochastic) {
        fit["reference_spp"] = config.reference_monte_carlo.spp;
        fit["reference_seed"] = config.reference_monte_carlo.seed;
    }
    fit["sun_elevations"] = config.sun_elevations;
    fit["view_zeniths"] = config.view_zeniths;
    fit["view_azimuths"] = config.view_azimuths;
    fit["iterations"] = config.iterations;
    fit["relative_rms"] = {rep.relative_rms[0], rep.relative_rms[1], rep.relative_rms[2]};
    fit["relative_rms_per_elevation_free"] = {rep.stage1_rms[0], rep.stage1_rms[1],
                                              rep.stage1_rms[2]};
    fit["max_relative_error"] = {rep.max_relative[0], rep.max_relative[1], rep.max_relative[2]};
    if (config.holdout) fit["holdout_relative_rms"] = rep.holdout_rms_all;
    co.fit_json = fit.dump();
    return result;
}

void WriteHosekWilkieFit(const HosekWilkieFitResult& result, const std::string& path) {
    WriteFileAtomically(path, HosekWilkieCoefficientsToJson(result.coefficients));
}

}  // namespace atmos
