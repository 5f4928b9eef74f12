// compare's custom views (issue 31 item 5), --luminance, sky and ground apart
// and the verdict per regime (issue 33 items 2-3), in-process on tiny images.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "atmos/spectral.h"
#include "compare_test_util.h"
#include "harness/compare_regions.h"
#include "harness/regimes.h"
#include "harness/report.h"
#include "studies/compare.h"
#include "studies/compare_views.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace atmos {
namespace {

fs::path Dir(const std::string& name) { return atmos_test::FreshTestTmpDir("verdict_" + name); }

using atmos_test::Slurp;

std::string ErrorOf(const std::string& json) {
    return atmos_test::ErrorOrEmpty([&] { ParseCompareViews(json, "v.json", 8, 4); });
}

// --- views files ------------------------------------------------------------

TEST(CompareViews, ParsesStringsAndObjectsLikeTheFlags) {
    const std::vector<CompareViewEntry> v = ParseCompareViews(
        R"({"b-plane": {"camera": "altitude=5000,azimuth=90,elevation=5,fov=40",
                        "sun": "elevation=3,azimuth=80", "exposure": 4},
            "a-sky": {"camera": {"projection": "equirect"}, "sun": {"elevation": 30},
                      "description": "whole sky"}})",
        "v.json", 8, 4);
    ASSERT_EQ(v.size(), 2u);
    EXPECT_EQ(v[0].name, "b-plane");  // the file's order
    EXPECT_EQ(v[1].name, "a-sky");
    const CameraSpec flag = ParseCameraSpec("altitude=5000,azimuth=90,elevation=5,fov=40");
    EXPECT_EQ(v[0].camera.altitude_m, flag.altitude_m);
    EXPECT_EQ(v[0].camera.azimuth_deg, flag.azimuth_deg);
    EXPECT_EQ(v[0].camera.fov_deg, flag.fov_deg);
    const Vec3d sun = ParseSunSpec("elevation=3,azimuth=80");
    EXPECT_EQ(v[0].sun_direction.x, sun.x);
    EXPECT_EQ(v[0].sun_direction.z, sun.z);
    EXPECT_EQ(v[0].exposure, 4.0f);
    EXPECT_EQ(v[1].camera.projection, Projection::kEquirect);
    EXPECT_EQ(v[1].sun_direction.z, ParseSunSpec("elevation=30").z);
    // The view is render --camera/--sun's, named.
    const AtmosphereParameters earth = EarthAtmosphere();
    const View made = MakeCompareView(v[0], earth);
    const View custom = CustomView(flag, sun, earth);
    EXPECT_EQ(made.name, "b-plane");
    EXPECT_EQ(made.camera.position.z, custom.camera.position.z);
    EXPECT_EQ(made.camera.forward.x, custom.camera.forward.x);
    EXPECT_EQ(made.sun_irradiance, custom.sun_irradiance);
    EXPECT_EQ(MakeCompareView(v[1], earth).description, "whole sky");
}

TEST(CompareViews, ErrorsNameTheFileTheEntryAndTheField) {
    const std::string fov = ErrorOf(R"({"x": {"camera": "fov=200", "sun": "elevation=5"}})");
    EXPECT_NE(fov.find("v.json: view 'x', camera: fov must be in (0, 180)"), std::string::npos)
        << fov;
    const std::string key = ErrorOf(R"({"x": {"camera": "zoom=2", "sun": "elevation=5"}})");
    EXPECT_NE(key.find("v.json: view 'x', camera: unknown key 'zoom'"), std::string::npos) << key;
    const std::string sun = ErrorOf(R"({"x": {"camera": "fov=50", "sun": "elevation=95"}})");
    EXPECT_NE(sun.find("v.json: view 'x', sun: elevation must be in [-90, 90]"), std::string::npos)
        << sun;
    const std::string missing = ErrorOf(R"({"x": {"camera": "fov=50"}})");
    EXPECT_NE(missing.find("v.json: view 'x': sun is missing"), std::string::npos) << missing;
    const std::string field =
        ErrorOf(R"({"x": {"camera": "fov=50", "sun": "elevation=5", "zoom": 1}})");
    EXPECT_NE(field.find("v.json: view 'x': unknown field 'zoom'"), std::string::npos) << field;
    const std::string exposure =
        ErrorOf(R"({"x": {"camera": "fov=50", "sun": "elevation=5", "exposure": -1}})");
    EXPECT_NE(exposure.find("v.json: view 'x', exposure must be a number > 0"), std::string::npos)
        << exposure;
    // The image size must suit the projection (8x4 is 2:1: equirect fits, cubemap does not).
    const std::string aspect =
        ErrorOf(R"({"x": {"camera": "projection=cubemap", "sun": "elevation=5"}})");
    EXPECT_NE(aspect.find("v.json: view 'x', camera: projection=cubemap needs a 6:1"),
              std::string::npos)
        << aspect;
    EXPECT_NE(ErrorOf(R"({"space": {"camera": "fov=50", "sun": "elevation=5"}})")
                  .find("v.json: view 'space': the name of one of the 12"),
              std::string::npos);
    EXPECT_NE(ErrorOf(R"({"a b": {"camera": "fov=50", "sun": "elevation=5"}})").find("'a b'"),
              std::string::npos);
    EXPECT_NE(ErrorOf("[1, 2]").find("v.json: expected a JSON object"), std::string::npos);
    EXPECT_NE(ErrorOf("{").find("v.json: not valid JSON"), std::string::npos);
}

