// Tests of the physics core against closed forms and independent integrals.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "atmos/atmosphere.h"
#include "physics/density.h"
#include "physics/geometry.h"
#include "physics/phase.h"
#include "physics/sampling.h"
#include "physics/transmittance.h"

namespace atmos {
namespace {

constexpr double kR = 6360e3;
constexpr double kTop = 6460e3;

TEST(Geometry, VerticalRays) {
    // Straight up from altitude h: the top is top - r away; straight down the
    // ground is r - bottom away.
    const double r = kR + 1234.5;
    EXPECT_NEAR(DistanceToTopAtmosphereBoundary(r, 1.0, kTop), kTop - r, 1e-6);
    EXPECT_NEAR(DistanceToTopAtmosphereBoundary(r, -1.0, kTop), kTop + r, 1e-6);
    EXPECT_TRUE(RayIntersectsGround(r, -1.0, kR));
    EXPECT_NEAR(DistanceToBottomAtmosphereBoundary(r, -1.0, kR), 1234.5, 1e-6);
    EXPECT_FALSE(RayIntersectsGround(r, 1.0, kR));
}

TEST(Geometry, HorizontalRays) {
    // Horizontal from r: the chord to the top sphere is sqrt(top^2 - r^2).
    for (double h : {0.0, 1.0, 5000.0, 99000.0}) {
        const double r = kR + h;
        EXPECT_NEAR(DistanceToTopAtmosphereBoundary(r, 0.0, kTop), std::sqrt(kTop * kTop - r * r),
                    1e-6);
        EXPECT_FALSE(RayIntersectsGround(r, 0.0, kR)) << h;
    }
}

TEST(Geometry, GrazingRaysAtTheHorizon) {
    // From altitude h the geometric horizon is at mu_h = -sqrt(1 - (R/r)^2):
    // just below it the ray hits the ground, just above it misses.
    for (double h : {1.0, 100.0, 5000.0, 100e3}) {
        const double r = kR + h;
        const double mu_h = -std::sqrt(1.0 - (kR / r) * (kR / r));
        EXPECT_TRUE(RayIntersectsGround(r, mu_h - 1e-9, kR)) << h;
        EXPECT_FALSE(RayIntersectsGround(r, mu_h + 1e-9, kR)) << h;
        // Tangent distance to the ground at the horizon: sqrt(r^2 - R^2).
        EXPECT_NEAR(DistanceToBottomAtmosphereBoundary(r, mu_h, kR), std::sqrt(r * r - kR * kR),
                    0.5)
            << h;
    }
}

TEST(Geometry, CameraAt6400kmInDouble) {
    // A camera at 6.4e6 m (40 km up) looking horizontally: a general ray/sphere
    // intersection must agree with the closed form to well under a millimetre.
    const Vec3d camera(0.0, 0.0, 6.4e6);
    const Vec3d dir(1.0, 0.0, 0.0);
    double t0, t1;
    ASSERT_TRUE(IntersectSphere(camera, dir, kTop, &t0, &t1));
    const double expected = std::sqrt(kTop * kTop - 6.4e6 * 6.4e6);
    EXPECT_NEAR(t1, expected, 1e-6);
    EXPECT_NEAR(t0, -expected, 1e-6);
    EXPECT_FALSE(IntersectSphere(camera, dir, kR, &t0, &t1));  // misses the ground

    // Slightly downward, tangent ray to the ground: hits it at sqrt(r^2 - R^2).
    const double mu_h = -std::sqrt(1.0 - (kR / 6.4e6) * (kR / 6.4e6));
    const Vec3d down(std::sqrt(1.0 - mu_h * mu_h), 0.0, mu_h - 1e-12);
    const AtmosphereSegment seg = ClipToAtmosphere(camera, Normalize(down), kR, kTop);
    EXPECT_TRUE(seg.hits_ground);
    EXPECT_NEAR(seg.t_end, std::sqrt(6.4e6 * 6.4e6 - kR * kR), 50.0);
}

TEST(Geometry, CameraInSpaceEntersAtTheTop) {
    const Vec3d camera(0.0, 0.0, kTop + 500e3);
    const AtmosphereSegment down = ClipToAtmosphere(camera, Vec3d(0, 0, -1), kR, kTop);
    EXPECT_TRUE(down.inside);
    EXPECT_TRUE(down.hits_ground);
    EXPECT_NEAR(down.t_start, 500e3, 1e-6);
    EXPECT_NEAR(down.t_end, 600e3, 1e-6);
    const AtmosphereSegment away = ClipToAtmosphere(camera, Vec3d(0, 0, 1), kR, kTop);
    EXPECT_FALSE(away.inside);
    EXPECT_FALSE(away.hits_ground);
    const AtmosphereSegment sideways = ClipToAtmosphere(camera, Vec3d(1, 0, 0), kR, kTop);
    EXPECT_FALSE(sideways.inside);
}

TEST(Geometry, CameraOnTheGround) {
    const Vec3d camera(0.0, 0.0, kR);
    const AtmosphereSegment up = ClipToAtmosphere(camera, Vec3d(0, 0, 1), kR, kTop);
    EXPECT_TRUE(up.inside);
    EXPECT_FALSE(up.hits_ground);
    EXPECT_NEAR(up.t_end, 100e3, 1e-6);
    const AtmosphereSegment down =
        ClipToAtmosphere(camera, Normalize(Vec3d(1, 0, -0.01)), kR, kTop);
    EXPECT_TRUE(down.hits_ground);
    EXPECT_FALSE(down.inside);
}

TEST(Density, OzoneTentIntegral) {
    // The tent (0 below 10 km, 1 at 25 km, 0 above 40 km) integrates to 15 km.
    const AtmosphereParameters atm = EarthAtmosphere();
    const int n = 200000;
    const double h_max = 60e3;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
        sum += GetProfileDensity(atm.absorption_density, (i + 0.5) * h_max / n);
    }
    EXPECT_NEAR(sum * h_max / n, 15e3, 1e-3 * 15e3 * 1e-3);
    EXPECT_DOUBLE_EQ(GetProfileDensity(atm.absorption_density, 25e3), 1.0);
    EXPECT_DOUBLE_EQ(GetProfileDensity(atm.absorption_density, 5e3), 0.0);
    EXPECT_DOUBLE_EQ(GetProfileDensity(atm.absorption_density, 45e3), 0.0);
}

TEST(Density, ExponentialProfile) {
    const DensityProfile p = ExponentialProfile(8000.0);
    EXPECT_DOUBLE_EQ(GetProfileDensity(p, 0.0), 1.0);
    EXPECT_NEAR(GetProfileDensity(p, 8000.0), std::exp(-1.0), 1e-15);
}

// Integral of a phase function over the sphere, in nu (the azimuth gives 2 pi).
template <typename F>
double SphereIntegral(F f) {
    const int n = 200000;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) sum += f(-1.0 + (i + 0.5) * 2.0 / n);
    return 2.0 * kPi * sum * 2.0 / n;
}

