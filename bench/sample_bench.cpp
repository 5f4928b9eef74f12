// Benchmarks of Model::Sample on 10^6 queries (the call `atmos sample` and the
// Python module's m.sample make), per query, on two threads: the C++ side of
// scripts/bench_python_sample.py, which times m.sample on the same queries.
//
// Run: build/bench/atmos_bench --benchmark_filter=ModelSample
// Queries (i in [0, 10^6)): altitude 0, mu = -1 + 2 (i % 1000) / 999,
// mu_s = -0.2 + 1.2 (i / 1000) / 999, azimuth 0.
//
// BM_ModelSampleRandom{Bruneton,Oneil}{Rgb,Wide40}: one thread, 20 000 queries drawn as
// bench/query_cost.py draws them (altitude 0-20 km, mu in [-0.3, 1], mu_s in
// [-0.2, 1], any azimuth), RGB or 40 wavelengths in wide channel batches
// (PrepareWide); counters ns_per_query and ns_per_wavelength (3 for RGB; issue 37's
// per-channel comparison with clear-sky-models). bruneton:orders=1 has the
// default's lookups with a fifth of its precomputation.
#include <benchmark/benchmark.h>

#include <memory>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "atmos/spectral.h"
#include "base/parallel.h"
#include "base/rng.h"
#include "harness/spectral_run.h"

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

std::vector<SampleQuery> RandomQueries() {
    std::vector<SampleQuery> queries;
    Rng rng(19, 0, 0);
    for (int i = 0; i < 20000; ++i) {
        SampleQuery q;
        q.altitude_m = 20000.0 * rng.Uniform();
        q.mu = -0.3 + 1.3 * rng.Uniform();
        q.mu_s = -0.2 + 1.2 * rng.Uniform();
        q.azimuth_deg = 360.0 * rng.Uniform();
        queries.push_back(q);
    }
    return queries;
}

void RunRandomSample(benchmark::State& state, const char* spec, bool wide) {
    ThreadLimit limit(1);
    std::unique_ptr<Model> model = CreateModel(ParseModelSpec(spec));
    int channels = 3;
    if (wide) {
        const SpectralAtmosphere spectral = LoadSpectralAtmosphere("earth");
        std::vector<double> nm;
        for (int i = 0; i < 40; ++i) nm.push_back(380.0 + 400.0 * i / 39.0);
        std::vector<AtmosphereParameters> batches;
        for (const auto& b : SpectralBatches(nm.size(), BatchLayout::kInterleaved)) {
            batches.push_back(spectral.AtWavelengths(nm[b[0]], nm[b[1]], nm[b[2]]));
        }
        model->PrepareWide(batches);
        channels = static_cast<int>(nm.size());
    } else {
        model->Prepare(EarthAtmosphere());
    }
    const std::vector<SampleQuery> queries = RandomQueries();
    for (auto _ : state) {
        if (wide) {
            std::vector<float> values = model->SampleWide(queries);
            benchmark::DoNotOptimize(values.data());
        } else {
            std::vector<SampleAnswer> answers = model->Sample(queries);
            benchmark::DoNotOptimize(answers.data());
        }
    }
    const double n = static_cast<double>(queries.size());
    state.counters["ns_per_query"] = benchmark::Counter(
        n * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
    state.counters["ns_per_wavelength"] =
        benchmark::Counter(n * channels * 1e-9, benchmark::Counter::kIsIterationInvariantRate |
                                                    benchmark::Counter::kInvert);
}

void BM_ModelSampleRandomBrunetonRgb(benchmark::State& state) {
    RunRandomSample(state, "bruneton:orders=1", false);
}
BENCHMARK(BM_ModelSampleRandomBrunetonRgb)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ModelSampleRandomBrunetonWide40(benchmark::State& state) {
    RunRandomSample(state, "bruneton:orders=1", true);
}
BENCHMARK(BM_ModelSampleRandomBrunetonWide40)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ModelSampleRandomOneilRgb(benchmark::State& state) {
    RunRandomSample(state, "oneil", false);
}
BENCHMARK(BM_ModelSampleRandomOneilRgb)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ModelSampleRandomOneilWide40(benchmark::State& state) {
    RunRandomSample(state, "oneil", true);
}
BENCHMARK(BM_ModelSampleRandomOneilWide40)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace atmos