TEST(CompareViews, ResolveReadsTheFileAndRefusesDuplicates) {
    const fs::path dir = Dir("resolve");
    const fs::path file = dir / "views.json";
    std::ofstream(file) << R"({"low-sun": {"camera": "fov=50", "sun": "elevation=2"}})";
    CompareRequest q;
    q.width = 8;
    q.height = 4;
    q.no_shipped = true;
    q.views = {"ground-noon", file.string()};
    const CompareConfig c = ResolveCompareConfig(q);
    ASSERT_EQ(c.views.size(), 2u);
    EXPECT_EQ(c.views[1], "low-sun");
    ASSERT_EQ(c.custom_views.size(), 1u);
    q.views = {file.string(), file.string()};
    EXPECT_THROW(ResolveCompareConfig(q), Error);
    q.views = {(dir / "missing.json").string()};
    EXPECT_THROW(ResolveCompareConfig(q), Error);
}

// --- sky and ground ---------------------------------------------------------

TEST(CompareRegions, MaskFollowsTheHorizon) {
    // ground-noon: a camera on the ground pitched 10 degrees up, 60 degrees
    // vertical field: a pixel row is ground exactly where its ray points down,
    // elevation = 10 deg + atan((1 - 2 (y + 0.5) / H) tan 30 deg) < 0 at the
    // centre column (rays in a row tilt less off-centre, so check the centre).
    const AtmosphereParameters earth = EarthAtmosphere();
    const View v = GetView("ground-noon", earth);
    const int w = 9, h = 40;
    const std::vector<uint8_t> mask = RegionMask(v, w, h, earth.bottom_radius);
    for (int y = 0; y < h; ++y) {
        const double e =
            10.0 + std::atan((1.0 - 2.0 * (y + 0.5) / h) * std::tan(Radians(30.0))) * 180.0 / kPi;
        EXPECT_EQ(mask[static_cast<size_t>(y * w + 4)], e < 0.0 ? 1 : 0) << "row " << y;
    }
    // Space: the planet's disc in the middle is ground, the corners sky.
    const View s = GetView("space", earth);
    const std::vector<uint8_t> m2 = RegionMask(s, 16, 9, earth.bottom_radius);
    EXPECT_EQ(m2[4 * 16 + 8], 1);
    EXPECT_EQ(m2[0], 0);
}

TEST(CompareRegions, MeansOverHandMadeImages) {
    // Two pixels of sky, one of ground, one without a ray.
    const std::vector<uint8_t> mask = {0, 1, 0, 2};
    const RegionValues flip = RegionMean({0.2f, 0.8f, 0.4f, 1.0f}, mask);
    EXPECT_NEAR(flip.sky, 0.3, 1e-7);
    EXPECT_NEAR(flip.ground, 0.8, 1e-7);
    Image a(2, 2), b(2, 2);
    for (size_t i = 0; i < a.size(); ++i) a.data()[i] = 1.0f;
    for (int c = 0; c < 3; ++c) {
        b.data()[c] = 1.0f;        // sky pixel 0: no error
        b.data()[3 + c] = 3.0f;    // ground: error 2
        b.data()[6 + c] = 5.0f;    // sky pixel 2: error 4
        b.data()[9 + c] = 100.0f;  // no ray: ignored
    }
    const RegionValues rmse = RegionRmse(a, b, mask);
    EXPECT_NEAR(rmse.sky, std::sqrt(8.0), 1e-12);  // sqrt((0 + 16) / 2)
    EXPECT_NEAR(rmse.ground, 2.0, 1e-12);
    Image var(2, 2);
    for (int c = 0; c < 3; ++c) var.data()[3 + c] = 0.25f;  // ground
    const RegionValues noise = RegionRmseNoise(var, mask);
    EXPECT_DOUBLE_EQ(noise.sky, 0.0);
    EXPECT_DOUBLE_EQ(noise.ground, 1.0);  // 2 sqrt(0.25)
    const RegionValues none = RegionMean({0.5f}, {0});
    EXPECT_TRUE(std::isnan(none.ground));
    // Luminance: Rec. 709 weights.
    Image g(1, 1);
    g.data()[1] = 1.0f;
    EXPECT_NEAR(MeanLuminance(g, {0}).sky, 0.7152, 1e-7);
}

