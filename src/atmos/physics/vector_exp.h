// atmos: an exponential that loops can vectorise, and the profile density on it.
//
// ExpPoly(x) is exp(x) from the math: x = k ln 2 + r with k = round(x / ln 2)
// (Cody and Waite's two-part ln 2, so k ln 2 is exact for |k| < 2^11),
// |r| <= ln 2 / 2, exp(r) by its Taylor series to degree 13 (the next term,
// r^14 / 14!, is under 4e-18), and 2^k built in the exponent bits in two halves
// (2^k1 2^k2, k1 + k2 = k) so that k = 1024 (overflow to inf) and subnormal
// results come out right. Every step is arithmetic or a compare without a
// branch, so a loop of it under ATMOS_SIMD compiles to vector code (glibc's
// exp is a scalar call). Against std::exp on 200,000 arguments in
// [-708, 709.7] (tests/vector_exp_test.cpp): at most 1 ulp (2^-52 relative)
// apart; exp(-inf) = 0, exp(inf) = inf, NaN stays NaN. ExpLane (below) is
// what the loops call.
//
// ATMOS_SIMD: `#pragma omp simd` where the compiler takes it (-fopenmp-simd,
// CMakeLists.txt), nothing elsewhere (nvcc, other compilers).
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

#include "atmos/atmosphere.h"
#include "atmos/math.h"

#if defined(ATMOS_OPENMP_SIMD) && !defined(__CUDACC__)
#define ATMOS_PRAGMA(x) _Pragma(#x)
#define ATMOS_SIMD ATMOS_PRAGMA(omp simd simdlen(4))
// simdlen(L): a loop whose vector length its caller picks (models/lane_loops.h).
#define ATMOS_SIMD_LEN(L) ATMOS_PRAGMA(omp simd simdlen(L))
#define ATMOS_SIMD_SUM3(a, b, c) ATMOS_PRAGMA(omp simd reduction(+ : a, b, c))
// No simdlen: the compiler's widest vectors (loops mixing float and double
// then run 8 lanes on AVX2, where simdlen(4) gives pairs of 16-byte halves).
#define ATMOS_SIMD_WIDE ATMOS_PRAGMA(omp simd)
#else
#define ATMOS_SIMD_WIDE
#define ATMOS_SIMD
#define ATMOS_SIMD_LEN(L)
#define ATMOS_SIMD_SUM3(a, b, c)
#endif

