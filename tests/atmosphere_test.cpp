// Tests of the atmosphere parameters: the canonical Earth, the presets in
// data/atmospheres, the JSON format, --set overrides and validation.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "test_util.h"

namespace atmos {
namespace {

// A local copy of Bruneton's 2017 implementation notes' GetLayerDensity / GetProfileDensity
// (Bruneton 2017), so the profiles are checked against the formula and not against our own code.
double LayerDensity(const DensityProfileLayer& layer, double altitude) {
    const double density = layer.exp_term * std::exp(layer.exp_scale * altitude) +
                           layer.linear_term * altitude + layer.constant_term;
    return std::min(std::max(density, 0.0), 1.0);
}
double ProfileDensity(const DensityProfile& profile, double altitude) {
    return altitude < profile.layers[0].width ? LayerDensity(profile.layers[0], altitude)
                                              : LayerDensity(profile.layers[1], altitude);
}

// Every scalar of an atmosphere with its field name, in struct order.
std::vector<std::pair<std::string, double>> Flatten(const AtmosphereParameters& a) {
    std::vector<std::pair<std::string, double>> out;
    const auto rgb = [&](const std::string& name, const Vec3d& v) {
        for (int c = 0; c < 3; ++c) out.emplace_back(name + "[" + std::to_string(c) + "]", v[c]);
    };
    const auto profile = [&](const std::string& name, const DensityProfile& p) {
        for (int i = 0; i < 2; ++i) {
            const std::string prefix = name + ".layers[" + std::to_string(i) + "].";
            out.emplace_back(prefix + "width", p.layers[i].width);
            out.emplace_back(prefix + "exp_term", p.layers[i].exp_term);
            out.emplace_back(prefix + "exp_scale", p.layers[i].exp_scale);
            out.emplace_back(prefix + "linear_term", p.layers[i].linear_term);
            out.emplace_back(prefix + "constant_term", p.layers[i].constant_term);
        }
    };
    out.emplace_back("bottom_radius", a.bottom_radius);
    out.emplace_back("top_radius", a.top_radius);
    rgb("rayleigh_scattering", a.rayleigh_scattering);
    profile("rayleigh_density", a.rayleigh_density);
    rgb("mie_scattering", a.mie_scattering);
    rgb("mie_extinction", a.mie_extinction);
    profile("mie_density", a.mie_density);
    out.emplace_back("mie_phase_g", a.mie_phase_g);
    out.emplace_back("mie_phase_g2", a.mie_phase_g2);
    out.emplace_back("mie_phase_weight2", a.mie_phase_weight2);
    rgb("absorption_extinction", a.absorption_extinction);
    profile("absorption_density", a.absorption_density);
    rgb("ground_albedo", a.ground_albedo);
    out.emplace_back("sun_angular_radius", a.sun_angular_radius);
    rgb("solar_irradiance", a.solar_irradiance);
    out.emplace_back("mu_s_min", a.mu_s_min);
    return out;
}

// The names of the scalars that differ (bitwise ==) between a and b.
std::vector<std::string> ChangedFields(const AtmosphereParameters& a,
                                       const AtmosphereParameters& b) {
    const auto fa = Flatten(a);
    const auto fb = Flatten(b);
    std::vector<std::string> changed;
    for (size_t i = 0; i < fa.size(); ++i) {
        if (!(fa[i].second == fb[i].second)) changed.push_back(fa[i].first);
    }
    return changed;
}

std::filesystem::path TempDir() {
    const char* env = std::getenv("ATMOS_TEST_TMP");
#ifdef ATMOS_TEST_TMP
    std::filesystem::path dir = env != nullptr ? env : ATMOS_TEST_TMP;
#else
    std::filesystem::path dir =
        env != nullptr ? std::filesystem::path(env) : std::filesystem::temp_directory_path();
#endif
    dir /= "atmosphere_test_files";
    std::filesystem::create_directories(dir);
    return dir;
}

std::string WriteTempFile(const std::string& name, const std::string& text) {
    const std::filesystem::path path = TempDir() / name;
    std::ofstream out(path, std::ios::binary);
    out << text;
    return path.string();
}

TEST(Atmosphere, PresetNamesListTheShippedFiles) {
    const std::vector<std::string> names = AtmospherePresetNames();
    for (const char* expected :
         {"earth", "earth-bruneton", "earth-atmosphere-plus", "mars", "titan", "venus"}) {
        EXPECT_NE(std::find(names.begin(), names.end(), expected), names.end()) << expected;
    }
}

TEST(Atmosphere, EveryPresetLoadsAndValidates) {
    for (const std::string& name : AtmospherePresetNames()) {
        SCOPED_TRACE(name);
        AtmosphereParameters a;
        ASSERT_NO_THROW(a = LoadAtmosphere(name));
        EXPECT_NO_THROW(ValidateAtmosphere(a));
        EXPECT_GT(a.top_radius, a.bottom_radius);
    }
}

TEST(Atmosphere, EarthAtmosphereIsValid) { EXPECT_NO_THROW(ValidateAtmosphere(EarthAtmosphere())); }

TEST(Atmosphere, EarthPresetEqualsEarthAtmosphere) {
    const auto from_file = Flatten(LoadAtmosphere("earth"));
    const auto from_code = Flatten(EarthAtmosphere());
    ASSERT_EQ(from_file.size(), from_code.size());
    for (size_t i = 0; i < from_file.size(); ++i) {
        EXPECT_NEAR(from_file[i].second, from_code[i].second, 1e-12 * std::abs(from_code[i].second))
            << from_code[i].first;
    }
}

TEST(Atmosphere, EarthAtmosphereHasTheCanonicalValues) {
    const AtmosphereParameters a = EarthAtmosphere();
    EXPECT_EQ(a.bottom_radius, 6360e3);
    EXPECT_EQ(a.top_radius, 6460e3);
    EXPECT_EQ(a.rayleigh_scattering[2], 33.1e-6);
    EXPECT_NEAR(ProfileDensity(a.rayleigh_density, 8000.0), std::exp(-1.0), 1e-15);
    EXPECT_NEAR(ProfileDensity(a.mie_density, 1200.0), std::exp(-1.0), 1e-15);
    EXPECT_EQ(ProfileDensity(a.mie_density, 0.0), 1.0);
    EXPECT_EQ(a.mie_scattering[1], 3.996e-6);
    EXPECT_EQ(a.mie_extinction[1], 4.44e-6);
    EXPECT_EQ(a.mie_phase_g, 0.8);
    EXPECT_EQ(a.absorption_extinction[1], 1.881e-6);
    EXPECT_EQ(a.ground_albedo[0], 0.0);
    EXPECT_EQ(a.sun_angular_radius, 0.004675);
    EXPECT_EQ(a.solar_irradiance[2], 1.0);
    EXPECT_NEAR(a.mu_s_min, -0.2079116908, 1e-10);
}

TEST(Atmosphere, OzoneTentProfileFollowsSeed004Formula) {
    const DensityProfile& ozone = EarthAtmosphere().absorption_density;
    EXPECT_NEAR(ProfileDensity(ozone, 0.0), 0.0, 1e-12);
    EXPECT_NEAR(ProfileDensity(ozone, 5000.0), 0.0, 1e-12);
    EXPECT_NEAR(ProfileDensity(ozone, 10000.0), 0.0, 1e-12);
    EXPECT_NEAR(ProfileDensity(ozone, 17500.0), 0.5, 1e-12);
    EXPECT_NEAR(ProfileDensity(ozone, 25000.0), 1.0, 1e-12);
    EXPECT_NEAR(ProfileDensity(ozone, 32500.0), 0.5, 1e-12);
    EXPECT_NEAR(ProfileDensity(ozone, 40000.0), 0.0, 1e-12);
    EXPECT_NEAR(ProfileDensity(ozone, 45000.0), 0.0, 1e-12);
    EXPECT_NEAR(ProfileDensity(ozone, 100000.0), 0.0, 1e-12);
}

TEST(Atmosphere, TentShorthandEqualsTheLayersOfSeed004Demo) {
    // earth.json writes the ozone as {"tent": ...}, earth-bruneton.json as the
    // demo's two layers: both must give the same profile bit for bit.
    const AtmosphereParameters earth = LoadAtmosphere("earth");
    const AtmosphereParameters bruneton = LoadAtmosphere("earth-bruneton");
    const AtmosphereParameters code = EarthAtmosphere();
    for (int i = 0; i < 2; ++i) {
        for (const AtmosphereParameters* a : {&earth, &bruneton}) {
            const DensityProfileLayer& l = a->absorption_density.layers[i];
            const DensityProfileLayer& r = code.absorption_density.layers[i];
            EXPECT_EQ(l.width, r.width);
            EXPECT_EQ(l.exp_term, r.exp_term);
            EXPECT_EQ(l.exp_scale, r.exp_scale);
            EXPECT_EQ(l.linear_term, r.linear_term);
            EXPECT_EQ(l.constant_term, r.constant_term);
        }
    }
}

TEST(Atmosphere, PresetsHaveTheirDocumentedValues) {
    const AtmosphereParameters bruneton = LoadAtmosphere("earth-bruneton");
    EXPECT_EQ(bruneton.top_radius, 6420e3);
    EXPECT_EQ(bruneton.ground_albedo[1], 0.1);

    const AtmosphereParameters plus = LoadAtmosphere("earth-atmosphere-plus");
    EXPECT_EQ(plus.mie_extinction[0], 8.396e-6);
    EXPECT_EQ(plus.absorption_extinction[2], 0.0);
    EXPECT_EQ(plus.solar_irradiance[0], 20.344770);
    EXPECT_EQ(plus.solar_irradiance[1], 16.907042);
    EXPECT_EQ(plus.solar_irradiance[2], 23.453083);

    const AtmosphereParameters mars = LoadAtmosphere("mars");
    EXPECT_EQ(mars.bottom_radius, 3389.5e3);
    EXPECT_EQ(mars.top_radius, 3489.5e3);
    EXPECT_EQ(mars.mie_phase_g, 0.65);
    // Vertical dust optical depth about 0.5.
    EXPECT_NEAR(mars.mie_extinction[0] * 11100.0, 0.5, 0.01);
    EXPECT_LT(mars.mie_scattering[2], mars.mie_scattering[0]);
}

// The vertical optical depth of one constituent from altitude h0 to the top
// (midpoint rule on 1 m steps: the profiles vary on kilometres).
double VerticalDepth(const AtmosphereParameters& a, const DensityProfile& p, double coefficient,
                     double h0 = 0.0) {
    const double top = a.top_radius - a.bottom_radius;
    double sum = 0.0;
    for (double h = h0 + 0.5; h < top; h += 1.0) sum += ProfileDensity(p, h);
    return sum * coefficient;
}

// Issue 32 item 5: the Titan-like and Venus-like presets. Their Rayleigh
// columns are checked against hydrostatics (column number p_s / (m g), from
// the surface pressures, molar masses and gravities of the sources cited in
// the files) times the cited cross-sections, not against the profiles'
// own arithmetic; their profiles are continuous at the layer boundary.
TEST(Atmosphere, ThickPresetsHaveTheirDocumentedOpticalDepths) {
    constexpr double kAmu = 1.66053907e-27;
    const auto sigma = [](double sigma532, double nm) {
        return sigma532 * std::pow(532.0 / nm, 4);
    };
    const double nm[3] = {680.0, 550.0, 440.0};
    const auto continuous = [](const DensityProfile& p) {
        const double w = p.layers[0].width;
        EXPECT_NEAR(LayerDensity(p.layers[0], w), LayerDensity(p.layers[1], w), 1e-9) << w;
    };

    const AtmosphereParameters titan = LoadAtmosphere("titan");
    EXPECT_EQ(titan.bottom_radius, 2574.73e3);
    EXPECT_EQ(titan.top_radius - titan.bottom_radius, 600e3);
    continuous(titan.rayleigh_density);
    continuous(titan.mie_density);
    // Huygens HASI: 1467 hPa, gravity 1.352 m/s^2; N2 (28.0134 u), 5.1e-31 m^2 at 532 nm.
    const double titan_column = 1.467e5 / (28.0134 * kAmu * 1.352);
    const double haze[3] = {3.18, 4.28, 5.85};  // 4.5 (nm / 531)^-1.4
    const double haze_albedo[3] = {0.95, 0.90, 0.80};
    for (int c = 0; c < 3; ++c) {
        SCOPED_TRACE(c);
        EXPECT_NEAR(VerticalDepth(titan, titan.rayleigh_density, titan.rayleigh_scattering[c]),
                    titan_column * sigma(5.1e-31, nm[c]),
                    0.005 * titan_column * sigma(5.1e-31, nm[c]));
        EXPECT_NEAR(VerticalDepth(titan, titan.mie_density, titan.mie_extinction[c]), haze[c],
                    0.01);
        EXPECT_NEAR(titan.mie_scattering[c] / titan.mie_extinction[c], haze_albedo[c], 1e-4);
    }
    EXPECT_EQ(MaxComponent(titan.absorption_extinction), 0.0);

    const AtmosphereParameters venus = LoadAtmosphere("venus");
    EXPECT_EQ(venus.bottom_radius, 6051.8e3);
    EXPECT_EQ(venus.top_radius - venus.bottom_radius, 100e3);
    continuous(venus.rayleigh_density);
    continuous(venus.mie_density);
    // VIRA: 92.1 bar, 43.44 u, gravity 8.87 m/s^2; CO2 1.24e-30 m^2 at 532 nm.
    // The two exponentials keep the column within 4 %.
    const double venus_column = 9.21e6 / (43.44 * kAmu * 8.87);
    for (int c = 0; c < 3; ++c) {
        SCOPED_TRACE(c);
        const double want = venus_column * sigma(1.24e-30, nm[c]);
        const double got =
            VerticalDepth(venus, venus.rayleigh_density, venus.rayleigh_scattering[c]);
        EXPECT_LT(got, want);
        EXPECT_GT(got, 0.96 * want);
        // Clouds: 30 in all, 1 above 70 km (the cloud top), none below 47.5 km.
        EXPECT_NEAR(VerticalDepth(venus, venus.mie_density, venus.mie_extinction[c]), 30.0, 0.01);
        EXPECT_NEAR(VerticalDepth(venus, venus.mie_density, venus.mie_extinction[c], 70e3), 1.0,
                    0.15);
    }
    EXPECT_EQ(ProfileDensity(venus.mie_density, 47.4e3), 0.0);
    EXPECT_EQ(ProfileDensity(venus.mie_density, 50e3), 1.0);
    // VIRA's densities relative to the surface at 60 and 70 km: 0.00724, 0.00129.
    EXPECT_NEAR(ProfileDensity(venus.rayleigh_density, 60e3), 0.00724, 0.2 * 0.00724);
    EXPECT_NEAR(ProfileDensity(venus.rayleigh_density, 70e3), 0.00129, 0.2 * 0.00129);
}

TEST(Atmosphere, JsonRoundTripIsExact) {
    std::vector<AtmosphereParameters> cases = {EarthAtmosphere()};
    for (const std::string& name : AtmospherePresetNames()) cases.push_back(LoadAtmosphere(name));
    AtmosphereParameters odd = EarthAtmosphere();
    odd.rayleigh_scattering = Vec3d(0.1 + 0.2, 1.0 / 3.0e6, std::nextafter(1e-5, 1.0));
    odd.mie_density.layers[0].width = 1234.5678901234567;
    odd.mie_density.layers[0].exp_scale = -std::sqrt(2.0) * 1e-4;
    odd.mie_phase_g = -0.0;
    odd.mu_s_min = std::nextafter(-1.0, 0.0);
    odd.solar_irradiance =
        Vec3d(std::numeric_limits<double>::denorm_min(), 1e9, 0.0);  // (at most 1e9 since issue 18)
    cases.push_back(odd);
    for (const AtmosphereParameters& a : cases) {
        const std::string text = AtmosphereToJson(a);
        const AtmosphereParameters b = AtmosphereFromJson(text, "round trip");
        EXPECT_TRUE(ChangedFields(a, b).empty()) << text;
        EXPECT_EQ(AtmosphereToJson(b), text);
    }
}

TEST(Atmosphere, SecondMieLobeRoundTripsAndIsValidated) {
    // Written only with a weight (or a g2): one-lobe atmospheres keep their
    // text (and the fingerprints made from it).
    const std::string earth_text = AtmosphereToJson(EarthAtmosphere());
    EXPECT_EQ(earth_text.find("mie_phase_g2"), std::string::npos) << earth_text;
    EXPECT_EQ(earth_text.find("mie_phase_weight2"), std::string::npos) << earth_text;
    for (const std::string& name : AtmospherePresetNames()) {
        if (name == "kider-2013-aeronet") continue;
        EXPECT_EQ(AtmosphereToJson(LoadAtmosphere(name)).find("mie_phase_weight2"),
                  std::string::npos)
            << name;
    }
    AtmosphereParameters a = EarthAtmosphere();
    a.mie_phase_g = 0.55;
    a.mie_phase_g2 = 0.94;
    a.mie_phase_weight2 = 0.1;
    const std::string text = AtmosphereToJson(a);
    EXPECT_NE(text.find("\"mie_phase_g2\": 0.94"), std::string::npos) << text;
    EXPECT_NE(text.find("\"mie_phase_weight2\": 0.1"), std::string::npos) << text;
    const AtmosphereParameters b = AtmosphereFromJson(text, "two lobes");
    EXPECT_TRUE(ChangedFields(a, b).empty()) << text;
    EXPECT_EQ(AtmosphereToJson(b), text);

    // --set reaches the two fields (absent from the file).
    const AtmosphereParameters c =
        LoadAtmosphere("earth", {"mie_phase_g2=0.9", "mie_phase_weight2=0.25"});
    EXPECT_EQ(ChangedFields(EarthAtmosphere(), c),
              (std::vector<std::string>{"mie_phase_g2", "mie_phase_weight2"}));
    EXPECT_EQ(c.mie_phase_g2, 0.9);
    EXPECT_EQ(c.mie_phase_weight2, 0.25);

    // The preset: kider-2013 with the AERONET-informed aerosol.
    const AtmosphereParameters k = LoadAtmosphere("kider-2013-aeronet");
    EXPECT_EQ(k.mie_phase_g, 0.55);
    EXPECT_EQ(k.mie_phase_g2, 0.94);
    EXPECT_EQ(k.mie_phase_weight2, 0.1);

    // Bad values name the field.
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"mie_phase_weight2=1.5"}),
                          "'mie_phase_weight2': 1.5 is outside the allowed range [0, 1]");
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"mie_phase_weight2=-0.1"}),
                          "'mie_phase_weight2'");
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"mie_phase_g2=1"}),
                          "'mie_phase_g2': 1 is outside the allowed range (-1, 1)");
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"mie_phase_g2=-1"}), "'mie_phase_g2'");
    std::string typed = text;
    typed.replace(typed.find("\"mie_phase_weight2\": 0.1"), 24, "\"mie_phase_weight2\": \"a\"");
    EXPECT_ERROR_CONTAINS(AtmosphereFromJson(typed, "typed"),
                          "field 'mie_phase_weight2' must be a number");
}

