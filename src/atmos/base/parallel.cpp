#include "base/parallel.h"

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>

#include "atmos/error.h"
#if defined(ATMOS_HAS_CUDA)
#include "cuda/runtime.h"
#endif

namespace atmos {

ThreadLimit::ThreadLimit(int threads) {
    if (threads > 0) {
        control_ = new tbb::global_control(tbb::global_control::max_allowed_parallelism,
                                           static_cast<size_t>(threads));
    }
}

ThreadLimit::~ThreadLimit() { delete static_cast<tbb::global_control*>(control_); }

int ParallelThreadCount() {
    return static_cast<int>(
        tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
}

void ParallelFor(int64_t count, int64_t grain, const std::function<void(int64_t)>& body) {
    if (count <= 0) return;
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, count, grain > 0 ? grain : 1),
                      [&](const tbb::blocked_range<int64_t>& range) {
                          for (int64_t i = range.begin(); i != range.end(); ++i) body(i);
                      });
}

void ParallelForTiles(int width, int height, int tile,
                      const std::function<void(int, int, int, int)>& body) {
    if (width <= 0 || height <= 0) return;
    const int tiles_x = (width + tile - 1) / tile;
    const int tiles_y = (height + tile - 1) / tile;
    ParallelFor(static_cast<int64_t>(tiles_x) * tiles_y, 1, [&](int64_t index) {
        const int tx = static_cast<int>(index % tiles_x);
        const int ty = static_cast<int>(index / tiles_x);
        const int x0 = tx * tile;
        const int y0 = ty * tile;
        body(x0, y0, x0 + tile < width ? x0 + tile : width,
             y0 + tile < height ? y0 + tile : height);
    });
}

namespace {
std::atomic<Backend> g_backend{Backend::kCpu};
}  // namespace

Backend ParseBackend(const std::string& text) {
    if (text == "cpu") return Backend::kCpu;
    if (text == "cuda") return Backend::kCuda;
    Fail("unknown backend '", text, "': expected cpu or cuda");
}

const char* BackendName(Backend backend) {
    switch (backend) {
        case Backend::kCuda:
            return "cuda";
        case Backend::kEmulatedDevice:
            return "emulated-device";
        default:
            return "cpu";
    }
}

bool HasCudaSupport() {
#if defined(ATMOS_HAS_CUDA)
    return true;
#else
    return false;
#endif
}

void CheckBackendAvailable(Backend backend) {
    if (backend != Backend::kCuda) return;
#if defined(ATMOS_HAS_CUDA)
    cuda::RequireDevice();
#else
    Fail("--backend cuda: this build has no CUDA support; configure with -DATMOS_CUDA=ON");
#endif
}

BackendScope::BackendScope(Backend backend) : previous_(g_backend.load()) {
    CheckBackendAvailable(backend);
    g_backend.store(backend);
}
BackendScope::~BackendScope() { g_backend.store(previous_); }
Backend CurrentBackend() { return g_backend.load(); }

}  // namespace atmos
