// Benchmarks of the `hillaire` model: each table's build time and the
// per-frame render time at 1920 x 1080, on two threads.
//
// Run: build/bench/atmos_bench --benchmark_filter=Hillaire
//        --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// Transmittance and multiple scattering depend only on the atmosphere
// (Prepare); the sky-view table and the aerial-perspective volume depend on
// the camera and the sun, so they are per-frame work (Leenman's 2025 thesis section 11.6
// counts the sky-view table as part of the render). A frame = BuildFrame +
// the per-pixel loop; cameras outside the atmosphere (orbit, space) build no
// frame tables and ray march every pixel.
#include <benchmark/benchmark.h>

#include <memory>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/image.h"
#include "atmos/view.h"
#include "base/parallel.h"
#include "bench_util.h"
#include "models/hillaire.h"
#include "render/render.h"
#include "render/stages.h"

namespace atmos {
namespace {

constexpr int kThreads = 2;
constexpr int kWidth = 1920;
constexpr int kHeight = 1080;

std::unique_ptr<HillaireModel> PreparedModel() {
    const HillaireOptions options;
    auto model = std::make_unique<HillaireModel>(options);
    model->Prepare(EarthAtmosphere());
    return model;
}

void BM_HillaireTransmittanceTable(benchmark::State& state) {
    ThreadLimit limit(kThreads);
    auto model = PreparedModel();
    for (auto _ : state) model->BuildTransmittance();
}
BENCHMARK(BM_HillaireTransmittanceTable)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_HillaireMultipleScatteringTable(benchmark::State& state) {
    ThreadLimit limit(kThreads);
    auto model = PreparedModel();
    for (auto _ : state) model->BuildMultipleScattering();
}
BENCHMARK(BM_HillaireMultipleScatteringTable)->Unit(benchmark::kMillisecond)->UseRealTime();

const char* const kViews[] = {"ground-sunrise", "plane-noon", "orbit-sunrise", "space"};

void BM_HillaireSkyViewTable(benchmark::State& state) {
    ThreadLimit limit(kThreads);
    auto model = PreparedModel();
    const View view = GetView(kViews[state.range(0)], model->atmosphere());
    state.SetLabel(view.name);
    for (auto _ : state) {
        auto frame = model->BuildFrame(view.camera, view.sun_direction,
                                       static_cast<double>(kWidth) / kHeight, false);
        benchmark::DoNotOptimize(frame);
    }
}
BENCHMARK(BM_HillaireSkyViewTable)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// Sky-view + aerial perspective (the whole per-frame table work).
void BM_HillaireFrameTables(benchmark::State& state) {
    ThreadLimit limit(kThreads);
    auto model = PreparedModel();
    const View view = GetView(kViews[state.range(0)], model->atmosphere());
    state.SetLabel(view.name);
    std::vector<StageTime> log;
    for (auto _ : state) {
        log.clear();
        const StageLogScope logging(&log);
        auto frame = model->BuildFrame(view.camera, view.sun_direction,
                                       static_cast<double>(kWidth) / kHeight, true);
        benchmark::DoNotOptimize(frame);
    }
    // The last frame's stages, from the one stage log.
    for (const StageTime& t : log) {
        if (t.name == "hillaire/sky-view") state.counters["sky_view_ms"] = t.total_ms;
        if (t.name == "hillaire/aerial-perspective") {
            state.counters["aerial_perspective_ms"] = t.total_ms;
        }
    }
}
BENCHMARK(BM_HillaireFrameTables)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// A 1920 x 1080 render of view kViews[range(0)] (the label).
RenderRequest FrameRequest(benchmark::State& state, const HillaireModel& model) {
    RenderRequest request;
    request.view = GetView(kViews[state.range(0)], model.atmosphere());
    state.SetLabel(request.view.name);
    request.width = kWidth;
    request.height = kHeight;
    request.show_progress = false;
    return request;
}

// The per-pixel loop alone at 1920 x 1080 (frame tables built outside the timing).
void BM_HillaireRenderPixels(benchmark::State& state) {
    ThreadLimit limit(kThreads);
    auto model = PreparedModel();
    const RenderRequest request = FrameRequest(state, *model);
    const View& view = request.view;
    const PixelSetup setup = MakePixelSetup(request, model->atmosphere());
    auto frame = model->BuildFrame(view.camera, view.sun_direction,
                                   static_cast<double>(kWidth) / kHeight, true);
    const HillaireEvaluator evaluator = frame->Evaluator();
    Image image(kWidth, kHeight);
    for (auto _ : state) RenderImage(evaluator, setup, image.View(), false);
}
BENCHMARK(BM_HillaireRenderPixels)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime();

// A whole frame: Model::Render (frame tables + pixels) at 1920 x 1080.
void BM_HillaireRenderFrame(benchmark::State& state) {
    ThreadLimit limit(kThreads);
    auto model = PreparedModel();
    const RenderRequest request = FrameRequest(state, *model);
    Image image;
    for (auto _ : state) model->Render(request, &image);
}
BENCHMARK(BM_HillaireRenderFrame)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// Nanoseconds per Evaluate() (one view ray) on one thread, over a fixed set of
// the view's pixel directions: the table path (ground-sunrise) and the ray
// march (space).
void BM_HillaireEvaluate(benchmark::State& state) {
    auto model = PreparedModel();
    const View view = GetView(kViews[state.range(0)], model->atmosphere());
    state.SetLabel(view.name);
    auto frame = model->BuildFrame(view.camera, view.sun_direction, 16.0 / 9.0, true);
    const HillaireEvaluator e = frame->Evaluator();
    BenchEvaluate(state, e, view);
}
BENCHMARK(BM_HillaireEvaluate)->Arg(0)->Arg(3);

}  // namespace
}  // namespace atmos
