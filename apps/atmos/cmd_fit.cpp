// atmos CLI: `atmos fit`: fits a fitted model (`neural`: its networks;
// `hosek-wilkie`: its coefficients, models/hosek_wilkie_fit.h) to a reference
// model and writes them as JSON.
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/model.h"
#include "base/library_progress.h"
#include "base/parallel.h"
#include "cli_common.h"
#include "io/output_path.h"
#include "models/hosek_wilkie_fit.h"
#include "models/neural_train.h"
#include "render/progressive.h"

namespace atmos::cli {

namespace {

struct FitOptions {
    std::string model = "neural";
    StudyFlags study;  // --atmosphere, --set, --threads, --quiet
    std::string reference = "bruneton";
    int64_t reference_spp = 64;
    std::string output;
    NeuralFitOptions fit;
    HosekWilkieFitConfig hosek;
    CLI::App* command = nullptr;  // to tell which flags were given
};

// The flags of the neural fit only (refused with --model hosek-wilkie).
constexpr const char* kNeuralOnlyFlags[] = {"--network",
                                            "--encoding",
                                            "--horizon-fraction",
                                            "--loss-epsilon",
                                            "--transmittance-samples",
                                            "--scattering-samples",
                                            "--transmittance-iterations",
                                            "--scattering-iterations",
                                            "--batch",
                                            "--learning-rate",
                                            "--final-learning-rate",
                                            "--holdout"};
constexpr const char* kHosekOnlyFlags[] = {"--sun-elevations", "--view-zeniths", "--view-azimuths",
                                           "--iterations"};

// `atmos fit --model hosek-wilkie`: the library's study, printed.
int CmdFitHosekWilkie(const FitOptions& o) {
    for (const char* flag : kNeuralOnlyFlags) {
        if (o.command->count(flag) > 0) {
            Fail("fit: ", flag, " applies to --model neural only");
        }
    }
    if (o.output.empty()) Fail("fit: -o FILE.json is required");
    HosekWilkieFitConfig config = o.hosek;
    config.reference = o.reference;
    config.reference_monte_carlo =
        MakeMonteCarloSettings(o.reference_spp, o.fit.seed, 0, "--reference-spp");
    ResolveHosekWilkieFitConfig(config);
    CheckOutputFile(o.output);
    ThreadLimit limit(o.study.threads);
    const LibraryProgressScope progress(!o.study.quiet);
    const AtmosphereParameters atmosphere = LoadAtmosphere(o.study.atmosphere, o.study.sets);
    const HosekWilkieFitResult result = RunHosekWilkieFit(config, o.study.atmosphere, atmosphere);
    WriteHosekWilkieFit(result, o.output);
    if (!o.study.quiet) {
        const HosekWilkieFitReport& r = result.report;
        std::printf(
            "reference %s prepared in %.2f s; %d samples x 3 channels in %.2f s; fitted in "
            "%.2f s (%d evaluations)\n",
            o.reference.c_str(), r.prepare_seconds, r.samples, r.sample_seconds, r.fit_seconds,
            r.evaluations);
        std::printf(
            "relative RMS error R G B %.4f %.4f %.4f (all %.4f; largest %.3f %.3f %.3f); free "
            "parameters per elevation %.4f %.4f %.4f\n",
            r.relative_rms[0], r.relative_rms[1], r.relative_rms[2], r.relative_rms_all,
            r.max_relative[0], r.max_relative[1], r.max_relative[2], r.stage1_rms[0],
            r.stage1_rms[1], r.stage1_rms[2]);
        if (r.holdout_rms_all >= 0.0) {
            std::printf("held-out grid: relative RMS error %.4f\n", r.holdout_rms_all);
        }
        if (r.published_rms_all >= 0.0) {
            std::printf(
                "published coefficients (colour=spectral) on the same samples: relative RMS "
                "%.4f at turbidity %.1f; with each channel's best factor %.4f at turbidity "
                "%.1f\n",
                r.published_rms_all, r.published_turbidity, r.published_shape_rms_all,
                r.published_shape_turbidity);
        }
        std::printf("wrote %s\n", o.output.c_str());
    }
    return 0;
}

int CmdFit(const FitOptions& o) {
    if (FitsHosekWilkieForm(o.model)) return CmdFitHosekWilkie(o);
    for (const char* flag : kHosekOnlyFlags) {
        if (o.command->count(flag) > 0)
            Fail("fit: ", flag, " applies to --model hosek-wilkie only");
    }
    bool trainable = false;  // a registered model that declares it (ModelCapabilities)
    for (const ModelInfo& info : ListModels())
        trainable |= info.name == o.model && info.capabilities.trainable;
    if (!trainable) {
        Fail("fit: only --model neural or hosek-wilkie can be fitted, got '", o.model, "'");
    }
    if (o.reference == o.model) Fail("fit: --reference cannot be the model being fitted");
    if (o.output.empty()) Fail("fit: -o FILE.json is required");
    CheckOutputFile(o.output);     // before the fit (io/output_path.h)
    CheckNeuralFitOptions(o.fit);  // before the reference's precomputation
    ThreadLimit limit(o.study.threads);
    // Progress bars (the reference's precomputation and samples, the training)
    // on a terminal for work over a second, unless --quiet.
    const LibraryProgressScope progress(!o.study.quiet);
    const AtmosphereParameters atmosphere = LoadAtmosphere(o.study.atmosphere, o.study.sets);
    const ModelSpec spec = ParseModelSpec(o.reference);
    if (spec.name == o.model) Fail("fit: --reference cannot be the model being fitted");
    std::unique_ptr<Model> reference = CreateModel(spec);
    // The fit learns radiance and transmittance everywhere (ground to space, sun
    // below the horizon): a reference without them would train on nonsense.
    const ModelCapabilities& rc = reference->Info().capabilities;
    if (!rc.radiance || !rc.transmittance || !rc.space_views || !rc.sun_below_horizon) {
        Fail("fit: --reference ", spec.name,
             " cannot be a reference (it needs radiance and transmittance for every camera and "
             "sun; `atmos list ",
             spec.name, "` shows its validity)");
    }
    NeuralFitOptions fit = o.fit;
    fit.reference_monte_carlo = MakeMonteCarloSettings(o.reference_spp, 0, 0, "--reference-spp");
    const auto t0 = std::chrono::steady_clock::now();
    reference->Prepare(atmosphere);
    const double prepare_s = Seconds(t0);
    NeuralFitReport report;
    NeuralWeights w = FitNeural(*reference, atmosphere, fit, &report);
    // Record where the data came from.
    {
        std::string t = w.training_json;
        const std::string extra =
            "\"reference\":\"" + o.reference + "\",\"atmosphere\":\"" + o.study.atmosphere + "\",";
        if (t.size() >= 2 && t.front() == '{') t.insert(1, extra);
        w.training_json = t;
    }
    const std::string text = NeuralWeightsToJson(w);
    WriteFileAtomically(o.output, text);
    if (!o.study.quiet) {
        auto line = [](const char* name, const NeuralNetFitReport& r) {
            std::printf(
                "%-13s loss %.5g -> %.5g; RMS ln-error train %.4f, held-out %.4f; held-out mean "
                "|error| / mean value %.4f\n",
                name, r.loss.empty() ? 0.0 : r.loss.front(), r.loss.empty() ? 0.0 : r.loss.back(),
                r.train_rms_log, r.holdout_rms_log, r.holdout_rel_mean);
        };
        std::printf("reference %s prepared in %.2f s; sampled in %.2f s; trained in %.2f s\n",
                    o.reference.c_str(), prepare_s, report.sample_seconds, report.train_seconds);
        line("transmittance", report.transmittance);
        line("scattering", report.scattering);
        std::printf("wrote %s\n", o.output.c_str());
    }
    return 0;
}

}  // namespace

Command AddFitCommand(CLI::App* root) {
    auto o = std::make_shared<FitOptions>();
    CLI::App* cmd = root->add_subcommand(
        "fit",
        "fit the neural model's networks or the hosek-wilkie form to a reference model; write "
        "the weights or coefficients as JSON");
    o->command = cmd;
    cmd->add_option("--model", o->model, "model to fit: neural or hosek-wilkie")
        ->capture_default_str();
    AddStudyFlags(cmd, &o->study, false, "print nothing");
    cmd->add_option("--reference", o->reference,
                    "model sampled for the training data, NAME[:OPTION=VALUE...]: bruneton "
                    "(fast) or reference (path tracer)")
        ->capture_default_str();
    cmd->add_option("--reference-spp", o->reference_spp,
                    "paths per query of a Monte Carlo reference (the path tracer)")
        ->capture_default_str();
    cmd->add_option("--network", o->fit.network,
                    "thesis (4-8-8-3 scattering) or large (8-32-32-3, horizon inputs)")
        ->capture_default_str();
    cmd->add_option("--encoding", o->fit.encoding,
                    "scattering inputs: thesis | extended | horizon (default: the network's "
                    "own; large: horizon, extended: before issue 15)");
    cmd->add_option_function<double>(
        "--horizon-fraction", [o](const double& v) { o->fit.horizon_fraction = v; },
        "fraction of scattering samples viewing near the horizon (default: thesis "
        "0, large 0.25)");
    cmd->add_option_function<double>(
        "--loss-epsilon", [o](const double& v) { o->fit.loss_epsilon = v; },
        "eps of the scattering loss ln((y_hat + eps) / (y + eps)) (default: "
        "thesis 1e-4, large 1e-6)");
    cmd->add_option("--transmittance-samples", o->fit.transmittance_samples)->capture_default_str();
    cmd->add_option("--scattering-samples", o->fit.scattering_samples)->capture_default_str();
    cmd->add_option("--transmittance-iterations", o->fit.transmittance_steps,
                    "Adam iterations of the transmittance network")
        ->capture_default_str();
    cmd->add_option("--scattering-iterations", o->fit.scattering_steps,
                    "Adam iterations of the scattering network")
        ->capture_default_str();
    cmd->add_option("--batch", o->fit.batch, "mini-batch size")->capture_default_str();
    cmd->add_option("--learning-rate", o->fit.learning_rate, "Adam step size")
        ->capture_default_str();
    cmd->add_option("--final-learning-rate", o->fit.final_learning_rate,
                    "the scattering network's step size at its last iteration (exponential "
                    "decay; equal to --learning-rate: constant, as the thesis)")
        ->capture_default_str();
    cmd->add_option("--holdout", o->fit.holdout, "fraction of samples held out")
        ->capture_default_str();
    cmd->add_option("--seed", o->fit.seed,
                    "seed of sampling, initialisation, batches (hosek-wilkie: of a Monte Carlo "
                    "reference)")
        ->capture_default_str();
    cmd->add_option("--sun-elevations", o->hosek.sun_elevations,
                    "hosek-wilkie: sun elevations sampled, 90 deg ((k + 1) / N)^3")
        ->capture_default_str();
    cmd->add_option("--view-zeniths", o->hosek.view_zeniths,
                    "hosek-wilkie: strata of cos(zenith) per elevation")
        ->capture_default_str();
    cmd->add_option("--view-azimuths", o->hosek.view_azimuths,
                    "hosek-wilkie: strata of azimuth from the sun (0-180 deg) per elevation")
        ->capture_default_str();
    cmd->add_option("--iterations", o->hosek.iterations,
                    "hosek-wilkie: Levenberg-Marquardt iterations per stage")
        ->capture_default_str();
    cmd->add_option("-o,--output", o->output, "weights or coefficients JSON to write")->required();
    return {cmd, [o] { return CmdFit(*o); }};
}

}  // namespace atmos::cli