TEST(Atmosphere, LoadsAFileByPath) {
    AtmosphereParameters a = EarthAtmosphere();
    a.ground_albedo = Vec3d(0.2, 0.3, 0.4);
    const std::string path = WriteTempFile("albedo.json", AtmosphereToJson(a));
    const AtmosphereParameters b = LoadAtmosphere(path);
    EXPECT_TRUE(ChangedFields(a, b).empty());
}

TEST(Atmosphere, OptionalFieldsAndShorthands) {
    // No mu_s_min (defaults to cos 102 deg), a name, RGB as one number, a
    // single layer (goes to layers[1]).
    const std::string text = R"({
        "name": "test", "description": "a test",
        "bottom_radius": 6360000, "top_radius": 6460000,
        "rayleigh_scattering": [5.802e-6, 13.558e-6, 33.1e-6],
        "rayleigh_density": {"layers": [{"exp_term": 1, "exp_scale": -1.25e-4}]},
        "mie_scattering": 3.996e-6, "mie_extinction": 4.44e-6,
        "mie_density": {"scale_height": 1200}, "mie_phase_g": 0.8,
        "absorption_extinction": [0.650e-6, 1.881e-6, 0.085e-6],
        "absorption_density": {"tent": {"center": 25000, "half_width": 15000}},
        "ground_albedo": 0, "sun_angular_radius": 0.004675, "solar_irradiance": 1})";
    const AtmosphereParameters a = AtmosphereFromJson(text, "inline");
    const std::vector<std::string> changed = ChangedFields(EarthAtmosphere(), a);
    EXPECT_TRUE(changed.empty()) << changed.front();
}

