// atmos studies: the bench study (bench.h).
#include "studies/bench.h"

#include <filesystem>

#include <algorithm>
#include <chrono>
#include <cstdarg>
#include <cstdio>
#include <memory>
#include <sstream>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/spectral.h"
#include "atmos/view.h"
#include "base/parallel.h"
#include "harness/machine.h"
#include "io/output_path.h"
#include "render/stages.h"
#include "studies/common.h"

namespace atmos {

namespace {

double Seconds(std::chrono::steady_clock::time_point since) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

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

std::string Format(const char* format, ...) __attribute__((format(printf, 1, 2)));
std::string Format(const char* format, ...) {
    char buf[1024];
    va_list args;
    va_start(args, format);
    std::vsnprintf(buf, sizeof buf, format, args);
    va_end(args);
    return buf;
}

RenderRequest Request(const View& view, const BenchConfig& c, Quantity quantity) {
    RenderRequest request;
    request.view = view;
    request.width = c.width;
    request.height = c.height;
    request.quantity = quantity;
    request.show_progress = false;
    request.monte_carlo = c.monte_carlo;
    return request;
}

std::vector<View> Views(const BenchConfig& c, const AtmosphereParameters& atmosphere) {
    std::vector<View> views;
    for (const std::string& v : c.views.empty() ? StandardViewNames() : c.views) {
        views.push_back(GetView(v, atmosphere));
    }
    return views;
}

void BenchSpectral(const BenchConfig& c, Quantity quantity, BenchResult* result,
                   const std::function<void(const std::string&)>& progress) {
    const SpectralAtmosphere spectral = LoadSpectralAtmosphere(c.atmosphere, c.sets);
    const AtmosphereParameters rgb = LoadAtmosphere(c.atmosphere, c.sets);
    const int repeat = c.repeat.value_or(5);
    for (const std::string& text : c.models) {
        const ModelSpec spec = ParseModelSpec(text);
        for (const View& view : Views(c, rgb)) {
            const RenderRequest request = Request(view, c, quantity);
            std::vector<double> rp, rr, sp, sr;
            for (int i = 0; i < repeat; ++i) {
                std::unique_ptr<Model> model = CreateModel(spec);
                auto t0 = std::chrono::steady_clock::now();
                model->Prepare(rgb);
                rp.push_back(Seconds(t0));
                Image image;
                t0 = std::chrono::steady_clock::now();
                model->Render(request, &image);
                rr.push_back(Seconds(t0));
                // The render time of the batches (or wide groups) as the run
                // measures it; the rest (model creation, Prepare or
                // PrepareWide) is the precomputation.
                std::vector<double> render_s;
                t0 = std::chrono::steady_clock::now();
                RenderSpectralRequests(
                    spec, spectral, c.wavelengths, {request},
                    [&](const AtmosphereParameters& a, Model* m) { m->Prepare(a); }, &render_s,
                    nullptr, c.batching);
                const double total = Seconds(t0);
                sp.push_back(total - render_s.front());
                sr.push_back(render_s.front());
            }
            BenchSpectralRow row;
            row.model = spec.text;
            row.view = view.name;
            row.width = c.width;
            row.height = c.height;
            row.wavelengths = c.wavelengths.size();
            row.batches = (c.wavelengths.size() + 2) / 3;
            row.threads = ParallelThreadCount();
            row.rgb_prepare_s = Median(rp);
            row.rgb_render_s = Median(rr);
            row.spectral_prepare_s = Median(sp);
            row.spectral_render_s = Median(sr);
            row.repeat = repeat;
            if (progress) progress(BenchSpectralText(row));
            result->spectral_rows.push_back(row);
        }
    }
}

}  // namespace

BenchConfig ResolveBenchConfig(BenchConfig c) {
    if (c.width < 1 || c.height < 1) Fail("bench: the size must be at least 1x1");
    if (c.repeat && *c.repeat < 1) Fail("--repeat must be at least 1");
    if (c.warmup && *c.warmup < 0) Fail("--warmup must be 0 or more");
    const Quantity quantity = ParseQuantity(c.quantity);
    const AtmosphereParameters atmosphere = LoadAtmosphere(c.atmosphere, c.sets);
    for (const std::string& m : c.models) ParseModelSpec(m);  // fail early
    const bool listed = c.models.empty();
    if (listed) {
        for (const ModelInfo& info : ListModels()) {
            const bool produces = quantity == Quantity::kRadiance ? info.capabilities.radiance
                                                                  : info.capabilities.transmittance;
            if (!info.capabilities.stochastic && produces) c.models.push_back(info.name);
        }
    }
    bool any_monte_carlo = false;
    for (const std::string& m : c.models) {
        const ModelInfo info = GetModelInfo(ParseModelSpec(m).name);
        RequireQuantity(info, quantity);
        any_monte_carlo = any_monte_carlo || info.capabilities.stochastic;
    }
    if (c.monte_carlo_given && !any_monte_carlo) {
        Fail(
            "--spp, --seed and --pass-spp apply to Monte Carlo models only; none of --models is "
            "one");
    }
    if (c.prepare_repeat < 1) Fail("--prepare-repeat must be at least 1");
    Views(c, atmosphere);  // fail early
    if (!c.wavelengths.empty()) {
        std::vector<std::string> spectral;
        for (const std::string& m : c.models) {
            const ModelInfo info = GetModelInfo(ParseModelSpec(m).name);
            if (listed && !HasSpectralForm(info)) continue;
            RequireSpectralModel(info);
            spectral.push_back(m);
        }
        c.models = spectral;
    }
    return c;
}

BenchResult RunBench(const BenchConfig& c,
                     const std::function<void(const std::string&)>& progress) {
    BenchResult result;
    const Quantity quantity = ParseQuantity(c.quantity);
    const Backend backend = CurrentBackend();
    result.on_device = backend == Backend::kCuda;
    result.threads = ParallelThreadCount();
    result.backend = BackendName(backend);
    result.repeat = c.repeat.value_or(result.on_device ? 256 : 5);
    result.warmup = c.warmup.value_or(result.on_device ? 16 : 1);
    if (!c.wavelengths.empty()) {
        BenchSpectral(c, quantity, &result, progress);
        return result;
    }
    result.cpu = CpuName();
    result.compiler = CompilerName();
    const AtmosphereParameters atmosphere = LoadAtmosphere(c.atmosphere, c.sets);
    const std::vector<View> views = Views(c, atmosphere);
    auto add_stages = [&](const std::string& model, const std::string& view,
                          const std::vector<StageRuns>& runs) {
        for (const StageRuns& r : runs) {
            BenchStage s;
            s.model = model;
            s.view = view;
            s.name = r.name;
            s.backend = r.backend;
            s.items = r.items;
            s.runs = static_cast<int>(r.kernel_ms.size());
            s.kernel_median_ms = Median(r.kernel_ms);
            s.total_median_ms = Median(r.total_ms);
            s.bytes_up = r.bytes_up;
            s.bytes_down = r.bytes_down;
            if (progress) progress(BenchStageText(s));
            result.stages.push_back(s);
        }
    };
    if (progress) progress(BenchHeaderText());
    for (const std::string& name : c.models) {
        std::unique_ptr<Model> model = CreateModel(ParseModelSpec(name));
        const bool stochastic = model->Info().capabilities.stochastic;
        std::vector<double> prepares;
        std::vector<StageRuns> prepare_stages;
        for (int k = 0; k < c.prepare_repeat; ++k) {
            std::vector<StageTime> log;
            const StageLogScope log_scope(&log);
            const auto p0 = std::chrono::steady_clock::now();
            model->Prepare(atmosphere);
            prepares.push_back(Seconds(p0));
            AddStageRuns(log, &prepare_stages);
        }
        const double prepare = Median(prepares);
        if (progress && (c.prepare_repeat > 1 || !prepare_stages.empty())) {
            progress(Format("%-20s prepare: median %.3f ms of %d (min %.3f, max %.3f)\n",
                            name.c_str(), prepare * 1e3, c.prepare_repeat,
                            *std::min_element(prepares.begin(), prepares.end()) * 1e3,
                            *std::max_element(prepares.begin(), prepares.end()) * 1e3));
        }
        add_stages(name, "prepare", prepare_stages);
        const int64_t spp = stochastic ? c.monte_carlo.spp : 0;
        for (const View& view : views) {
            const RenderRequest request = Request(view, c, quantity);
            Image image;
            std::vector<double> times;
            std::vector<StageRuns> frame_stages;
            std::vector<StageTime> frame_log;
            const StageLogScope log_scope(&frame_log);
            if (result.on_device && !stochastic) {
                for (int i = 0; i < result.warmup; ++i) model->Render(request, &image);
                frame_log.clear();
                for (int i = 0; i < result.repeat; ++i) model->Render(request, &image);
                for (const StageTime& t : frame_log) {
                    if (t.name == "render") times.push_back(1e-3 * t.kernel_ms);
                }
                if (times.empty()) Fail("model ", name, " did not render through the device loop");
            } else {
                const int runs = result.on_device ? c.repeat.value_or(3) : result.repeat;
                const int warm = result.on_device ? c.warmup.value_or(1) : result.warmup;
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
            BenchRow row;
            row.model = name;
            row.view = view.name;
            row.width = c.width;
            row.height = c.height;
            row.quantity = quantity;
            row.threads = result.threads;
            row.prepare_s = prepare;
            row.render_median_s = Median(times);
            row.render_min_s = times.front();
            row.render_max_s = times.back();
            row.runs = static_cast<int>(times.size());
            row.megapixels_per_s =
                static_cast<double>(c.width) * c.height / row.render_median_s / 1e6;
            row.paths_per_s = stochastic ? static_cast<double>(c.width) * c.height *
                                               static_cast<double>(spp) / row.render_median_s
                                         : 0.0;
            row.cpu = result.cpu;
            row.compiler = result.compiler;
            row.backend = result.backend;
            if (progress) progress(BenchRowText(row));
            result.rows.push_back(row);
            add_stages(name, view.name, frame_stages);
        }
    }
    return result;
}

std::string BenchCsv(const BenchResult& result) {
    std::ostringstream csv;
    csv << "model,view,width,height,quantity,threads,prepare_s,render_median_s,render_min_s,"
           "render_max_s,repeat,megapixels_per_s,paths_per_s,cpu,compiler,backend\n";
    for (const BenchRow& r : result.rows) {
        csv << r.model << "," << r.view << "," << r.width << "," << r.height << ","
            << QuantityName(r.quantity) << "," << r.threads << "," << r.prepare_s << ","
            << r.render_median_s << "," << r.render_min_s << "," << r.render_max_s << "," << r.runs
            << "," << r.megapixels_per_s << "," << r.paths_per_s << "," << CsvField(r.cpu) << ","
            << CsvField(r.compiler) << "," << r.backend << "\n";
    }
    return csv.str();
}

std::string BenchStagesCsv(const BenchResult& result) {
    std::ostringstream csv;
    csv << "model,view,stage,items,backend,runs,kernel_median_ms,total_median_ms,bytes_up,"
           "bytes_down\n";
    for (const BenchStage& s : result.stages) {
        csv << s.model << "," << s.view << "," << CsvField(s.name) << "," << s.items << ","
            << s.backend << "," << s.runs << "," << s.kernel_median_ms << "," << s.total_median_ms
            << "," << s.bytes_up << "," << s.bytes_down << "\n";
    }
    return csv.str();
}

std::string BenchSpectralCsv(const BenchResult& result) {
    std::ostringstream csv;
    csv << "model,view,width,height,wavelengths,batches,threads,rgb_prepare_s,rgb_render_s,"
           "spectral_prepare_s,spectral_render_s,prepare_ratio,render_ratio,repeat\n";
    for (const BenchSpectralRow& r : result.spectral_rows) {
        const double a = r.rgb_prepare_s, b = r.rgb_render_s;
        const double c = r.spectral_prepare_s, d = r.spectral_render_s;
        csv << CsvField(r.model) << "," << r.view << "," << r.width << "," << r.height << ","
            << r.wavelengths << "," << r.batches << "," << r.threads << "," << a << "," << b << ","
            << c << "," << d << "," << (a > 0 ? c / a : 0.0) << "," << (b > 0 ? d / b : 0.0) << ","
            << r.repeat << "\n";
    }
    return csv.str();
}

std::string BenchHeaderText() {
    return Format("%-20s %-22s %12s %12s %12s %12s %10s\n", "model", "view", "prepare_ms",
                  "median_ms", "min_ms", "max_ms", "Mpix/s");
}

std::string BenchRowText(const BenchRow& r) {
    std::string text = Format("%-20s %-22s %12.3f %12.3f %12.3f %12.3f %10.3f", r.model.c_str(),
                              r.view.c_str(), r.prepare_s * 1e3, r.render_median_s * 1e3,
                              r.render_min_s * 1e3, r.render_max_s * 1e3, r.megapixels_per_s);
    if (r.paths_per_s > 0.0) text += Format("  %.4g paths/s", r.paths_per_s);
    return text + "\n";
}

std::string BenchStageText(const BenchStage& s) {
    std::string text =
        Format("  stage %-34s %10lld items %10.3f ms kernel %10.3f ms total (%s, %d runs)",
               s.name.c_str(), static_cast<long long>(s.items), s.kernel_median_ms,
               s.total_median_ms, s.backend.c_str(), s.runs);
    if (s.bytes_up || s.bytes_down) {
        text += Format(" %.2f MB up %.2f MB down", 1e-6 * static_cast<double>(s.bytes_up),
                       1e-6 * static_cast<double>(s.bytes_down));
    }
    return text + "\n";
}

std::string BenchSpectralText(const BenchSpectralRow& r) {
    const double a = r.rgb_prepare_s, b = r.rgb_render_s;
    const double c = r.spectral_prepare_s, d = r.spectral_render_s;
    return Format(
        "%-24s %-18s RGB prepare %8.3f s render %8.3f s | %zu wavelengths: "
        "prepare %8.3f s (x%.1f) render %8.3f s (x%.1f)\n",
        r.model.c_str(), r.view.c_str(), a, b, r.wavelengths, c, a > 0 ? c / a : 0.0, d,
        b > 0 ? d / b : 0.0);
}

std::string BenchStagesPath(const std::string& output, const std::string& stages_output) {
    if (!stages_output.empty()) return stages_output;
    if (IsStreamOutput(output)) return "";
    const std::filesystem::path p(output);
    return (p.parent_path() / (p.stem().string() + "_stages.csv")).string();
}

}  // namespace atmos
