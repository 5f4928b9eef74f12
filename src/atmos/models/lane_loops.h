// atmos: the vector loops of the single-scattering models' exponentials
// (oneil, schuler), kept out of line (ATMOS_LANE_LOOP), with an AVX-512 form
// chosen at run time.
#pragma once

#include "atmos/platform.h"
#include "base/cpu_features.h"
#include "physics/vector_exp.h"

// The vector loops (ATMOS_LANE_LOOP): out of line
// and flattened. In a large translation unit GCC stops inlining ExpPoly
// (physics/vector_exp.h: "inline-unit-growth limit reached") and the loop
// stays a scalar call per value; `flatten` inlines it into the loop
// whatever the unit, so every copy of the loop is the vector one.
// Nothing under nvcc (on the device these loops are plain scalar code, best
// inlined; nvcc's front end need not take `flatten`).
//
// On x86-64 hosts each loop also has an AVX-512 form (ATMOS_LANE_LOOP_AVX512:
// the same loop compiled for 8-double vectors), taken where the CPU has
// AVX-512 (HostUsesAvx512, base/cpu_features.h). Each lane does the same IEEE
// operations in the same order in both forms (the build has no contraction),
// so they give the same bits (tests/vector_exp_test.cpp, LaneLoops.*).
#if defined(__CUDACC__)
#define ATMOS_LANE_LOOP
#elif defined(__GNUC__)
#define ATMOS_LANE_LOOP __attribute__((noinline, flatten))
#else
#define ATMOS_LANE_LOOP
#endif
#if ATMOS_HOST_AVX512_DISPATCH
#define ATMOS_LANE_LOOP_AVX512 __attribute__((noinline, flatten, target("avx512f")))
#endif
#if defined(__GNUC__) && !defined(__CUDACC__)
#define ATMOS_LANE_BODY __attribute__((always_inline)) inline
#else
#define ATMOS_LANE_BODY inline
#endif

// Defines NAME(PARAMS) calling the loop NAME##Body<L>(ARGS) (an
// ATMOS_LANE_BODY template on its vector length L, ATMOS_SIMD_LEN(L)): its
// default form NAME##Default (4 lanes, ATMOS_SIMD's) and, on x86-64 hosts,
// its AVX-512 form NAME##Avx512 (8 lanes), chosen at run time for loops of
// at least kLaneLoopAvx512Min values (PARAMS name their count n; shorter
// loops, e.g. RGB's three channels, run faster in the default form).
#if ATMOS_HOST_AVX512_DISPATCH
#define ATMOS_DEFINE_LANE_LOOP(NAME, PARAMS, ARGS)                                 \
    ATMOS_LANE_LOOP inline void NAME##Default PARAMS { NAME##Body<4> ARGS; }       \
    ATMOS_LANE_LOOP_AVX512 inline void NAME##Avx512 PARAMS { NAME##Body<8> ARGS; } \
    inline void NAME PARAMS {                                                      \
        if (n >= kLaneLoopAvx512Min && HostUsesAvx512()) {                         \
            NAME##Avx512 ARGS;                                                     \
        } else {                                                                   \
            NAME##Default ARGS;                                                    \
        }                                                                          \
    }
#else
#define ATMOS_DEFINE_LANE_LOOP(NAME, PARAMS, ARGS)                                    \
    ATMOS_HD ATMOS_LANE_LOOP inline void NAME##Default PARAMS { NAME##Body<4> ARGS; } \
    ATMOS_HD inline void NAME PARAMS { NAME##Default ARGS; }
#endif

namespace atmos {

constexpr int kLaneLoopAvx512Min = 16;

// x[i] = exp(-x[i]) on ExpLane.
template <int L>
ATMOS_HD ATMOS_LANE_BODY void ExpNegLanesBody(double* __restrict__ x, int n) {
    ATMOS_SIMD_LEN(L)
    for (int i = 0; i < n; ++i) x[i] = ExpLane(-x[i]);
}
ATMOS_DEFINE_LANE_LOOP(ExpNegLanes, (double* __restrict__ x, int n), (x, n))

}  // namespace atmos
