// atmos CLI: `atmos bench`: precomputation and rendering timed apart, per model and view.
//
// Per model: Prepare() timed once (cold). Per view: `warmup` renders, then
// `repeat` timed renders; the median, min and max, and megapixels per second
// of the median. Thread count, CPU and compiler go in every CSV row.
//
// --backend cuda: the render kernel alone is timed on the device, between CUDA
// events, as the one launch log records it (the "render" entries of
// StageLogScope, render/stages.h): `warmup` untimed renders (default 16), then
// `repeat` timed ones (default 256, as the thesis); table uploads (once per
// model: its tables stay on the device) and the copy back are excluded. Prepare() runs on the
// chosen backend:
// --prepare-repeat times (default 1; the first run on a device also pays for
// loading its kernels, so ask for a few), the median reported.
//
// Precomputation stages (render/stages.h) are logged per Prepare() and per
// render (Hillaire's per-frame tables): the median over the runs of each
// stage's kernel time (CPU: wall time of its ParallelFor; CUDA: between events)
// and of its whole call (CUDA: with the copies) go to the stages CSV
// (`--stages-output`, default beside the CSV: <stem>_stages.csv).
//
// Monte Carlo models (the reference, only when named in --models) are timed as
// whole renders (wall time, both backends, --repeat default 3 on cuda) and
// their paths per second (width x height x spp / median) go in the CSV.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/model.h"
#include "atmos/spectral.h"
#include "atmos/view.h"
#include "base/parallel.h"
#include "cli_common.h"
#include "cli_monte_carlo.h"
#include "harness/machine.h"
#include "harness/spectral_run.h"
#include "io/output_path.h"
#include "render/stages.h"

namespace fs = std::filesystem;

