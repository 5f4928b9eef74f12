// atmos: the host CPU's vector features, for loops with a run-time choice of
// instruction set.
//
// ATMOS_HOST_AVX512_DISPATCH is 1 where a host loop may have an AVX-512 form
// beside its default one (GCC or Clang host code for x86-64; not under nvcc).
// HostUsesAvx512() says whether this process takes those forms: the CPU has
// AVX-512F and the environment variable ATMOS_AVX512 is not "0" (for
// side-by-side benchmarks). Either form gives the same values; only speed
// differs.
#pragma once

#if !defined(__CUDACC__) && defined(__GNUC__) && defined(__x86_64__)
#define ATMOS_HOST_AVX512_DISPATCH 1
#else
#define ATMOS_HOST_AVX512_DISPATCH 0
#endif

#if ATMOS_HOST_AVX512_DISPATCH
#include <cstdlib>
#include <cstring>

namespace atmos {

inline bool HostUsesAvx512() {
    static const bool use = [] {
        const char* v = std::getenv("ATMOS_AVX512");
        if (v && std::strcmp(v, "0") == 0) return false;
        return __builtin_cpu_supports("avx512f") != 0;
    }();
    return use;
}

}  // namespace atmos
#endif
