// atmos: the vector loops of the single-scattering models' exponentials
// (oneil, schuler), kept out of line (ATMOS_LANE_LOOP).
#pragma once

#include "atmos/platform.h"
#include "physics/vector_exp.h"

// The vector loops (ATMOS_LANE_LOOP): out of line
// and flattened. In a large translation unit GCC stops inlining ExpPoly
// (physics/vector_exp.h: "inline-unit-growth limit reached") and the loop
// stays a scalar call per value; `flatten` inlines it into the loop
// whatever the unit, so every copy of the loop is the vector one.
// Nothing under nvcc (on the device these loops are plain scalar code, best
// inlined; nvcc's front end need not take `flatten`).
#if defined(__CUDACC__)
#define ATMOS_LANE_LOOP
#elif defined(__GNUC__)
#define ATMOS_LANE_LOOP __attribute__((noinline, flatten))
#else
#define ATMOS_LANE_LOOP
#endif

namespace atmos {

// x[i] = exp(-x[i]) on ExpLane.
ATMOS_HD ATMOS_LANE_LOOP inline void ExpNegLanes(double* __restrict__ x, int n) {
    ATMOS_SIMD
    for (int i = 0; i < n; ++i) x[i] = ExpLane(-x[i]);
}

}  // namespace atmos
