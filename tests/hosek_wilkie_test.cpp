// The `hosek-wilkie` model (issue 34): the paper's equations against values
// computed independently (scripts/hosek_wilkie_reference.py, from the JSON),
// the data layout, the blend in turbidity, albedo and elevation, the units.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "atmos/model.h"
#include "atmos/spectral.h"
#include "models/hosek_wilkie.h"

namespace atmos {
namespace {

// A channel of a float colour, as double.
double At(const Rgb& c, int i) { return static_cast<double>(c[i]); }

std::unique_ptr<Model> Make(const std::string& spec) {
    const ModelSpec s = ParseModelSpec(spec);
    return CreateModel(s.name, s.options);
}

// A ground query with view zenith theta, sun elevation el and angle gamma
// between them (degrees).
SampleQuery Query(double el, double theta, double gamma) {
    SampleQuery q;
    q.mu = std::cos(Radians(theta));
    q.mu_s = std::sin(Radians(el));
    const double st = std::sin(Radians(theta)), ss = std::cos(Radians(el));
    double c = 1.0;
    if (st * ss > 1e-12) c = (std::cos(Radians(gamma)) - q.mu * q.mu_s) / (st * ss);
    q.azimuth_deg = std::acos(std::max(-1.0, std::min(1.0, c))) * 180.0 / kPi;
    return q;
}

struct Case {
    double turbidity, albedo, elevation, theta, gamma;
    double rgb[3], xyz[3], spectral[3];  // spectral: 320, 550, 700 nm
};

// scripts/hosek_wilkie_reference.py (Python, standard library, from the JSON;
// no atmos code), in the authors' units.
const Case kCases[] = {
    {3.0,
     0.1,
     30.0,
     60.0,
     40.0,
     {5.73659015, 8.727579783, 13.34111199},
     {7.868454186, 8.413199873, 13.74859082},
     {0.03707340539, 0.07980733533, 0.03400086147}},
    {2.5,
     0.0,
     5.0,
     80.0,
     10.0,
     {23.31607265, 17.45249886, 9.024636352},
     {17.6597682, 18.17966048, 11.5071795},
     {0.003434910139, 0.1668770251, 0.1631817703}},
    {7.3,
     0.65,
     70.0,
     60.0,
     75.0,
     {9.068197313, 13.15213441, 20.61991978},
     {12.03719095, 12.80263933, 21.4146261},
     {0.06777780816, 0.1210673376, 0.05358037243}},
    {10.0,
     1.0,
     90.0,
     45.0,
     45.0,
     {16.70186267, 19.85389065, 24.14526477},
     {18.91829774, 19.98039788, 25.50200495},
     {0.08058267861, 0.1859606478, 0.1089854028}},
    {1.0,
     0.3,
     0.0,
     89.0,
     120.0,
     {3.322642032, 1.358447729, 0.2390857199},
     {2.008773898, 1.775651832, 0.5051801617},
     {0.0001076410854, 0.01360419156, 0.02648466287}},
};

std::string Spec(const Case& c, const char* colour) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "hosek-wilkie:turbidity=%.17g:albedo=%.17g:colour=%s",
                  c.turbidity, c.albedo, colour);
    return buf;
}

TEST(HosekWilkie, AuthorsRadianceMatchesAnIndependentEvaluationOfThePaper) {
    for (const Case& c : kCases) {
        const double el = Radians(c.elevation), th = Radians(c.theta), g = Radians(c.gamma);
        for (int ch = 0; ch < 3; ++ch) {
            EXPECT_NEAR(HosekWilkieAuthorsRadiance(HosekWilkieColour::kRgb, ch, 0.0, c.turbidity,
                                                   c.albedo, el, th, g) /
                            c.rgb[ch],
                        1.0, 1e-8)
                << "rgb " << ch << " T " << c.turbidity;
            EXPECT_NEAR(HosekWilkieAuthorsRadiance(HosekWilkieColour::kXyz, ch, 0.0, c.turbidity,
                                                   c.albedo, el, th, g) /
                            c.xyz[ch],
                        1.0, 1e-8)
                << "xyz " << ch << " T " << c.turbidity;
        }
        const double nm[3] = {320.0, 550.0, 700.0};
        for (int i = 0; i < 3; ++i) {
            EXPECT_NEAR(HosekWilkieAuthorsRadiance(HosekWilkieColour::kSpectral, 0, nm[i],
                                                   c.turbidity, c.albedo, el, th, g) /
                            c.spectral[i],
                        1.0, 1e-8)
                << nm[i] << " nm, T " << c.turbidity;
        }
    }
}

