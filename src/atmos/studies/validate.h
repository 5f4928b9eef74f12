// atmos studies: the validate study (`atmos validate kider-2013`, Python
// atmos.validate): spectral models against the measured clear sky of Kider et
// al. 2014 (harness/kider.h), optionally after an aerosol fit
// (studies/aerosol_fit.h). docs/harness.md "Measured sky".
//
// The shape of every study (docs/architecture.md "Studies"): a config whose
// member initialisers are the defaults, ResolveValidateConfig (checks and
// policy, one atmos::Error naming the field), RunValidate (plain data, no file
// output; progress through a callback) and writers that only read the result.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "harness/kider.h"
#include "studies/aerosol_fit.h"

namespace atmos {

struct ValidateConfig {
    std::string dataset = "kider-2013";                       // the only data set
    std::string data_dir = "../shared/data/kider-2013";       // holds kider_ref.csv
    std::vector<std::string> models = {"naive", "bruneton"};  // model specs
    std::string atmosphere = "kider-2013";                    // preset name or JSON file
    std::vector<std::string> sets;                            // FIELD=VALUE overrides
    std::vector<std::string> captures;                        // e.g. "09:30"; empty: all 15
    bool theory_azimuth = false;  // the computed sun azimuth, not the one estimated from the sky
    int64_t spp = 256;            // Monte Carlo models: paths per direction
    int64_t seed = 0;             // Monte Carlo models: seed
    // The aerosol fit: fitted on fit_captures (empty: `captures`) at fit_nm with
    // fit_model, then every model evaluated with it. The path tracer (spp paths,
    // fixed seed): 8x faster than hillaire on this job and inside its validity
    // (hillaire's f_ms exceeds 0.5 here). Nine bins spread over 372-795 nm, off
    // the O2 / H2O bands and the strongest solar lines.
    bool fit = false;
    std::string fit_model = "reference";
    std::vector<double> fit_nm = {371.75, 418.75, 465.75, 512.75, 559.75,
                                  606.75, 653.75, 700.75, 794.75};
    std::vector<std::string> fit_captures;
    int fit_evaluations = 40;
    bool fit_second_lobe = false;
    bool quiet = true;  // false: the fit prints each evaluation on stderr
};

// Checks the config (data set, model specs, the fit's model and bins); throws
// atmos::Error naming the field.
ValidateConfig ResolveValidateConfig(ValidateConfig config);

// One row of the errors table: a model over one (capture, scope, region) set.
// capture "all" pools the captures; scope is a band ("360-500nm", ...,
// "360-720nm", "all") or one bin ("<nm>nm", capture and region "all").
struct ValidateErrorRow {
    std::string capture, scope, region;
    ErrorSum error;
    double model_sum = 0.0;  // the model's values summed over the set
};

struct ValidateModelResult {
    std::string model;           // the spec as given
    std::vector<double> values;  // [sample * bins + i]: W m^-2 sr^-1 nm^-1; NaN: not answered
    size_t bins_answered = 0;    // bins the model's spectral form covers (hosek-wilkie: 320-720 nm)
    double seconds = 0.0;
    std::vector<ValidateErrorRow> rows;  // the bands' rows (pooled capture last), then the bins'
    // The row of (capture, scope, region), or nullptr.
    const ValidateErrorRow* Find(const std::string& capture, const std::string& scope,
                                 const std::string& region) const;
};

struct ValidateResult {
    std::vector<KiderSample> samples;  // the samples evaluated (sample 0 excluded)
    std::vector<double> nm;            // the 40 Kider bins
    bool fitted = false;
    AerosolFit fit;          // when fitted
    size_t fit_samples = 0;  // directions of the fit
    double fit_seconds = 0.0;
    std::vector<std::string> sets;  // the overrides the models ran with (+ the fit's)
    std::vector<ValidateModelResult> models;
};

// Runs the study on the measured samples (ReadKiderCsv of config.data_dir's
// kider_ref.csv: ReadValidateData). `progress` (optional) sees the result so far
// after the fit (no models yet) and after each model (the last one new). Throws
// atmos::Error.
ValidateResult RunValidate(const ValidateConfig& config, const std::vector<KiderSample>& all,
                           const std::function<void(const ValidateResult&)>& progress = {});
std::vector<KiderSample> ReadValidateData(const ValidateConfig& config);

// Writers (they only read the result).
// The errors CSV: model, capture, scope, region, rel_rmse_percent, ...
std::string ValidateErrorsCsv(const ValidateResult& result);
// The model radiance per direction: model, capture, sample, L_<nm>...
std::string ValidateValuesCsv(const ValidateResult& result);
// One SVG plot per capture at 442, 548 and 677 nm (measured solid, models dashed).
std::string ValidateHtml(const ValidateResult& result, const std::string& title);
// The fit's summary lines (what `validate --fit` prints on stderr).
std::string AerosolFitSummary(const ValidateResult& result, const ValidateConfig& config);
// A model's summary lines (relative RMSE overall, in clear-sky-models' range, per region).
std::string ValidateModelSummary(const ValidateModelResult& model, size_t directions);

}  // namespace atmos
