// Tests of the `atmosphere-plus` model (Boody's Atmosphere Plus notes): mappings, integration
// rules, tables against direct integration, scattering orders, rendering.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/model.h"
#include "atmos/view.h"
#include "models/atmosphere_plus.h"
#include "models/naive.h"
#include "physics/transmittance.h"
#include "render/render.h"
#include "test_util.h"

namespace atmos {
namespace {

const AtmosphereParameters& SeedAtmosphere() {
    static const AtmosphereParameters atm = LoadAtmosphere("earth-atmosphere-plus");
    return atm;
}

AplusMapping MakeMapping(AplusParameterization kind,
                         AplusHorizonAngle angle = AplusHorizonAngle::kGeometric) {
    AplusMapping m;
    m.kind = kind;
    m.horizon_angle = angle;
    m.bottom_radius = 6360e3;
    m.height = 100e3;
    return m;
}

AplusSettings SmallSettings(AplusParameterization kind, int orders) {
    AplusSettings s;
    s.mapping.kind = kind;
    s.width = 16;
    s.height = 64;
    s.depth = 16;
    s.transmittance_width = 32;
    s.transmittance_height = 128;
    s.orders = orders;
    return s;
}

Vec3d Dir(double mu) { return Vec3d(std::sqrt(1.0 - mu * mu), 0.0, mu); }

// ---------------------------------------------------------------- mappings

TEST(AtmospherePlus, EveryMappingRoundTrips) {
    std::vector<AplusMapping> maps = {
        MakeMapping(AplusParameterization::kLinear), MakeMapping(AplusParameterization::kNonlinear),
        MakeMapping(AplusParameterization::kHorizon),
        MakeMapping(AplusParameterization::kHorizon, AplusHorizonAngle::kSeed)};
    for (double p : {0.5, 1.5, 2.0, 4.0}) {
        AplusMapping m = MakeMapping(AplusParameterization::kPower);
        m.p_u = p;
        m.p_v = p + 1.0;
        m.p_w = 2.0 * p;
        maps.push_back(m);
    }
    AplusMapping custom = MakeMapping(AplusParameterization::kHorizon);
    custom.p_u = 3.0;
    custom.p_a = 2.0;
    custom.p_s = 1.5;
    custom.s = 0.3;
    maps.push_back(custom);
    for (const AplusMapping& m : maps) {
        for (double h : {0.0, 10.0, 1000.0, 8000.0, 35e3, 99e3, 100e3}) {
            EXPECT_NEAR(m.H(m.U(h)), h, 1e-6 * 100e3) << static_cast<int>(m.kind);
            for (int i = 0; i <= 200; ++i) {
                const double mu = -1.0 + i / 100.0;
                const double v = m.V(h, mu);
                ASSERT_GE(v, 0.0);
                ASSERT_LE(v, 1.0);
                // At h = 0 the horizon mapping gives the surface no texture space
                // (s u = 0): rays below the horizon have no atmosphere there.
                if (m.kind == AplusParameterization::kHorizon && h == 0.0 &&
                    mu < m.HorizonCosine(h))
                    continue;
                EXPECT_NEAR(m.Mu(h, v), mu, 1e-9) << static_cast<int>(m.kind) << " h " << h;
            }
        }
        for (int i = 0; i <= 200; ++i) {
            const double mu_s = -1.0 + i / 100.0;
            EXPECT_NEAR(m.MuS(m.W(mu_s)), mu_s, 1e-9);
            const double t = i / 200.0;  // and texture -> parameter -> texture
            EXPECT_NEAR(m.W(m.MuS(t)), t, 1e-9);
            EXPECT_NEAR(m.U(m.H(t)), t, 1e-9);
            EXPECT_NEAR(m.V(50e3, m.Mu(50e3, t)), t, 1e-9);
        }
    }
}

TEST(AtmospherePlus, HorizonMappingAtTheHorizonAndAtAltitude) {
    const AplusMapping m = MakeMapping(AplusParameterization::kHorizon);
    for (double h : {0.0, 1000.0, 20e3, 100e3}) {
        const double c_h = m.HorizonCosine(h);
        const double r = m.bottom_radius + h;
        // Geometric horizon: the ray grazes the ground, r^2 (1 - c_h^2) = R_p^2.
        EXPECT_NEAR(r * r * (1.0 - c_h * c_h) / (m.bottom_radius * m.bottom_radius), 1.0, 1e-12);
        // The horizon sits at v = s u; the zenith at v = 1, the nadir at v = 0.
        EXPECT_NEAR(m.V(h, c_h), m.s * m.U(h), 1e-12);
        EXPECT_NEAR(m.V(h, 1.0), 1.0, 1e-12);
        if (h > 0.0) {
            EXPECT_NEAR(m.V(h, -1.0), 0.0, 1e-12);
            EXPECT_NEAR(m.Mu(h, m.s * m.U(h)), c_h, 1e-12);
            // Continuous across the horizon.
            EXPECT_NEAR(m.V(h, c_h + 1e-9), m.V(h, c_h - 1e-9), 1e-2);
        }
    }
    // At the top (u = 1) the surface gets the fraction s of the v range.
    EXPECT_NEAR(m.V(100e3, m.HorizonCosine(100e3)), 0.5, 1e-12);
    // The seed's literal horizon -1 + R_p/r is above the geometric one.
    const AplusMapping seed =
        MakeMapping(AplusParameterization::kHorizon, AplusHorizonAngle::kSeed);
    EXPECT_NEAR(seed.HorizonCosine(100e3), -1.0 + 6360.0 / 6460.0, 1e-12);
    EXPECT_GT(seed.HorizonCosine(100e3), m.HorizonCosine(100e3) + 0.1);
}

TEST(AtmospherePlus, LinearAndNonlinearMappingsAreTheSeedFormulas) {
    const AplusMapping lin = MakeMapping(AplusParameterization::kLinear);
    const AplusMapping non = MakeMapping(AplusParameterization::kNonlinear);
    for (double h : {0.0, 2500.0, 50e3, 100e3}) {
        EXPECT_NEAR(lin.U(h), h / 100e3, 1e-15);
        EXPECT_NEAR(non.U(h), std::sqrt(h / 100e3), 1e-15);  // Boody's Atmosphere Plus notes 2.4.2
    }
    for (double c : {-1.0, -0.3, 0.0, 0.008, 0.7, 1.0}) {
        EXPECT_NEAR(lin.V(0.0, c), (c + 1.0) / 2.0, 1e-15);
        EXPECT_NEAR(lin.W(c), (c + 1.0) / 2.0, 1e-15);
        // The earlier Atmosphere Plus notes (Boody)'s form of the same map: 0.5 (1 + sign(c)
        // |c|^(1/3)).
        const double seed002 = 0.5 * (1.0 + (c < 0 ? -1.0 : 1.0) * std::cbrt(std::fabs(c)));
        EXPECT_NEAR(non.V(0.0, c), seed002, 1e-12);
        EXPECT_NEAR(non.W(c), seed002, 1e-12);
    }
    // The cube root puts more texels near the horizon: v(0.008) - v(0) = 0.1.
    EXPECT_NEAR(non.V(0.0, 0.008) - non.V(0.0, 0.0), 0.1, 1e-12);
}

// ------------------------------------------------------------ integration

TEST(AtmospherePlus, Trapezoid2DMatchesClosedFormIntegrals) {
    // Bilinear functions are integrated exactly by the 2D trapezoidal rule.
    const auto bilinear = [](double x, double y) { return 1.0 + 2.0 * x - 3.0 * y + 5.0 * x * y; };
    // int_0^2 int_-1^3 (...) dy dx = 8 + 16 - 24 + 40 = 40.
    EXPECT_NEAR(AplusTrapezoid2D<double>(bilinear, 0.0, 2.0, -1.0, 3.0, 3, 5), 40.0, 1e-12);
    // Over the sphere (dw = sin(Theta) dTheta dPhi):
    //   int (1 + cos^2 Theta) dw = 16 pi / 3; int F_R dw = 4 pi; int F_M dw = 4 pi.
    const auto sphere = [](double theta, double) {
        const double c = std::cos(theta);
        return (1.0 + c * c) * std::sin(theta);
    };
    const double coarse = AplusTrapezoid2D<double>(sphere, 0.0, kPi, 0.0, 2.0 * kPi, 6, 12);
    const double fine = AplusTrapezoid2D<double>(sphere, 0.0, kPi, 0.0, 2.0 * kPi, 64, 128);
    const double exact = 16.0 * kPi / 3.0;
    EXPECT_NEAR(fine, exact, 1e-3 * exact);
    EXPECT_LT(std::fabs(fine - exact), std::fabs(coarse - exact));
    const Vec3d v = Normalize(Vec3d(0.3, 0.4, 0.5));  // a tilted lobe axis
    const auto mie = [&](double theta, double phi) {
        const Vec3d w(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                      std::cos(theta));
        return AplusMiePhase(0.8, Dot(w, v)) * std::sin(theta);
    };
    EXPECT_NEAR(AplusTrapezoid2D<double>(mie, 0.0, kPi, 0.0, 2.0 * kPi, 400, 800), 4.0 * kPi,
                1e-3 * 4.0 * kPi);
    const auto rayleigh = [&](double theta, double phi) {
        const Vec3d w(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                      std::cos(theta));
        return AplusRayleighPhase(Dot(w, v)) * std::sin(theta);
    };
    EXPECT_NEAR(AplusTrapezoid2D<double>(rayleigh, 0.0, kPi, 0.0, 2.0 * kPi, 64, 128), 4.0 * kPi,
                1e-3 * 4.0 * kPi);
}

TEST(AtmospherePlus, PhaseFunctionsAreTheSeeds) {
    for (double c : {-1.0, -0.5, 0.0, 0.25, 1.0}) {
        EXPECT_NEAR(AplusRayleighPhase(c), 0.75 * (1 + c * c), 1e-15);
        EXPECT_NEAR(AplusModifiedRayleighPhase(c), 0.8 * (1.4 + 0.5 * c * c), 1e-15);
        // Boody's Atmosphere Plus notes: 3(1-g^2)/(2(2+g^2)) (1+c^2)/(1+g^2-2gc)^1.5 with g = 0.8.
        const double g = 0.8;
        const double seed000 = 3 * (1 - g * g) / (2 * (2 + g * g)) * (1 + c * c) /
                               std::pow(1 + g * g - 2 * g * c, 1.5);
        EXPECT_NEAR(AplusMiePhase(g, c), seed000, 1e-12 * seed000);
        // The earlier Atmosphere Plus notes (Boody) writes +2g cos with g = -0.85: the same lobe as
        // g = +0.85 here.
        const double g2 = -0.85;
        const double seed002 = 3 * (1 - g2 * g2) / (2 * (2 + g2 * g2)) * (1 + c * c) /
                               std::pow(1 + g2 * g2 + 2 * g2 * c, 1.5);
        EXPECT_NEAR(AplusMiePhase(0.85, c), seed002, 1e-12 * seed002);
    }
}

TEST(AtmospherePlus, PresetCarriesTheSeedsIncidentLight) {
    // Boody's Atmosphere Plus notes 1.2: I_I = SpectralIrradiance x Exposure x SpectralToRGB.
    const AtmosphereParameters& atm = SeedAtmosphere();
    const double ii[3] = {0.1526 * 133.3209, 0.191 * 88.51855, 0.208 * 112.7552};
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(Channel(atm.solar_irradiance, c), ii[c], 1e-5);
    EXPECT_NEAR(atm.bottom_radius, 6360e3, 1e-6);
    EXPECT_NEAR(atm.top_radius, 6460e3, 1e-6);
    EXPECT_NEAR(atm.mie_extinction.y, 3.996e-6 + 4.40e-6, 1e-12);
}

// ------------------------------------------------------------ transmittance

// Trapezoidal rule of exp(-x/H) over [0, L] with n intervals, closed form:
// H (1 - exp(-L/H)) (d/2H) coth(d/2H), d = L/n.
double TrapezoidExp(double scale_height, double length, int n) {
    const double a = length / n / (2.0 * scale_height);
    return scale_height * (1.0 - std::exp(-length / scale_height)) * a / std::tanh(a);
}

TEST(AtmospherePlus, ZenithTransmittanceMatchesClosedForms) {
    // Boody's Atmosphere Plus notes (n = 30, the seed's value) and the earlier Atmosphere Plus
    // notes (Boody)'s constants (R_p 6371 km, Rayleigh (6.55, 17.3, 23.0)e-6, Mie 2e-6 with
    // extinction 2e-6/0.9): the table's texel at h = 0, mu = 1 holds exp(-trapezoid sum), which has
    // a closed form for a vertical ray through exponential layers.
    AtmosphereParameters seed002 = SeedAtmosphere();
    seed002.bottom_radius = 6371e3;
    seed002.top_radius = 6471e3;
    seed002.rayleigh_scattering = Vec3d(6.55e-6, 1.73e-5, 2.30e-5);
    seed002.mie_scattering = Vec3d(2e-6);
    seed002.mie_extinction = Vec3d(2e-6 / 0.9);
    seed002.mie_phase_g = 0.85;
    const AtmosphereParameters* atms[2] = {&SeedAtmosphere(), &seed002};
    for (const AtmosphereParameters* atm : atms) {
        for (int n : {30, 1000}) {
            AplusSettings s = SmallSettings(AplusParameterization::kNonlinear, 1);
            s.width = s.height = s.depth = 2;
            s.transmittance_width = s.transmittance_height = 2;
            s.transmittance_steps = n;
            const AplusTables t = AplusPrecompute(*atm, s);
            const TableView& tv = t.transmittance.view();
            const Vec4f zenith = tv.Fetch(0, tv.height - 1);
            const double mie = atm->mie_extinction.x * TrapezoidExp(1200.0, 100e3, n);
            const float got[3] = {zenith.x, zenith.y, zenith.z};
            for (int c = 0; c < 3; ++c) {
                const double tau =
                    Channel(atm->rayleigh_scattering, c) * TrapezoidExp(8000.0, 100e3, n) + mie;
                EXPECT_NEAR(got[c], std::exp(-tau), 2e-6) << "n " << n << " c " << c;
            }
        }
    }
}

TEST(AtmospherePlus, TransmittanceTableMatchesDirectIntegration) {
    const AtmosphereParameters& atm = SeedAtmosphere();
    for (AplusParameterization kind :
         {AplusParameterization::kNonlinear, AplusParameterization::kHorizon}) {
        AplusSettings s = SmallSettings(kind, 1);
        s.width = s.height = s.depth = 2;
        s.transmittance_width = 64;
        s.transmittance_height = 256;
        s.transmittance_steps = 200;
        const AplusTables t = AplusPrecompute(atm, s);
        AplusMapping m = s.mapping;
        m.bottom_radius = atm.bottom_radius;
        m.height = atm.top_radius - atm.bottom_radius;
        double worst = 0.0;
        for (double h : {130.0, 1700.0, 9100.0, 33e3, 77e3}) {
            for (double mu : {0.93, 0.61, 0.33, 0.17, 0.09}) {
                const Rgb table = AplusSampleTransmittance(t.transmittance.view(), m, h, mu);
                const Vec3d tau =
                    OpticalDepthToTopAtmosphereBoundary(atm, atm.bottom_radius + h, mu, 20000);
                for (int c = 0; c < 3; ++c) {
                    const double direct = std::exp(-Channel(tau, c));
                    const double got = c == 0 ? table.x : c == 1 ? table.y : table.z;
                    worst = std::max(worst, std::fabs(got - direct));
                }
            }
        }
        std::printf("transmittance table (64x256) worst abs error: %.2e\n", worst);
        EXPECT_LT(worst, 3e-3) << static_cast<int>(kind);
    }
}

TEST(AtmospherePlus, FixedLookupIsTheGenericBitForBit) {
    // Issue 19: the evaluator's AplusSampleTableFixed<4> (scattering) and <3>
    // (transmittance, depth 1) against AplusSampleTable on tables of random
    // texels, every mapping, altitudes on and between the rows (the ground row
    // with rays below the horizon included): the same bits.
    std::mt19937 rng(19);
    std::uniform_real_distribution<float> texel(0.0f, 1.0f);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (const auto kind : {AplusParameterization::kLinear, AplusParameterization::kNonlinear,
                            AplusParameterization::kHorizon, AplusParameterization::kPower}) {
        const AplusMapping m = MakeMapping(kind);
        Table scattering(6, 9, 5, 4), transmittance(7, 11, 1, 3);
        for (Table* t : {&scattering, &transmittance}) {
            const size_t n = static_cast<size_t>(t->width()) * t->height() * t->depth() *
                             static_cast<size_t>(t->channels());
            for (size_t i = 0; i < n; ++i) t->data()[i] = texel(rng);
        }
        Vec4f one;
        one.x = one.y = one.z = 1.0f;
        const float zero4[4] = {0.0f, 0.0f, 0.0f, 0.0f}, one3[3] = {1.0f, 1.0f, 1.0f};
        for (int q = 0; q < 2000; ++q) {
            const double h = q % 7 == 0 ? 0.0 : m.height * u(rng) * u(rng);
            const double mu = 2.0 * u(rng) - 1.0, w = u(rng);
            const Vec4f a = AplusSampleTable(scattering.view(), m, h, mu, w, Vec4f());
            float b[4];
            AplusSampleTableFixed<4>(scattering.view(), m, h, mu, w, zero4, b);
            EXPECT_EQ(std::memcmp(&a.x, &b[0], sizeof(float)), 0) << h << " " << mu;
            EXPECT_EQ(std::memcmp(&a.y, &b[1], sizeof(float)), 0) << h << " " << mu;
            EXPECT_EQ(std::memcmp(&a.z, &b[2], sizeof(float)), 0) << h << " " << mu;
            EXPECT_EQ(std::memcmp(&a.w, &b[3], sizeof(float)), 0) << h << " " << mu;
            const Rgb ta = AplusSampleTable(transmittance.view(), m, h, mu, 0.5, one).rgb();
            float tb[3];
            AplusSampleTableFixed<3>(transmittance.view(), m, h, mu, 0.5, one3, tb);
            EXPECT_EQ(std::memcmp(&ta.x, &tb[0], sizeof(float)), 0) << h << " " << mu;
            EXPECT_EQ(std::memcmp(&ta.y, &tb[1], sizeof(float)), 0) << h << " " << mu;
            EXPECT_EQ(std::memcmp(&ta.z, &tb[2], sizeof(float)), 0) << h << " " << mu;
        }
    }
}

// ------------------------------------------------------------ scattering

TEST(AtmospherePlus, SingleScatteringMatchesAnIndependentIntegrator) {
    // Rayleigh only (the Mie alpha channel is one wavelength by design): the
    // factored single scattering times the seed's phase equals `naive` with many
    // steps (an independent midpoint-rule implementation) in the sun's plane.
    AtmosphereParameters atm = SeedAtmosphere();
    atm.mie_scattering = Vec3d(0.0);
    atm.mie_extinction = Vec3d(0.0);
    NaiveEvaluator naive;
    naive.atm = atm;
    naive.steps = 400;
    naive.light_steps = 200;
    for (double h : {0.0, 3000.0, 20e3}) {
        for (double mu : {0.9, 0.4, 0.1}) {
            for (double mu_s : {0.8, 0.2, 0.02}) {
                const AplusValue v = AplusSingleScattering(atm, h, mu, mu_s, 400, 200);
                const double nu = mu * mu_s + std::sqrt((1 - mu * mu) * (1 - mu_s * mu_s));
                const Vec3d ours = v.rayleigh * AplusRayleighPhase(nu);
                const RayResult r =
                    naive.Evaluate(Vec3d(0, 0, atm.bottom_radius + h), Dir(mu), Dir(mu_s), false);
                const Vec3d theirs(r.sky);
                for (int c = 0; c < 3; ++c) {
                    EXPECT_NEAR(Channel(ours, c), Channel(theirs, c), 5e-3 * Channel(theirs, c))
                        << h << " " << mu << " " << mu_s;
                }
            }
        }
    }
}

TEST(AtmospherePlus, SingleScatteringTableMatchesDirectIntegration) {
    // Order-1 tables: exact at the texels, and off the texels the error against
    // direct integration (same physics, no table) shrinks as the table grows.
    const AtmosphereParameters& atm = SeedAtmosphere();
    AplusSettings small = SmallSettings(AplusParameterization::kNonlinear, 1);
    small.width = 8;
    small.height = 32;
    small.depth = 8;
    AplusSettings big = small;
    big.width = 16;
    big.height = 128;
    big.depth = 16;
    const AplusTables ts = AplusPrecompute(atm, small);
    const AplusTables tb = AplusPrecompute(atm, big);
    AplusMapping m = small.mapping;
    m.bottom_radius = atm.bottom_radius;
    m.height = atm.top_radius - atm.bottom_radius;
    // At a texel: equal up to float rounding.
    for (int x : {0, 3, 7}) {
        for (int y : {5, 20, 31}) {
            for (int z : {1, 6}) {
                double h, mu, mu_s;
                AplusTexelParameters(m, x, y, z, 8, 32, 8, &h, &mu, &mu_s);
                const AplusValue d = AplusSingleScattering(atm, h, mu, mu_s, 30, 30);
                const Vec4f t = ts.scattering.view().Fetch(x, y, z);
                EXPECT_NEAR(t.y, d.rayleigh.y, 1e-5 * d.rayleigh.y + 1e-12);
                EXPECT_NEAR(t.w, d.mie, 1e-5 * d.mie + 1e-12);
            }
        }
    }
    double err_small = 0.0, err_big = 0.0, norm = 0.0;
    for (double h : {250.0, 4100.0, 17e3, 52e3}) {
        for (double mu : {0.83, 0.41, 0.13, 0.04, -0.27}) {
            for (double mu_s : {0.71, 0.29, 0.06}) {
                const AplusValue d = AplusSingleScattering(atm, h, mu, mu_s, 30, 30);
                const Vec4f a = AplusSample(ts.scattering.view(), m, h, mu, mu_s);
                const Vec4f b = AplusSample(tb.scattering.view(), m, h, mu, mu_s);
                err_small += std::pow(static_cast<double>(a.z) - d.rayleigh.z, 2) +
                             std::pow(static_cast<double>(a.w) - d.mie, 2);
                err_big += std::pow(static_cast<double>(b.z) - d.rayleigh.z, 2) +
                           std::pow(static_cast<double>(b.w) - d.mie, 2);
                norm += d.rayleigh.z * d.rayleigh.z + d.mie * d.mie;
            }
        }
    }
    const double rel_small = std::sqrt(err_small / norm), rel_big = std::sqrt(err_big / norm);
    std::printf("order-1 table relative RMS error: 8x32x8 %.4f, 16x128x16 %.4f\n", rel_small,
                rel_big);
    EXPECT_LT(rel_big, 0.5 * rel_small);
    EXPECT_LT(rel_big, 0.05);
}

TEST(AtmospherePlus, MultipleScatteringOrdersArePositiveAndDecreasing) {
    const AtmosphereParameters& atm = SeedAtmosphere();
    AplusSettings s = SmallSettings(AplusParameterization::kNonlinear, 4);
    s.width = 8;
    s.height = 32;
    s.depth = 8;
    s.gather_theta = 12;
    s.gather_phi = 24;
    const AplusTables t = AplusPrecompute(atm, s, true);
    ASSERT_EQ(t.orders.size(), 4u);
    ASSERT_EQ(t.order_seconds.size(), 4u);
    double previous[4] = {1e300, 1e300, 1e300, 1e300};
    for (const Table& order : t.orders) {
        double sum[4] = {0, 0, 0, 0};
        for (size_t i = 0; i < order.size(); ++i) {
            ASSERT_TRUE(std::isfinite(order.data()[i]));
            ASSERT_GE(order.data()[i], 0.0f);
            sum[i % 4] += static_cast<double>(order.data()[i]);
        }
        for (int c = 0; c < 4; ++c) {
            EXPECT_GT(sum[c], 0.0);
            EXPECT_LT(sum[c], previous[c]);
            previous[c] = sum[c];
        }
    }
    // The total is the sum of the orders.
    const size_t probe = t.scattering.size() / 3;
    float total = 0.0f;
    for (const Table& order : t.orders) total += order.data()[probe];
    EXPECT_NEAR(t.scattering.data()[probe], total, 1e-6f * total + 1e-12f);
}

// ------------------------------------------------------------ rendering

std::unique_ptr<Model> SmallModel(std::map<std::string, std::string> extra = {}) {
    std::map<std::string, std::string> o = {
        {"table-width", "8"},          {"table-height", "32"},         {"table-depth", "8"},
        {"transmittance-width", "16"}, {"transmittance-height", "64"}, {"orders", "2"}};
    for (const auto& kv : extra) o[kv.first] = kv.second;
    return CreateModel("atmosphere-plus", o);
}

TEST(AtmospherePlus, EvaluatorSweepIsFiniteAndNonNegative) {
    for (const char* p : {"linear", "nonlinear", "power", "horizon"}) {
        auto model = SmallModel({{"parameterization", p}});
        model->Prepare(SeedAtmosphere());
        const AtmospherePlusEvaluator e =
            static_cast<AtmospherePlusModel*>(model.get())->MakeEvaluator();
        const double R = SeedAtmosphere().bottom_radius;
        for (double alt : {0.0, 1.0, 5000.0, 99999.0, 100e3, 2e6}) {
            for (int i = 0; i <= 40; ++i) {
                const double mu = -1.0 + i / 20.0;
                for (double mu_s : {1.0, 0.1, 0.0, -0.1, -1.0}) {
                    const RayResult r = e.Evaluate(Vec3d(0, 0, R + alt), Dir(mu), Dir(mu_s), true);
                    for (float v : {r.sky.x, r.sky.y, r.sky.z, r.transmittance.x, r.transmittance.z,
                                    r.ground.y}) {
                        ASSERT_TRUE(std::isfinite(v)) << p;
                        ASSERT_GE(v, 0.0f) << p;
                    }
                    ASSERT_LE(r.transmittance.x, 1.0f);
                }
            }
        }
        // A ray that misses the atmosphere: no light, full transmittance.
        const RayResult miss = e.Evaluate(Vec3d(0, 0, R + 2e6), Dir(1.0), Dir(0.5), true);
        EXPECT_EQ(miss.sky.x, 0.0f);
        EXPECT_EQ(miss.transmittance.y, 1.0f);
    }
}

TEST(AtmospherePlus, ViewersInSpaceAreMovedToTheBoundary) {
    auto model = SmallModel();
    model->Prepare(SeedAtmosphere());
    const AtmospherePlusEvaluator e =
        static_cast<AtmospherePlusModel*>(model.get())->MakeEvaluator();
    const double top = SeedAtmosphere().top_radius;
    const Vec3d dir = Normalize(Vec3d(0.3, 0.1, -1.0));
    const Vec3d far(0.0, 0.0, top + 3e6);
    double t0, t1;
    ASSERT_TRUE(IntersectSphere(far, dir, top, &t0, &t1));
    const Vec3d entry = far + dir * t0;
    const Vec3d sun = Normalize(Vec3d(1.0, 0.0, 0.4));
    const RayResult a = e.Evaluate(far, dir, sun, false);
    const RayResult b = e.Evaluate(entry, dir, sun, false);
    EXPECT_GT(a.sky.z, 0.0f);
    EXPECT_NEAR(a.sky.z, b.sky.z, 1e-6f * b.sky.z);
    EXPECT_NEAR(a.transmittance.x, b.transmittance.x, 1e-6f);
}

TEST(AtmospherePlus, ModifiedRayleighPhaseOnlyChangesTheRayleighPart) {
    AtmosphereParameters atm = SeedAtmosphere();
    atm.mie_scattering = Vec3d(0.0);
    atm.mie_extinction = Vec3d(0.0);
    auto standard = SmallModel();
    auto modified = SmallModel({{"rayleigh-phase", "modified"}});
    standard->Prepare(atm);
    modified->Prepare(atm);
    const std::vector<SampleQuery> q = {{100.0, 0.5, 0.5, 0.0}, {100.0, 0.5, 0.5, 180.0}};
    const auto a = standard->Sample(q);
    const auto b = modified->Sample(q);
    for (size_t i = 0; i < q.size(); ++i) {
        const double nu = i == 0 ? 1.0 : 0.5 * 0.5 - 0.75;  // same side / opposite sides
        const double ratio = AplusModifiedRayleighPhase(nu) / AplusRayleighPhase(nu);
        EXPECT_NEAR(b[i].radiance.y / a[i].radiance.y, ratio, 1e-4);
    }
}

TEST(AtmospherePlus, RendersAllParameterizationsAndRejectsBadOptions) {
    const View view = GetView("ground-sunrise", SeedAtmosphere());
    for (const char* p : {"linear", "nonlinear", "power", "horizon"}) {
        auto model = SmallModel({{"parameterization", p}});
        model->Prepare(SeedAtmosphere());
        RenderRequest request = atmos_test::QuietRequest(view, 32, 18);
        Image image;
        model->Render(request, &image);
        double sum = 0.0;
        for (int y = 0; y < 18; ++y) {
            for (int x = 0; x < 32; ++x) sum += static_cast<double>(image.Get(x, y).z);
        }
        EXPECT_GT(sum, 0.0) << p;
    }
    EXPECT_THROW(CreateModel("atmosphere-plus", {{"parameterization", "cubic"}}), Error);
    EXPECT_THROW(CreateModel("atmosphere-plus", {{"table-height", "1"}}), Error);
    EXPECT_THROW(CreateModel("atmosphere-plus", {{"orders", "0"}}), Error);
    EXPECT_THROW(CreateModel("atmosphere-plus", {{"parameterization", "linear"}, {"p-u", "2"}}),
                 Error);
    EXPECT_THROW(CreateModel("atmosphere-plus", {{"parameterization", "power"}, {"p-a", "2"}}),
                 Error);
    EXPECT_NO_THROW(CreateModel("atmosphere-plus", {{"parameterization", "power"}, {"p-v", "2"}}));
    auto unprepared = CreateModel("atmosphere-plus");
    EXPECT_THROW(unprepared->Sample({{0.0, 1.0, 1.0, 0.0}}), Error);
}

TEST(AtmospherePlus, BakeAndLoadRoundTrip) {
    const std::string dir = std::string(ATMOS_TEST_TMP) + "/aplus_bake_" +
                            std::to_string(static_cast<long>(::getpid()));
    std::filesystem::create_directories(dir);
    auto model = SmallModel();
    ASSERT_TRUE(model->CanBake());
    model->Prepare(SeedAtmosphere());
    model->Bake(dir);
    auto loaded = SmallModel();
    loaded->LoadBaked(dir, SeedAtmosphere());
    const std::vector<SampleQuery> q = {{100.0, 0.3, 0.2, 0.0}, {2e6, -0.6, 0.5, 90.0}};
    const auto a = model->Sample(q);
    const auto b = loaded->Sample(q);
    for (size_t i = 0; i < q.size(); ++i) {
        EXPECT_EQ(a[i].radiance.y, b[i].radiance.y);
        EXPECT_EQ(a[i].transmittance.z, b[i].transmittance.z);
    }
    auto other = SmallModel({{"parameterization", "linear"}});
    EXPECT_THROW(other->LoadBaked(dir, SeedAtmosphere()), Error);
    EXPECT_THROW(loaded->LoadBaked(dir, EarthAtmosphere()), Error);
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace atmos