TEST(Atmosphere, SetScalarChangesOnlyThatField) {
    const AtmosphereParameters a = LoadAtmosphere("earth", {"ground_albedo=0.3"});
    EXPECT_EQ(
        ChangedFields(EarthAtmosphere(), a),
        (std::vector<std::string>{"ground_albedo[0]", "ground_albedo[1]", "ground_albedo[2]"}));
    EXPECT_EQ(a.ground_albedo[1], 0.3);

    const AtmosphereParameters b = LoadAtmosphere("earth", {"mie_phase_g=0.76"});
    EXPECT_EQ(ChangedFields(EarthAtmosphere(), b), (std::vector<std::string>{"mie_phase_g"}));
    EXPECT_EQ(b.mie_phase_g, 0.76);
}

TEST(Atmosphere, SetRgbSingleAndTriple) {
    const AtmosphereParameters single = LoadAtmosphere("earth", {"mie_scattering=4e-6"});
    EXPECT_EQ(
        ChangedFields(EarthAtmosphere(), single),
        (std::vector<std::string>{"mie_scattering[0]", "mie_scattering[1]", "mie_scattering[2]"}));
    EXPECT_EQ(single.mie_scattering[2], 4e-6);

    const AtmosphereParameters triple =
        LoadAtmosphere("earth", {"rayleigh_scattering=5.8e-6,1.35e-5,3.3e-5"});
    EXPECT_EQ(ChangedFields(EarthAtmosphere(), triple),
              (std::vector<std::string>{"rayleigh_scattering[0]", "rayleigh_scattering[1]",
                                        "rayleigh_scattering[2]"}));
    EXPECT_EQ(triple.rayleigh_scattering[0], 5.8e-6);
    EXPECT_EQ(triple.rayleigh_scattering[1], 1.35e-5);
    EXPECT_EQ(triple.rayleigh_scattering[2], 3.3e-5);

    const AtmosphereParameters json_array =
        LoadAtmosphere("earth", {"ground_albedo=[0.1, 0.2, 0.3]"});
    EXPECT_EQ(json_array.ground_albedo[2], 0.3);

    const AtmosphereParameters one_channel = LoadAtmosphere("earth", {"ground_albedo.1=0.5"});
    EXPECT_EQ(ChangedFields(EarthAtmosphere(), one_channel),
              (std::vector<std::string>{"ground_albedo[1]"}));
}

