// Tests of the naive single-scattering model and the render loop around it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <utility>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/model.h"
#include "atmos/view.h"
#include "base/parallel.h"
#include "models/naive.h"
#include "physics/transmittance.h"
#include "test_util.h"

namespace atmos {
namespace {

NaiveEvaluator MakeNaive(int steps = 16, int light_steps = 8) {
    NaiveEvaluator e;
    e.atm = EarthAtmosphere();
    e.steps = steps;
    e.light_steps = light_steps;
    return e;
}

Vec3d Dir(double mu) { return Vec3d(std::sqrt(1.0 - mu * mu), 0.0, mu); }

TEST(Naive, TransmittanceIsExpOfOpticalDepth) {
    // The model's view transmittance equals exp(-tau) with tau integrated
    // independently (trapezoid, many samples) over the same segment.
    const NaiveEvaluator e = MakeNaive(2048, 8);  // midpoint error ~1/n^2: 3e-6 here
    const AtmosphereParameters& atm = e.atm;
    for (double h : {0.0, 5000.0, 40e3}) {
        for (double mu : {1.0, 0.5, 0.1, 0.02}) {
            const Vec3d camera(0, 0, atm.bottom_radius + h);
            const RayResult r = e.Evaluate(camera, Dir(mu), Vec3d(0, 0, 1), false);
            const Vec3d tau = OpticalDepthToTopAtmosphereBoundary(atm, camera.z, mu, 20000);
            for (int c = 0; c < 3; ++c) {
                const double expected = std::exp(-tau[c]);
                EXPECT_NEAR(r.transmittance[c], expected, 2e-5 * expected + 1e-7)
                    << "h " << h << " mu " << mu << " c " << c;
            }
        }
    }
}

// The naive model before issue 19's vector loop: the extinction summed per
// light sample through GetDensities (glibc's exp, a branch per layer).
struct ScalarNaiveMedium {
    AtmosphereParameters atm;
    int light_steps = 8;
    Vec3d ExtinctionAt(double altitude, double* rho_r, double* rho_m) const {
        const Densities d = GetDensities(atm, altitude);
        *rho_r = d.rayleigh;
        *rho_m = d.mie;
        return Extinction(atm, d);
    }
    bool LightDepth(const Vec3d& p, const Vec3d& sun, Vec3d* tau) const {
        const double r = Length(p);
        const double mu_s = ClampCosine(Dot(p, sun) / r);
        if (RayIntersectsGround(r, mu_s, atm.bottom_radius)) return false;
        const double length = DistanceToTopAtmosphereBoundary(r, mu_s, atm.top_radius);
        const double ds = length / light_steps;
        Vec3d sum;
        for (int j = 0; j < light_steps; ++j) {
            const Vec3d q = p + sun * ((j + 0.5) * ds);
            sum += Extinction(atm, GetDensities(atm, Length(q) - atm.bottom_radius));
        }
        *tau = sum * ds;
        return true;
    }
};

TEST(Naive, VectorLoopMatchesTheScalarIntegral) {
    // Issue 19: the light march as a vector loop (ExpLane, densities summed
    // before the coefficients) changes only rounding: over random queries
    // (ground to 60 km, up to down, sun above and below the horizon, ground
    // on) every float output within 4e-7 relative of the scalar form (a few
    // float ulp), most of them identical.
    std::mt19937_64 rng(19);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int same = 0, total = 0;
    for (int light_steps : {8, 3}) {
        NaiveEvaluator fast = MakeNaive(16, light_steps);
        fast.atm.ground_albedo = Vec3d(0.3);
        ScalarNaiveMedium old{fast.atm, light_steps};
        for (int q = 0; q < 300; ++q) {
            const Vec3d camera(0, 0, fast.atm.bottom_radius + 60e3 * u(rng) * u(rng));
            const Vec3d dir = Dir(2.0 * u(rng) - 1.0);
            const double mu_s = 1.2 * u(rng) - 0.2, phi = kPi * u(rng);
            const double sin_s = std::sqrt(1.0 - mu_s * mu_s);
            const Vec3d sun(sin_s * std::cos(phi), sin_s * std::sin(phi), mu_s);
            const RayResult a = fast.Evaluate(camera, dir, sun, true);
            const RayResult b =
                IntegrateSingleScattering(fast.atm, old, 16, camera, dir, sun, true);
            for (int c = 0; c < 3; ++c) {
                for (const auto& pair :
                     {std::make_pair(a.sky[c], b.sky[c]), std::make_pair(a.ground[c], b.ground[c]),
                      std::make_pair(a.transmittance[c], b.transmittance[c])}) {
                    EXPECT_NEAR(pair.first, pair.second, 4e-7f * std::fabs(pair.second)) << q;
                    same += pair.first == pair.second;
                    ++total;
                }
            }
        }
    }
    EXPECT_GT(same, total / 2);
}

TEST(Naive, ZenithAtNoonIsBlue) {
    const NaiveEvaluator e = MakeNaive();
    const Vec3d camera(0, 0, e.atm.bottom_radius);
    const RayResult r = e.Evaluate(camera, Vec3d(0, 0, 1), Vec3d(0, 0, 1), false);
    EXPECT_GT(r.sky.z, r.sky.y);
    EXPECT_GT(r.sky.y, r.sky.x);
    EXPECT_GT(r.sky.x, 0.0f);
}

TEST(Naive, SkyNearTheSunIsRedderAtSunriseThanAtNoon) {
    const NaiveEvaluator e = MakeNaive();
    const Vec3d camera(0, 0, e.atm.bottom_radius);
    auto redness = [&](double sun_elevation_deg) {
        const double el = Radians(sun_elevation_deg);
        const Vec3d sun(std::cos(el), 0.0, std::sin(el));
        // Look 3 degrees above the sun (still within its Mie halo).
        const double vel = Radians(sun_elevation_deg + 3.0);
        const Vec3d dir(std::cos(vel), 0.0, std::sin(vel));
        const RayResult r = e.Evaluate(camera, dir, sun, false);
        return r.sky.x / r.sky.z;
    };
    EXPECT_GT(redness(6.0), 1.5f * redness(80.0));
}

TEST(Naive, PlanetShadowBlocksTheSun) {
    // Sun 30 deg below the horizon, looking at the horizon from the ground: every
    // sample within tens of km is in the planet's shadow; only high samples far
    // away are lit, so the sky is far darker than with the sun above.
    const NaiveEvaluator e = MakeNaive();
    const Vec3d camera(0, 0, e.atm.bottom_radius);
    const Vec3d below(std::cos(Radians(-30.0)), 0.0, std::sin(Radians(-30.0)));
    const Vec3d above(std::cos(Radians(30.0)), 0.0, std::sin(Radians(30.0)));
    const RayResult dark = e.Evaluate(camera, Vec3d(0, 0, 1), below, false);
    const RayResult lit = e.Evaluate(camera, Vec3d(0, 0, 1), above, false);
    EXPECT_EQ(dark.sky.x, 0.0f);  // zenith column entirely in shadow
    EXPECT_GT(lit.sky.x, 0.0f);
}

TEST(Naive, ConvergesWithStepCount) {
    // |L(n) - L(1024)| shrinks as the step counts grow; the error at the
    // defaults (16, 8) is printed for the record.
    const Vec3d camera(0, 0, EarthAtmosphere().bottom_radius);
    const double el = Radians(6.0);
    const Vec3d sun(std::cos(el), 0.0, std::sin(el));
    const Vec3d dir = Normalize(Vec3d(1.0, 0.0, 0.05));  // low sky toward the sun
    const Rgb converged = MakeNaive(1024, 512).Evaluate(camera, dir, sun, false).sky;
    double previous = 1e30;
    for (int n : {4, 16, 64, 256}) {
        const Rgb l = MakeNaive(n, n / 2).Evaluate(camera, dir, sun, false).sky;
        double err = 0.0;
        for (int c = 0; c < 3; ++c)
            err = std::fmax(err, std::fabs(static_cast<double>(l[c] / converged[c]) - 1.0));
        EXPECT_LT(err, previous) << n;
        previous = err;
    }
    const Rgb l_default = MakeNaive().Evaluate(camera, dir, sun, false).sky;
    double err_default = 0.0;
    for (int c = 0; c < 3; ++c) {
        err_default = std::fmax(err_default,
                                std::fabs(static_cast<double>(l_default[c] / converged[c]) - 1.0));
    }
    std::printf("naive relative error at the defaults (16, 8), low sky at sunrise: %.4f\n",
                err_default);
    EXPECT_LT(previous, 0.01);  // 256 steps: within 1 %
}

TEST(Naive, SpaceViewerSeesTheSameColumnAsFromTheTop) {
    // A camera in space looking straight down integrates from the top: same as
    // a camera at the top looking down.
    const NaiveEvaluator e = MakeNaive();
    const Vec3d sun = Normalize(Vec3d(0.3, 0.0, 1.0));
    const RayResult from_space =
        e.Evaluate(Vec3d(0, 0, e.atm.top_radius + 1e6), Vec3d(0, 0, -1), sun, false);
    const RayResult from_top =
        e.Evaluate(Vec3d(0, 0, e.atm.top_radius), Vec3d(0, 0, -1), sun, false);
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(from_space.sky[c], from_top.sky[c], 1e-6f * from_top.sky[c]);
        EXPECT_NEAR(from_space.transmittance[c], from_top.transmittance[c], 1e-6f);
    }
    const RayResult miss =
        e.Evaluate(Vec3d(0, 0, e.atm.top_radius + 1e6), Vec3d(1, 0, 0), sun, false);
    EXPECT_EQ(miss.sky.x, 0.0f);
    EXPECT_EQ(miss.transmittance.x, 1.0f);
}

TEST(Naive, BlackGroundAtAlbedoZeroLitGroundOtherwise) {
    NaiveEvaluator e = MakeNaive();
    const Vec3d camera(0, 0, e.atm.bottom_radius + 5000.0);
    const Vec3d sun(0, 0, 1);
    EXPECT_EQ(e.Evaluate(camera, Vec3d(0, 0, -1), sun, true).ground.x, 0.0f);
    e.atm.ground_albedo = Vec3d(0.3);
    const RayResult r = e.Evaluate(camera, Vec3d(0, 0, -1), sun, true);
    EXPECT_TRUE(r.hits_ground);
    // a/pi * T_sun(ground, zenith) * T_view(5 km column): close to 0.3/pi * T^2.
    EXPECT_GT(r.ground.x, 0.05f);
    EXPECT_LT(r.ground.x, 0.3f / kPiF);
}

void ExpectAllFiniteNonNegative(const Image& image, const std::string& what) {
    for (size_t i = 0; i < image.size(); ++i) {
        const float v = image.data()[i];
        ASSERT_TRUE(std::isfinite(v) && v >= 0.0f) << what << " at float " << i << ": " << v;
    }
}

TEST(Render, AllTwelveViewsFiniteAndNonNegative) {
    auto model = CreateModel("naive");
    model->Prepare(EarthAtmosphere());
    for (const View& view : StandardViews(EarthAtmosphere())) {
        for (Quantity q : {Quantity::kRadiance, Quantity::kTransmittance}) {
            RenderRequest request;
            request.view = view;
            request.width = 64;
            request.height = 36;
            request.quantity = q;
            request.sun_disc = true;
            request.show_progress = false;
            Image image;
            model->Render(request, &image);
            ExpectAllFiniteNonNegative(image, view.name);
            double sum = 0.0;
            for (size_t i = 0; i < image.size(); ++i) sum += static_cast<double>(image.data()[i]);
            EXPECT_GT(sum, 0.0) << view.name << " is black";
        }
    }
}

TEST(Render, SameBytesForOneAndTwoThreads) {
    auto model = CreateModel("naive");
    model->Prepare(EarthAtmosphere());
    RenderRequest request = atmos_test::QuietRequest(GetView("ground-sunrise", EarthAtmosphere()),
                                                     97, 41);  // not a multiple of the tile size
    atmos_test::ExpectSameImageForOneAndTwoThreads(*model, request);
}

TEST(Sample, MatchesEvaluatorAndContract) {
    auto model = CreateModel("naive");
    model->Prepare(EarthAtmosphere());
    std::vector<SampleQuery> q(3);
    q[0] = {0.0, 1.0, 1.0, 0.0};       // zenith at noon
    q[1] = {1000.0, -0.5, 0.5, 30.0};  // looking down: hits the ground
    q[2] = {1e6, 0.0, 0.5, 0.0};       // space, looking sideways: misses
    const std::vector<SampleAnswer> a = model->Sample(q);
    ASSERT_EQ(a.size(), 3u);
    EXPECT_GT(a[0].radiance.z, a[0].radiance.x);
    EXPECT_GT(a[0].transmittance.x, 0.5f);
    EXPECT_EQ(a[1].transmittance.x, 0.0f);  // hits the ground: T = 0
    EXPECT_GT(a[1].radiance.z, 0.0f);
    EXPECT_EQ(a[2].radiance.x, 0.0f);  // misses: L = 0, T = 1
    EXPECT_EQ(a[2].transmittance.y, 1.0f);
}

TEST(Models, RegistryAndOptions) {
    EXPECT_THROW(CreateModel("no-such-model"), Error);
    EXPECT_THROW(CreateModel("naive", {{"steps", "0"}}), Error);
    EXPECT_THROW(CreateModel("naive", {{"steps", "abc"}}), Error);
    EXPECT_THROW(CreateModel("naive", {{"steps", "2.5"}}), Error);
    EXPECT_THROW(CreateModel("naive", {{"spp", "4"}}), Error);
    EXPECT_THROW(CreateModel("empty", {{"steps", "4"}}), Error);
    EXPECT_NO_THROW(CreateModel("naive", {{"steps", "32"}, {"light-steps", "4"}}));
    bool found = false;
    for (const ModelInfo& info : ListModels()) found |= info.name == "naive";
    EXPECT_TRUE(found);
}

}  // namespace
}  // namespace atmos
