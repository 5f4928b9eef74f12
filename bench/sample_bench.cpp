// Benchmarks of Model::Sample on 10^6 queries (the call `atmos sample` and the
// Python module's m.sample make), per query, on two threads: the C++ side of
// scripts/bench_python_sample.py, which times m.sample on the same queries.
//
// Run: build/bench/atmos_bench --benchmark_filter=ModelSample
// Queries (i in [0, 10^6)): altitude 0, mu = -1 + 2 (i % 1000) / 999,
// mu_s = -0.2 + 1.2 (i / 1000) / 999, azimuth 0.
#include <benchmark/benchmark.h>

#include <memory>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "base/parallel.h"

namespace atmos {
namespace {

constexpr int kThreads = 2;
constexpr int kQueries = 1000000;

std::vector<SampleQuery> Queries() {
    std::vector<SampleQuery> q(kQueries);
    for (int i = 0; i < kQueries; ++i) {
        q[static_cast<size_t>(i)].altitude_m = 0.0;
        q[static_cast<size_t>(i)].mu = -1.0 + 2.0 * (i % 1000) / 999.0;
        q[static_cast<size_t>(i)].mu_s = -0.2 + 1.2 * (i / 1000) / 999.0;
        q[static_cast<size_t>(i)].azimuth_deg = 0.0;
    }
    return q;
}

void RunSample(benchmark::State& state, const char* name) {
    ThreadLimit limit(kThreads);
    std::unique_ptr<Model> model = CreateModel(name);
    model->Prepare(EarthAtmosphere());
    const std::vector<SampleQuery> queries = Queries();
    for (auto _ : state) {
        std::vector<SampleAnswer> answers = model->Sample(queries);
        benchmark::DoNotOptimize(answers.data());
    }
    state.SetItemsProcessed(state.iterations() * kQueries);
    state.counters["ns_per_query"] = benchmark::Counter(
        static_cast<double>(kQueries) * 1e-9,
        benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_ModelSampleNaive(benchmark::State& state) { RunSample(state, "naive"); }
BENCHMARK(BM_ModelSampleNaive)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ModelSampleBruneton(benchmark::State& state) { RunSample(state, "bruneton"); }
BENCHMARK(BM_ModelSampleBruneton)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace atmos
