// atmos benchmarks of the metrics: FLIP and RMSE of a 1920x1080 pair (the
// thesis's image size), on all cores.
//
// Run: build/bench/atmos_bench --benchmark_filter=Flip --benchmark_repetitions=5
//      --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include "atmos/image.h"
#include "metrics/flip.h"
#include "metrics/rmse.h"

namespace atmos {
namespace {

// A sky-like pair: a smooth HDR gradient with a bright disc; the test image
// is 3% brighter in its right half.
void MakePair(int w, int h, Image* ref, Image* test) {
    *ref = Image(w, h);
    *test = Image(w, h);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const float t = static_cast<float>(y) / static_cast<float>(h);
            Rgb c(0.05f + 0.6f * t, 0.1f + 0.5f * t, 0.9f - 0.5f * t);
            const float dx = static_cast<float>(x - w / 3), dy = static_cast<float>(y - h / 4);
            if (dx * dx + dy * dy < 400.0f) c = Rgb(20.0f, 18.0f, 15.0f);
            ref->Set(x, y, c);
            test->Set(x, y, x > w / 2 ? c * 1.03f : c);
        }
    }
}

void BM_HdrFlip1080p(benchmark::State& state) {
    Image ref, test;
    MakePair(1920, 1080, &ref, &test);
    int exposures = 0;
    for (auto _ : state) {
        const FlipResult r = HdrFlip(ref, test);
        exposures = r.exposures.count;
        benchmark::DoNotOptimize(r.mean);
    }
    state.counters["exposures"] = exposures;
}
BENCHMARK(BM_HdrFlip1080p)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_LdrFlip1080p(benchmark::State& state) {
    Image ref, test;
    MakePair(1920, 1080, &ref, &test);
    for (float* p = ref.data(); p != ref.data() + ref.size(); ++p) *p = *p > 1.0f ? 1.0f : *p;
    for (float* p = test.data(); p != test.data() + test.size(); ++p) *p = *p > 1.0f ? 1.0f : *p;
    for (auto _ : state) benchmark::DoNotOptimize(LdrFlip(ref, test).mean);
}
BENCHMARK(BM_LdrFlip1080p)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Rmse1080p(benchmark::State& state) {
    Image ref, test;
    MakePair(1920, 1080, &ref, &test);
    for (auto _ : state) benchmark::DoNotOptimize(ComputeRmse(ref, test).overall);
}
BENCHMARK(BM_Rmse1080p)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace atmos