TEST(Phase, EachIntegratesToOne) {
    EXPECT_NEAR(SphereIntegral([](double nu) { return RayleighPhase(nu); }), 1.0, 1e-9);
    EXPECT_NEAR(SphereIntegral([](double) { return IsotropicPhase(); }), 1.0,
                1e-10);  // summation rounding
    for (double g : {-0.5, 0.0, 0.3, 0.76, 0.8}) {
        EXPECT_NEAR(SphereIntegral([g](double nu) { return HenyeyGreensteinPhase(g, nu); }), 1.0,
                    1e-6)
            << g;
        EXPECT_NEAR(SphereIntegral([g](double nu) { return CornetteShanksPhase(g, nu); }), 1.0,
                    1e-6)
            << g;
    }
}

// An atmosphere whose only use here is its Mie phase: lobes g and g2, weight w.
AtmosphereParameters TwoLobes(double g, double g2, double w) {
    AtmosphereParameters a = EarthAtmosphere();
    a.mie_phase_g = g;
    a.mie_phase_g2 = g2;
    a.mie_phase_weight2 = w;
    return a;
}

TEST(Phase, TwoLobeMieIntegratesToOneAndIsOneLobeAtWeightZero) {
    for (double w : {0.0, 0.3, 1.0}) {
        const double lobes[2][2] = {{0.55, 0.94}, {0.8, -0.3}};
        for (const auto& lobe : lobes) {
            const AtmosphereParameters a = TwoLobes(lobe[0], lobe[1], w);
            EXPECT_NEAR(SphereIntegral([&a](double nu) { return MiePhase(a, nu); }), 1.0, 1e-6)
                << w << " " << lobe[1];
        }
    }
    // w = 0: exactly the one lobe (bit for bit), whatever g2; w = 1: exactly lobe 2's.
    for (double nu : {-1.0, -0.3, 0.0, 0.5, 0.99, 1.0}) {
        EXPECT_EQ(MiePhase(TwoLobes(0.7, 0.94, 0.0), nu), CornetteShanksPhase(0.7, nu)) << nu;
        EXPECT_EQ(MiePhase(TwoLobes(0.7, 0.0, 0.0), nu), CornetteShanksPhase(0.7, nu)) << nu;
        EXPECT_EQ(MiePhase(TwoLobes(0.7, 0.94, 1.0), nu), CornetteShanksPhase(0.94, nu)) << nu;
        EXPECT_NEAR(MiePhase(TwoLobes(0.55, 0.94, 0.1), nu),
                    0.9 * CornetteShanksPhase(0.55, nu) + 0.1 * CornetteShanksPhase(0.94, nu),
                    1e-14 * CornetteShanksPhase(0.94, nu));
    }
}