TEST(Atmosphere, SetDottedLayerPath) {
    // earth.json writes rayleigh_density as {"scale_height": 8000}; the layer
    // path addresses DensityProfile::layers whatever form the file used.
    const AtmosphereParameters a =
        LoadAtmosphere("earth", {"rayleigh_density.layers.1.exp_scale=-1.0e-4"});
    EXPECT_EQ(ChangedFields(EarthAtmosphere(), a),
              (std::vector<std::string>{"rayleigh_density.layers[1].exp_scale"}));
    EXPECT_EQ(a.rayleigh_density.layers[1].exp_scale, -1.0e-4);

    const AtmosphereParameters b =
        LoadAtmosphere("earth", {"absorption_density.layers.0.width=20000"});
    EXPECT_EQ(ChangedFields(EarthAtmosphere(), b),
              (std::vector<std::string>{"absorption_density.layers[0].width"}));
}

TEST(Atmosphere, SetScaleHeightShorthand) {
    const AtmosphereParameters a = LoadAtmosphere("earth", {"mie_density.scale_height=1500"});
    EXPECT_EQ(ChangedFields(EarthAtmosphere(), a),
              (std::vector<std::string>{"mie_density.layers[1].exp_scale"}));
    EXPECT_EQ(a.mie_density.layers[1].exp_scale, -1.0 / 1500.0);
    EXPECT_NEAR(ProfileDensity(a.mie_density, 1500.0), std::exp(-1.0), 1e-15);
}