// --- regimes ----------------------------------------------------------------

TEST(CompareRegimes, TheTwelveViewsFallWhereTheThesisPutsThem) {
    const AtmosphereParameters earth = EarthAtmosphere();
    const std::vector<std::pair<std::string, std::string>> expected = {
        {"ground", "twilight"},   {"ground", "sunrise"},       {"ground", "day"},
        {"aircraft", "twilight"}, {"aircraft", "sunrise"},     {"aircraft", "day"},
        {"orbit", "twilight"},    {"orbit", "sunrise"},        {"orbit", "day"},
        {"space", "day"},         {"ground", "planet shadow"}, {"orbit", "planet shadow"}};
    const std::vector<View> views = StandardViews(earth);
    ASSERT_EQ(views.size(), expected.size());
    for (size_t i = 0; i < views.size(); ++i) {
        EXPECT_EQ(PlaceRegime(views[i], earth), expected[i].first) << views[i].name;
        EXPECT_EQ(LightRegime(views[i], earth), expected[i].second) << views[i].name;
    }
}

// A synthetic result: models "a" (physical), "empty" (the baseline) and
// "preetham" (outside its validity in the orbit view).
CompareResult SyntheticResult() {
    CompareResult r;
    r.models = {"naive", "naive:steps=8", "empty", "preetham"};
    r.model_names = {"naive", "naive", "empty", "preetham"};
    r.model_titles = r.models;
    r.prepare_seconds = {0.0, 0.0, 0.0, 0.0};
    r.table_bytes = {-1, -1, -1, -1};
    r.threads = 2;
    const struct {
        const char* view;
        const char* place;
        double noise;
        double flip[4];
        bool preetham_outside;
    } rows[] = {{"ground-noon", "ground", 0.01, {0.050, 0.055, 0.001, 0.010}, false},
                {"orbit-noon", "orbit", 0.01, {0.100, 0.300, 0.001, 0.001}, true}};
    for (const auto& x : rows) {
        CompareRow row;
        row.view = row.label = x.view;
        row.place = x.place;
        row.light = "day";
        row.reference_noise = x.noise;
        for (int m = 0; m < 4; ++m) {
            CompareCell c;
            c.flip = x.flip[m];
            c.render_seconds = 0.001 * (m + 1);
            if (m == 3 && x.preetham_outside) c.validity_note = "declared valid on the ground only";
            row.cells.push_back(c);
        }
        r.rows.push_back(row);
    }
    return r;
}

TEST(CompareRegimes, VerdictOnASyntheticResult) {
    const CompareResult r = SyntheticResult();
    const std::vector<RegimeVerdict> v = JudgeRegimes(r);
    // place: ground, orbit; light: day.
    ASSERT_EQ(v.size(), 3u);
    EXPECT_EQ(v[0].regime, "ground");
    // Ground: preetham is best (the baseline, lower still, is left out).
    ASSERT_EQ(v[0].best.size(), 1u);
    EXPECT_EQ(v[0].best[0], 3);
    EXPECT_DOUBLE_EQ(v[0].flip[0], 0.010);
    // Orbit: preetham is outside its validity, empty a baseline: naive alone
    // (naive:steps=8 is 0.2 worse, beyond the noise 0.01).
    EXPECT_EQ(v[1].regime, "orbit");
    ASSERT_EQ(v[1].best.size(), 1u);
    EXPECT_EQ(v[1].best[0], 0);
    ASSERT_EQ(v[1].excluded.size(), 2u);
    // Day (both views): preetham is out (orbit), naive (0.075) and
    // naive:steps=8 (0.1775) are not tied.
    EXPECT_EQ(v[2].regime, "day");
    ASSERT_EQ(v[2].best.size(), 1u);
    EXPECT_EQ(v[2].best[0], 0);
    // A tie: within the noise.
    CompareResult tied = r;
    tied.rows[0].cells[1].flip = 0.052;
    tied.rows[0].cells[3].flip = 0.5;
    const std::vector<RegimeVerdict> t = JudgeRegimes(tied);
    ASSERT_EQ(t[0].best.size(), 2u);
    EXPECT_EQ(t[0].best[0], 0);
    EXPECT_EQ(t[0].best[1], 1);
    // The CSV.
    const fs::path dir = Dir("regimes");
    CompareConfig config;
    WriteRegimesCsv((dir / "regimes.csv").string(), config, tied);
    const std::string csv = Slurp(dir / "regimes.csv");
    EXPECT_NE(csv.find("place,ground,ground-noon,naive naive:steps=8,0.05 0.052,0.001 0.002,0 0,"
                       "CPU; 2 threads"),
              std::string::npos)
        << csv;
}

