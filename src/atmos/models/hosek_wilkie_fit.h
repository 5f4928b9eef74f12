// atmos model `hosek-wilkie`: the form fitted to any atmosphere (`atmos fit
// --model hosek-wilkie`, issue 34 item 5; docs/models/hosek-wilkie.md "Fitted to
// any atmosphere"). It lives beside the model, as neural_train.h beside
// `neural`: it needs the form's internals (hosek_wilkie.h), which the layers
// above the models do not see. Shape of a study: a config whose member
// initialisers are the defaults, a check, a run returning plain data, a writer.
//
// The nine-parameter form F(theta, gamma) of Hosek & Wilkie 2012 (eq. 8-9) and
// its radiance scale L_M, each a quintic Bezier of six control points over
// x = (elevation / (pi/2))^(1/3) (the authors' structure), fitted per channel to
// a reference model's radiance at ground views, in relative error (m / y - 1):
//   samples: K sun elevations at x_k = (k + 1) / K (elevation 90 deg x_k^3, so
//     denser near the horizon, as the Bezier's own parameter is), and per
//     elevation a grid of views stratified in solid angle: cos(theta) at the
//     midpoints of Z strata of [0, 1], azimuth from the sun at the midpoints of
//     A strata of [0, 180] deg (the sky is symmetric about the sun's vertical);
//     so the objective is the relative RMSE over the sky;
//   1. per elevation (from the zenith sun down), L_M fixed to the grid's mean
//     radiance and the nine parameters fitted by Levenberg-Marquardt, from the
//     published RGB coefficients (T = 3, albedo 0) and from the neighbouring
//     elevation's answer (kept unless the published start is twice as good);
//   2. A, B, E, H: their six control points by linear least squares over the
//     elevations; L_M and C, D, F, G, I, which enter the form only as the
//     products L_M C, ..., L_M I: alternating least squares for quintics whose
//     products match stage 1's;
//   3. all 60 control points of a channel by Levenberg-Marquardt on every
//     sample, from stage 2 and from the published points (L_M scaled by the
//     data's best factor); at each trial point the 30 control points of
//     C, D, F, G, I, in which the form is linear once the others are fixed,
//     are solved for exactly, and L_M's are kept >= 0; the better end is kept.
// The fit is serial and the reference's answers do not depend on the thread
// count, so the coefficients are the same bytes for any --threads.
#pragma once

#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "models/hosek_wilkie_coefficients.h"

namespace atmos {

struct HosekWilkieFitConfig {
    std::string reference = "bruneton";        // the model spec sampled
    MonteCarloSettings reference_monte_carlo;  // a Monte Carlo reference's spp and seed
    int sun_elevations = 30;                   // K, in [8, 200]
    int view_zeniths = 16;                     // Z, in [4, 256]
    int view_azimuths = 24;                    // A, in [4, 512]
    int iterations = 200;  // Levenberg-Marquardt iterations per stage, in [1, 10000]
    // Also sample the points halfway between the grid's (in elevation's x,
    // cos(theta) and azimuth) and report the fit's error there.
    bool holdout = true;
    // Also score the published coefficients (colour=spectral, the atmosphere's
    // albedo) on the same samples at turbidity 1, 1.5, ..., 10.
    bool score_published = true;
};

// Checks the ranges (one atmos::Error naming the field) and the reference
// spec (a model that gives radiance; not a transmittance model).
void ResolveHosekWilkieFitConfig(const HosekWilkieFitConfig& config);

// Whether `model` (a model spec) is this form, the one RunHosekWilkieFit fits:
// decided by the model's type, not its name (false for a spec that does not parse).
bool FitsHosekWilkieForm(const std::string& model);

// The reference's radiance on the fit's grid (elevation-major, then zenith,
// then azimuth).
struct HosekWilkieFitData {
    int elevations = 0, zeniths = 0, azimuths = 0;
    std::vector<double> elevation;     // radians, per elevation
    std::vector<SampleQuery> queries;  // elevations x zeniths x azimuths
    std::vector<double> value;         // [query * 3 + channel]
};

// The grid's queries (shifted: the hold-out grid).
HosekWilkieFitData HosekWilkieFitGrid(const HosekWilkieFitConfig& config, bool shifted);
// Fills data->value from `reference` (already prepared).
void SampleHosekWilkieFitData(const Model& reference, const MonteCarloSettings& monte_carlo,
                              HosekWilkieFitData* data);

struct HosekWilkieFitReport {
    int samples = 0;              // per channel
    int skipped = 0;              // samples with a reference value <= 0 (left out)
    double stage1_rms[3] = {};    // relative RMS, free parameters per elevation
    double relative_rms[3] = {};  // relative RMS of the Bezier form on the samples
    double relative_rms_all = 0;  // over the three channels
    double max_relative[3] = {};  // largest |m / y - 1|
    double holdout_rms_all = -1;  // on the shifted grid (< 0: not measured)
    // The published coefficients on the same samples (< 0: not measured).
    double published_turbidity = -1, published_rms_all = -1;
    // The same with each channel's best constant factor (the shape alone).
    double published_shape_turbidity = -1, published_shape_rms_all = -1;
    double prepare_seconds = 0, sample_seconds = 0, fit_seconds = 0;
    int evaluations = 0;  // Levenberg-Marquardt cost evaluations, all stages
};

struct HosekWilkieFitResult {
    HosekWilkieCoefficients coefficients;
    HosekWilkieFitReport report;
};

// The fit of the form to `data` (stages 1-3); fills coefficients.ctrl and the
// report's residuals (not the reference, atmosphere, holdout or published).
HosekWilkieFitResult FitHosekWilkieForm(const HosekWilkieFitData& data,
                                        const HosekWilkieFitConfig& config);

// The relative errors (m / y - 1, the model's output clamped at 0 as it
// renders) of `ctrl` on `data`: RMS per channel and over all, and the largest.
void HosekWilkieFitError(const double ctrl[3][6][10], const HosekWilkieFitData& data, double rms[3],
                         double* rms_all, double max_abs[3]);

// The whole study: creates and prepares the reference for `atmosphere`
// (`atmosphere_name` as given, recorded in the file), samples, fits, scores
// the hold-out grid and the published coefficients.
HosekWilkieFitResult RunHosekWilkieFit(const HosekWilkieFitConfig& config,
                                       const std::string& atmosphere_name,
                                       const AtmosphereParameters& atmosphere);

// Writes the coefficient file (models/hosek_wilkie_coefficients.h) atomically.
void WriteHosekWilkieFit(const HosekWilkieFitResult& result, const std::string& path);

}  // namespace atmos
