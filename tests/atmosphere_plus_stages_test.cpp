// Model atmosphere-plus's precomputation stages (models/atmosphere_plus_stages.h):
// the gather stage against the former CPU formulation (AplusTrapezoid2D over a
// per-texel vector of incoming values) and against the closed-form integral of
// the phase functions; the sum of orders; the stage sequence of a precompute.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>
#include <vector>

#include "atmos/atmosphere.h"
#include "models/atmosphere_plus.h"
#include "models/atmosphere_plus_stages.h"
#include "render/stages.h"
#include "test_util.h"

namespace atmos {
namespace {

static_assert(atmos_test::kAreDeviceStages<AplusTransmittanceStage, AplusSingleScatteringStage,
                                           AplusGatherStage, AplusOrderStage, AplusAddStage>,
              "device stages");

AplusSettings Small(const AtmosphereParameters& atm) {
    AplusSettings s;
    s.mapping.kind = AplusParameterization::kHorizon;
    s.mapping.bottom_radius = atm.bottom_radius;
    s.mapping.height = atm.top_radius - atm.bottom_radius;
    s.width = 4;
    s.height = 16;
    s.depth = 4;
    s.transmittance_width = 8;
    s.transmittance_height = 32;
    return s;
}

int64_t Count(const AplusSettings& s) { return static_cast<int64_t>(s.width) * s.height * s.depth; }

// The gather as the CPU computed it before the stages: incoming values in a
// std::vector, one per Theta node, and AplusTrapezoid2D over a lambda that
// finds its node by rounding Theta / dTheta.
Vec4f FormerGather(const TableView& prev, const AtmosphereParameters& atm, const AplusSettings& s,
                   int x, int y, int z) {
    double h, mu, mu_s;
    AplusTexelParameters(s.mapping, x, y, z, s.width, s.height, s.depth, &h, &mu, &mu_s);
    const int n = s.gather_theta;
    const double d_theta = kPi / n;
    std::vector<AplusValue> incoming(static_cast<size_t>(n) + 1);
    for (int j = 0; j <= n; ++j) {
        incoming[static_cast<size_t>(j)] =
            AplusFromVec4f(AplusSample(prev, s.mapping, h, std::cos(j * d_theta), mu_s));
    }
    const double sin_phi = SafeSqrt(1.0 - mu * mu);
    const auto f = [&](double theta, double phi) {
        const int j = static_cast<int>(std::lround(theta / d_theta));
        const double sin_t = std::sin(theta);
        const double c = ClampCosine(sin_t * std::cos(phi) * sin_phi + std::cos(theta) * mu);
        const AplusValue& in = incoming[static_cast<size_t>(j)];
        AplusValue out;
        out.rayleigh = in.rayleigh * (AplusRayleighPhase(c) * sin_t);
        out.mie = in.mie * AplusMiePhase(atm.mie_phase_g, c) * sin_t;
        return out;
    };
    return AplusToVec4f(AplusTrapezoid2D<AplusValue>(f, 0.0, kPi, 0.0, 2.0 * kPi, n, s.gather_phi));
}

// Both paths of the gather stage (incoming values kept in the local array, and
// looked up again at every node beyond kAplusGatherCachedThetas) give the
// former code's table: the same arithmetic in the same order, bound 1e-6
// relative (observed: identical).
TEST(AtmospherePlusStages, GatherStageMatchesTheFormerFormulation) {
    const AtmosphereParameters atm = LoadAtmosphere("earth-atmosphere-plus");
    AplusSettings s = Small(atm);
    s.orders = 1;
    const AplusTables t = AplusPrecompute(atm, s);
    for (int n : {6, kAplusGatherCachedThetas, kAplusGatherCachedThetas + 3}) {
        SCOPED_TRACE(n);
        s.gather_theta = n;
        s.gather_phi = n == 6 ? 12 : 5;
        Table g(s.width, s.height, s.depth, 4);
        RunStage("gather", Count(s), 3, AplusGatherStage{atm, s, t.scattering.view(), g.out()});
        double worst = 0.0;
        for (int z = 0; z < s.depth; ++z) {
            for (int y = 0; y < s.height; ++y) {
                for (int x = 0; x < s.width; ++x) {
                    const Vec4f want = FormerGather(t.scattering.view(), atm, s, x, y, z);
                    const float* got = g.Texel(x, y, z);
                    const float w[4] = {want.x, want.y, want.z, want.w};
                    for (int c = 0; c < 4; ++c) {
                        const double d = std::fabs(static_cast<double>(got[c] - w[c]));
                        worst = std::max(worst,
                                         d / std::max(std::fabs(static_cast<double>(w[c])), 1e-30));
                    }
                }
            }
        }
        EXPECT_LE(worst, 1e-6);
    }
}

// With a constant incoming intensity (1 in every channel) the gather is the
// integral of the phase functions over the sphere, 4 pi for both in the seed's
// normalisation (Boody's Atmosphere Plus notes 1.7); the 2D trapezoidal rule converges to it.
TEST(AtmospherePlusStages, GatherOfAConstantIntensityIsTheIntegralOfThePhase) {
    AtmosphereParameters atm = LoadAtmosphere("earth-atmosphere-plus");
    atm.mie_phase_g = 0.3;  // a smooth Mie lobe, resolved by the grid below
    AplusSettings s = Small(atm);
    Table ones(s.width, s.height, s.depth, 4);
    std::fill(ones.data(), ones.data() + ones.size(), 1.0f);
    for (int n : {48, kAplusGatherCachedThetas + 16}) {
        SCOPED_TRACE(n);
        s.gather_theta = n;
        s.gather_phi = 2 * n;
        Table g(s.width, s.height, s.depth, 4);
        RunStage("gather", Count(s), 3, AplusGatherStage{atm, s, ones.view(), g.out()});
        // Rows above the ground row (at h = 0 rays below the horizon read 0).
        for (int z = 0; z < s.depth; ++z) {
            for (int y = 0; y < s.height; ++y) {
                for (int x = 2; x < s.width; ++x) {
                    const float* v = g.Texel(x, y, z);
                    for (int c = 0; c < 4; ++c) {
                        EXPECT_NEAR(v[c], 4.0 * kPi, 2e-3 * 4.0 * kPi) << x << " " << y << " " << z;
                    }
                }
            }
        }
    }
}

TEST(AtmospherePlusStages, TheScatteringTableIsTheSumOfTheOrders) {
    const AtmosphereParameters atm = LoadAtmosphere("earth-atmosphere-plus");
    AplusSettings s = Small(atm);
    s.orders = 3;
    const AplusTables t = AplusPrecompute(atm, s, true);
    ASSERT_EQ(t.orders.size(), 3u);
    for (size_t i = 0; i < t.scattering.size(); ++i) {
        const float sum = (t.orders[0].data()[i] + t.orders[1].data()[i]) + t.orders[2].data()[i];
        ASSERT_EQ(t.scattering.data()[i], sum) << i;
    }
}

TEST(AtmospherePlusStages, PrecomputeRunsItsStagesInOrder) {
    const AtmosphereParameters atm = LoadAtmosphere("earth-atmosphere-plus");
    AplusSettings s = Small(atm);
    s.orders = 3;
    std::vector<StageTime> log;
    {
        const StageLogScope scope(&log);
        (void)AplusPrecompute(atm, s);
    }
    const std::vector<std::string> want = {
        "atmosphere-plus/transmittance", "atmosphere-plus/order-1", "atmosphere-plus/gather",
        "atmosphere-plus/order-k",       "atmosphere-plus/sum",     "atmosphere-plus/gather",
        "atmosphere-plus/order-k",       "atmosphere-plus/sum"};
    ASSERT_EQ(log.size(), want.size());
    for (size_t i = 0; i < log.size(); ++i) {
        EXPECT_EQ(log[i].name, want[i]);
        EXPECT_EQ(log[i].backend, "cpu");
        EXPECT_EQ(log[i].items, i == 0 ? int64_t{8 * 32} : Count(s));
    }
}

}  // namespace
}  // namespace atmos