TEST(CompareRegimes, ParetoFrontLeavesOutBaselinesAndModelsOutsideTheirValidity) {
    CompareResult r = SyntheticResult();
    CompareConfig config;
    config.width = 8;
    config.height = 4;
    const std::vector<CompareSummary> s = SummarizeCompare(config, r);
    ASSERT_EQ(s.size(), 4u);
    // empty is fastest and preetham is cheap, but both are apart.
    EXPECT_FALSE(s[2].pareto);
    EXPECT_EQ(s[2].pareto_apart, "a baseline");
    EXPECT_FALSE(s[3].pareto);
    EXPECT_FALSE(s[3].pareto_apart.empty());
    EXPECT_TRUE(s[0].pareto);   // the fastest eligible
    EXPECT_FALSE(s[1].pareto);  // slower and worse
}

// --- the run ----------------------------------------------------------------

TEST(CompareVerdict, RunWritesRegionsRegimesAndLuminance) {
    const fs::path dir = Dir("run");
    std::ofstream(dir / "views.json")
        << R"({"sky-5deg": {"camera": "projection=equirect", "sun": "elevation=5,azimuth=90"}})";
    CompareRequest q = TinyCompareRequest(
        {"naive:steps=8", "empty"}, {"ground-noon", (dir / "views.json").string()}, dir / "out");
    q.luminance = true;
    const CompareConfig config = ResolveCompareConfig(q);
    const CompareResult r = RunCompare(config);
    ASSERT_EQ(r.rows.size(), 2u);
    EXPECT_EQ(r.rows[1].view, "sky-5deg");
    EXPECT_EQ(r.rows[1].light, "sunrise");
    EXPECT_EQ(r.rows[1].place, "ground");
    // The equirect's lower half is ground, the upper sky.
    EXPECT_EQ(r.rows[1].sky_pixels, 16);
    EXPECT_EQ(r.rows[1].ground_pixels, 16);
    // The first model is the reference: zero in every region.
    EXPECT_EQ(r.rows[1].cells[0].flip_sky, 0.0);
    EXPECT_EQ(r.rows[1].cells[0].rmse_ground, 0.0);
    EXPECT_GT(r.rows[1].cells[1].rmse_sky, 0.0);
    // Luminance: the reference's and the identical model's agree, and the sun
    // illuminance scale is the Sun's (ASTM G173: about 1.3e5 lx).
    EXPECT_GT(SolarIlluminanceLux(), 1.2e5);
    EXPECT_LT(SolarIlluminanceLux(), 1.4e5);
    EXPECT_GT(r.rows[0].reference_luminance.sky, 0.0);
    EXPECT_EQ(r.rows[0].reference_luminance.all, r.rows[0].cells[0].luminance.all);
    // empty is constant 1 per unit irradiance: Y = 1 x the view's multiplier,
    // so its luminance is the Sun's illuminance (per steradian) in every view.
    EXPECT_NEAR(r.rows[1].cells[1].luminance.sky, SolarIlluminanceLux(),
                1e-6 * SolarIlluminanceLux());
    EXPECT_NEAR(r.rows[0].cells[1].luminance.sky, SolarIlluminanceLux(),
                1e-6 * SolarIlluminanceLux());
    // A tabulated solar spectrum (W m^-2 nm^-1) makes the images physical:
    // 683 lm/W x the CIE y integral; a flat one (earth's), per unit irradiance.
    CompareRequest spectral = q;
    spectral.atmosphere = "earth-spectral";
    EXPECT_NEAR(ResolveCompareConfig(spectral).luminance_scale,
                kMaxLuminousEfficacy * CieYIntegral(), 1e-9);
    spectral.wavelengths = {450.0, 550.0, 650.0};
    spectral.atmosphere = "earth";
    EXPECT_EQ(ResolveCompareConfig(spectral).luminance_scale, SolarIlluminanceLux());
    WriteCompareImages(config, r);
    WriteCompareTables(config, r);
    const fs::path out = config.output_dir;
    for (const char* f : {"flip_sky.csv", "flip_ground.csv", "rmse_sky.csv", "rmse_ground.csv",
                          "reference_noise_regions.csv", "regimes.csv", "luminance.csv",
                          "images/sky-5deg/reference.png", "index.html"}) {
        EXPECT_TRUE(fs::is_regular_file(out / f)) << f;
    }
    EXPECT_EQ(Slurp(out / "flip_sky.csv").rfind("FLIP errors (sky),naive:steps=8,empty,best\n", 0),
              0u);
    const std::string html = Slurp(out / "index.html");
    EXPECT_LT(html.find("id=\"regimes\""), html.find("Which model?"));  // the first table
}

}  // namespace
}  // namespace atmos
