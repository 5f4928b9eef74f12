// Tests of physics/vector_exp.h: ExpPoly and ExpLane against std::exp, the branch-free
// profile density against GetProfileDensity.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "atmos/atmosphere.h"
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

}  // namespace
}  // namespace atmos