namespace atmos {

namespace detail {
inline double BitsToDouble(uint64_t b) {
    double d;
    std::memcpy(&d, &b, sizeof d);
    return d;
}
inline uint64_t DoubleToBits(double d) {
    uint64_t b;
    std::memcpy(&b, &d, sizeof b);
    return b;
}
}  // namespace detail

// The polynomial exponential (host; any instruction set).
inline double ExpPoly(double x) {
    // 1.5 * 2^52: adding it rounds to an integer, held in the low mantissa bits.
    const double kShift = 6755399441055744.0;
    const double kInvLn2 = 1.4426950408889634;
    // ln 2 = kLn2Hi + kLn2Lo; kLn2Hi has 32 significant bits (k kLn2Hi exact).
    const double kLn2Hi = 0.6931471803691238;
    const double kLn2Lo = 1.9082149292705877e-10;
    x = x < -746.0 ? -746.0 : x;  // exp(-746) = 0, exp(710) = inf; NaN passes
    x = x > 710.0 ? 710.0 : x;
    const double k = (x * kInvLn2 + kShift) - kShift;
    const double r = (x - k * kLn2Hi) - k * kLn2Lo;
    double p = 1.0 / 6227020800.0;  // 1/13!
    p = p * r + 1.0 / 479001600.0;
    p = p * r + 1.0 / 39916800.0;
    p = p * r + 1.0 / 3628800.0;
    p = p * r + 1.0 / 362880.0;
    p = p * r + 1.0 / 40320.0;
    p = p * r + 1.0 / 5040.0;
    p = p * r + 1.0 / 720.0;
    p = p * r + 1.0 / 120.0;
    p = p * r + 1.0 / 24.0;
    p = p * r + 1.0 / 6.0;
    p = p * r + 0.5;
    p = p * r + 1.0;
    p = p * r + 1.0;
    const double k1 = (k * 0.5 + kShift) - kShift;
    const double k2 = k - k1;
    const uint64_t shift_bits = detail::DoubleToBits(kShift);
    const uint64_t e1 = (detail::DoubleToBits(k1 + kShift) - shift_bits + 1023) << 52;
    const uint64_t e2 = (detail::DoubleToBits(k2 + kShift) - shift_bits + 1023) << 52;
    return p * detail::BitsToDouble(e1) * detail::BitsToDouble(e2);
}

// ExpLane: ExpPoly where loops of it become 4-lane vector code (AVX2, e.g.
// ATMOS_ARCH=x86-64-v3); elsewhere glibc's exp (its scalar FMA path, chosen at
// run time, is faster than 2-lane SSE2 vectors of ExpPoly); CUDA's exp on the
// device.
ATMOS_HD inline double ExpLane(double x) {
#if defined(__CUDA_ARCH__)
    return exp(x);
#elif defined(__AVX2__)
    return ExpPoly(x);
#else
    return exp(x);
#endif
}

ATMOS_HD inline Vec3d ExpLane(const Vec3d& a) { return {ExpLane(a.x), ExpLane(a.y), ExpLane(a.z)}; }

// ExpPolyF(x): exp in float, for loops over many channels whose result is a
// float anyway (8 lanes on AVX2 where ExpPoly runs 4). The same construction
// as ExpPoly: x = k ln 2 + r (two-part ln 2; kLn2HiF has 9 significant bits, so
// k kLn2HiF is exact for |k| < 2^15), |r| <= ln 2 / 2, exp(r) by its Taylor
// series to degree 7 (the next term, r^8 / 8!, is under 6e-9 = 0.05 ulp), and
// 2^k in two halves so that overflow gives inf and the subnormals come out
// right. Against exp in double rounded to float on 200,000 arguments in
// [-103, 88.7] (tests/vector_exp_test.cpp): at most 2 ulp (2^-22 relative) for
// normal results; exp(-inf) = 0, exp(inf) = inf, NaN stays NaN.
inline float ExpPolyF(float x) {
    const float kShift = 12582912.0f;  // 1.5 * 2^23
    const float kInvLn2 = 1.44269504f;
    const float kLn2Hi = 0.693359375f;
    const float kLn2Lo = -2.12194440e-4f;
    x = x < -104.0f ? -104.0f : x;  // exp(-104) = 0 in float, exp(89) = inf
    x = x > 89.0f ? 89.0f : x;
    const float k = (x * kInvLn2 + kShift) - kShift;
    const float r = (x - k * kLn2Hi) - k * kLn2Lo;
    float p = 1.0f / 5040.0f;
    p = p * r + 1.0f / 720.0f;
    p = p * r + 1.0f / 120.0f;
    p = p * r + 1.0f / 24.0f;
    p = p * r + 1.0f / 6.0f;
    p = p * r + 0.5f;
    p = p * r + 1.0f;
    p = p * r + 1.0f;
    const float k1 = (k * 0.5f + kShift) - kShift;
    const float k2 = k - k1;
    uint32_t shift_bits;
    std::memcpy(&shift_bits, &kShift, sizeof shift_bits);
    const float f1 = k1 + kShift, f2 = k2 + kShift;
    uint32_t b1, b2;
    std::memcpy(&b1, &f1, sizeof b1);
    std::memcpy(&b2, &f2, sizeof b2);
    const uint32_t e1 = (b1 - shift_bits + 127u) << 23;
    const uint32_t e2 = (b2 - shift_bits + 127u) << 23;
    float s1, s2;
    std::memcpy(&s1, &e1, sizeof s1);
    std::memcpy(&s2, &e2, sizeof s2);
    return p * s1 * s2;
}

// ExpLaneF: ExpPolyF where loops of it become vector code (AVX2); elsewhere
// the C library's expf; CUDA's expf on the device. The scalar and the vector
// code give the same bits, so a three-channel evaluator and a wide one agree.
ATMOS_HD inline float ExpLaneF(float x) {
#if defined(__CUDA_ARCH__)
    return expf(x);
#elif defined(__AVX2__)
    return ExpPolyF(x);
#else
    return std::exp(x);
#endif
}

// GetProfileDensity (physics/density.h) without branches, on ExpLane, for
// loops: the profile's terms in locals (no loads through the atmosphere in the
// loop), the layer's terms selected, then one density formula. `kExp` false:
// both layers' exp_term are 0 (e.g. the ozone tent), no exponential.
struct LaneProfile {
    double width;
    double exp_term[2], exp_scale[2], linear[2], constant[2];
    bool any_exp;
    ATMOS_HD explicit LaneProfile(const DensityProfile& p)
        : width(p.layers[0].width),
          exp_term{p.layers[0].exp_term, p.layers[1].exp_term},
          exp_scale{p.layers[0].exp_scale, p.layers[1].exp_scale},
          linear{p.layers[0].linear_term, p.layers[1].linear_term},
          constant{p.layers[0].constant_term, p.layers[1].constant_term},
          any_exp(exp_term[0] != 0.0 || exp_term[1] != 0.0) {}

    template <bool kExp>
    ATMOS_HD double Density(double altitude) const {
        const bool lower = altitude < width;
        double e = 0.0;
        if (kExp) {
            const double term = lower ? exp_term[0] : exp_term[1];
            const double x = ExpLane((lower ? exp_scale[0] : exp_scale[1]) * altitude);
            e = term != 0.0 ? term * x : 0.0;
        }
        const double density =
            e + (lower ? linear[0] : linear[1]) * altitude + (lower ? constant[0] : constant[1]);
        return Clamp(density, 0.0, 1.0);
    }
    ATMOS_HD double Density(double altitude) const {
        return any_exp ? Density<true>(altitude) : Density<false>(altitude);
    }
};

}  // namespace atmos
