// atmos CLI: options and helpers shared by the subcommands.
//
// Each subcommand lives in its own file (cmd_*.cpp or main.cpp) and registers
// itself through a function declared here, returning the CLI11 subcommand and
// the function that runs it once parsed.
#pragma once

#include <CLI/CLI.hpp>
#include <chrono>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "atmos/view.h"
#include "harness/spectral_run.h"
#include "studies/common.h"  // RequireQuantity

namespace atmos::cli {

// Options every model-running command takes: --model NAME[:OPTION=VALUE...],
// --atmosphere, --set, --threads, --quiet, --load.
struct CommonOptions {
    std::string model = "naive";
    std::string atmosphere = "earth";
    std::vector<std::string> sets;
    int threads = 0;
    std::string backend = "cpu";  // --backend cpu|cuda (base/parallel.h)
    bool quiet = false;
    std::string load;       // --load DIR: read baked tables instead of Prepare()
    bool no_cache = false;  // --no-cache: neither read nor write the table cache
};

void AddCommonOptions(CLI::App* cmd, CommonOptions* o);
// --strict was given: output values the output guard replaced (NaN, infinity,
// negative; OutputGuardCount()) fail the command instead of a warning.
bool StrictRequested();
// --backend cpu|cuda: where the per-pixel loops run (render, sample, compare,
// bench). The command selects it with a BackendScope (base/parallel.h), which
// fails with one clear error when CUDA is not built in or no device is present.
void AddBackendOption(CLI::App* cmd, std::string* backend);
// The model of --model, parsed and validated (atmos::Error naming the option
// and its range).
ModelSpec GivenModel(const CommonOptions& o);
// "WxH" with 1 <= W, H <= 16384; throws atmos::Error otherwise.
void ParseSize(const std::string& text, int* width, int* height);
double Seconds(std::chrono::steady_clock::time_point since);
// Prepare()s the model for the atmosphere, or loads its baked tables with
// --load; returns the seconds it took.
double PrepareModel(const CommonOptions& o, const AtmosphereParameters& atmosphere, Model* model);
// How a spectral run's wide group is prepared (SpectralBatching::prepare_wide):
// the batches' tables through PrepareModel (the table cache) when the cache
// holds every batch's, else the model's own precomputation of all the
// channels (bruneton: one instead of one per batch; not stored in the cache),
// with the progress bar as PrepareModel shows it.
WidePrepareFunction CliWidePrepare(const CommonOptions& o);

// The flags the studies (compare, bench, validate; studies/) share, declared once:
// --atmosphere, --set, --threads, and --quiet / --backend where the study has them.
// The caller sets the defaults in the struct before adding the flags.
struct StudyFlags {
    std::string atmosphere = "earth";
    std::vector<std::string> sets;
    int threads = 0;
    std::string backend = "cpu";
    bool quiet = false;
};
void AddStudyFlags(CLI::App* cmd, StudyFlags* flags, bool backend, const char* quiet_help);

// --wavelengths, --colour, --white (render, sample, compare, bench): a spectral run
// (harness/spectral_run.h) when `wavelengths` is not empty.
struct SpectralFlags {
    std::string wavelengths;
    std::string colour = "srgb";
    std::string white = "d65";
    std::string batch_seeds = "distinct";      // harness/spectral_run.h BatchSeeds
    std::string batch_layout = "interleaved";  // harness/spectral_run.h BatchLayout
    std::string channel_batches = "wide";      // SpectralBatching::wide: wide or three
};
void AddSpectralFlags(CLI::App* cmd, SpectralFlags* flags, bool colour = true);
// --colour, --white, --batch-seeds and --batch-layout changed from their
// defaults without --wavelengths (they would be ignored): one atmos::Error.
void CheckSpectralFlagsNeedWavelengths(const SpectralFlags& flags);
// --batch-seeds and --batch-layout as parsed values (throws on an unknown name).
SpectralBatching ParseSpectralBatching(const SpectralFlags& flags);

// A registered subcommand: its CLI11 app and what runs it (returns the exit status).
struct Command {
    CLI::App* app = nullptr;
    std::function<int()> run;
};

// Registration functions, one per subcommand file.
Command AddListCommand(CLI::App* root);
Command AddRenderCommand(CLI::App* root);
Command AddMergeCommand(CLI::App* root);
Command AddSampleCommand(CLI::App* root);
Command AddIrradianceCommand(CLI::App* root);
Command AddBakeCommand(CLI::App* root);
Command AddViewerCommand(CLI::App* root);
Command AddFlipCommand(CLI::App* root);
Command AddRmseCommand(CLI::App* root);
// compare records its command line (argc, argv) for the report.
Command AddCompareCommand(CLI::App* root, int argc, char** argv);
Command AddBenchCommand(CLI::App* root);
Command AddLocCommand(CLI::App* root);
Command AddFitCommand(CLI::App* root);
Command AddValidateCommand(CLI::App* root);
Command AddReferenceProvenanceCommand(CLI::App* root);
Command AddSunCommand(CLI::App* root);

}  // namespace atmos::cli
