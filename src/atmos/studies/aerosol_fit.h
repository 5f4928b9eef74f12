// atmos studies: the aerosol fit of the validate study (`atmos validate kider-2013
// --fit`, studies/validate.h): the aerosol of an atmosphere (Angstrom beta and
// alpha, single-scattering albedo, Cornette-Shanks g) fitted to the measured sky
// by bounded least squares (docs/harness.md "Aerosol fit").
#pragma once

#include <string>
#include <vector>

#include "atmos/model.h"
#include "atmos/spectral.h"
#include "harness/kider.h"

namespace atmos {

// The parameters, their bounds and the --set field each one writes: the four
// of every fit, then the second Mie lobe's two (--fit-second-lobe).
struct AerosolParameter {
    const char* field;  // e.g. "mie_extinction.angstrom.beta"
    const char* name;   // e.g. "beta"
    double lower, upper, step;
};
constexpr int kAerosolBaseParameters = 4;
constexpr int kAerosolMaxParameters = 6;
constexpr AerosolParameter kAerosolParameters[kAerosolMaxParameters] = {
    {"mie_extinction.angstrom.beta", "beta", 0.005, 0.3, 0.01},
    {"mie_extinction.angstrom.alpha", "alpha", 0.0, 2.5, 0.2},
    {"mie_scattering.single_scattering_albedo", "albedo", 0.5, 1.0, 0.05},
    {"mie_phase_g", "g", 0.0, 0.95, 0.05},
    {"mie_phase_g2", "g2", 0.5, 0.98, 0.02},
    {"mie_phase_weight2", "weight2", 0.0, 0.5, 0.05},
};

struct AerosolFitSettings {
    std::string model = "reference";  // a model spec; Monte Carlo models use `monte_carlo`
    MonteCarloSettings monte_carlo;
    std::vector<double> nm;  // Kider bins (nm) the fit compares
    int max_evaluations = 40;
    bool second_lobe = false;  // also fit mie_phase_g2 and mie_phase_weight2
    bool quiet = false;
};

struct AerosolFit {
    int count = kAerosolBaseParameters;  // the parameters fitted (4, or 6 with the second lobe)
    double values[kAerosolMaxParameters] = {};  // kAerosolParameters order
    double start_values[kAerosolMaxParameters] = {};
    double residual = 0.0;        // relative RMSE (RMSE / mean measured) on the fit's set
    double start_residual = 0.0;  // the same with the atmosphere as given
    int evaluations = 0;
    std::string stop;  // why the optimiser stopped
    // `sets` plus the fitted --set overrides (FIELD=VALUE, %.6g).
    std::vector<std::string> sets;
};

// The spectral radiance validate scores, [query * nm.size() + i]: `spec` sampled
// at the queries and Kider bins with a plain Prepare(), in the batches that keep
// each wavelength's own value least noisy (kPerWavelengthBatching); the fit and
// the evaluation both use it.
std::vector<double> KiderModelSpectra(const ModelSpec& spec, const SpectralAtmosphere& atmosphere,
                                      const std::vector<double>& nm,
                                      const std::vector<SampleQuery>& queries,
                                      const MonteCarloSettings& monte_carlo);

// The relative RMSE of `model` with the atmosphere `atmosphere` + `sets` against
// the measured `samples` at the Kider bins `nm`.
double KiderResidual(const AerosolFitSettings& settings, const std::string& atmosphere,
                     const std::vector<std::string>& sets, const std::vector<KiderSample>& samples,
                     const std::vector<SampleQuery>& queries);

// Bounded least squares (NLopt's BOBYQA, derivative-free) of the four parameters
// (six with settings.second_lobe) from the atmosphere's own values. Throws atmos::Error when the
// atmosphere has no Angstrom aerosol or the build has no NLopt.
AerosolFit FitAerosol(const AerosolFitSettings& settings, const std::string& atmosphere,
                      const std::vector<std::string>& sets, const std::vector<KiderSample>& samples,
                      const std::vector<SampleQuery>& queries);

// The Kider bin index of a wavelength (-1 when it is not one of the 40 bins).
int KiderBinIndex(double nm);

}  // namespace atmos