namespace atmos::cli {

namespace {

struct BenchOptions {
    std::vector<std::string> models, views, sets;
    std::string size = "480x270";
    std::string atmosphere = "earth";
    std::string output = "out/bench.csv";
    std::string quantity = "radiance";
    int repeat = 5;
    int warmup = 1;
    int threads = 0;
    std::string backend = "cpu";
    int prepare_repeat = 1;
    std::string stages_output;
    CLI::Option* repeat_flag = nullptr;
    CLI::Option* warmup_flag = nullptr;
    MonteCarloFlags monte_carlo;
    SpectralFlags spectral;
};

double Median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Per stage name, in first-seen order: its runs' kernel and total times.
struct StageRuns {
    std::string name, backend;
    int64_t items = 0;
    std::vector<double> kernel_ms, total_ms;
    int64_t bytes_up = 0, bytes_down = 0;  // of the last run
};
void AddStageRuns(const std::vector<StageTime>& log, std::vector<StageRuns>* runs) {
    for (const StageTime& t : log) {
        StageRuns* r = nullptr;
        for (StageRuns& existing : *runs) {
            if (existing.name == t.name && existing.items == t.items) r = &existing;
        }
        if (!r) {
            runs->push_back({t.name, t.backend, t.items, {}, {}});
            r = &runs->back();
        }
        r->kernel_ms.push_back(t.kernel_ms);
        r->total_ms.push_back(t.total_ms);
        r->bytes_up = t.bytes_up;
        r->bytes_down = t.bytes_down;
    }
}

std::string CsvField(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
}

// --wavelengths: per model and view, the RGB run (Prepare + one render) against the
// spectral run (every batch's Prepare + render), wall time, median of --repeat.
int BenchSpectral(const BenchOptions& o, const std::vector<ModelSpec>& models,
                  const std::vector<View>& views, int width, int height, Quantity quantity,
                  const MonteCarloSettings& monte_carlo) {
    const std::vector<double> nm = ParseWavelengths(o.spectral.wavelengths);
    const SpectralAtmosphere spectral = LoadSpectralAtmosphere(o.atmosphere, o.sets);
    const AtmosphereParameters rgb = LoadAtmosphere(o.atmosphere, o.sets);
    if (fs::path(o.output).has_parent_path())
        fs::create_directories(fs::path(o.output).parent_path());
    CheckOutputFile(o.output);
    TextOutput csv(o.output);  // written at the end, atomically
    csv << "model,view,width,height,wavelengths,batches,threads,rgb_prepare_s,rgb_render_s,"
           "spectral_prepare_s,spectral_render_s,prepare_ratio,render_ratio,repeat\n";
    for (const ModelSpec& spec : models) {
        const ModelInfo info = GetModelInfo(spec.name);
        if (o.models.empty() && !HasSpectralForm(info)) continue;
        RequireSpectralModel(info);
        for (const View& view : views) {
            RenderRequest request = ViewRequest(view, width, height, quantity, monte_carlo);
            std::vector<double> rp, rr, sp, sr;
            for (int i = 0; i < o.repeat; ++i) {
                std::unique_ptr<Model> model = CreateModel(spec);
                auto t0 = std::chrono::steady_clock::now();
                model->Prepare(rgb);
                rp.push_back(Seconds(t0));
                Image image;
                t0 = std::chrono::steady_clock::now();
                model->Render(request, &image);
                rr.push_back(Seconds(t0));
                double prepare_s = 0.0;
                t0 = std::chrono::steady_clock::now();
                RenderSpectral(
                    spec, spectral, nm, request,
                    [&](const AtmosphereParameters& a, Model* m) {
                        const auto p0 = std::chrono::steady_clock::now();
                        m->Prepare(a);
                        prepare_s += Seconds(p0);
                    },
                    ParseSpectralBatching(o.spectral));
                const double total = Seconds(t0);
                sp.push_back(prepare_s);
                sr.push_back(total - prepare_s);
            }
            const double a = Median(rp), b = Median(rr), c = Median(sp), d = Median(sr);
            csv << CsvField(spec.text) << "," << view.name << "," << width << "," << height << ","
                << nm.size() << "," << (nm.size() + 2) / 3 << "," << ParallelThreadCount() << ","
                << a << "," << b << "," << c << "," << d << "," << (a > 0 ? c / a : 0.0) << ","
                << (b > 0 ? d / b : 0.0) << "," << o.repeat << "\n";
            std::printf(
                "%-24s %-18s RGB prepare %8.3f s render %8.3f s | %zu wavelengths: "
                "prepare %8.3f s (x%.1f) render %8.3f s (x%.1f)\n",
                spec.text.c_str(), view.name.c_str(), a, b, nm.size(), c, a > 0 ? c / a : 0.0, d,
                b > 0 ? d / b : 0.0);
        }
    }
    csv.Commit();
    std::printf("wrote %s\n", o.output.c_str());
    return 0;
}

int CmdBench(const BenchOptions& o) {
    int width = 0, height = 0;
    ParseSize(o.size, &width, &height);
    if (o.repeat < 1) Fail("--repeat must be at least 1");
    if (o.warmup < 0) Fail("--warmup must be 0 or more");
    const Quantity quantity = ParseQuantity(o.quantity);
    const AtmosphereParameters atmosphere = LoadAtmosphere(o.atmosphere, o.sets);
    std::vector<ModelSpec> models;
    for (const std::string& m : o.models) models.push_back(ParseModelSpec(m));
    if (models.empty()) {
        for (const ModelInfo& info : ListModels()) {
            const bool produces = quantity == Quantity::kRadiance ? info.capabilities.radiance
                                                                  : info.capabilities.transmittance;
            if (!info.capabilities.stochastic && produces) {
                models.push_back(ParseModelSpec(info.name));
            }
        }
    }
    for (const ModelSpec& m : models) RequireQuantity(GetModelInfo(m.name), quantity);
    bool any_monte_carlo = false;
    for (const ModelSpec& m : models) {
        any_monte_carlo = any_monte_carlo || GetModelInfo(m.name).capabilities.stochastic;
    }
    if (o.monte_carlo.Given() && !any_monte_carlo) {
        Fail(
            "--spp, --seed and --pass-spp apply to Monte Carlo models only; none of --models is "
            "one");
    }
    const MonteCarloSettings monte_carlo = o.monte_carlo.Checked();
    if (o.prepare_repeat < 1) Fail("--prepare-repeat must be at least 1");
    std::vector<View> views;
    for (const std::string& v : o.views.empty() ? StandardViewNames() : o.views) {
        views.push_back(GetView(v, atmosphere));
    }
    ThreadLimit limit(o.threads);
    const Backend backend = ParseBackend(o.backend);
    const BackendScope backend_scope(backend);
    if (!o.spectral.wavelengths.empty()) {
        return BenchSpectral(o, models, views, width, height, quantity, monte_carlo);
    }
    const bool on_device = backend == Backend::kCuda;
    const int repeat = on_device && o.repeat_flag->count() == 0 ? 256 : o.repeat;
    const int warmup = on_device && o.warmup_flag->count() == 0 ? 16 : o.warmup;
    const int threads = ParallelThreadCount();
    const std::string cpu = CpuName(), compiler = CompilerName();
    if (fs::path(o.output).has_parent_path())
        fs::create_directories(fs::path(o.output).parent_path());
    CheckOutputFile(o.output);
    TextOutput csv(o.output);  // written at the end, atomically
    csv << "model,view,width,height,quantity,threads,prepare_s,render_median_s,render_min_s,"
           "render_max_s,repeat,megapixels_per_s,paths_per_s,cpu,compiler,backend\n";
    // Beside the CSV, unless the CSV goes to a stream (/dev/null, stdout, a
    // FIFO): then only where --stages-output names it.
    const std::string stages_path = !o.stages_output.empty() ? o.stages_output
                                    : IsStreamOutput(o.output)
                                        ? std::string()
                                        : (fs::path(o.output).parent_path() /
                                           (fs::path(o.output).stem().string() + "_stages.csv"))
                                              .string();
    if (!stages_path.empty()) CheckOutputFile(stages_path);
    TextOutput stages_csv(stages_path);
    stages_csv << "model,view,stage,items,backend,runs,kernel_median_ms,total_median_ms,bytes_up,"
                  "bytes_down\n";
    auto write_stages = [&](const std::string& model, const std::string& view,
                            const std::vector<StageRuns>& runs) {
        for (const StageRuns& r : runs) {
            const double k = Median(r.kernel_ms), t = Median(r.total_ms);
            stages_csv << model << "," << view << "," << CsvField(r.name) << "," << r.items << ","
                       << r.backend << "," << r.kernel_ms.size() << "," << k << "," << t << ","
                       << r.bytes_up << "," << r.bytes_down << "\n";
            std::printf(
                "  stage %-34s %10lld items %10.3f ms kernel %10.3f ms total (%s, %zu runs)",
                r.name.c_str(), static_cast<long long>(r.items), k, t, r.backend.c_str(),
                r.kernel_ms.size());
            if (r.bytes_up || r.bytes_down) {
                std::printf(" %.2f MB up %.2f MB down", 1e-6 * static_cast<double>(r.bytes_up),
                            1e-6 * static_cast<double>(r.bytes_down));
            }
            std::printf("\n");
        }
    };
    std::printf("%-20s %-22s %12s %12s %12s %12s %10s\n", "model", "view", "prepare_ms",
                "median_ms", "min_ms", "max_ms", "Mpix/s");
    for (const ModelSpec& spec : models) {
        const std::string& name = spec.text;
        std::unique_ptr<Model> model = CreateModel(spec);
        const bool stochastic = model->Info().capabilities.stochastic;
        std::vector<double> prepares;
        std::vector<StageRuns> prepare_stages;
        for (int k = 0; k < o.prepare_repeat; ++k) {
            std::vector<StageTime> log;
            const StageLogScope log_scope(&log);
            const auto p0 = std::chrono::steady_clock::now();
            model->Prepare(atmosphere);
            prepares.push_back(Seconds(p0));
            AddStageRuns(log, &prepare_stages);
        }
        const double prepare = Median(prepares);
        if (o.prepare_repeat > 1 || !prepare_stages.empty()) {
            std::printf("%-20s prepare: median %.3f ms of %d (min %.3f, max %.3f)\n", name.c_str(),
                        prepare * 1e3, o.prepare_repeat,
                        *std::min_element(prepares.begin(), prepares.end()) * 1e3,
                        *std::max_element(prepares.begin(), prepares.end()) * 1e3);
        }
        write_stages(name, "prepare", prepare_stages);
        const int64_t spp = stochastic ? monte_carlo.spp : 0;
        for (const View& view : views) {
            RenderRequest request = ViewRequest(view, width, height, quantity, monte_carlo);
            Image image;
            std::vector<double> times;
            std::vector<StageRuns> frame_stages;
            std::vector<StageTime> frame_log;
            const StageLogScope log_scope(&frame_log);
            if (on_device && !stochastic) {
                for (int i = 0; i < warmup; ++i) model->Render(request, &image);
                frame_log.clear();
                for (int i = 0; i < repeat; ++i) model->Render(request, &image);
                for (const StageTime& t : frame_log) {
                    if (t.name == "render") times.push_back(1e-3 * t.kernel_ms);
                }
                if (times.empty()) Fail("model ", name, " did not render through the device loop");
            } else {
                const int runs =
                    on_device && stochastic && o.repeat_flag->count() == 0 ? 3 : repeat;
                const int warm =
                    on_device && stochastic && o.warmup_flag->count() == 0 ? 1 : warmup;
                for (int i = 0; i < warm; ++i) model->Render(request, &image);
                frame_log.clear();
                for (int i = 0; i < runs; ++i) {
                    const auto t0 = std::chrono::steady_clock::now();
                    model->Render(request, &image);
                    times.push_back(Seconds(t0));
                }
            }
            AddStageRuns(frame_log, &frame_stages);
            std::sort(times.begin(), times.end());
            const double median = Median(times);
            const double mpix = static_cast<double>(width) * height / median / 1e6;
            const double paths =
                stochastic ? static_cast<double>(width) * height * static_cast<double>(spp) / median
                           : 0.0;
            csv << name << "," << view.name << "," << width << "," << height << ","
                << QuantityName(quantity) << "," << threads << "," << prepare << "," << median
                << "," << times.front() << "," << times.back() << "," << times.size() << "," << mpix
                << "," << paths << "," << CsvField(cpu) << "," << CsvField(compiler) << ","
                << BackendName(backend) << "\n";
            std::printf("%-20s %-22s %12.3f %12.3f %12.3f %12.3f %10.3f", name.c_str(),
                        view.name.c_str(), prepare * 1e3, median * 1e3, times.front() * 1e3,
                        times.back() * 1e3, mpix);
            if (stochastic) std::printf("  %.4g paths/s", paths);
            std::printf("\n");
            write_stages(name, view.name, frame_stages);
            std::fflush(stdout);
        }
    }
    csv.Commit();
    if (!stages_path.empty()) stages_csv.Commit();
    std::printf("%s: %d threads, %s, %s; %dx%d, median of %d after %d warm-up%s; wrote %s, %s\n",
                BackendName(backend), threads, cpu.c_str(), compiler.c_str(), width, height, repeat,
                warmup, on_device ? " (kernel time, CUDA events)" : "", o.output.c_str(),
                stages_path.empty() ? "no stages CSV" : stages_path.c_str());
    return 0;
}

}  // namespace

Command AddBenchCommand(CLI::App* root) {
    auto o = std::make_shared<BenchOptions>();
    CLI::App* cmd = root->add_subcommand(
        "bench", "time Prepare() and Render() apart, per model and view (CSV + table)");
    cmd->add_option("--models", o->models,
                    "models with their options, NAME[:OPTION=VALUE...] (default: all but the "
                    "reference; e.g. reference:spp=256,bruneton:orders=2)")
        ->delimiter(',');
    cmd->add_option("--prepare-repeat", o->prepare_repeat,
                    "Prepare() runs per model; the median is reported (default 1)")
        ->capture_default_str();
    cmd->add_option("--stages-output", o->stages_output,
                    "CSV of the precomputation stages (default: <output stem>_stages.csv)");
    cmd->add_option("--views", o->views, "views (default: all 12)")->delimiter(',');
    cmd->add_option("--size,-s", o->size, "image size WIDTHxHEIGHT")->capture_default_str();
    cmd->add_option("--quantity", o->quantity, "radiance or transmittance")->capture_default_str();
    o->repeat_flag =
        cmd->add_option("--repeat,-n", o->repeat, "timed renders per view (cuda: default 256)")
            ->capture_default_str();
    o->warmup_flag =
        cmd->add_option("--warmup", o->warmup, "untimed renders first (cuda: default 16)")
            ->capture_default_str();
    AddBackendOption(cmd, &o->backend);
    cmd->add_option("--atmosphere,-a", o->atmosphere, "preset name or JSON file")
        ->capture_default_str();
    cmd->add_option("--set", o->sets, "override one atmosphere field: FIELD=VALUE (repeatable)")
        ->allow_extra_args(false);
    cmd->add_option("--threads", o->threads, "worker threads (0: all cores)")
        ->check(CLI::Range(0, 4096));  // (NonNegativeNumber printed a 309-digit bound)
    cmd->add_option("-o,--output", o->output, "CSV file")->capture_default_str();
    AddMonteCarloFlags(cmd, &o->monte_carlo);
    AddSpectralFlags(cmd, &o->spectral, false);
    Command c;
    c.app = cmd;
    c.run = [o] { return CmdBench(*o); };
    return c;
}

}  // namespace atmos::cli
