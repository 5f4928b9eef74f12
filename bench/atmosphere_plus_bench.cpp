// atmos micro-benchmarks of `atmosphere-plus` (Boody's Atmosphere Plus notes): precomputation time
// per scattering order and table size, and the per-call cost of the evaluator.
//
// Run: build/bench/atmos_bench --benchmark_filter=Aplus
// BM_AplusPrecompute/H/K runs once (the work is seconds): counters order1_s ...
// give each order's time, transmittance_s the transmittance table's.
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/view.h"
#include "bench_util.h"
#include "models/atmosphere_plus.h"
#include "render/render.h"

namespace atmos {
namespace {

void BM_AplusPrecompute(benchmark::State& state) {
    const AtmosphereParameters atm = LoadAtmosphere("earth-atmosphere-plus");
    AplusSettings s;
    s.height = static_cast<int>(state.range(0));
    s.orders = static_cast<int>(state.range(1));
    AplusTables t;
    for (auto _ : state) {
        t = AplusPrecompute(atm, s);
        benchmark::DoNotOptimize(t.scattering.data());
    }
    state.counters["transmittance_s"] = t.transmittance_seconds;
    for (size_t k = 0; k < t.order_seconds.size(); ++k) {
        state.counters["order" + std::to_string(k + 1) + "_s"] = t.order_seconds[k];
    }
    state.counters["table_MiB"] =
        static_cast<double>(t.scattering.size() * sizeof(float)) / (1024.0 * 1024.0);
}
// Table heights of Boody's Atmosphere Plus notes 2.4 (width 32, depth 32), three orders.
BENCHMARK(BM_AplusPrecompute)
    ->Args({64, 3})
    ->Args({128, 3})
    ->Args({256, 3})
    ->Iterations(1)
    ->Unit(benchmark::kSecond);

// One evaluator call (one view ray) with the default tables (32 x 256 x 32,
// five orders), rays sweeping the view.
void RunAplusEvaluate(benchmark::State& state, const char* view_name) {
    static const AtmosphereParameters atm = LoadAtmosphere("earth-atmosphere-plus");
    static const AplusTables tables = [] {
        AplusSettings s;
        s.orders = 2;  // the order count does not change the per-call cost
        return AplusPrecompute(atm, s);
    }();
    AtmospherePlusEvaluator e;
    e.atm = atm;
    e.mapping.bottom_radius = atm.bottom_radius;
    e.mapping.height = atm.top_radius - atm.bottom_radius;
    e.scattering = tables.scattering.view();
    e.transmittance = tables.transmittance.view();
    BenchEvaluate(state, e, GetView(view_name, atm));
}

void BM_AplusEvaluateGroundSunrise(benchmark::State& state) {
    RunAplusEvaluate(state, "ground-sunrise");
}
BENCHMARK(BM_AplusEvaluateGroundSunrise);

void BM_AplusEvaluateSpace(benchmark::State& state) { RunAplusEvaluate(state, "space"); }
BENCHMARK(BM_AplusEvaluateSpace);

}  // namespace
}  // namespace atmos