TEST(Sampling, TwoLobeMieSamplingIsUnbiasedAndBounded) {
    // E[f(mu) P(mu) / pdf(mu)] over SampleMiePhaseCosine's directions (1e6
    // stratified uniform numbers: the mean is a quadrature in xi) equals the
    // integral of P f over the sphere (2e5 midpoints in mu), for f = 1 and
    // a forward-peaked f; the weight P / pdf stays below 1.5 (the larger of
    // the lobes' CS/HG ratios).
    auto forward = [](double mu) { return std::exp(8.0 * (mu - 1.0)); };
    for (double w : {0.0, 0.1, 0.5, 1.0}) {
        const AtmosphereParameters a = TwoLobes(0.55, 0.94, w);
        const int n = 1000000;
        double sum_one = 0.0, sum_forward = 0.0, max_weight = 0.0;
        for (int i = 0; i < n; ++i) {
            const double mu = SampleMiePhaseCosine(a, (i + 0.5) / n);
            const double weight = MiePhaseOverSamplingPdf(a, mu);
            EXPECT_NEAR(weight, MiePhase(a, mu) / MiePhaseSamplingPdf(a, mu), 1e-12 * weight);
            max_weight = std::max(max_weight, weight);
            sum_one += weight;
            sum_forward += weight * forward(mu);
        }
        const double want =
            SphereIntegral([&](double mu) { return MiePhase(a, mu) * forward(mu); });
        EXPECT_NEAR(sum_one / n, 1.0, 2e-4) << w;
        EXPECT_NEAR(sum_forward / n, want, 2e-4 * want) << w;
        EXPECT_LE(max_weight, 1.5) << w;
    }
    // w = 0 draws exactly as Henyey-Greenstein g alone, with its weight.
    const AtmosphereParameters one = TwoLobes(0.7, 0.94, 0.0);
    for (double xi : {0.0, 0.1, 0.5, 0.93}) {
        const double mu = SampleMiePhaseCosine(one, xi);
        EXPECT_EQ(mu, SampleHenyeyGreensteinCosine(0.7, xi));
        EXPECT_EQ(MiePhaseOverSamplingPdf(one, mu), CornetteShanksOverHenyeyGreenstein(0.7, mu));
        EXPECT_EQ(MiePhaseSamplingPdf(one, mu), HenyeyGreensteinPhase(0.7, mu));
    }
}

TEST(Phase, KnownValuesAndSymmetry) {
    EXPECT_NEAR(RayleighPhase(0.0), 3.0 / (16.0 * kPi), 1e-15);
    EXPECT_NEAR(RayleighPhase(1.0), RayleighPhase(-1.0), 1e-15);
    EXPECT_NEAR(CornetteShanksPhase(0.0, 0.5), RayleighPhase(0.5) * 1.0, 1e-15);
    EXPECT_GT(CornetteShanksPhase(0.8, 1.0), 100.0 * CornetteShanksPhase(0.8, -1.0));
    EXPECT_NEAR(HenyeyGreensteinPhase(0.0, 0.3), IsotropicPhase(), 1e-15);
}

TEST(OpticalDepth, ExponentialLayerVertical) {
    // A vertical ray from the ground through exp(-h/H) over a height Delta has
    // optical length H (1 - exp(-Delta/H)).
    AtmosphereParameters atm = EarthAtmosphere();
    const double H = 8000.0;
    const double delta = atm.top_radius - atm.bottom_radius;
    const double numeric = OpticalLength(atm, ExponentialProfile(H), Vec3d(0, 0, atm.bottom_radius),
                                         Vec3d(0, 0, 1), delta, 20000);
    const double exact = H * (1.0 - std::exp(-delta / H));
    EXPECT_NEAR(numeric, exact, 1e-6 * exact);
    // From altitude h0 up to the top: H (exp(-h0/H) - exp(-Delta/H)).
    const double h0 = 3000.0;
    const double partial =
        OpticalLength(atm, ExponentialProfile(H), Vec3d(0, 0, atm.bottom_radius + h0),
                      Vec3d(0, 0, 1), delta - h0, 20000);
    EXPECT_NEAR(partial, H * (std::exp(-h0 / H) - std::exp(-delta / H)), 1e-6 * partial);
}

TEST(OpticalDepth, ZenithEarthMatchesClosedForm) {
    // Full extinction optical depth at the zenith from the ground: each
    // constituent's closed form (exponentials; 15 km for the ozone tent).
    const AtmosphereParameters atm = EarthAtmosphere();
    const Vec3d tau = OpticalDepthToTopAtmosphereBoundary(atm, atm.bottom_radius, 1.0, 20000);
    const double d = atm.top_radius - atm.bottom_radius;
    for (int c = 0; c < 3; ++c) {
        const double expected = atm.rayleigh_scattering[c] * 8000.0 * (1 - std::exp(-d / 8000.0)) +
                                atm.mie_extinction[c] * 1200.0 * (1 - std::exp(-d / 1200.0)) +
                                atm.absorption_extinction[c] * 15000.0;
        EXPECT_NEAR(tau[c], expected, 1e-6 * expected) << c;
    }
}

}  // namespace
}  // namespace atmos