TEST(Atmosphere, SetTentCentre) {
    const AtmosphereParameters a =
        LoadAtmosphere("earth", {"absorption_density.tent.center=30000"});
    EXPECT_NEAR(ProfileDensity(a.absorption_density, 30000.0), 1.0, 1e-12);
    EXPECT_NEAR(ProfileDensity(a.absorption_density, 22500.0), 0.5, 1e-12);
    EXPECT_NEAR(ProfileDensity(a.absorption_density, 45000.0), 0.0, 1e-12);
}

TEST(Atmosphere, LaterOverridesWin) {
    const AtmosphereParameters a = LoadAtmosphere("earth", {"mie_phase_g=0.5", "mie_phase_g=0.7"});
    EXPECT_EQ(a.mie_phase_g, 0.7);
}

TEST(Atmosphere, ValidateNamesTheField) {
    AtmosphereParameters a = EarthAtmosphere();
    a.mie_phase_g = 1.5;
    EXPECT_EQ(atmos_test::ErrorMessage([&] { ValidateAtmosphere(a); }),
              "invalid atmosphere field 'mie_phase_g': 1.5 is outside the allowed range (-1, 1)");

    a = EarthAtmosphere();
    a.rayleigh_scattering[2] = -1e-6;
    EXPECT_ERROR_CONTAINS(ValidateAtmosphere(a), "'rayleigh_scattering[2]'");

    a = EarthAtmosphere();
    a.mie_density.layers[1].exp_scale = std::numeric_limits<double>::infinity();
    EXPECT_ERROR_CONTAINS(ValidateAtmosphere(a), "'mie_density.layers[1].exp_scale'");

    a = EarthAtmosphere();
    a.absorption_density.layers[0].width = -1.0;
    EXPECT_ERROR_CONTAINS(ValidateAtmosphere(a), "'absorption_density.layers[0].width'");

    a = EarthAtmosphere();
    a.bottom_radius = 10.0;
    EXPECT_ERROR_CONTAINS(ValidateAtmosphere(a), "'bottom_radius'");

    a = EarthAtmosphere();
    a.top_radius = 3.0 * a.bottom_radius;
    EXPECT_ERROR_CONTAINS(ValidateAtmosphere(a), "'top_radius'");

    a = EarthAtmosphere();
    a.ground_albedo[0] = 1.1;
    EXPECT_ERROR_CONTAINS(ValidateAtmosphere(a), "'ground_albedo[0]'");

    a = EarthAtmosphere();
    a.sun_angular_radius = 0.0;
    EXPECT_ERROR_CONTAINS(ValidateAtmosphere(a), "'sun_angular_radius'");

    a = EarthAtmosphere();
    a.solar_irradiance[1] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_ERROR_CONTAINS(ValidateAtmosphere(a), "'solar_irradiance[1]'");

    a = EarthAtmosphere();
    a.mu_s_min = -1.5;
    EXPECT_ERROR_CONTAINS(ValidateAtmosphere(a), "'mu_s_min'");

    a = EarthAtmosphere();
    a.absorption_extinction[0] = 2.0;
    EXPECT_ERROR_CONTAINS(ValidateAtmosphere(a), "'absorption_extinction[0]'");
}

