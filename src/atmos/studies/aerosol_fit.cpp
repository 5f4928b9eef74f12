// atmos studies: the aerosol fit of the validate study (aerosol_fit.h).
#include "studies/aerosol_fit.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#ifdef ATMOS_HAVE_NLOPT
#include <nlopt.h>
#endif

#include "atmos/error.h"
#include "atmos/spectral.h"
#include "harness/spectral_run.h"

namespace atmos {

namespace {

std::string SetText(const char* field, double value) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%s=%.6g", field, value);
    return buf;
}

std::vector<std::string> WithAerosol(const std::vector<std::string>& sets, const double* x,
                                     int count) {
    std::vector<std::string> out = sets;
    for (int i = 0; i < count; ++i) out.push_back(SetText(kAerosolParameters[i].field, x[i]));
    return out;
}

#ifdef ATMOS_HAVE_NLOPT
struct Objective {
    const AerosolFitSettings* settings = nullptr;
    const std::string* atmosphere = nullptr;
    const std::vector<std::string>* sets = nullptr;
    const std::vector<KiderSample>* samples = nullptr;
    const std::vector<SampleQuery>* queries = nullptr;
    int evaluations = 0;
    double best = HUGE_VAL;
    nlopt_opt opt = nullptr;
    std::string error;  // an atmos::Error of an evaluation (not thrown through NLopt's C)
};

double ObjectiveFunction(unsigned n, const double* x, double* gradient, void* data) {
    (void)gradient;  // BOBYQA is derivative-free
    Objective& o = *static_cast<Objective*>(data);
    double r = 0.0;
    try {
        r = KiderResidual(*o.settings, *o.atmosphere, WithAerosol(*o.sets, x, static_cast<int>(n)),
                          *o.samples, *o.queries);
    } catch (const std::exception& e) {
        o.error = e.what();
        nlopt_force_stop(o.opt);
        return HUGE_VAL;
    }
    ++o.evaluations;
    o.best = std::min(o.best, r);
    if (!o.settings->quiet) {
        char lobe[64] = "";
        if (n > kAerosolBaseParameters) {
            std::snprintf(lobe, sizeof lobe, " g2 %.4f weight2 %.4f", x[4], x[5]);
        }
        std::fprintf(stderr,
                     "fit %3d: beta %.5f alpha %.4f albedo %.4f g %.4f%s -> %.3f %% (best %.3f "
                     "%%)\n",
                     o.evaluations, x[0], x[1], x[2], x[3], lobe, 100.0 * r, 100.0 * o.best);
    }
    return r * r;  // the mean squared error over mean measured^2: least squares
}

const char* StopReason(nlopt_result r) {
    switch (r) {
        case NLOPT_MAXEVAL_REACHED:
            return "evaluation limit reached";
        case NLOPT_XTOL_REACHED:
            return "parameters converged (relative 1e-3)";
        case NLOPT_FTOL_REACHED:
            return "residual converged (relative 1e-4)";
        case NLOPT_SUCCESS:
            return "converged";
        default:
            return "stopped";
    }
}
#endif

}  // namespace

int KiderBinIndex(double nm) {
    const std::vector<double> bins = KiderWavelengths();
    for (size_t i = 0; i < bins.size(); ++i) {
        if (std::abs(bins[i] - nm) < 1e-6) return static_cast<int>(i);
    }
    return -1;
}

std::vector<double> KiderModelSpectra(const ModelSpec& spec, const SpectralAtmosphere& atmosphere,
                                      const std::vector<double>& nm,
                                      const std::vector<SampleQuery>& queries,
                                      const MonteCarloSettings& monte_carlo) {
    return SampleSpectral(
        spec, atmosphere, nm, queries, monte_carlo,
        [](const AtmosphereParameters& p, Model* model) { model->Prepare(p); },
        kPerWavelengthBatching);
}

double KiderResidual(const AerosolFitSettings& settings, const std::string& atmosphere,
                     const std::vector<std::string>& sets, const std::vector<KiderSample>& samples,
                     const std::vector<SampleQuery>& queries) {
    std::vector<int> bins;
    for (double l : settings.nm) {
        bins.push_back(KiderBinIndex(l));
        if (bins.back() < 0) Fail("--fit-wavelengths: ", l, " nm is not a Kider bin");
    }
    const SpectralAtmosphere a = LoadSpectralAtmosphere(atmosphere, sets);
    const std::vector<double> values = KiderModelSpectra(
        ParseModelSpec(settings.model), a, settings.nm, queries, settings.monte_carlo);
    ErrorSum e;
    for (size_t q = 0; q < samples.size(); ++q) {
        for (size_t i = 0; i < bins.size(); ++i) {
            e.Add(values[q * bins.size() + i], samples[q].spectrum[bins[i]]);
        }
    }
    return e.RelativeRmse();
}

