// The reference's hero-wavelength paths (issue 37 item 3): one path carries all
// of a spectral run's wavelengths. Against the per-batch reference (three
// wavelengths per path): order 1 the same numbers, all orders within Monte
// Carlo error (z-scores on several atmospheres, a thick one at low spp), the
// same answer on 1 and 2 threads, and energy on a conservative slab.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "atmos/model.h"
#include "atmos/spectral.h"
#include "base/parallel.h"
#include "harness/spectral_run.h"
#include "models/reference.h"
#include "physics/density.h"
#include "test_util.h"

namespace atmos {
namespace {

const PrepareFunction kPrepare = [](const AtmosphereParameters& a, Model* m) { m->Prepare(a); };

std::vector<double> Wavelengths(int count) {
    std::vector<double> nm;
    for (int i = 0; i < count; ++i) nm.push_back(360.0 + (830.0 - 360.0) * i / (count - 1));
    return nm;
}

std::vector<SampleQuery> Queries() {
    std::vector<SampleQuery> q;
    for (double mu_s : {0.6, 0.05}) {
        for (double mu : {0.02, 0.2, 0.7}) {
            for (double az : {20.0, 160.0}) q.push_back({0.0, mu, mu_s, az});
        }
    }
    q.push_back({3000.0, -0.3, 0.4, 90.0, 1});  // looking down at the ground
    return q;
}

// Mean and standard error of each value over `runs` independent seeds.
struct Estimate {
    std::vector<double> mean, error;
};

Estimate Run(const std::string& model, const SpectralAtmosphere& atm, const std::vector<double>& nm,
             const std::vector<SampleQuery>& queries, int64_t spp, int runs, uint64_t first_seed) {
    Estimate e;
    std::vector<double> sum, sum2;
    for (int s = 0; s < runs; ++s) {
        MonteCarloSettings mc;
        mc.spp = spp;
        mc.seed = first_seed + static_cast<uint64_t>(s);
        const std::vector<double> v =
            SampleSpectral(ParseModelSpec(model), atm, nm, queries, mc, kPrepare);
        if (sum.empty()) sum.assign(v.size(), 0.0), sum2.assign(v.size(), 0.0);
        for (size_t i = 0; i < v.size(); ++i) {
            sum[i] += v[i];
            sum2[i] += v[i] * v[i];
        }
    }
    for (size_t i = 0; i < sum.size(); ++i) {
        const double m = sum[i] / runs;
        const double var = std::max(sum2[i] / runs - m * m, 0.0) * runs / (runs - 1);
        e.mean.push_back(m);
        e.error.push_back(std::sqrt(var / runs));
    }
    return e;
}

// The z-scores of hero against batches: |z| <= 5 everywhere and the mean z^2
// within [0.3, 3] (a t-distribution with runs - 1 degrees of freedom per
// error: variance (runs - 1) / (runs - 3)).
void ExpectAgree(const std::string& preset, int count, int64_t spp, int runs) {
    SCOPED_TRACE(preset);
    const SpectralAtmosphere atm = LoadSpectralAtmosphere(preset);
    const std::vector<double> nm = Wavelengths(count);
    const std::vector<SampleQuery> queries = Queries();
    // Seeds apart (batch b uses seed + b 2^40): independent estimates.
    const Estimate hero = Run("reference:spectral=hero", atm, nm, queries, spp, runs, 5000);
    const Estimate batch = Run("reference:spectral=batches", atm, nm, queries, spp, runs, 1000);
    double z2 = 0.0, worst = 0.0;
    int n = 0;
    for (size_t i = 0; i < hero.mean.size(); ++i) {
        const double se = std::hypot(hero.error[i], batch.error[i]);
        if (!(se > 0.0)) {
            EXPECT_EQ(hero.mean[i], batch.mean[i]) << i;
            continue;
        }
        const double z = (hero.mean[i] - batch.mean[i]) / se;
        z2 += z * z;
        worst = std::max(worst, std::abs(z));
        ++n;
        EXPECT_LE(std::abs(z), 5.0)
            << "query " << i / nm.size() << " at " << nm[i % nm.size()] << " nm: hero "
            << hero.mean[i] << ", batches " << batch.mean[i] << " +- " << se;
    }
    ASSERT_GT(n, 0);
    EXPECT_GT(z2 / n, 0.3) << "worst |z| " << worst;
    EXPECT_LT(z2 / n, 3.0) << "worst |z| " << worst;
}

TEST(ReferenceHero, OrderOneIsTheBatchesOrderOne) {
    // Order 1 is the same quadrature per group of three channels: with
    // consecutive batches (the same groups) the same numbers bit for bit.
    const SpectralAtmosphere atm = LoadSpectralAtmosphere("earth-spectral");
    const std::vector<double> nm = Wavelengths(13);
    MonteCarloSettings mc;
    mc.spp = 3;
    const std::vector<double> hero =
        SampleSpectral(ParseModelSpec("reference:spectral=hero:max-order=1"), atm, nm, Queries(),
                       mc, kPrepare, kPerWavelengthBatching);
    const std::vector<double> batch =
        SampleSpectral(ParseModelSpec("reference:spectral=batches:max-order=1"), atm, nm, Queries(),
                       mc, kPrepare, kPerWavelengthBatching);
    ASSERT_EQ(hero.size(), batch.size());
    for (size_t i = 0; i < hero.size(); ++i) EXPECT_EQ(hero[i], batch[i]) << i;
}

TEST(ReferenceHero, AgreesWithBatchesOnEarth) { ExpectAgree("earth-spectral", 12, 16, 16); }

TEST(ReferenceHero, AgreesWithBatchesOnMarsAndTitan) {
    ExpectAgree("mars", 9, 16, 16);
    ExpectAgree("titan", 9, 8, 16);
}

TEST(ReferenceHero, AgreesWithBatchesOnThickVenusAtLowSpp) { ExpectAgree("venus", 6, 2, 16); }

// Energy, exact: a conservatively scattering slab (Rayleigh only, a black
// ground) under a zenith sun reflects and transmits all it receives in every
// channel, R + T = 1 (as ReferenceThick.ConservativeSlab...: the upwelling
// flux at the top, the downwelling diffuse + direct flux at the bottom, 16
// directions by the midpoint rule in mu^2), here with six channels of
// optical thickness 1 to 30 carried by the same paths.
TEST(ReferenceHero, ConservativeSlabConservesEnergyInEveryChannel) {
    constexpr double kThickness = 1000.0;
    const double taus[6] = {1.0, 2.0, 5.0, 10.0, 20.0, 30.0};
    AtmosphereParameters atm = EarthAtmosphere();
    atm.bottom_radius = 1e9;
    atm.top_radius = 1e9 + kThickness;
    atm.rayleigh_scattering = Vec3d(30.0 / kThickness, 10.0 / kThickness, 1.0 / kThickness);
    atm.rayleigh_density = DensityProfile();
    atm.rayleigh_density.layers[1].constant_term = 1.0;
    atm.rayleigh_density.layers[0] = atm.rayleigh_density.layers[1];
    atm.mie_scattering = atm.mie_extinction = Vec3d(0.0);
    atm.absorption_extinction = Vec3d(0.0);
    atm.ground_albedo = Vec3d(0.0);
    ValidateAtmosphere(atm);
    ReferenceModel model{ReferenceOptions()};
    model.Prepare(atm);  // its majorants bound tau 30, the largest
    ReferenceHero hero;
    static_cast<ReferenceHybrid&>(hero) = model.evaluator();
    hero.spec.count = 6;
    for (int c = 0; c < 6; ++c) hero.spec.rayleigh[c] = taus[c] / kThickness;
    hero.spec.column_scale = Vec3d(30.0 / kThickness, 0.0, 0.0);
    constexpr int kDirections = 16, kBatches = 8, kPerBatch = 64;
    hero.sample_count = kPerBatch;
    double sum[6] = {}, sum_sq[6] = {};
    for (int b = 0; b < kBatches; ++b) {
        hero.sample_begin = static_cast<int64_t>(b) * kPerBatch;
        double flux[6] = {};
        for (int i = 0; i < kDirections; ++i) {
            const double mu = std::sqrt((i + 0.5) / kDirections);
            const Vec3d sun(0.0, 0.0, 1.0);
            const Vec3d dir_down(std::sqrt(1.0 - mu * mu), 0.0, mu);
            const Vec3d dir_up(dir_down.x, 0.0, -mu);
            double sky[kHeroMaxChannels], ground[kHeroMaxChannels];
            hero.EvaluateHero(Vec3d(0.0, 0.0, atm.top_radius - 1e-3), dir_up, sun, true, 2 * i + 1,
                              sky, ground);
            for (int c = 0; c < 6; ++c) {
                flux[c] += kPi * (sky[c] + ground[c]) / kPerBatch / kDirections;
            }
            hero.EvaluateHero(Vec3d(0.0, 0.0, atm.bottom_radius + 1e-3), dir_down, sun, true,
                              2 * i + 2, sky, ground);
            for (int c = 0; c < 6; ++c) {
                flux[c] += kPi * (sky[c] + ground[c]) / kPerBatch / kDirections;
            }
        }
        for (int c = 0; c < 6; ++c) {
            flux[c] += std::exp(-taus[c]);  // the direct beam
            sum[c] += flux[c];
            sum_sq[c] += flux[c] * flux[c];
        }
    }
    for (int c = 0; c < 6; ++c) {
        const double mean = sum[c] / kBatches;
        const double se =
            std::sqrt(std::max(sum_sq[c] / kBatches - mean * mean, 0.0) / (kBatches - 1.0));
        EXPECT_NEAR(mean, 1.0, std::max(4.0 * se, 0.02)) << "tau " << taus[c] << ", s.e. " << se;
    }
}

TEST(ReferenceHero, SameAnswerOnOneAndTwoThreads) {
    const SpectralAtmosphere atm = LoadSpectralAtmosphere("earth-spectral");
    const std::vector<double> nm = Wavelengths(40);
    RenderRequest request =
        atmos_test::MonteCarloRequest(GetView("ground-sunrise", atm.base), 12, 8, 4, 0, 7);
    auto render = [&](int threads) {
        ThreadLimit limit(threads);
        return RenderSpectral(ParseModelSpec("reference:spectral=hero"), atm, nm, request, kPrepare)
            .values;
    };
    const std::vector<float> one = render(1), two = render(2);
    ASSERT_EQ(one.size(), two.size());
    EXPECT_EQ(one, two);
    double sum = 0.0;
    for (float v : one) sum += static_cast<double>(v);
    EXPECT_GT(sum, 0.0);
}

}  // namespace
}  // namespace atmos