TEST(Atmosphere, RejectsNaNFromSet) {
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"mie_phase_g=NaN"}), "mie_phase_g");
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"ground_albedo=0.1,nan,0.2"}), "ground_albedo");
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"top_radius=inf"}), "top_radius");
    // Too large for a double.
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"bottom_radius=1e400"}), "bottom_radius");
}

TEST(Atmosphere, RejectsGEqualToOne) {
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"mie_phase_g=1"}), "'mie_phase_g'");
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"mie_phase_g=-1"}), "'mie_phase_g'");
}

TEST(Atmosphere, RejectsTopNotAboveBottom) {
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"top_radius=6360000"}), "'top_radius'");
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"top_radius=6000000"}), "'top_radius'");
}

TEST(Atmosphere, RejectsNegativeScattering) {
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"rayleigh_scattering=5e-6,-1e-6,3e-5"}),
                          "'rayleigh_scattering[1]'");
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"mie_scattering=-1e-6"}), "mie_scattering");
}

TEST(Atmosphere, RejectsExtinctionBelowScattering) {
    const std::string message =
        atmos_test::ErrorMessage([] { LoadAtmosphere("earth", {"mie_extinction=3e-6"}); });
    EXPECT_NE(message.find("'mie_extinction[0]'"), std::string::npos) << message;
    EXPECT_NE(message.find("mie_scattering"), std::string::npos) << message;
}