AerosolFit FitAerosol(const AerosolFitSettings& settings, const std::string& atmosphere,
                      const std::vector<std::string>& sets, const std::vector<KiderSample>& samples,
                      const std::vector<SampleQuery>& queries) {
    for (double l : settings.nm) {
        if (KiderBinIndex(l) < 0) Fail("--fit-wavelengths: ", l, " nm is not a Kider bin");
    }
    if (settings.max_evaluations < 1) Fail("--fit-evaluations must be at least 1");
    AerosolFit fit;
    fit.count = settings.second_lobe ? kAerosolMaxParameters : kAerosolBaseParameters;
    const int n = fit.count;
    // The start: the atmosphere's own values, read off its spectra (beta = the
    // Mie extinction at 1 um times the Mie scale height, alpha from 500 and
    // 1000 nm, the albedo at 550 nm).
    {
        const SpectralAtmosphere a = LoadSpectralAtmosphere(atmosphere, sets);
        const double scale = a.base.mie_density.layers[1].exp_scale;
        const double e1000 = a.mie_extinction.At(1000.0), e500 = a.mie_extinction.At(500.0);
        if (!(scale < 0.0) || !(e1000 > 0.0) || !(e500 > 0.0)) {
            Fail(
                "--fit needs an exponential aerosol (mie_density {\"scale_height\": H}) with a "
                "positive Mie extinction");
        }
        if (a.base.mie_phase_kind == MiePhaseKind::kIsotropic ||
            a.base.mie_phase_kind == MiePhaseKind::kTabulated) {
            Fail("--fit fits mie_phase_g, which a ", MiePhaseKindName(a.base.mie_phase_kind),
                 " mie_phase does not use: fit with a cornette-shanks or henyey-greenstein "
                 "mie_phase");
        }
        fit.start_values[0] = e1000 / -scale;
        fit.start_values[1] = std::log(e500 / e1000) / std::log(2.0);
        fit.start_values[2] = a.mie_scattering.At(550.0) / a.mie_extinction.At(550.0);
        fit.start_values[3] = a.base.mie_phase_g;
        fit.start_values[4] = a.base.mie_phase_g2;
        fit.start_values[5] = a.base.mie_phase_weight2;
        for (int i = 0; i < n; ++i) {
            fit.start_values[i] = std::clamp(fit.start_values[i], kAerosolParameters[i].lower,
                                             kAerosolParameters[i].upper);
        }
    }
    // The --set paths need the Angstrom and albedo forms: one clear error if not.
    LoadSpectralAtmosphere(atmosphere, WithAerosol(sets, fit.start_values, n));
#ifdef ATMOS_HAVE_NLOPT
    Objective objective;
    objective.settings = &settings;
    objective.atmosphere = &atmosphere;
    objective.sets = &sets;
    objective.samples = &samples;
    objective.queries = &queries;
    fit.start_residual = KiderResidual(settings, atmosphere, WithAerosol(sets, fit.start_values, n),
                                       samples, queries);
    nlopt_opt opt = nlopt_create(NLOPT_LN_BOBYQA, static_cast<unsigned>(n));
    objective.opt = opt;
    double lower[kAerosolMaxParameters], upper[kAerosolMaxParameters], step[kAerosolMaxParameters],
        x[kAerosolMaxParameters];
    for (int i = 0; i < n; ++i) {
        lower[i] = kAerosolParameters[i].lower;
        upper[i] = kAerosolParameters[i].upper;
        step[i] = kAerosolParameters[i].step;
        x[i] = fit.start_values[i];
    }
    nlopt_set_lower_bounds(opt, lower);
    nlopt_set_upper_bounds(opt, upper);
    nlopt_set_initial_step(opt, step);
    nlopt_set_min_objective(opt, ObjectiveFunction, &objective);
    nlopt_set_xtol_rel(opt, 1e-3);
    nlopt_set_ftol_rel(opt, 1e-4);
    nlopt_set_maxeval(opt, settings.max_evaluations);
    double value = 0.0;
    const nlopt_result result = nlopt_optimize(opt, x, &value);
    nlopt_destroy(opt);
    if (!objective.error.empty()) Fail(objective.error);
    if (result < 0 && result != NLOPT_ROUNDOFF_LIMITED) {
        Fail("--fit: the optimiser failed (NLopt code ", static_cast<int>(result), ")");
    }
    for (int i = 0; i < n; ++i) fit.values[i] = x[i];
    fit.residual = std::sqrt(value);
    fit.evaluations = objective.evaluations + 1;  // + the start's
    fit.stop = StopReason(result);
    fit.sets = WithAerosol(sets, fit.values, n);
    return fit;
#else
    (void)queries;
    (void)samples;
    Fail("--fit needs NLopt (libnlopt-dev); this build has none");
#endif
}

}  // namespace atmos
