// atmos: THE loop of the precomputations (the tables of bruneton, hillaire,
// atmosphere-plus), on the CPU or, in a CUDA build, on the device, from the
// same source.
//
// A stage is a trivially copyable struct:
//
//   struct MyStage {
//       TableView input;    // tables it reads (host pointers)
//       TableOut output;    // tables it writes (host pointers)
//       template <typename V> void VisitTables(V& v) { v(input); v(output); }
//       ATMOS_HD void operator()(int64_t item) const;  // does item `item`
//   };
//
// Items must be independent (each writes its own texels), so the result does not
// depend on the schedule. RunStage(name, count, grain, stage) calls stage(i) for
// i in [0, count):
// - on the CPU backend, through the project's one ParallelFor (chunks of `grain`);
// - on the CUDA backend, for stages declared with ATMOS_DEVICE_STAGE (below) and
//   instantiated in a .cu file with ATMOS_INSTANTIATE_DEVICE_STAGE
//   (src/atmos/cuda/stage_launch.cuh): every table VisitTables names is copied
//   to the device (outputs too, so a stage may read-modify-write its output),
//   one thread runs each item, and the outputs are copied back. A table named
//   twice (the same host pointer) has one device copy.
// A stage without device code fails with one clear error on the CUDA backend.
//
// A StageLogScope collects, per stage run, the name, item count and the time:
// wall time on the CPU; on the device, the kernel alone between CUDA events
// and the whole call with the copies (`atmos bench` prints them).
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include "base/parallel.h"
#include "base/texture.h"

namespace atmos {

// True for stages with device code (ATMOS_DEVICE_STAGE).
template <typename Stage>
struct HasDeviceStage : std::false_type {};

// Declares, next to a stage's definition (at namespace atmos scope), that a .cu
// file instantiates it with ATMOS_INSTANTIATE_DEVICE_STAGE. A stage declared
// but not instantiated fails to link in a CUDA build.
#define ATMOS_DEVICE_STAGE(S) \
    template <>               \
    struct HasDeviceStage<S> : std::true_type {};

struct StageTime {
    std::string name;
    int64_t items = 0;
    std::string backend;     // "cpu" or "cuda"
    double kernel_ms = 0.0;  // CPU: the ParallelFor; CUDA: between events around the kernel
    double total_ms = 0.0;   // CUDA: with the copies to and from the device
};

// Installs a log that every RunStage appends to while it lives (process-wide;
// nested scopes: the innermost wins).
class StageLogScope {
  public:
    explicit StageLogScope(std::vector<StageTime>* log);
    ~StageLogScope();
    StageLogScope(const StageLogScope&) = delete;
    StageLogScope& operator=(const StageLogScope&) = delete;

  private:
    std::vector<StageTime>* previous_;
};
std::vector<StageTime>* CurrentStageLog();
void LogStage(StageTime entry);

[[noreturn]] void FailNoDeviceStage(const char* name, bool has_cuda);

#if defined(ATMOS_HAS_CUDA)
namespace cuda {
// Defined in src/atmos/cuda/stage_launch.cuh; instantiated per stage.
template <typename Stage>
void RunStageDevice(const char* name, int64_t count, const Stage& stage);
}  // namespace cuda
#endif

template <typename Stage>
void RunStage(const char* name, int64_t count, int64_t grain, const Stage& stage) {
    static_assert(std::is_trivially_copyable<Stage>::value,
                  "stages are passed to kernels by value");
    if (count <= 0) return;
    if (CurrentBackend() == Backend::kCuda) {
#if defined(ATMOS_HAS_CUDA)
        if constexpr (HasDeviceStage<Stage>::value) {
            cuda::RunStageDevice(name, count, stage);
            return;
        } else {
            FailNoDeviceStage(name, true);
        }
#else
        FailNoDeviceStage(name, false);
#endif
    }
    const auto start = std::chrono::steady_clock::now();
    ParallelFor(count, grain, [&](int64_t i) { stage(i); });
    if (CurrentStageLog()) {
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        LogStage({name, count, "cpu", ms, ms});
    }
}

}  // namespace atmos
