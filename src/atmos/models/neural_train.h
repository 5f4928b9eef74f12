// atmos: fitting the `neural` model's networks (host side; `atmos fit`).
//
// Source: Leenman's 2025 thesis section 9.6 (Adam, learning rate 0.01; network sizes) and
// 9.1 (training data: transmittance over (h, mu), scattering over
// (h, mu, mu_s, nu), height squared); Kingma & Ba 2015 (Adam, Algorithm 1).
//
// The training data come from a reference model's Sample() (DESIGN.md sample
// contract): transmittance of rays that reach the top of the atmosphere
// (mu above the horizon; the model reverses rays that look down, Leenman's 2025 thesis
// section 9.6.3), and sky radiance per unit irradiance for rays to their end.
// Loss: mean squared difference of ln(y + eps) (a relative error, so that
// twilight and the zenith count alike); eps = 1e-4 for the transmittance and
// the thesis network, 1e-6 for the large one (NeuralFitOptions::loss_epsilon). Training is
// single-threaded and uses the counter-based Rng only, so it is deterministic for a seed.
//
// The networks are small (at most ~1400 weights), so the multilayer
// perceptron, its backpropagation and Adam are written out here (clear loops in
// double) rather than pulling in a linear-algebra or learning library.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "models/neural.h"

namespace atmos {

struct NeuralFitOptions {
    std::string network = "thesis";  // thesis: 4-8-8-3; large: 8-32-32-3, horizon inputs
    // Input encoding of the scattering network (models/neural_net.h): empty =
    // the network's own (thesis: thesis; large: horizon); "extended" is the
    // large network's encoding before issue 15. The thesis network takes only
    // "thesis".
    std::string encoding;
    // Fraction of the scattering samples whose view direction is drawn near
    // the horizon (mu = mu_horizon(h) +- 0.15 v^2, v uniform; issue 15);
    // unset = the network's own (thesis: 0, the thesis's uniform mu;
    // large: 0.25); a set value must lie in [0, 1].
    std::optional<double> horizon_fraction;
    // eps of the scattering network's loss, squared ln((y_hat + eps) / (y + eps)):
    // values well below eps hardly count. Unset = the network's own
    // (thesis: 1e-4, as before; large: 1e-6, issue 15: at 1e-4 the radiance of
    // rays high in the atmosphere, ~1e-6 per unit irradiance, was not fitted:
    // horizontal rays at 99 km came out 3-4x too bright; 1e-7 and 3e-7 fitted
    // them better and the rest of the sky worse, docs/models/neural.md).
    std::optional<double> loss_epsilon;
    int transmittance_samples = 4096;
    int scattering_samples = 16384;
    int transmittance_steps = 3000;
    int scattering_steps = 8000;
    int batch = 128;
    double learning_rate = 0.01;  // Leenman's 2025 thesis section 9.6
    // Beyond the thesis: the step size decays exponentially from
    // learning_rate to final_learning_rate over the steps (equal: constant);
    // the scattering network's only (the transmittance network keeps
    // learning_rate).
    double final_learning_rate = 0.01;
    double holdout = 0.1;  // fraction of samples held out
    uint64_t seed = 1;
    // A Monte Carlo reference's estimate per query (spp, seed).
    MonteCarloSettings reference_monte_carlo;
};

struct NeuralNetFitReport {
    std::vector<double> loss;       // mean batch loss per 1% of the steps
    double train_rms_log = 0.0;     // RMS of ln((y_hat + eps) / (y + eps)) over the train set
    double holdout_rms_log = 0.0;   // same over the held-out set
    double holdout_rel_mean = 0.0;  // mean |y_hat - y| / mean y over the held-out set
};

struct NeuralFitReport {
    NeuralNetFitReport transmittance;
    NeuralNetFitReport scattering;
    double sample_seconds = 0.0;
    double train_seconds = 0.0;
};

// What the options resolve to (the network's own encoding, horizon fraction
// and loss eps where not given).
struct NeuralFitChoices {
    NeuralEncoding encoding = NeuralEncoding::kThesis;
    double horizon_fraction = 0.0;
    double loss_epsilon = 1e-4;
};
// Throws atmos::Error naming the first bad option (FitNeural calls it; the CLI
// too, before the reference's precomputation).
NeuralFitChoices CheckNeuralFitOptions(const NeuralFitOptions& options);

// Samples `reference` (already prepared for `atmosphere`) and fits both networks.
NeuralWeights FitNeural(const Model& reference, const AtmosphereParameters& atmosphere,
                        const NeuralFitOptions& options, NeuralFitReport* report);

}  // namespace atmos