TEST(HosekWilkie, ModelSamplesArePaperValuesInAtmosUnits) {
    for (const Case& c : kCases) {
        const SampleQuery q = Query(c.elevation, c.theta, c.gamma);
        // RGB: divided by the sun's Y.
        auto rgb = Make(Spec(c, "rgb"));
        const SampleAnswer a = rgb->Sample({q})[0];
        for (int ch = 0; ch < 3; ++ch) {
            EXPECT_NEAR(At(a.radiance, ch) * kHosekWilkieSunY / c.rgb[ch], 1.0, 2e-6)
                << "rgb " << ch << " T " << c.turbidity;
        }
        EXPECT_EQ(a.transmittance[0], 1.0f);
        // XYZ: through the sRGB matrix; invert it (IEC 61966-2-1).
        auto xyz = Make(Spec(c, "xyz"));
        const Rgb s = xyz->Sample({q})[0].radiance;
        const double X = 0.4124564 * At(s, 0) + 0.3575761 * At(s, 1) + 0.1804375 * At(s, 2);
        const double Y = 0.2126729 * At(s, 0) + 0.7151522 * At(s, 1) + 0.0721750 * At(s, 2);
        const double Z = 0.0193339 * At(s, 0) + 0.1191920 * At(s, 1) + 0.9503041 * At(s, 2);
        const double got[3] = {X, Y, Z};
        for (int ch = 0; ch < 3; ++ch) {
            EXPECT_NEAR(got[ch] * kHosekWilkieSunY / c.xyz[ch], 1.0, 2e-5)
                << "xyz " << ch << " T " << c.turbidity;
        }
        // Spectral at 320, 550, 700 nm: divided by the authors' sun there.
        auto spectral = Make(Spec(c, "spectral"));
        const double nm[3] = {320.0, 550.0, 700.0};
        spectral->SetSpectralBatch(SpectralAtmosphere(), nm);
        spectral->Prepare(EarthAtmosphere());
        const Rgb l = spectral->Sample({q})[0].radiance;
        for (int i = 0; i < 3; ++i) {
            EXPECT_NEAR(At(l, i) * HosekWilkieSolarIrradiance(nm[i]) / c.spectral[i], 1.0, 2e-6)
                << nm[i] << " nm, T " << c.turbidity;
        }
    }
}

TEST(HosekWilkie, DataLayoutReadByHand) {
    // rgb.json "config"[0] opens with -1.099459 (albedo 0, turbidity 1, control
    // point 0, A); its element 727 = ((1 * 10 + 3) * 6 + 2) * 9 + 7 (albedo 1,
    // turbidity 4, control point 2, the data's 8th value, I) is -5.221111.
    // spectral.json "radiance"[5] (520 nm) element 59 (albedo 0, turbidity 10,
    // control point 5) is 0.17086.
    double ctrl[6][10];
    HosekWilkieBlend(HosekWilkieDataset(HosekWilkieColour::kRgb), 0, 1.0, 0.0, ctrl);
    EXPECT_EQ(ctrl[0][0], -1.099459);
    HosekWilkieBlend(HosekWilkieDataset(HosekWilkieColour::kRgb), 0, 4.0, 1.0, ctrl);
    EXPECT_EQ(ctrl[2][7], -5.221111);
    HosekWilkieBlend(HosekWilkieDataset(HosekWilkieColour::kSpectral), 5, 10.0, 0.0, ctrl);
    EXPECT_EQ(ctrl[5][9], 0.17086);
    EXPECT_EQ(HosekWilkieDataset(HosekWilkieColour::kSpectral).channels, 11);
    EXPECT_EQ(HosekWilkieDataset(HosekWilkieColour::kXyz).channels, 3);
}

