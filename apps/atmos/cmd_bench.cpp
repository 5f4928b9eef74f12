// atmos CLI: `atmos bench`: the flags of the bench study (studies/bench.h:
// precomputation and rendering timed apart, per model and view), CSV + table.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "atmos/spectral.h"
#include "base/parallel.h"
#include "cli_common.h"
#include "cli_monte_carlo.h"
#include "io/output_path.h"
#include "studies/bench.h"

namespace fs = std::filesystem;

namespace atmos::cli {

namespace {

struct BenchOptions {
    BenchConfig config;
    StudyFlags study;
    std::string size = "480x270";
    std::string output = "out/bench.csv";
    std::string stages_output;  // default: <output stem>_stages.csv
    int repeat = 5, warmup = 1;
    CLI::Option *repeat_flag = nullptr, *warmup_flag = nullptr;
    MonteCarloFlags monte_carlo;
    SpectralFlags spectral;
};

int CmdBench(BenchOptions o) {
    BenchConfig& c = o.config;
    ParseSize(o.size, &c.width, &c.height);
    if (o.repeat_flag->count() > 0) c.repeat = o.repeat;
    if (o.warmup_flag->count() > 0) c.warmup = o.warmup;
    c.atmosphere = o.study.atmosphere;
    c.sets = o.study.sets;
    c.monte_carlo_given = o.monte_carlo.Given();
    c.monte_carlo = o.monte_carlo.Checked();
    CheckSpectralFlagsNeedWavelengths(o.spectral);
    if (!o.spectral.wavelengths.empty()) c.wavelengths = ParseWavelengths(o.spectral.wavelengths);
    c.batching = ParseSpectralBatching(o.spectral);
    c = ResolveBenchConfig(c);
    ThreadLimit limit(o.study.threads);
    const BackendScope backend_scope(ParseBackend(o.study.backend));
    const bool spectral = !c.wavelengths.empty();
    const std::string stages_path = BenchStagesPath(o.output, o.stages_output);
    if (fs::path(o.output).has_parent_path() && !IsStreamOutput(o.output))
        fs::create_directories(fs::path(o.output).parent_path());
    CheckOutputFile(o.output);
    if (!spectral && !stages_path.empty()) CheckOutputFile(stages_path);
    const BenchResult r = RunBench(c, [](const std::string& line) {
        std::fputs(line.c_str(), stdout);
        std::fflush(stdout);
    });
    if (spectral) {
        WriteFileAtomically(o.output, BenchSpectralCsv(r));
        std::printf("wrote %s\n", o.output.c_str());
        return 0;
    }
    WriteFileAtomically(o.output, BenchCsv(r));
    if (!stages_path.empty()) WriteFileAtomically(stages_path, BenchStagesCsv(r));
    std::printf("%s: %d threads, %s, %s; %dx%d, median of %d after %d warm-up%s; wrote %s, %s\n",
                r.backend.c_str(), r.threads, r.cpu.c_str(), r.compiler.c_str(), c.width, c.height,
                r.repeat, r.warmup, r.on_device ? " (kernel time, CUDA events)" : "",
                o.output.c_str(), stages_path.empty() ? "no stages CSV" : stages_path.c_str());
    return 0;
}

}  // namespace

Command AddBenchCommand(CLI::App* root) {
    auto o = std::make_shared<BenchOptions>();
    CLI::App* cmd = root->add_subcommand(
        "bench", "time Prepare() and Render() apart, per model and view (CSV + table)");
    cmd->add_option("--models", o->config.models,
                    "models with their options, NAME[:OPTION=VALUE...] (default: all but the "
                    "reference; e.g. reference:estimator=tracking,bruneton:orders=2; a Monte Carlo "
                    "model's paths per pixel are --spp)")
        ->delimiter(',');
    cmd->add_option("--prepare-repeat", o->config.prepare_repeat,
                    "Prepare() runs per model; the median is reported (default 1)")
        ->capture_default_str();
    cmd->add_option("--stages-output", o->stages_output,
                    "CSV of the precomputation stages (default: <output stem>_stages.csv)");
    cmd->add_option("--views", o->config.views, "views (default: all 12)")->delimiter(',');
    cmd->add_option("--size,-s", o->size, "image size WIDTHxHEIGHT")->capture_default_str();
    cmd->add_option("--quantity", o->config.quantity, "radiance or transmittance")
        ->capture_default_str();
    o->repeat_flag =
        cmd->add_option("--repeat,-n", o->repeat, "timed renders per view (cuda: default 256)")
            ->capture_default_str();
    o->warmup_flag =
        cmd->add_option("--warmup", o->warmup, "untimed renders first (cuda: default 16)")
            ->capture_default_str();
    AddStudyFlags(cmd, &o->study, true, nullptr);
    cmd->add_option("-o,--output", o->output, "CSV file")->capture_default_str();
    AddMonteCarloFlags(cmd, &o->monte_carlo);
    AddSpectralFlags(cmd, &o->spectral, false);
    return {cmd, [o] { return CmdBench(*o); }};
}

}  // namespace atmos::cli
