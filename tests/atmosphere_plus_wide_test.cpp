// atmosphere-plus's wide channel batches (models/atmosphere_plus_wide.h): the
// wide precomputation's tables hold, channel for channel, the tables of each
// batch's three-channel precomputation, bit for bit (renders and samples:
// tests/wide_channels_test.cpp).
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/model.h"
#include "atmos/spectral.h"
#include "models/atmosphere_plus.h"
#include "models/atmosphere_plus_wide.h"
#include "physics/exp_quadrature.h"

namespace atmos {
namespace {

AplusSettings SmallSettings() {
    AplusSettings s;
    s.width = 8;
    s.height = 16;
    s.depth = 8;
    s.transmittance_width = 16;
    s.transmittance_height = 32;
    s.orders = 3;
    s.gather_theta = 6;
    s.gather_phi = 12;
    s.transmittance_steps = 10;
    return s;
}

// Three batches of consecutive wavelengths (their extinctions far apart).
std::vector<AtmosphereParameters> Batches(const SpectralAtmosphere& spectral) {
    return {spectral.AtWavelengths(380, 400, 420), spectral.AtWavelengths(500, 550, 600),
            spectral.AtWavelengths(650, 700, 780)};
}

// Counts the floats of batch b's table `narrow` (channels `narrow_channels` of
// each texel) that differ from the wide table's channels `wide_channel(c)`.
template <typename F>
size_t Differences(const Table& narrow, const Table& wide, F wide_channel) {
    EXPECT_EQ(narrow.width(), wide.width());
    EXPECT_EQ(narrow.height(), wide.height());
    EXPECT_EQ(narrow.depth(), wide.depth());
    const size_t texels = static_cast<size_t>(narrow.width()) * narrow.height() * narrow.depth();
    size_t differ = 0;
    for (size_t i = 0; i < texels; ++i) {
        for (int c = 0; c < narrow.channels(); ++c) {
            const float a = narrow.data()[i * narrow.channels() + c];
            const float b = wide.data()[i * wide.channels() + wide_channel(c)];
            if (std::memcmp(&a, &b, sizeof(float)) != 0) ++differ;
        }
    }
    return differ;
}

void ExpectTablesOfTheBatches(const std::vector<AtmosphereParameters>& batches,
                              const AplusSettings& s) {
    const AplusWideTables wide = AplusPrecomputeWide(batches, s);
    const int n = 3 * static_cast<int>(batches.size());
    ASSERT_EQ(wide.scattering.channels(), n + n / 3);
    ASSERT_EQ(wide.transmittance.channels(), n);
    for (size_t b = 0; b < batches.size(); ++b) {
        SCOPED_TRACE("batch " + std::to_string(b));
        const AplusTables narrow = AplusPrecompute(batches[b], s);
        const int bi = static_cast<int>(b);
        EXPECT_EQ(Differences(narrow.transmittance, wide.transmittance,
                              [&](int c) { return 3 * bi + c; }),
                  0u);
        EXPECT_EQ(Differences(narrow.scattering, wide.scattering,
                              [&](int c) { return c < 3 ? 3 * bi + c : n + bi; }),
                  0u);
    }
}

TEST(AtmospherePlusWide, TablesEqualTheBatchesTablesBitForBit) {
    const SpectralAtmosphere spectral = LoadSpectralAtmosphere("kider-2013");
    ExpectTablesOfTheBatches(Batches(spectral), SmallSettings());
}

TEST(AtmospherePlusWide, OtherMappingsAndTheUncachedGather) {
    const SpectralAtmosphere spectral = LoadSpectralAtmosphere("earth");
    AplusSettings linear = SmallSettings();
    linear.mapping.kind = AplusParameterization::kLinear;
    linear.modified_rayleigh = true;
    ExpectTablesOfTheBatches(Batches(spectral), linear);
    // More gather directions than the three-channel stage caches (it looks
    // them up again at every node), and one batch.
    AplusSettings wide_gather = SmallSettings();
    wide_gather.gather_theta = 50;
    wide_gather.gather_phi = 4;
    wide_gather.orders = 2;
    ExpectTablesOfTheBatches({spectral.AtWavelengths(440, 550, 680)}, wide_gather);
}

TEST(AtmospherePlusWide, BatchesWithAndWithoutThickSteps) {
    // Dense air with few steps: the view rays of some columns have optically
    // thick steps in the blue batch and not in the red one, so one column
    // runs the exponential-linear rule for some channels and the trapezoid
    // for others.
    std::vector<AtmosphereParameters> batches = Batches(LoadSpectralAtmosphere("kider-2013"));
    for (AtmosphereParameters& a : batches) a.rayleigh_scattering = a.rayleigh_scattering * 3.0;
    AplusSettings s = SmallSettings();
    s.transmittance_steps = 6;
    // The test's case is reached: a column thick in batch 0 and not in batch 2.
    AplusMapping m = s.mapping;
    m.bottom_radius = batches[0].bottom_radius;
    m.height = batches[0].top_radius - batches[0].bottom_radius;
    int mixed = 0, thick = 0;
    for (int x = 0; x < s.width; ++x) {
        for (int y = 0; y < s.height; ++y) {
            double h, mu, mu_s;
            AplusTexelParameters(m, x, y, 0, s.width, s.height, s.depth, &h, &mu, &mu_s);
            const AplusTexelRay ray = AplusTexelRayOf(batches[0], h, mu, mu_s);
            if (!ray.seg.inside) continue;
            const double ds = (ray.seg.t_end - ray.seg.t_start) / s.transmittance_steps;
            bool t[3];
            for (int b = 0; b < 3; ++b) {
                t[b] = RayHasThickSteps(batches[b], ray.p0, ray.view, ray.seg.t_start, ds,
                                        s.transmittance_steps);
            }
            thick += t[0] ? 1 : 0;
            mixed += t[0] && !t[2] ? 1 : 0;
        }
    }
    ASSERT_GT(mixed, 0) << "no column mixes thick and thin batches: the test misses its case";
    ASSERT_LT(thick, s.width * s.height);
    ExpectTablesOfTheBatches(batches, s);
}

TEST(AtmospherePlusWide, RefusesBatchesThatDifferBeyondTheirCoefficients) {
    const SpectralAtmosphere spectral = LoadSpectralAtmosphere("kider-2013");
    std::vector<AtmosphereParameters> batches = Batches(spectral);
    batches[1].top_radius += 1000.0;
    EXPECT_THROW(AplusPrecomputeWide(batches, SmallSettings()), Error);
    // Render before PrepareWide: one clear error.
    std::unique_ptr<Model> model = CreateModel("atmosphere-plus");
    EXPECT_TRUE(model->Info().capabilities.wide_channels);
    EXPECT_THROW(model->SampleWide({SampleQuery()}), Error);
}

}  // namespace
}  // namespace atmos
