// Tests of physics/vector_exp.h: ExpPoly and ExpLane against std::exp, the branch-free
// profile density against GetProfileDensity.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "atmos/atmosphere.h"
#include "base/cpu_features.h"
#include "models/lane_loops.h"
#include "models/oneil.h"
#include "physics/density.h"
#include "physics/vector_exp.h"

namespace atmos {
namespace {

TEST(VectorExp, WithinOneUlpOfStdExp) {
    // Over the whole range where exp is finite and normal: at most 1 ulp
    // (2^-52 relative) from glibc's correctly rounded-or-nearly exp.
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> wide(-708.0, 709.7), narrow(-2.0, 2.0);
    std::vector<double> x(200000), y(x.size());
    for (size_t i = 0; i < x.size(); ++i) x[i] = (i % 2) ? wide(rng) : narrow(rng);
    ATMOS_SIMD
    for (size_t i = 0; i < x.size(); ++i) y[i] = ExpPoly(x[i]);  // the vector loop
    double worst = 0.0;
    for (size_t i = 0; i < x.size(); ++i) {
        const double want = std::exp(x[i]);
        worst = std::max(worst, std::fabs(y[i] - want) / want);
        EXPECT_EQ(y[i], ExpPoly(x[i])) << x[i];  // scalar and vector code agree
        EXPECT_LE(std::fabs(ExpLane(x[i]) - want), std::ldexp(want, -52)) << x[i];
    }
    EXPECT_LE(worst, std::ldexp(1.0, -52));
}

TEST(VectorExp, EdgesOfTheRange) {
    const double inf = std::numeric_limits<double>::infinity();
    EXPECT_EQ(ExpPoly(0.0), 1.0);
    EXPECT_EQ(ExpPoly(-inf), 0.0);
    EXPECT_EQ(ExpPoly(-800.0), 0.0);
    EXPECT_EQ(ExpPoly(inf), inf);
    EXPECT_EQ(ExpPoly(709.9), inf);
    EXPECT_TRUE(std::isnan(ExpPoly(std::nan(""))));
    // Near the overflow and in the subnormals: a few ulp of the subnormal spacing.
    EXPECT_NEAR(ExpPoly(709.7) / std::exp(709.7), 1.0, 1e-15);
    for (double x : {-709.0, -720.0, -740.0, -745.0}) {
        EXPECT_NEAR(ExpPoly(x), std::exp(x), 4 * std::numeric_limits<double>::denorm_min()) << x;
    }
}

TEST(VectorExp, FloatWithinTwoUlpOfExp) {
    // Normal results: at most 2 ulp (2^-22 relative) from exp in double
    // rounded to float; the vector loop and the scalar function agree.
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<float> wide(-87.0f, 88.7f), narrow(-2.0f, 2.0f);
    std::vector<float> x(200000), y(x.size());
    for (size_t i = 0; i < x.size(); ++i) x[i] = (i % 2) ? wide(rng) : narrow(rng);
    ATMOS_SIMD_WIDE
    for (size_t i = 0; i < x.size(); ++i) y[i] = ExpPolyF(x[i]);
    double worst = 0.0;
    for (size_t i = 0; i < x.size(); ++i) {
        const double want = static_cast<float>(std::exp(static_cast<double>(x[i])));
        worst = std::max(worst, std::fabs(static_cast<double>(y[i]) - want) / want);
        EXPECT_EQ(y[i], ExpPolyF(x[i])) << x[i];
        EXPECT_LE(std::fabs(static_cast<double>(ExpLaneF(x[i])) - want), std::ldexp(want, -22))
            << x[i];
    }
    EXPECT_LE(worst, std::ldexp(1.0, -22));
}

TEST(VectorExp, FloatEdgesOfTheRange) {
    const float inf = std::numeric_limits<float>::infinity();
    EXPECT_EQ(ExpPolyF(0.0f), 1.0f);
    EXPECT_EQ(ExpPolyF(-inf), 0.0f);
    EXPECT_EQ(ExpPolyF(-110.0f), 0.0f);
    EXPECT_EQ(ExpPolyF(inf), inf);
    EXPECT_EQ(ExpPolyF(89.0f), inf);
    EXPECT_TRUE(std::isnan(ExpPolyF(std::nanf(""))));
    // Subnormal results: within a few subnormal spacings.
    for (float x : {-88.0f, -95.0f, -100.0f, -103.0f}) {
        EXPECT_NEAR(ExpPolyF(x), std::exp(static_cast<double>(x)),
                    4 * std::numeric_limits<float>::denorm_min())
            << x;
    }
}

TEST(VectorExp, LaneProfileIsGetProfileDensity) {
    // Every profile kind of the presets: one exponential (layers[0] empty), the
    // ozone tent (two linear layers, no exponential), and a two-layer profile
    // with both terms; the altitude crosses the layer boundary.
    const AtmosphereParameters earth = EarthAtmosphere();
    DensityProfile mixed;
    mixed.layers[0] = {10e3, 0.7, -1.0 / 3000.0, 1e-5, 0.1};
    mixed.layers[1] = {0.0, 2.0, -1.0 / 9000.0, -2e-6, 0.05};
    // 1 ulp of the exponential term: relative for a pure exponential, up to
    // 1 ulp of exp_term (2) absolute where linear and constant terms are added.
    const std::pair<DensityProfile, double> cases[] = {{earth.rayleigh_density, 0.0},
                                                       {earth.mie_density, 0.0},
                                                       {earth.absorption_density, 0.0},
                                                       {mixed, 4.5e-16}};
    for (const auto& c : cases) {
        const DensityProfile& p = c.first;
        const double slack = c.second;
        for (double h = -100.0; h < 120e3; h += 37.5) {
            const double want = GetProfileDensity(p, h);
            const LaneProfile lane(p);
            EXPECT_NEAR(lane.Density(h), want, 2.3e-16 * want + slack) << h;
            if (!lane.any_exp) {
                EXPECT_EQ(lane.Density<false>(h), want) << h;
            }
        }
    }
    EXPECT_FALSE(LaneProfile(earth.absorption_density).any_exp);
    EXPECT_TRUE(LaneProfile(earth.rayleigh_density).any_exp);
}

#if ATMOS_HOST_AVX512_DISPATCH
// The lane loops' AVX-512 forms (models/lane_loops.h: 8-double vectors) give
// the default forms' bits on every value: exponents over the whole range and
// its edges (including the clamps, 0 and infinity), n from 1 to 48 (the
// vector loops' remainders).
TEST(LaneLoops, Avx512FormsEqualTheDefaultFormsBitForBit) {
    if (!__builtin_cpu_supports("avx512f")) GTEST_SKIP() << "no AVX-512 on this CPU";
    std::mt19937_64 rng(37);
    std::uniform_real_distribution<double> wide(-760.0, 720.0), small(-3.0, 3.0), coeff(0.0, 5e-5),
        length(0.0, 2e6), weight(0.0, 1e3);
    const double edges[] = {-800.0, -746.0, -745.1, -700.0, -1e-300, 0.0,
                            1e-300, 60.0,   709.7,  710.0,  800.0};
    const auto same = [](double a, double b) {
        uint64_t x, y;
        std::memcpy(&x, &a, sizeof x);
        std::memcpy(&y, &b, sizeof y);
        return x == y;
    };
    int compared = 0;
    for (int round = 0; round < 200; ++round) {
        const int n = 1 + round % 48;
        std::vector<double> x(static_cast<size_t>(n));
        for (int i = 0; i < n; ++i) {
            const double v = round % 3 == 0 ? wide(rng) : small(rng);
            x[static_cast<size_t>(i)] = round % 7 == 0 ? edges[(i + round) % 11] : v;
        }
        std::vector<double> a = x, b = x;
        ExpNegLanesDefault(a.data(), n);
        ExpNegLanesAvx512(b.data(), n);
        for (int i = 0; i < n; ++i) ASSERT_TRUE(same(a[i], b[i])) << "ExpNegLanes " << x[i];
        a = x;
        b = x;
        OneilSafeExpLanesDefault(a.data(), n);
        OneilSafeExpLanesAvx512(b.data(), n);
        for (int i = 0; i < n; ++i) ASSERT_TRUE(same(a[i], b[i])) << "OneilSafeExpLanes " << x[i];
        std::vector<double> ca(static_cast<size_t>(n)), cb(static_cast<size_t>(n));
        for (int i = 0; i < n; ++i) {
            ca[static_cast<size_t>(i)] = coeff(rng);
            cb[static_cast<size_t>(i)] = coeff(rng);
        }
        const double l_r = length(rng), l_m = length(rng) * 0.1, w_r = weight(rng),
                     w_m = weight(rng);
        std::vector<double> ra(x), ma(x), rb(x), mb(x);
        for (int step = 0; step < 3; ++step) {
            OneilAttenuateLanesDefault(ca.data(), cb.data(), n, l_r * step, l_m * step, w_r, w_m,
                                       ra.data(), ma.data());
            OneilAttenuateLanesAvx512(ca.data(), cb.data(), n, l_r * step, l_m * step, w_r, w_m,
                                      rb.data(), mb.data());
        }
        for (int i = 0; i < n; ++i) {
            ASSERT_TRUE(same(ra[i], rb[i]) && same(ma[i], mb[i])) << "OneilAttenuateLanes " << i;
        }
        compared += 4 * n;
    }
    std::printf("lane loops: %d values equal in both forms\n", compared);
}
#endif

}  // namespace
}  // namespace atmos
