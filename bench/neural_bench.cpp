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
#include "models/bruneton.h"
#include "models/neural.h"
#include "render/render.h"

namespace atmos {
namespace {

template <typename M>
void BenchEvaluator(benchmark::State& state, const char* name,
                    const std::map<std::string, std::string>& options, const char* view_name) {
    std::unique_ptr<Model> base = CreateModel(name, options);
    base->Prepare(EarthAtmosphere());
    const auto evaluator = dynamic_cast<const M&>(*base).MakeEvaluator();
    const View view = GetView(view_name, EarthAtmosphere());
    std::vector<Vec3d> dirs;
    for (int i = 0; i < 64 * 36; ++i)
        dirs.push_back(view.camera.RayDirection(i % 64, i / 64, 64, 36));
    size_t i = 0;
    for (auto _ : state) {
        RayResult r = evaluator.Evaluate(view.camera.position, dirs[i], view.sun_direction, true);
        benchmark::DoNotOptimize(r);
        i = (i + 1) % dirs.size();
    }
    state.SetItemsProcessed(state.iterations());
}

void BM_NeuralThesis(benchmark::State& s, const char* view) {
    BenchEvaluator<NeuralModel>(s, "neural", {{"network", "thesis"}}, view);
}
void BM_NeuralLarge(benchmark::State& s, const char* view) {
    BenchEvaluator<NeuralModel>(s, "neural", {{"network", "large"}}, view);
}
BENCHMARK_CAPTURE(BM_NeuralThesis, ground_sunrise, "ground-sunrise");
BENCHMARK_CAPTURE(BM_NeuralLarge, ground_sunrise, "ground-sunrise");
BENCHMARK_CAPTURE(BM_NeuralThesis, orbit, "orbit-sunrise");
BENCHMARK_CAPTURE(BM_NeuralLarge, orbit, "orbit-sunrise");

}  // namespace
}  // namespace atmos
