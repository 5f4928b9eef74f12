// Benchmarks of environment maps (issue 31): an equirect 2048 x 1024 map of
// `bruneton` (tables prepared once, outside the timing) and of `hillaire`
// (its per-frame sky-view table inside, as every render builds it), on two
// threads, sun 5 degrees above the horizon. Target: <= 1 s each.
//
// Run: build/bench/atmos_bench --benchmark_filter=EnvMap
//        --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <memory>
#include <string>

#include "atmos/atmosphere.h"
#include "atmos/image.h"
#include "atmos/model.h"
#include "atmos/view.h"
#include "base/parallel.h"

namespace atmos {
namespace {

void BenchEquirect(benchmark::State& state, const char* name) {
    ThreadLimit limit(2);
    std::unique_ptr<Model> model = CreateModel(name);
    const AtmosphereParameters atm = EarthAtmosphere();
    model->Prepare(atm);
    CameraSpec spec;
    spec.projection = Projection::kEquirect;
    RenderRequest request;
    request.view = CustomView(spec, DirectionFromAzimuthElevation(120.0, 5.0), atm);
    request.width = 2048;
    request.height = 1024;
    request.show_progress = false;
    Image image;
    for (auto _ : state) {
        model->Render(request, &image);
        benchmark::DoNotOptimize(image.data());
    }
    state.SetItemsProcessed(state.iterations() * request.width * request.height);
}

void BM_EnvMapEquirectBruneton(benchmark::State& state) { BenchEquirect(state, "bruneton"); }
BENCHMARK(BM_EnvMapEquirectBruneton)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_EnvMapEquirectHillaire(benchmark::State& state) { BenchEquirect(state, "hillaire"); }
BENCHMARK(BM_EnvMapEquirectHillaire)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace atmos