TEST(Atmosphere, RejectsUnknownKeyInFile) {
    AtmosphereParameters a = EarthAtmosphere();
    std::string text = AtmosphereToJson(a);
    text.replace(text.find("\"mie_phase_g\""), 13, "\"mie_phase_function_g\"");
    EXPECT_ERROR_CONTAINS(AtmosphereFromJson(text, "typo.json"), "'mie_phase_function_g'");
    EXPECT_ERROR_CONTAINS(AtmosphereFromJson(text, "typo.json"), "typo.json");

    std::string layer_typo = AtmosphereToJson(a);
    layer_typo.replace(layer_typo.find("\"exp_scale\""), 11, "\"exp_scal\"");
    EXPECT_ERROR_CONTAINS(AtmosphereFromJson(layer_typo, "t"),
                          "rayleigh_density.layers[0].exp_scal");
}

TEST(Atmosphere, RejectsMissingOrMistypedField) {
    std::string text = AtmosphereToJson(EarthAtmosphere());
    std::string missing = text;
    missing.replace(missing.find("\"top_radius\""), 12, "\"name\": \"x\", \"unused\"");
    // The unknown key is reported first; a plain removal reports the missing field.
    EXPECT_ERROR_CONTAINS(AtmosphereFromJson(missing, "m.json"), "'unused'");
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"top_radius=\"high\""}),
                          "field 'top_radius' must be a number");
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"ground_albedo=[0.1, 0.2]"}), "'ground_albedo'");
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"mie_density={}"}), "'mie_density'");
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"mie_density.scale_height=-3"}),
                          "mie_density.scale_height");
    const std::string no_top = R"({"bottom_radius": 6360000})";
    EXPECT_ERROR_CONTAINS(AtmosphereFromJson(no_top, "short.json"), "'top_radius' is missing");
}

