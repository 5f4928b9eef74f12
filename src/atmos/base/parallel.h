// atmos: the one ParallelFor of the project (CPU backend: oneTBB).
//
// Work is split into independent items; results must not depend on the
// schedule, so a render is bit-identical for any thread count.
#pragma once

#include <cstdint>
#include <functional>

namespace atmos {

// Limits the worker threads used by ParallelFor for the lifetime of the
// returned guard (0: all cores). Nested guards: the innermost wins.
class ThreadLimit {
  public:
    explicit ThreadLimit(int threads);
    ~ThreadLimit();
    ThreadLimit(const ThreadLimit&) = delete;
    ThreadLimit& operator=(const ThreadLimit&) = delete;

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

}  // namespace atmos
