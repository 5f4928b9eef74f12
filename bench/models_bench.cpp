// atmos micro-benchmarks: nanoseconds per evaluator call (one view ray).
//
// Run: build/bench/atmos_bench [--benchmark_filter=naive]
// The rays sweep a fixed set of directions from a ground camera at sunrise, so
// every iteration does comparable work.
#include <benchmark/benchmark.h>

#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/view.h"
#include "bench_util.h"
#include "models/empty.h"
#include "models/naive.h"
#include "render/render.h"

namespace atmos {
namespace {

template <typename Evaluator>
void RunEvaluator(benchmark::State& state, const Evaluator& evaluator, const char* view_name) {
    BenchEvaluate(state, evaluator, GetView(view_name, EarthAtmosphere()));
}

void BM_EmptyEvaluate(benchmark::State& state) {
    RunEvaluator(state, EmptyEvaluator{}, "ground-sunrise");
}
BENCHMARK(BM_EmptyEvaluate);

void BM_NaiveEvaluate(benchmark::State& state) {
    NaiveEvaluator e;
    e.atm = EarthAtmosphere();
    e.steps = static_cast<int>(state.range(0));
    e.light_steps = static_cast<int>(state.range(1));
    RunEvaluator(state, e, "ground-sunrise");
}
BENCHMARK(BM_NaiveEvaluate)->Args({16, 8})->Args({32, 16})->Args({64, 32});

void BM_NaiveEvaluateSpace(benchmark::State& state) {
    NaiveEvaluator e;
    e.atm = EarthAtmosphere();
    RunEvaluator(state, e, "space");
}
BENCHMARK(BM_NaiveEvaluateSpace);

}  // namespace
}  // namespace atmos