TEST(Atmosphere, RejectsUnknownSetField) {
    const std::string message =
        atmos_test::ErrorMessage([] { LoadAtmosphere("earth", {"xyz=1"}); });
    EXPECT_NE(message.find("unknown atmosphere field 'xyz' in --set xyz=1 (fields: "),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("mie_phase_g"), std::string::npos) << message;
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"mie_density.foo=1"}), "'mie_density.foo'");
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"mie_density.layers.2.width=1"}),
                          "'mie_density.layers.2.width'");
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"mie_phase_g.x=1"}), "'mie_phase_g.x'");
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"ground_albedo.3=1"}), "'ground_albedo.3'");
}

TEST(Atmosphere, RejectsSetWithoutEquals) {
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"ground_albedo"}), "ground_albedo");
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"ground_albedo"}), "FIELD=VALUE");
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"ground_albedo="}), "ground_albedo");
    EXPECT_ERROR_CONTAINS(LoadAtmosphere("earth", {"ground_albedo=abc"}), "ground_albedo");
}

TEST(Atmosphere, RejectsMalformedJson) {
    EXPECT_ERROR_CONTAINS(AtmosphereFromJson("{\"bottom_radius\": 6360000,", "broken.json"),
                          "broken.json");
    EXPECT_ERROR_CONTAINS(AtmosphereFromJson("{\"bottom_radius\": 6360000,", "broken.json"),
                          "syntax error");
    EXPECT_ERROR_CONTAINS(AtmosphereFromJson("[1, 2]", "array.json"), "array.json");
    const std::string path = WriteTempFile("broken.json", "{ \"bottom_radius\": }");
    EXPECT_ERROR_CONTAINS(LoadAtmosphere(path), path);
}

TEST(Atmosphere, RejectsNonexistentFile) {
    const std::string path = (TempDir() / "no_such_atmosphere.json").string();
    const std::string message = atmos_test::ErrorMessage([&] { LoadAtmosphere(path); });
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find("earth-bruneton"), std::string::npos) << message;  // lists presets
    EXPECT_ERROR_CONTAINS(LoadAtmosphere(TempDir().string()), TempDir().string());
}

}  // namespace
}  // namespace atmos
