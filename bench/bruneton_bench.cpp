// atmos benchmarks of model `bruneton`: precomputation time per stage, and the
// per-call cost of rendering from the tables.
//
// Run: build/bench/atmos_bench --benchmark_filter=Bruneton
// BM_BrunetonPrecompute/ORDERS/THREADS reports the stages (seconds, wall clock,
// summed over orders from the stage log) as counters;
// BM_BrunetonPrecomputeTexelStages/ORDERS/THREADS the same with every stage per texel (the CUDA
// backend's stages) on the CPU.
#include <benchmark/benchmark.h>

#include <string>
#include <utility>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/view.h"
#include "base/parallel.h"
#include "bench_util.h"
#include "models/bruneton.h"
#include "models/bruneton_stages.h"
#include "render/render.h"
#include "render/stages.h"

namespace atmos {
namespace {

// texel_stages: every stage per texel (models/bruneton_stages.h: what the CUDA
// backend runs), here on the CPU; otherwise the CPU backend's path.
void Precompute(benchmark::State& state, bool texel_stages) {
    BrunetonConfig config;
    config.orders = static_cast<int>(state.range(0));
    ThreadLimit limit(static_cast<int>(state.range(1)));
    const AtmosphereParameters atm = EarthAtmosphere();
    std::vector<StageTime> log;
    for (auto _ : state) {
        log.clear();
        const StageLogScope logging(&log);
        BrunetonTables tables;
        PrecomputeBrunetonWith(atm, config, texel_stages, &tables);
        benchmark::DoNotOptimize(tables.scattering.data());
    }
    // Wall clock per stage name (all orders together), from the one stage log.
    double total = 0.0;
    for (const StageTime& t : log) {
        state.counters[t.name] = state.counters[t.name] + 1e-3 * t.total_ms;
        total += 1e-3 * t.total_ms;
    }
    state.counters["total"] = total;
}
void BM_BrunetonPrecompute(benchmark::State& state) { Precompute(state, false); }
void BM_BrunetonPrecomputeTexelStages(benchmark::State& state) { Precompute(state, true); }
// Args: orders, threads (0: all cores).
BENCHMARK(BM_BrunetonPrecompute)
    ->Args({4, 2})
    ->Args({4, 1})
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();
BENCHMARK(BM_BrunetonPrecomputeTexelStages)
    ->Args({4, 2})
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();

struct Prepared {
    BrunetonTables tables;
    BrunetonEvaluator evaluator;
    Prepared() {
        const AtmosphereParameters atm = EarthAtmosphere();
        BrunetonConfig config;
        PrecomputeBruneton(atm, config, &tables);
        evaluator.lut = MakeBrunetonLut(atm, config, tables);
    }
};
const Prepared& GetPrepared() {
    static const Prepared p;
    return p;
}

void RunView(benchmark::State& state, const char* view_name) {
    const BrunetonEvaluator& e = GetPrepared().evaluator;
    BenchEvaluate(state, e, GetView(view_name, EarthAtmosphere()));
}

void BM_BrunetonEvaluateGroundSunrise(benchmark::State& state) { RunView(state, "ground-sunrise"); }
BENCHMARK(BM_BrunetonEvaluateGroundSunrise);

void BM_BrunetonEvaluatePlaneNoon(benchmark::State& state) { RunView(state, "plane-noon"); }
BENCHMARK(BM_BrunetonEvaluatePlaneNoon);

void BM_BrunetonEvaluateSpace(benchmark::State& state) { RunView(state, "space"); }
BENCHMARK(BM_BrunetonEvaluateSpace);

// A whole 1920x1080 image through the render loop (all threads).
void BM_BrunetonRender1080p(benchmark::State& state) {
    const BrunetonEvaluator& e = GetPrepared().evaluator;
    RenderRequest request;
    request.view = GetView("ground-sunrise", EarthAtmosphere());
    request.width = 1920;
    request.height = 1080;
    request.show_progress = false;
    const PixelSetup setup = MakePixelSetup(request, EarthAtmosphere());
    Image image;
    image.Resize(1920, 1080);
    for (auto _ : state) {
        RenderImage(e, setup, image.View(), false);
        benchmark::ClobberMemory();
    }
}
BENCHMARK(BM_BrunetonRender1080p)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace atmos
