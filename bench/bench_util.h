// atmos benchmarks: what several benchmark files share.
#pragma once

#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "atmos/view.h"
#include "render/render.h"

namespace atmos {

// The pixel directions of a 64 x 36 image of `view`'s camera, row by row.
inline std::vector<Vec3d> BenchDirections(const View& view) {
    std::vector<Vec3d> dirs;
    for (int i = 0; i < 64 * 36; ++i) {
        dirs.push_back(view.camera.RayDirection(i % 64, i / 64, 64, 36));
    }
    return dirs;
}

// Times one Evaluate() (one view ray) per iteration, cycling through
// BenchDirections(view), on the calling thread.
template <typename Evaluator>
void BenchEvaluate(benchmark::State& state, const Evaluator& evaluator, const View& view) {
    const std::vector<Vec3d> dirs = BenchDirections(view);
    size_t i = 0;
    for (auto _ : state) {
        RayResult r = evaluator.Evaluate(view.camera.position, dirs[i], view.sun_direction, true);
        benchmark::DoNotOptimize(r);
        i = (i + 1) % dirs.size();
    }
    state.SetItemsProcessed(state.iterations());
}

// BenchEvaluate on the evaluator of the registered model `name` (class M) with
// `options`, prepared for Earth, in the view `view_name`.
template <typename M>
void BenchModelEvaluate(benchmark::State& state, const char* name,
                        const std::map<std::string, std::string>& options, const char* view_name) {
    std::unique_ptr<Model> base = CreateModel(name, options);
    base->Prepare(EarthAtmosphere());
    const auto evaluator = dynamic_cast<const M&>(*base).MakeEvaluator();
    BenchEvaluate(state, evaluator, GetView(view_name, EarthAtmosphere()));
}

}  // namespace atmos
