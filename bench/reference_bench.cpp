// atmos micro-benchmarks of the reference path tracer: paths per second for
// the spectral estimator (48 shells, or one global majorant) and the thesis's
// baseline (one channel per path, delta tracking), over the pixels of a small
// image of a view (so every path length of the view is represented).
#include <benchmark/benchmark.h>

#include <string>

#include "atmos/atmosphere.h"
#include "atmos/view.h"
#include "models/reference.h"

namespace atmos {
namespace {

void RunReference(benchmark::State& state, const char* view_name, bool spectral, int shells) {
    const AtmosphereParameters atm = EarthAtmosphere();
    const View view = GetView(view_name, atm);
    ReferenceEvaluator e;
    e.atm = atm;
    e.shells = BuildMajorantShells(atm, shells);
    e.spectral = spectral;
    e.sample_count = 1;
    e.need_transmittance = false;  // as in a radiance render (no sun disc): the paths alone
    const int w = 48, h = 27;
    int64_t i = 0;
    for (auto _ : state) {
        const int x = static_cast<int>(i % w), y = static_cast<int>((i / w) % h);
        e.sample_begin = static_cast<int>(i / (w * h));
        RayResult r = e.EvaluateKeyed(view.camera.position, view.camera.RayDirection(x, y, w, h),
                                      view.sun_direction, true, static_cast<uint64_t>(y * w + x));
        benchmark::DoNotOptimize(r);
        ++i;
    }
    state.SetItemsProcessed(state.iterations());
}

// The three views of the noise study.
void GroundNoon(benchmark::State& s, bool spectral, int shells) {
    RunReference(s, "ground-noon", spectral, shells);
}
void GroundSunrise(benchmark::State& s, bool spectral, int shells) {
    RunReference(s, "ground-sunrise", spectral, shells);
}
void Space(benchmark::State& s, bool spectral, int shells) {
    RunReference(s, "space", spectral, shells);
}
BENCHMARK_CAPTURE(GroundNoon, spectral_48shells, true, 48);
BENCHMARK_CAPTURE(GroundNoon, spectral_global, true, 1);
BENCHMARK_CAPTURE(GroundNoon, thesis_global, false, 1);
BENCHMARK_CAPTURE(GroundSunrise, spectral_48shells, true, 48);
BENCHMARK_CAPTURE(GroundSunrise, spectral_global, true, 1);
BENCHMARK_CAPTURE(GroundSunrise, thesis_global, false, 1);
BENCHMARK_CAPTURE(Space, spectral_48shells, true, 48);
BENCHMARK_CAPTURE(Space, spectral_global, true, 1);
BENCHMARK_CAPTURE(Space, thesis_global, false, 1);
}  // namespace

}  // namespace atmos