TEST(HosekWilkie, BlendIsLinearInTurbidityAndAlbedoAndBezierInElevation) {
    const HosekWilkieData& d = HosekWilkieDataset(HosekWilkieColour::kXyz);
    double n[2][2][6][10];  // [albedo][turbidity 4 or 5]
    for (int a = 0; a < 2; ++a) {
        for (int t = 0; t < 2; ++t) HosekWilkieBlend(d, 1, 4.0 + t, a, n[a][t]);
    }
    double mid[6][10];
    HosekWilkieBlend(d, 1, 4.25, 0.6, mid);
    for (int k = 0; k < 6; ++k) {
        for (int p = 0; p < 10; ++p) {
            const double want = 0.4 * 0.75 * n[0][0][k][p] + 0.4 * 0.25 * n[0][1][k][p] +
                                0.6 * 0.75 * n[1][0][k][p] + 0.6 * 0.25 * n[1][1][k][p];
            EXPECT_NEAR(mid[k][p], want, 1e-12 * (1.0 + std::abs(want))) << k << " " << p;
        }
    }
    // Turbidity 10 is the last node; 9.5 halfway between 9 and 10.
    double t9[6][10], t10[6][10], t95[6][10];
    HosekWilkieBlend(d, 0, 9.0, 0.0, t9);
    HosekWilkieBlend(d, 0, 10.0, 0.0, t10);
    HosekWilkieBlend(d, 0, 9.5, 0.0, t95);
    EXPECT_NEAR(t95[3][4], 0.5 * (t9[3][4] + t10[3][4]), 1e-12);
    EXPECT_NE(t9[3][4], t10[3][4]);
    // Elevation: x = (el / 90 deg)^(1/3); the curve's ends are its end points,
    // and at x = 1/2 the Bernstein weights are (1, 5, 10, 10, 5, 1) / 32.
    EXPECT_EQ(HosekWilkieCook(mid, 0.0).v[6], mid[0][6]);
    EXPECT_NEAR(HosekWilkieCook(mid, 0.5 * kPi).v[6], mid[5][6], 1e-12);
    const double el_half = 0.5 * kPi / 8.0;
    const double w[6] = {1, 5, 10, 10, 5, 1};
    for (int p = 0; p < 10; ++p) {
        double want = 0.0;
        for (int k = 0; k < 6; ++k) want += w[k] / 32.0 * mid[k][p];
        EXPECT_NEAR(HosekWilkieCook(mid, el_half).v[p], want, 1e-12 * (1.0 + std::abs(want)));
    }
}

TEST(HosekWilkie, AtmosOverAuthorsIsOneConstantPerChannel) {
    // The documented constant: the Y of the authors' extraterrestrial sun.
    std::vector<double> nm, ybar;
    SpectralDataTable("cie1931-2deg", 1, &nm, &ybar);
    double y = 0.0;
    for (size_t i = 0; i < nm.size(); ++i) {
        if (nm[i] <= 720.0) y += HosekWilkieSolarIrradiance(nm[i]) * ybar[i] * 5.0;
    }
    EXPECT_NEAR(y / kHosekWilkieSunY, 1.0, 1e-9);

    std::mt19937 rng(34);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double wl[3] = {333.0, 587.5, 720.0};
    for (int m = 0; m < 6; ++m) {
        const double T = 1.0 + 9.0 * u(rng), albedo = u(rng);
        char spec[128];
        std::snprintf(spec, sizeof spec, "hosek-wilkie:turbidity=%.17g:albedo=%.17g", T, albedo);
        auto rgb = Make(spec);
        auto spectral = Make(spec);
        spectral->SetSpectralBatch(SpectralAtmosphere(), wl);
        spectral->Prepare(EarthAtmosphere());
        std::vector<SampleQuery> qs;
        for (int i = 0; i < 40; ++i) {
            SampleQuery q;
            q.mu = u(rng);
            q.mu_s = u(rng);
            q.azimuth_deg = 360.0 * u(rng);
            qs.push_back(q);
        }
        const auto a = rgb->Sample(qs), s = spectral->Sample(qs);
        for (size_t i = 0; i < qs.size(); ++i) {
            const double el = std::asin(qs[i].mu_s), th = std::acos(qs[i].mu);
            const double sv = std::sin(th), ss = std::cos(el);
            const double g = std::acos(
                std::max(-1.0, std::min(1.0, sv * ss * std::cos(Radians(qs[i].azimuth_deg)) +
                                                 qs[i].mu * qs[i].mu_s)));
            for (int ch = 0; ch < 3; ++ch) {
                const double authors = HosekWilkieAuthorsRadiance(HosekWilkieColour::kRgb, ch, 0.0,
                                                                  T, albedo, el, th, g);
                if (authors > 1e-3) {
                    EXPECT_NEAR(At(a[i].radiance, ch) / authors * kHosekWilkieSunY, 1.0, 2e-6)
                        << "rgb " << ch;
                }
                const double sa = HosekWilkieAuthorsRadiance(HosekWilkieColour::kSpectral, 0,
                                                             wl[ch], T, albedo, el, th, g);
                if (sa > 1e-6) {
                    EXPECT_NEAR(At(s[i].radiance, ch) / sa * HosekWilkieSolarIrradiance(wl[ch]),
                                1.0, 2e-6)
                        << wl[ch] << " nm";
                }
            }
        }
    }
}

