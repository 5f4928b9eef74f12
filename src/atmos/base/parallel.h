// atmos: the one ParallelFor of the project (CPU backend: oneTBB), and the
// choice of backend for the per-pixel loops.
//
// Work is split into independent items; results must not depend on the
// schedule, so a render is bit-identical for any thread count.
//
// Backend: the one loop of the project (RunStage, render/stages.h: renders,
// samples and precomputation stages) runs on the CPU (ParallelFor, the
// default) or, in a build with CUDA (ATMOS_CUDA, which defines
// ATMOS_HAS_CUDA), as CUDA kernels over the same per-item code. The choice is
// made here, once per process (BackendScope), and read by that loop.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "base/non_copyable.h"

namespace atmos {

// Limits the worker threads used by ParallelFor for the lifetime of the
// returned guard (0: all cores). Nested guards: the innermost wins.
class ThreadLimit : private NonCopyable {
  public:
    explicit ThreadLimit(int threads);
    ~ThreadLimit();

  private:
    void* control_ = nullptr;
};

// Number of threads ParallelFor uses now.
int ParallelThreadCount();

// Calls body(i) for i in [0, count), in parallel, in chunks of `grain` items.
void ParallelFor(int64_t count, int64_t grain, const std::function<void(int64_t)>& body);

// Splits a width x height grid into tiles of tile x tile and calls
// body(x0, y0, x1, y1) for each tile (half-open), in parallel.
void ParallelForTiles(int width, int height, int tile,
                      const std::function<void(int, int, int, int)>& body);

// kEmulatedDevice: tests only (not a command-line choice): every launch
// (renders, samples, precomputation stages) runs the CUDA backend's
// bookkeeping with host memory standing in for the device (render/stages.h).
enum class Backend { kCpu, kCuda, kEmulatedDevice };
// True for the backends whose precomputations keep tables in device copies.
inline bool IsDeviceBackend(Backend backend) { return backend != Backend::kCpu; }

// "cpu" | "cuda"; throws atmos::Error otherwise.
Backend ParseBackend(const std::string& text);
const char* BackendName(Backend backend);
// True when this build was configured with CUDA (ATMOS_CUDA).
bool HasCudaSupport();
// Throws one clear atmos::Error when `backend` cannot run here: a build
// without CUDA, or no usable CUDA device (naming what cudaGetDeviceCount
// returned).
void CheckBackendAvailable(Backend backend);

// Selects the backend of the per-pixel loops for the lifetime of the guard
// (checked with CheckBackendAvailable first). Process-wide; nested guards:
// the innermost wins.
class BackendScope : private NonCopyable {
  public:
    explicit BackendScope(Backend backend);
    ~BackendScope();

  private:
    Backend previous_;
};
Backend CurrentBackend();

}  // namespace atmos
