// atmos studies: the bench study (`atmos bench`, Python atmos.bench):
// precomputation and rendering timed apart, per model and view.
//
// Per model: Prepare() timed prepare_repeat times (the first run on a device
// also pays for loading its kernels), the median reported. Per view: `warmup`
// renders, then `repeat` timed renders; the median, min and max, and megapixels
// per second of the median.
//
// On the CUDA backend the render kernel alone is timed on the device, between
// CUDA events, as the one launch log records it (the "render" entries of
// StageLogScope, render/stages.h): warmup untimed renders (default 16), then
// repeat timed ones (default 256, as the thesis); table uploads (once per model:
// its tables stay on the device) and the copy back are excluded.
//
// Precomputation stages (render/stages.h) are logged per Prepare() and per
// render (Hillaire's per-frame tables): the median over the runs of each stage's
// kernel time (CPU: wall time of its ParallelFor; CUDA: between events) and of
// its whole call (CUDA: with the copies).
//
// Monte Carlo models (the reference, only when named in `models`) are timed as
// whole renders (wall time, both backends; repeat default 3 on cuda) and their
// paths per second (width x height x spp / median) reported.
//
// With wavelengths: per model and view, the RGB run (Prepare + one render)
// against the spectral run (every batch's Prepare + render), wall time, median
// of `repeat`.
//
// The run uses the backend of the caller's BackendScope (base/parallel.h).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "atmos/model.h"
#include "harness/spectral_run.h"

namespace atmos {

struct BenchConfig {
    // Specs; empty: every model that produces the quantity and is not Monte Carlo
    // (with wavelengths: and has a spectral form).
    std::vector<std::string> models;
    std::vector<std::string> views;  // empty: all 12
    int width = 480, height = 270;
    std::string quantity = "radiance";  // or transmittance
    std::string atmosphere = "earth";   // preset name or JSON file
    std::vector<std::string> sets;      // FIELD=VALUE overrides
    // Timed and untimed renders per view; unset: 5 and 1 on the CPU, 256 and 16
    // on a device (Monte Carlo models on a device: 3 and 1).
    std::optional<int> repeat, warmup;
    int prepare_repeat = 1;           // Prepare() runs per model, the median reported
    MonteCarloSettings monte_carlo;   // Monte Carlo models' estimate
    bool monte_carlo_given = false;   // set by the caller: an error unless a model is Monte Carlo
    std::vector<double> wavelengths;  // non-empty: the spectral bench
    SpectralBatching batching;
};

// The defaults and the checks; throws atmos::Error naming the flag. Fills
// `models` when empty.
BenchConfig ResolveBenchConfig(BenchConfig config);

struct BenchRow {
    std::string model, view;
    int width = 0, height = 0;
    Quantity quantity = Quantity::kRadiance;
    int threads = 0;
    double prepare_s = 0.0;
    double render_median_s = 0.0, render_min_s = 0.0, render_max_s = 0.0;
    int runs = 0;
    double megapixels_per_s = 0.0;
    double paths_per_s = 0.0;  // Monte Carlo models, else 0
    std::string cpu, compiler, backend;
};

struct BenchStage {
    std::string model, view;  // view "prepare": the model's Prepare()
    std::string name, backend;
    int64_t items = 0;
    int runs = 0;
    double kernel_median_ms = 0.0, total_median_ms = 0.0;
    int64_t bytes_up = 0, bytes_down = 0;  // of the last run
};

struct BenchSpectralRow {
    std::string model, view;
    int width = 0, height = 0;
    size_t wavelengths = 0, batches = 0;
    int threads = 0;
    double rgb_prepare_s = 0.0, rgb_render_s = 0.0;
    double spectral_prepare_s = 0.0, spectral_render_s = 0.0;
    int repeat = 0;
};

struct BenchResult {
    std::vector<BenchRow> rows;
    std::vector<BenchStage> stages;
    std::vector<BenchSpectralRow> spectral_rows;  // the spectral bench
    int threads = 0;
    std::string cpu, compiler, backend;
    int repeat = 0, warmup = 0;  // of the models that are not Monte Carlo
    bool on_device = false;
};

// Runs the bench. `progress` (optional) gets the table's lines as they are
// measured (what `atmos bench` prints). Throws atmos::Error.
BenchResult RunBench(const BenchConfig& config,
                     const std::function<void(const std::string&)>& progress = {});

// Writers (they only read the result): the CSV, the stages CSV, the spectral CSV.
std::string BenchCsv(const BenchResult& result);
std::string BenchStagesCsv(const BenchResult& result);
std::string BenchSpectralCsv(const BenchResult& result);
// The table's lines: the header, one row, one stage, one spectral row, the summary.
std::string BenchHeaderText();
std::string BenchRowText(const BenchRow& row);
std::string BenchStageText(const BenchStage& stage);
std::string BenchSpectralText(const BenchSpectralRow& row);

// Where the stages CSV goes: `stages_output` when given, else beside `output`
// (STEM_stages.csv), or "" when `output` is a stream (/dev/null, stdout, a FIFO).
std::string BenchStagesPath(const std::string& output, const std::string& stages_output);

}  // namespace atmos