TEST(HosekWilkie, SpectralAtTheRgbWavelengthsIsColourSpectral) {
    auto a = Make("hosek-wilkie:turbidity=4:colour=spectral");
    auto b = Make("hosek-wilkie:turbidity=4");
    b->SetSpectralBatch(SpectralAtmosphere(), kRgbWavelengths);
    b->Prepare(EarthAtmosphere());
    const std::vector<SampleQuery> qs = {Query(20.0, 50.0, 30.0), Query(60.0, 10.0, 70.0)};
    const auto x = a->Sample(qs), y = b->Sample(qs);
    for (size_t i = 0; i < qs.size(); ++i) {
        for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(x[i].radiance[ch], y[i].radiance[ch]);
    }
}

TEST(HosekWilkie, OutsideValidity) {
    auto m = Make("hosek-wilkie");
    // The sun below the horizon is the sun on it (same azimuth).
    SampleQuery below = Query(0.0, 70.0, 50.0), on = below;
    below.mu_s = -0.3;
    const auto r = m->Sample({below, on});
    for (int ch = 0; ch < 3; ++ch) {
        EXPECT_EQ(r[0].radiance[ch], r[1].radiance[ch]);
        EXPECT_GT(r[0].radiance[ch], 0.0f);
    }
    // The lower hemisphere is black, transmittance 0.
    SampleQuery down = Query(30.0, 100.0, 80.0);
    const SampleAnswer d = m->Sample({down})[0];
    for (int ch = 0; ch < 3; ++ch) {
        EXPECT_EQ(d.radiance[ch], 0.0f);
        EXPECT_EQ(d.transmittance[ch], 0.0f);
    }
    // Default albedo: the atmosphere's (earth: 0); an explicit one changes it.
    EXPECT_NE(Make("hosek-wilkie:albedo=0.5")->Sample({on})[0].radiance[1], r[1].radiance[1]);
    EXPECT_EQ(Make("hosek-wilkie:albedo=0")->Sample({on})[0].radiance[1], r[1].radiance[1]);
    // Bad options and wavelengths: one clear error.
    EXPECT_THROW(ParseModelSpec("hosek-wilkie:turbidity=11"), Error);
    EXPECT_THROW(ParseModelSpec("hosek-wilkie:albedo=1.5"), Error);
    EXPECT_THROW(ParseModelSpec("hosek-wilkie:albedo=grass"), Error);
    const double outside[3] = {319.0, 550.0, 600.0};
    EXPECT_THROW(m->SetSpectralBatch(SpectralAtmosphere(), outside), Error);
    EXPECT_THROW(HosekWilkieSolarIrradiance(720.5), Error);
}

// The bake (issue 34 item 6: the model as a shader): the constants it writes
// reload into the same answers, and a bake for other options or another
// atmosphere is refused.
TEST(HosekWilkie, BakeReloadsTheSameAnswersAndRefusesOtherOptions) {
    const char* env = std::getenv("ATMOS_TEST_TMP");
    const std::filesystem::path dir =
        std::filesystem::path(env ? env : "/tmp") / "hosek_wilkie_bake";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    std::unique_ptr<Model> baked = Make("hosek-wilkie:turbidity=4.5:albedo=0.3");
    ASSERT_TRUE(baked->CanBake());
    baked->Bake(dir.string());
    ASSERT_TRUE(std::filesystem::exists(dir / "shaders" / "hosek_wilkie_constants.glsl"));
    const std::vector<SampleQuery> queries = {Query(30.0, 50.0, 40.0), Query(5.0, 80.0, 10.0)};
    std::unique_ptr<Model> loaded = Make("hosek-wilkie:turbidity=4.5:albedo=0.3");
    loaded->LoadBaked(dir.string(), EarthAtmosphere());
    const std::vector<SampleAnswer> a = baked->Sample(queries), b = loaded->Sample(queries);
    for (size_t q = 0; q < queries.size(); ++q) {
        for (int c = 0; c < 3; ++c) EXPECT_EQ(At(a[q].radiance, c), At(b[q].radiance, c));
    }
    EXPECT_THROW(
        Make("hosek-wilkie:turbidity=5:albedo=0.3")->LoadBaked(dir.string(), EarthAtmosphere()),
        Error);
    AtmosphereParameters other = EarthAtmosphere();
    other.bottom_radius *= 1.01;
    other.top_radius *= 1.01;
    EXPECT_THROW(loaded->LoadBaked(dir.string(), other), Error);
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace atmos
