// atmos micro-benchmarks of the single-scattering / analytic family and the
// transmittance models: nanoseconds per evaluator call (one view ray), from
// the ground at sunrise (the thesis's ground-sunrise view), through the
// evaluators directly (no render loop).
//
// Run: build/bench/atmos_bench --benchmark_filter=Analytic
#include <benchmark/benchmark.h>

#include <memory>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/model.h"
#include "atmos/view.h"
#include "bench_util.h"
#include "models/flat.h"
#include "models/oneil.h"
#include "models/preetham.h"
#include "models/raymarched.h"
#include "models/schuler.h"
#include "models/transmittance_chapman.h"
#include "models/transmittance_erfc.h"
#include "models/transmittance_flat.h"
#include "models/transmittance_oneil.h"
#include "models/transmittance_polynomial.h"
#include "models/transmittance_reference.h"
#include "render/render.h"

namespace atmos {
namespace {

#define ATMOS_ANALYTIC_BENCH(Type, name)                             \
    void BM_Analytic_##Type(benchmark::State& state) {               \
        BenchModelEvaluate<Type>(state, name, {}, "ground-sunrise"); \
    }                                                                \
    BENCHMARK(BM_Analytic_##Type);                                   \
    void BM_Analytic_##Type##_Space(benchmark::State& state) {       \
        BenchModelEvaluate<Type>(state, name, {}, "space");          \
    }                                                                \
    BENCHMARK(BM_Analytic_##Type##_Space);

ATMOS_ANALYTIC_BENCH(OneilModel, "oneil")
ATMOS_ANALYTIC_BENCH(SchulerModel, "schuler")
ATMOS_ANALYTIC_BENCH(FlatModel, "flat")
ATMOS_ANALYTIC_BENCH(RaymarchedModel, "raymarched")
ATMOS_ANALYTIC_BENCH(PreethamModel, "preetham")
ATMOS_ANALYTIC_BENCH(TransmittanceReferenceModel, "transmittance-reference")
ATMOS_ANALYTIC_BENCH(TransmittanceFlatModel, "transmittance-flat")
ATMOS_ANALYTIC_BENCH(TransmittanceErfcModel, "transmittance-erfc")
ATMOS_ANALYTIC_BENCH(TransmittanceChapmanModel, "transmittance-chapman")
ATMOS_ANALYTIC_BENCH(TransmittanceOneilModel, "transmittance-oneil")
ATMOS_ANALYTIC_BENCH(TransmittancePolynomialModel, "transmittance-polynomial")

}  // namespace
}  // namespace atmos
