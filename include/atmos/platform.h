// atmos: platform macros shared by host (C++17) and device (CUDA) code.
//
// ATMOS_HD marks every function that runs per pixel: it expands to
// `__host__ __device__` under nvcc and to nothing in the plain C++ build, so the
// same source compiles for both. Code marked ATMOS_HD uses no virtual calls, no
// std:: containers, no exceptions and no allocation.
#pragma once

#if defined(__CUDACC__)
#define ATMOS_HD __host__ __device__
#define ATMOS_HOST __host__
#else
#define ATMOS_HD
#define ATMOS_HOST
#endif

// True while compiling device code (the nvcc device pass).
#if defined(__CUDA_ARCH__)
#define ATMOS_IS_GPU_CODE 1
#else
#define ATMOS_IS_GPU_CODE 0
#endif

// Debug-build domain checks usable in per-pixel code. On the device (and in
// release builds) they compile to nothing.
#if !ATMOS_IS_GPU_CODE && !defined(NDEBUG)
#include <cassert>
#define ATMOS_DASSERT(cond) assert(cond)
#else
#define ATMOS_DASSERT(cond) ((void)0)
#endif
