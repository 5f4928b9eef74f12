// atmos CLI: `atmos bench`: precomputation and rendering timed apart, per model and view.
//
// Per model: Prepare() timed once (cold). Per view: `warmup` renders, then
// `repeat` timed renders; the median, min and max, and megapixels per second
// of the median. Thread count, CPU and compiler go in every CSV row.
//
// --backend cuda: the render kernel alone is timed on the device, between CUDA
// events (DeviceTimingRequest, base/parallel.h): `warmup` untimed launches
// (default 16), then `repeat` timed ones (default 256, as the thesis); table
// uploads and the copy back are excluded. Prepare() still runs on the CPU.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/model.h"
#include "atmos/view.h"
#include "base/parallel.h"
#include "cli_common.h"
#include "harness/machine.h"

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
    CLI::Option* repeat_flag = nullptr;
    CLI::Option* warmup_flag = nullptr;
};

std::string CsvField(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
}

int CmdBench(const BenchOptions& o) {
    int width = 0, height = 0;
    ParseSize(o.size, &width, &height);
    if (o.repeat < 1) Fail("--repeat must be at least 1");
    if (o.warmup < 0) Fail("--warmup must be 0 or more");
    const Quantity quantity = ParseQuantity(o.quantity);
    const AtmosphereParameters atmosphere = LoadAtmosphere(o.atmosphere, o.sets);
    std::vector<std::string> models = o.models;
    if (models.empty()) {
        for (const ModelInfo& info : ListModels()) {
            if (info.name != "reference") models.push_back(info.name);
        }
    }
    for (const std::string& m : models) GetModelInfo(m);
    std::vector<View> views;
    for (const std::string& v : o.views.empty() ? StandardViewNames() : o.views) {
        views.push_back(GetView(v, atmosphere));
    }
    ThreadLimit limit(o.threads);
    const Backend backend = ParseBackend(o.backend);
    const BackendScope backend_scope(backend);
    const bool on_device = backend == Backend::kCuda;
    const int repeat = on_device && o.repeat_flag->count() == 0 ? 256 : o.repeat;
    const int warmup = on_device && o.warmup_flag->count() == 0 ? 16 : o.warmup;
    const int threads = ParallelThreadCount();
    const std::string cpu = CpuName(), compiler = CompilerName();
    if (fs::path(o.output).has_parent_path())
        fs::create_directories(fs::path(o.output).parent_path());
    std::ofstream csv(o.output);
    if (!csv) Fail("cannot write '", o.output, "'");
    csv << "model,view,width,height,quantity,threads,prepare_s,render_median_s,render_min_s,"
           "render_max_s,repeat,megapixels_per_s,cpu,compiler,backend\n";
    std::printf("%-20s %-22s %12s %12s %12s %12s %10s\n", "model", "view", "prepare_ms",
                "median_ms", "min_ms", "max_ms", "Mpix/s");
    for (const std::string& name : models) {
        std::unique_ptr<Model> model = CreateModel(name);
        const auto p0 = std::chrono::steady_clock::now();
        model->Prepare(atmosphere);
        const double prepare = Seconds(p0);
        for (const View& view : views) {
            RenderRequest request;
            request.view = view;
            request.width = width;
            request.height = height;
            request.quantity = quantity;
            request.show_progress = false;
            Image image;
            std::vector<double> times;
            if (on_device) {
                DeviceTimingRequest timing;
                timing.warmup = warmup;
                timing.repeats = repeat;
                {
                    const DeviceTimingScope timing_scope(&timing);
                    model->Render(request, &image);
                }
                if (timing.milliseconds.empty()) {
                    Fail("model ", name, " did not render through the device loop");
                }
                for (float ms : timing.milliseconds)
                    times.push_back(1e-3 * static_cast<double>(ms));
            } else {
                for (int i = 0; i < warmup; ++i) model->Render(request, &image);
                for (int i = 0; i < repeat; ++i) {
                    const auto t0 = std::chrono::steady_clock::now();
                    model->Render(request, &image);
                    times.push_back(Seconds(t0));
                }
            }
            std::sort(times.begin(), times.end());
            const size_t n = times.size();
            const double median =
                n % 2 == 1 ? times[n / 2] : 0.5 * (times[n / 2 - 1] + times[n / 2]);
            const double mpix = static_cast<double>(width) * height / median / 1e6;
            csv << name << "," << view.name << "," << width << "," << height << ","
                << QuantityName(quantity) << "," << threads << "," << prepare << "," << median
                << "," << times.front() << "," << times.back() << "," << repeat << "," << mpix
                << "," << CsvField(cpu) << "," << CsvField(compiler) << "," << BackendName(backend)
                << "\n";
            std::printf("%-20s %-22s %12.3f %12.3f %12.3f %12.3f %10.3f\n", name.c_str(),
                        view.name.c_str(), prepare * 1e3, median * 1e3, times.front() * 1e3,
                        times.back() * 1e3, mpix);
            std::fflush(stdout);
        }
    }
    if (!csv) Fail("cannot write '", o.output, "'");
    std::printf("%s: %d threads, %s, %s; %dx%d, median of %d after %d warm-up%s; wrote %s\n",
                BackendName(backend), threads, cpu.c_str(), compiler.c_str(), width, height, repeat,
                warmup, on_device ? " (kernel time, CUDA events)" : "", o.output.c_str());
    return 0;
}

}  // namespace

Command AddBenchCommand(CLI::App* root) {
    auto o = std::make_shared<BenchOptions>();
    CLI::App* cmd = root->add_subcommand(
        "bench", "time Prepare() and Render() apart, per model and view (CSV + table)");
    cmd->add_option("--models", o->models, "models (default: all but the reference)")
        ->delimiter(',');
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
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("-o,--output", o->output, "CSV file")->capture_default_str();
    Command c;
    c.app = cmd;
    c.run = [o] { return CmdBench(*o); };
    return c;
}

}  // namespace atmos::cli
