// Bruneton's precomputation of n channels at once (PrecomputeBrunetonWide,
// issue 37): its tables equal the three-channel precomputation's tables of
// each batch, gathered side by side (channel 3b + c = batch b's channel c),
// bit for bit.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <ostream>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/spectral.h"
#include "base/parallel.h"
#include "models/bruneton.h"
#include "models/bruneton_stages.h"
#include "physics/exp_quadrature.h"
#include "render/stages.h"

namespace atmos {
namespace {

// Small tables; 20 view-ray intervals make the low rays of the short
// wavelengths optically thick (RayHasThickSteps) and the long ones not, so
// the batches of a group take different rules on the same rows.
BrunetonConfig SmallConfig(int orders) {
    BrunetonConfig c;
    c.orders = orders;
    c.scattering_samples = 20;
    c.transmittance_width = 32;
    c.transmittance_height = 8;
    c.irradiance_width = 16;
    c.irradiance_height = 4;
    c.scattering_r = 8;
    c.scattering_mu = 16;
    c.scattering_mu_s = 8;
    c.scattering_nu = 4;
    return c;
}

std::vector<AtmosphereParameters> Batches(const SpectralAtmosphere& spectral,
                                          const std::vector<double>& nm) {
    std::vector<AtmosphereParameters> batches;
    for (size_t i = 0; i < nm.size(); i += 3) {
        batches.push_back(spectral.AtWavelengths(nm[i], nm[i + 1], nm[i + 2]));
    }
    return batches;
}

// Each batch's tables by the three-channel precomputation (the CPU backend's
// row forms), side by side.
void GatherBatches(const std::vector<AtmosphereParameters>& batches, const BrunetonConfig& c,
                   BrunetonTables* out) {
    const int n = 3 * static_cast<int>(batches.size());
    for (size_t b = 0; b < batches.size(); ++b) {
        BrunetonTables t;
        PrecomputeBrunetonWith(batches[b], c, false, &t);
        const auto gather = [&](const Table& from, Table* to) {
            if (b == 0) to->Resize(from.width(), from.height(), from.depth(), n);
            const size_t texels = static_cast<size_t>(from.width()) * from.height() * from.depth();
            for (size_t i = 0; i < texels; ++i) {
                for (size_t ch = 0; ch < 3; ++ch) {
                    to->data()[i * n + 3 * b + ch] = from.data()[i * 3 + ch];
                }
            }
        };
        gather(t.transmittance, &out->transmittance);
        gather(t.irradiance, &out->irradiance);
        gather(t.scattering, &out->scattering);
        gather(t.single_mie, &out->single_mie);
    }
}

// The number of floats whose bits differ (and the first one's index).
size_t DifferentFloats(const Table& a, const Table& b, size_t* first) {
    EXPECT_EQ(a.width(), b.width());
    EXPECT_EQ(a.height(), b.height());
    EXPECT_EQ(a.depth(), b.depth());
    EXPECT_EQ(a.channels(), b.channels());
    if (a.size() != b.size()) return a.size() + b.size();
    size_t differ = 0;
    *first = a.size();
    for (size_t i = 0; i < a.size(); ++i) {
        if (std::memcmp(a.data() + i, b.data() + i, sizeof(float)) != 0) {
            if (differ++ == 0) *first = i;
        }
    }
    return differ;
}

void ExpectSameTables(const BrunetonTables& wide, const BrunetonTables& gathered) {
    const struct {
        const char* name;
        const Table& a;
        const Table& b;
    } tables[] = {{"transmittance", wide.transmittance, gathered.transmittance},
                  {"irradiance", wide.irradiance, gathered.irradiance},
                  {"scattering", wide.scattering, gathered.scattering},
                  {"single mie", wide.single_mie, gathered.single_mie}};
    for (const auto& t : tables) {
        size_t first = 0;
        const size_t differ = DifferentFloats(t.a, t.b, &first);
        EXPECT_EQ(differ, 0u) << t.name << ": first at " << first << " (channel "
                              << first % static_cast<size_t>(t.a.channels())
                              << "): " << (first < t.a.size() ? t.a.data()[first] : 0.0f) << " vs "
                              << (first < t.b.size() ? t.b.data()[first] : 0.0f);
    }
}

struct Case {
    const char* preset;
    int orders;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.preset << ", orders " << c.orders; }

class BrunetonWidePrecompute : public ::testing::TestWithParam<Case> {};

TEST_P(BrunetonWidePrecompute, EqualsTheBatchesTablesBitForBit) {
    const Case& k = GetParam();
    const SpectralAtmosphere spectral = LoadSpectralAtmosphere(k.preset);
    // 9 wavelengths: 3 batches, short ones first.
    const std::vector<AtmosphereParameters> batches =
        Batches(spectral, {380, 400, 430, 470, 520, 560, 610, 680, 760});
    const BrunetonConfig c = SmallConfig(k.orders);
    for (int threads : {1, 2}) {
        SCOPED_TRACE(threads);
        ThreadLimit limit(threads);
        BrunetonTables wide, gathered;
        PrecomputeBrunetonWide(batches, c, &wide);
        GatherBatches(batches, c, &gathered);
        ExpectSameTables(wide, gathered);
    }
}

// earth: no ground albedo, one Cornette-Shanks lobe; mars: a reddish ground
// (the incident radiance's ground term); kider-2013-aeronet: two lobes (the
// density's second sums); -tabulated: a tabulated phase function (the
// density's generic sums); orders 4: the orders after the second.
INSTANTIATE_TEST_SUITE_P(Presets, BrunetonWidePrecompute,
                         ::testing::Values(Case{"earth", 3}, Case{"mars", 4},
                                           Case{"kider-2013-aeronet", 3},
                                           Case{"kider-2013-aeronet-tabulated", 3}),
                         [](const ::testing::TestParamInfo<Case>& p) {
                             std::string name = p.param.preset;
                             for (char& ch : name) {
                                 if (ch == '-') ch = '_';
                             }
                             return name + "_orders" + std::to_string(p.param.orders);
                         });

TEST(BrunetonWidePrecompute, ThickRowsDifferBetweenTheBatches) {
    // The test above relies on rows that are thick for some batches only:
    // the smallest Rayleigh extinction of the group against the largest.
    const SpectralAtmosphere spectral = LoadSpectralAtmosphere("earth");
    const std::vector<AtmosphereParameters> batches =
        Batches(spectral, {380, 400, 430, 470, 520, 560, 610, 680, 760});
    const BrunetonConfig c = SmallConfig(3);
    const BrunetonLut lut0(batches.front(), c), lut2(batches.back(), c);
    int only_first = 0;
    for (int y = 0; y < c.scattering_mu; ++y) {
        for (int z = 0; z < c.scattering_r; ++z) {
            double r, mu, mu_s, nu;
            bool ground;
            lut0.RMuMuSNuFromTexel(0, y, z, &r, &mu, &mu_s, &nu, &ground);
            const double dx =
                lut0.DistanceToNearestAtmosphereBoundary(r, mu, ground) / c.scattering_samples;
            const bool t0 = RayHasThickSteps(batches.front(), r, mu, dx, c.scattering_samples);
            const bool t2 = RayHasThickSteps(batches.back(), r, mu, dx, c.scattering_samples);
            if (t0 && !t2) ++only_first;
        }
    }
    EXPECT_GT(only_first, 0);
}

TEST(BrunetonWidePrecompute, RefusesCombinedMieStorage) {
    const SpectralAtmosphere spectral = LoadSpectralAtmosphere("earth");
    BrunetonConfig c = SmallConfig(2);
    c.combined_mie = true;
    BrunetonTables t;
    EXPECT_THROW(PrecomputeBrunetonWide(Batches(spectral, {400, 500, 600}), c, &t), Error);
}

// The stage times of the default tables: RGB (earth's preset) and 40
// wavelengths at once (earth-spectral, 14 batches), one thread, interleaved
// rounds; wall and process CPU time of each precomputation. ATMOS_WIDE_PRECOMPUTE_ORDERS sets the
// orders (default 4), ATMOS_WIDE_PRECOMPUTE_ROUNDS the rounds (default 3).
TEST(BrunetonWidePrecompute, DISABLED_StageTimes) {
    BrunetonConfig c;
    if (const char* o = std::getenv("ATMOS_WIDE_PRECOMPUTE_ORDERS")) c.orders = std::atoi(o);
    int rounds = 3;
    if (const char* r = std::getenv("ATMOS_WIDE_PRECOMPUTE_ROUNDS")) rounds = std::atoi(r);
    const SpectralAtmosphere spectral = LoadSpectralAtmosphere("earth-spectral");
    std::vector<double> nm;
    for (int i = 0; i < 40; ++i) nm.push_back(380.0 + 400.0 * i / 39.0);
    nm.push_back(780.0);
    nm.push_back(780.0);  // 14 batches, the last short (as SpectralBatches repeats)
    const std::vector<AtmosphereParameters> batches = Batches(spectral, nm);
    const AtmosphereParameters rgb = LoadAtmosphere("earth");
    ThreadLimit limit(1);
    for (int round = 0; round < rounds; ++round) {
        for (int wide = 0; wide < 2; ++wide) {
            std::vector<StageTime> log;
            const StageLogScope scope(&log);
            BrunetonTables t;
            const auto start = std::chrono::steady_clock::now();
            const std::clock_t cpu_start = std::clock();
            if (wide) {
                PrecomputeBrunetonWide(batches, c, &t);
            } else {
                PrecomputeBruneton(rgb, c, &t);
            }
            const double s =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            const double cpu = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
            std::printf("round %d %s: %.3f s wall, %.3f s CPU\n", round, wide ? "wide 40" : "RGB",
                        s, cpu);
            for (const StageTime& st : log) {
                std::printf("  %-45s %10.1f ms\n", st.name.c_str(), st.kernel_ms);
            }
        }
    }
}

}  // namespace
}  // namespace atmos
