// atmos micro-benchmark of the `neural` model: nanoseconds per evaluator call
// (one view ray) for the thesis-size network (4-8-8-3) and the large one
// (8-32-32-3), from the ground at sunrise and from orbit, through the evaluator
// directly (no render loop). `bruneton` beside them for scale.
//
// Run: build/bench/atmos_bench --benchmark_filter=Neural
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "atmos/view.h"
#include "bench_util.h"
#include "models/bruneton.h"
#include "models/neural.h"
#include "render/render.h"

namespace atmos {
namespace {

void BM_NeuralThesis(benchmark::State& s, const char* view) {
    BenchModelEvaluate<NeuralModel>(s, "neural", {{"network", "thesis"}}, view);
}
void BM_NeuralLarge(benchmark::State& s, const char* view) {
    BenchModelEvaluate<NeuralModel>(s, "neural", {{"network", "large"}}, view);
}
BENCHMARK_CAPTURE(BM_NeuralThesis, ground_sunrise, "ground-sunrise");
BENCHMARK_CAPTURE(BM_NeuralLarge, ground_sunrise, "ground-sunrise");
BENCHMARK_CAPTURE(BM_NeuralThesis, orbit, "orbit-sunrise");
BENCHMARK_CAPTURE(BM_NeuralLarge, orbit, "orbit-sunrise");

}  // namespace
}  // namespace atmos
