// atmos CLI: `atmos validate kider-2013`: the flags of the validate study
// (studies/validate.h: spectral models against the measured clear sky of Kider
// et al. 2014), errors as CSV.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "atmos/spectral.h"
#include "base/parallel.h"
#include "cli_common.h"
#include "io/output_path.h"
#include "studies/validate.h"

namespace atmos::cli {

namespace {

struct ValidateOptions {
    ValidateConfig config;
    StudyFlags study;
    std::string output, html, values;
    std::string fit_wavelengths;  // empty: config.fit_nm
};

int CmdValidate(ValidateOptions o) {
    ValidateConfig& config = o.config;
    config.atmosphere = o.study.atmosphere;
    config.sets = o.study.sets;
    config.quiet = o.study.quiet;
    if (!o.fit_wavelengths.empty()) config.fit_nm = ParseWavelengths(o.fit_wavelengths);
    config = ResolveValidateConfig(config);
    for (const std::string* path : {&o.output, &o.html, &o.values}) {
        if (!path->empty()) CheckOutputFile(*path);
    }
    ThreadLimit limit(o.study.threads);
    const std::vector<KiderSample> all = ReadValidateData(config);
    const ValidateResult result = RunValidate(config, all, [&](const ValidateResult& r) {
        if (r.models.empty()) {  // the fit: always printed (it is what --fit is for)
            std::fputs(AerosolFitSummary(r, config).c_str(), stderr);
        } else if (!o.study.quiet) {
            std::fputs(ValidateModelSummary(r.models.back(), r.samples.size()).c_str(), stderr);
        }
    });
    if (!o.html.empty()) {
        WriteFileAtomically(o.html, ValidateHtml(result, "atmosphere " + config.atmosphere +
                                                             ", data " + config.data_dir));
    }
    if (!o.values.empty()) WriteFileAtomically(o.values, ValidateValuesCsv(result));
    const std::string csv = ValidateErrorsCsv(result);
    if (o.output.empty()) {
        std::fputs(csv.c_str(), stdout);
    } else {
        WriteFileAtomically(o.output, csv);
    }
    return 0;
}

}  // namespace

Command AddValidateCommand(CLI::App* root) {
    auto o = std::make_shared<ValidateOptions>();
    ValidateConfig& c = o->config;
    CLI::App* cmd = root->add_subcommand(
        "validate",
        "spectral models against a measured sky (kider-2013: Kider et al. 2014's 15 clear-sky "
        "captures, 40 bins 360-818.25 nm); errors as CSV");
    cmd->add_option("dataset", c.dataset, "the measured data set: kider-2013")->required();
    cmd->add_option("--data", c.data_dir, "directory holding kider_ref.csv")->capture_default_str();
    cmd->add_option("--models", c.models, "models, comma-separated (NAME[:OPT=V])")
        ->delimiter(',')
        ->capture_default_str();
    o->study.atmosphere = c.atmosphere;
    AddStudyFlags(cmd, &o->study, false, "no summary on stderr");
    cmd->add_option("--captures", c.captures,
                    "captures to use, comma-separated (e.g. 09:30,11:45); default all 15")
        ->delimiter(',');
    cmd->add_flag("--theory-azimuth", c.theory_azimuth,
                  "use the computed sun azimuth instead of the one estimated from the sky");
    cmd->add_option("--spp", c.spp, "Monte Carlo models: paths per direction")
        ->capture_default_str();
    cmd->add_option("--seed", c.seed, "Monte Carlo models: seed")->capture_default_str();
    cmd->add_option("-o,--output", o->output, "CSV file (default: stdout)");
    cmd->add_option("--values", o->values,
                    "CSV file of the model radiance per direction: model, capture, sample, "
                    "then L_<nm> per bin (W m^-2 sr^-1 nm^-1)");
    cmd->add_option("--html", o->html,
                    "HTML page with one plot per capture: measured and modelled radiance at "
                    "442, 548 and 677 nm along the samples");
    cmd->add_flag("--fit", c.fit,
                  "first fit the aerosol (Angstrom beta and alpha, single-scattering albedo, "
                  "Cornette-Shanks g; bounded least squares, NLopt BOBYQA) with --fit-model at "
                  "--fit-wavelengths on --fit-captures, then evaluate --models with it");
    cmd->add_option("--fit-model", c.fit_model, "--fit: the model evaluated by the fit")
        ->capture_default_str();
    cmd->add_option("--fit-wavelengths", o->fit_wavelengths,
                    "--fit: Kider bins (nm) the fit compares, a list or START:STOP:COUNT "
                    "(default: 371.75,418.75,465.75,512.75,559.75,606.75,653.75,700.75,794.75)");
    cmd->add_option("--fit-captures", c.fit_captures,
                    "--fit: captures the fit compares (default: those of --captures)")
        ->delimiter(',');
    cmd->add_option("--fit-evaluations", c.fit_evaluations,
                    "--fit: the most model evaluations of the optimiser")
        ->capture_default_str();
    cmd->add_flag("--fit-second-lobe", c.fit_second_lobe,
                  "--fit: also fit the second Cornette-Shanks lobe (mie_phase_g2 in [0.5, 0.98], "
                  "mie_phase_weight2 in [0, 0.5])");
    return {cmd, [o] { return CmdValidate(*o); }};
}

}  // namespace atmos::cli
