// Spectral atmospheres, spectral runs and colour (issue 17).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/model.h"
#include "atmos/spectral.h"
#include "atmos/view.h"
#include "harness/kider.h"
#include "harness/spectral_run.h"
#include "test_util.h"

namespace atmos {
namespace {

void ExpectSameBits(const Vec3d& a, const Vec3d& b, const char* field) {
    EXPECT_EQ(std::memcmp(&a, &b, sizeof(Vec3d)), 0)
        << field << ": " << a.x << " " << a.y << " " << a.z << " vs " << b.x << " " << b.y << " "
        << b.z;
}

void ExpectSameAtmosphere(const AtmosphereParameters& a, const AtmosphereParameters& b) {
    ExpectSameBits(a.rayleigh_scattering, b.rayleigh_scattering, "rayleigh_scattering");
    ExpectSameBits(a.mie_scattering, b.mie_scattering, "mie_scattering");
    ExpectSameBits(a.mie_extinction, b.mie_extinction, "mie_extinction");
    ExpectSameBits(a.absorption_extinction, b.absorption_extinction, "absorption_extinction");
    ExpectSameBits(a.ground_albedo, b.ground_albedo, "ground_albedo");
    ExpectSameBits(a.solar_irradiance, b.solar_irradiance, "solar_irradiance");
    EXPECT_EQ(std::memcmp(&a, &b, sizeof(AtmosphereParameters)), 0);
}

// An atmosphere file's error message, or "" when it loads.
std::string LoadError(const std::string& json) {
    const std::filesystem::path path =
        std::filesystem::temp_directory_path() /
        ("atmos_spectral_" + std::to_string(std::hash<std::string>()(json)) + ".json");
    std::ofstream(path) << json;
    try {
        LoadSpectralAtmosphere(path.string());
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

// The kider-2013 preset with one field replaced by `value` (JSON text).
std::string WithField(const std::string& field, const std::string& value) {
    return R"({"bottom_radius": 6360000, "top_radius": 6420000,
      "rayleigh_scattering": )" +
           (field == "rayleigh_scattering" ? value : R"({"penndorf": {}})") + R"(,
      "rayleigh_density": {"scale_height": 8000},
      "mie_scattering": )" +
           (field == "mie_scattering" ? value : R"({"single_scattering_albedo": 0.8})") + R"(,
      "mie_extinction": )" +
           (field == "mie_extinction" ? value : R"({"angstrom": {"alpha": 0.8, "beta": 0.04}})") +
           R"(,
      "mie_density": {"scale_height": 1200}, "mie_phase_g": 0.7,
      "absorption_extinction": )" +
           (field == "absorption_extinction" ? value : "0") + R"(,
      "absorption_density": {"tent": {"center": 25000, "half_width": 15000}},
      "ground_albedo": )" +
           (field == "ground_albedo" ? value : R"({"table": "grass-feister-1995"})") + R"(,
      "sun_angular_radius": 0.004675,
      "solar_irradiance": )" +
           (field == "solar_irradiance" ? value : R"({"table": "astm-g173-etr-11.75nm"})") + "}";
}

TEST(Spectral, RgbFileIsAThreeWavelengthAtmosphere) {
    for (const std::string& name : AtmospherePresetNames()) {
        SCOPED_TRACE(name);
        const SpectralAtmosphere s = LoadSpectralAtmosphere(name);
        // The RGB reader of any file (spectral or not) gives the 680/550/440 nm values.
        ExpectSameAtmosphere(s.AtWavelengths(680, 550, 440), LoadAtmosphere(name));
    }
    EXPECT_FALSE(LoadSpectralAtmosphere("earth").spectral);
    EXPECT_TRUE(LoadSpectralAtmosphere("kider-2013").spectral);
    // Between the RGB wavelengths an RGB file interpolates linearly.
    const SpectralAtmosphere earth = LoadSpectralAtmosphere("earth");
    EXPECT_DOUBLE_EQ(earth.rayleigh_scattering.At(495), 0.5 * (33.1e-6 + 13.558e-6));
    EXPECT_DOUBLE_EQ(earth.rayleigh_scattering.At(400), 33.1e-6);
}

TEST(Spectral, ThreeWavelengthRunEqualsTheRgbRunBitForBit) {
    const AtmosphereParameters rgb = LoadAtmosphere("earth");
    const SpectralAtmosphere spectral = LoadSpectralAtmosphere("earth");
    const std::vector<double> nm = {680, 550, 440};
    const auto prepare = [](const AtmosphereParameters& a, Model* m) { m->Prepare(a); };
    for (const char* name : {"naive", "flat"}) {
        SCOPED_TRACE(name);
        auto model = CreateModel(name);
        model->Prepare(rgb);
        RenderRequest request = atmos_test::QuietRequest(GetView("ground-sunrise", rgb), 24, 14);
        Image image;
        model->Render(request, &image);
        const SpectralImage s =
            RenderSpectral(ParseModelSpec(name), spectral, nm, request, prepare);
        ASSERT_EQ(s.values.size(), image.size());
        EXPECT_EQ(std::memcmp(s.values.data(), image.data(), image.size() * sizeof(float)), 0);

        const std::vector<SampleQuery> queries = {{0, 0.3, 0.2, 40}, {2000, 0.05, 0.6, 170}};
        const std::vector<SampleAnswer> answers = model->Sample(queries);
        const std::vector<double> values =
            SampleSpectral(ParseModelSpec(name), spectral, nm, queries, {}, prepare);
        for (size_t q = 0; q < queries.size(); ++q) {
            for (int c = 0; c < 3; ++c) {
                EXPECT_EQ(values[q * 3 + static_cast<size_t>(c)],
                          static_cast<double>(answers[q].radiance[c]));  // solar_irradiance 1
            }
        }
    }
}

TEST(Spectral, BatchesOfThreeCoverEveryWavelength) {
    // 4 wavelengths: two batches, the second padded; each value equals the run of
    // that wavelength alone.
    const SpectralAtmosphere a = LoadSpectralAtmosphere("kider-2013");
    const auto prepare = [](const AtmosphereParameters& p, Model* m) { m->Prepare(p); };
    const std::vector<SampleQuery> queries = {{0, 0.5, 0.7, 90}};
    const std::vector<double> nm = {400, 500, 600, 700};
    const std::vector<double> all =
        SampleSpectral(ParseModelSpec("naive"), a, nm, queries, {}, prepare);
    for (size_t i = 0; i < nm.size(); ++i) {
        const std::vector<double> one =
            SampleSpectral(ParseModelSpec("naive"), a, {nm[i]}, queries, {}, prepare);
        EXPECT_EQ(all[i], one[0]) << nm[i];
        EXPECT_GT(one[0], 0.0);
    }
    EXPECT_THROW(SampleSpectral(ParseModelSpec("neural"), a, nm, queries, {}, prepare), Error);
}

TEST(Spectral, RequestsShareOnePreparePerBatch) {
    // Two views at 4 wavelengths: two batches, so two Prepare()s for both views
    // (not one per batch and view), and each view's values are those of its own
    // run.
    const SpectralAtmosphere a = LoadSpectralAtmosphere("kider-2013");
    const AtmosphereParameters rgb = a.AtWavelengths(680, 550, 440);
    int prepares = 0;
    const auto prepare = [&](const AtmosphereParameters& p, Model* m) {
        ++prepares;
        m->Prepare(p);
    };
    const std::vector<double> nm = {400, 500, 600, 700};
    std::vector<RenderRequest> requests(2);
    const char* views[2] = {"ground-noon", "ground-sunrise"};
    for (int v = 0; v < 2; ++v) {
        requests[v].view = GetView(views[v], rgb);
        requests[v].width = 12 + 4 * v;
        requests[v].height = 7;
        requests[v].show_progress = false;
    }
    std::vector<double> seconds;
    // The batches of three (naive also has wide channel batches, which
    // prepare one model for both batches without calling `prepare`:
    // tests/wide_channels_test.cpp).
    SpectralBatching three;
    three.wide = false;
    const std::vector<SpectralImage> both = RenderSpectralRequests(
        ParseModelSpec("naive"), a, nm, requests, prepare, &seconds, nullptr, three);
    EXPECT_EQ(prepares, 2);
    ASSERT_EQ(both.size(), 2u);
    ASSERT_EQ(seconds.size(), 2u);
    for (int v = 0; v < 2; ++v) {
        const SpectralImage one =
            RenderSpectral(ParseModelSpec("naive"), a, nm, requests[v], prepare);
        EXPECT_EQ(both[v].width, requests[v].width);
        EXPECT_EQ(both[v].values, one.values) << views[v];
    }
    // Groups bound the memory of the images: 12x7x4 floats = 1344 bytes.
    const auto groups = SpectralRequestGroups(requests, nm.size(), 2500);
    ASSERT_EQ(groups.size(), 2u);
    EXPECT_EQ(groups[0], std::vector<size_t>{0});
    EXPECT_EQ(SpectralRequestGroups(requests, nm.size()).size(), 1u);
}

TEST(Spectral, BatchSeedsCorrelateOrSeparateTheBatches) {
    // 502 and 503 nm lie in different batches but have nearly the same
    // coefficients: with the same seed the path tracer's two values are nearly
    // equal (the same paths), with distinct seeds they differ by the noise.
    const SpectralAtmosphere a = LoadSpectralAtmosphere("kider-2013");
    const auto prepare = [](const AtmosphereParameters& p, Model* m) { m->Prepare(p); };
    const std::vector<double> nm = {500, 501, 502, 503, 504, 505};
    std::vector<SampleQuery> queries;
    // 32 queries: the statistic is a mean over queries (random numbers are
    // keyed by the query since issue 33; with 8 the same-seed gap was 0.022).
    for (int i = 0; i < 32; ++i) queries.push_back({0, 0.1 + 0.028 * i, 0.6, 11.25 * i});
    MonteCarloSettings mc;
    mc.spp = 2;
    mc.pass_spp = 2;
    double gap[2] = {0.0, 0.0};
    for (const BatchSeeds seeds : {BatchSeeds::kSame, BatchSeeds::kDistinct}) {
        const std::vector<double> v =
            SampleSpectral(ParseModelSpec("reference:spectral=batches"), a, nm, queries, mc,
                           prepare, SpectralBatching{seeds, BatchLayout::kConsecutive});
        double sum = 0.0, mean = 0.0;
        for (size_t q = 0; q < queries.size(); ++q) {
            sum += std::abs(v[q * 6 + 3] - v[q * 6 + 2]);
            mean += v[q * 6 + 2];
        }
        gap[seeds == BatchSeeds::kDistinct] = sum / mean;
    }
    std::printf("relative |L(503) - L(502)|: same seeds %.4f, distinct %.4f\n", gap[0], gap[1]);
    EXPECT_LT(gap[0], 0.02);
    EXPECT_GT(gap[1], 0.05);
    EXPECT_EQ(BatchSeed(7, 3, BatchSeeds::kSame), 7u);
    EXPECT_EQ(BatchSeed(7, 3, BatchSeeds::kDistinct), 7u + (uint64_t{3} << 40));
    EXPECT_THROW(ParseBatchSeeds("other"), Error);
}

// Both layouts hold every wavelength in exactly one batch (a short batch repeats
// an index it already holds), in ceil(N/3) batches; interleaved batches take
// b, b + S, b + 2S.
TEST(Spectral, BatchLayoutsHoldEveryWavelengthOnce) {
    for (const BatchLayout layout : {BatchLayout::kConsecutive, BatchLayout::kInterleaved}) {
        for (size_t n = 1; n <= 45; ++n) {
            const std::vector<std::array<size_t, 3>> batches = SpectralBatches(n, layout);
            ASSERT_EQ(batches.size(), (n + 2) / 3) << n;
            std::vector<int> held(n, 0);
            for (const std::array<size_t, 3>& b : batches) {
                for (size_t c = 0; c < 3; ++c) {
                    ASSERT_LT(b[c], n);
                    bool repeat = false;
                    for (size_t k = 0; k < c; ++k) repeat = repeat || b[k] == b[c];
                    if (!repeat) ++held[b[c]];
                }
            }
            for (size_t i = 0; i < n; ++i) EXPECT_EQ(held[i], 1) << "n " << n << " index " << i;
        }
    }
    const std::vector<std::array<size_t, 3>> b40 = SpectralBatches(40, BatchLayout::kInterleaved);
    EXPECT_EQ(b40[0], (std::array<size_t, 3>{0, 14, 28}));
    EXPECT_EQ(b40[11], (std::array<size_t, 3>{11, 25, 39}));
    EXPECT_EQ(b40[13], (std::array<size_t, 3>{13, 27, 27}));
    EXPECT_EQ(SpectralBatches(40, BatchLayout::kConsecutive)[13],
              (std::array<size_t, 3>{39, 39, 39}));
    EXPECT_EQ(ParseBatchLayout("interleaved"), BatchLayout::kInterleaved);
    EXPECT_THROW(ParseBatchLayout("hero"), Error);
}

// A deterministic model's value at a wavelength does not depend on which batch
// carries it: the interleaved layout stores each batch's channels at their own
// wavelengths (a swapped index would put a neighbour's value there).
TEST(Spectral, InterleavedBatchesStoreEachWavelengthsOwnValue) {
    const SpectralAtmosphere a = LoadSpectralAtmosphere("earth-spectral");
    const auto prepare = [](const AtmosphereParameters& p, Model* m) { m->Prepare(p); };
    const std::vector<double> nm = ParseWavelengths("380:780:11");
    std::vector<SampleQuery> queries;
    for (int i = 0; i < 6; ++i) queries.push_back({1000.0, 0.05 + 0.15 * i, 0.4, 40.0 * i});
    const std::vector<double> consecutive =
        SampleSpectral(ParseModelSpec("naive"), a, nm, queries, {}, prepare, SpectralBatching{});
    const std::vector<double> interleaved =
        SampleSpectral(ParseModelSpec("naive"), a, nm, queries, {}, prepare,
                       SpectralBatching{BatchSeeds::kSame, BatchLayout::kInterleaved});
    ASSERT_EQ(consecutive.size(), interleaved.size());
    for (size_t i = 0; i < consecutive.size(); ++i) {
        EXPECT_NEAR(interleaved[i], consecutive[i], 1e-5 * consecutive[i] + 1e-12)
            << "query " << i / nm.size() << " at " << nm[i % nm.size()] << " nm";
    }
}

TEST(Spectral, FilesAreValidatedNamingTheField) {
    EXPECT_EQ(LoadError(WithField("", "")), "");
    const struct {
        const char* field;
        const char* value;
        const char* needle;
    } cases[] = {
        {"mie_extinction", R"({"angstrom": {"alpha": 0.8}})",
         "'mie_extinction.angstrom.beta' is missing"},
        {"mie_extinction", R"({"angstrom": {"alpha": 0.8, "beta": -1}})",
         "mie_extinction.angstrom.beta"},
        {"mie_extinction", R"({"angstrom": {"alpha": 0.8, "beta": 0.04, "g": 1}})",
         "mie_extinction.angstrom.g"},
        {"ground_albedo", R"({"table": {"nm": [400, 300], "value": [0.1, 0.2]}})",
         "ground_albedo.table.nm"},
        {"ground_albedo", R"({"table": {"nm": [400, 500], "value": [0.1]}})",
         "ground_albedo.table"},
        {"ground_albedo", R"({"table": "no-such-table"})",
         "unknown spectral table 'no-such-table'"},
        {"ground_albedo", R"({"table": {"nm": [400, 500], "value": [0.1, 2]}})",
         "ground_albedo[0]"},
        {"ground_albedo", R"({"angstrom": {"alpha": 1, "beta": 1}})", "ground_albedo.angstrom"},
        {"rayleigh_scattering", R"({"penndorf": {"scale": "x"}})",
         "rayleigh_scattering.penndorf.scale"},
        {"rayleigh_scattering", R"({"power_law": {"value": 1e-6, "exponent": 4}})",
         "rayleigh_scattering.power_law.reference_nm"},
        {"absorption_extinction", R"({"ozone": {"dobson": 300}})",
         "absorption_extinction.ozone.cross_section"},
        {"absorption_extinction", R"({"ozone": {"cross_section": 1e-25}})",
         "absorption_extinction.ozone"},
        {"solar_irradiance", R"({"table": {"nm": [400, 500], "value": [1, "a"]}})",
         "solar_irradiance.table.value[1]"},
        {"mie_scattering", R"({"single_scattering_albedo": 1.5})", "mie_scattering"},
    };
    for (const auto& c : cases) {
        const std::string error = LoadError(WithField(c.field, c.value));
        EXPECT_NE(error.find(c.needle), std::string::npos) << c.value << "\n-> " << error;
    }
}

TEST(Spectral, SetReachesSpectralFields) {
    const SpectralAtmosphere a =
        LoadSpectralAtmosphere("kider-2013", {"mie_extinction.angstrom.beta=0.08"});
    const SpectralAtmosphere b = LoadSpectralAtmosphere("kider-2013");
    EXPECT_NEAR(a.mie_extinction.At(550) / b.mie_extinction.At(550), 2.0, 1e-12);
    EXPECT_THROW(LoadSpectralAtmosphere("kider-2013", {"mie_extinction.angstrom.gamma=1"}), Error);
}

TEST(Spectral, LawsMatchTheirSources) {
    // Penndorf's law against his Table III (0 deg C, scaled to 15 deg C by his eq. 12).
    std::vector<double> nm, table;
    SpectralDataTable("penndorf-1957", 0, &nm, &table);
    ASSERT_EQ(nm.size(), 48u);
    for (size_t i = 0; i < nm.size(); ++i) {
        // 360-800 nm within 0.1 % (measured: 0.07 % at most); the table's last three
        // entries (810-830 nm, as tabulated by clear-sky-models) are 1.2-2.8 % above
        // the formula and its own lambda^-4 trend.
        EXPECT_NEAR(PenndorfRayleigh(nm[i]) / (table[i] * 273.16 / 288.16), 1.0,
                    nm[i] <= 800 ? 1e-3 : 3e-2)
            << nm[i];
    }
    // kider-2013: Angstrom beta (lambda / 1 um)^-alpha / H, albedo 0.8.
    const SpectralAtmosphere k = LoadSpectralAtmosphere("kider-2013");
    EXPECT_NEAR(k.mie_extinction.At(500), 0.04 * std::pow(0.5, -0.8) / 1200.0, 1e-18);
    EXPECT_NEAR(k.mie_scattering.At(500), 0.8 * k.mie_extinction.At(500), 1e-18);
    // earth-spectral: Bruneton 2017's demo: 300 DU over the 15 km-equivalent tent.
    const SpectralAtmosphere e = LoadSpectralAtmosphere("earth-spectral");
    EXPECT_NEAR(e.absorption_extinction.At(600) / (300 * 2.687e20 / 15000.0 * 5.019e-25), 1.0,
                1e-6);
    EXPECT_NEAR(e.rayleigh_scattering.At(500), 1.24062e-6 * 16.0, 1e-15);
    EXPECT_NEAR(e.solar_irradiance.At(550), 1.8504, 1e-12);
}

TEST(Spectral, FlatSpectrumIntegratesToTheKnownWhite) {
    std::vector<double> nm;
    for (int l = 360; l <= 830; l += 5) nm.push_back(l);
    const std::vector<double> ones(nm.size(), 1.0);
    const Vec3d xyz = SpectrumToXyz(nm, WavelengthWeights(nm), ones.data());
    // The CIE functions have equal integrals (illuminant E: X = Y = Z), 106.86 nm.
    EXPECT_NEAR(xyz.y, 106.86, 0.1);
    EXPECT_DOUBLE_EQ(CieYIntegral(), xyz.y);
    // A spectral image of a flat spectrum: Y = the spectrum's value.
    SpectralImage flat;
    flat.width = flat.height = 1;
    flat.nm = nm;
    flat.values.assign(nm.size(), 0.25f);
    EXPECT_NEAR(SpectralToColour(flat, ColourOutput::kXyz, WhitePoint::kD65).Get(0, 0).y, 0.25,
                1e-6);
    const Rgb grey = SpectralToColour(flat, ColourOutput::kSrgb, WhitePoint::kE).Get(0, 0);
    EXPECT_NEAR(grey.x, 0.25, 1e-3);
    EXPECT_NEAR(grey.z, 0.25, 1e-3);
    EXPECT_NEAR(xyz.x / xyz.y, 1.0, 2e-3);
    EXPECT_NEAR(xyz.z / xyz.y, 1.0, 2e-3);
    // White E: grey in sRGB; D65: D65's XYZ maps to (1, 1, 1).
    const Vec3d e = XyzToLinearSrgb(xyz, WhitePoint::kE);
    EXPECT_NEAR(e.x / e.y, 1.0, 3e-3);
    EXPECT_NEAR(e.z / e.y, 1.0, 3e-3);
    const Vec3d d65 = XyzToLinearSrgb(Vec3d(0.95047, 1.0, 1.08883), WhitePoint::kD65);
    EXPECT_NEAR(d65.x, 1.0, 1e-3);
    EXPECT_NEAR(d65.y, 1.0, 1e-3);
    EXPECT_NEAR(d65.z, 1.0, 1e-3);
    const Vec3d e_pink = XyzToLinearSrgb(xyz, WhitePoint::kD65);
    EXPECT_GT(e_pink.x / e_pink.z, 1.05);  // E is redder than D65
}

// The roughness of log(measured / sun) over the Kider bins: the rms of its second
// difference, bins next to the O2 / H2O bands (689, 724.25, 759.5, 818.25 nm) left
// out. The sky's radiance per unit solar irradiance is smooth in wavelength, so a
// sun at the instrument's bandpass leaves a smooth ratio (scripts/solar_resolution.py).
double KiderSunRoughness(const Spectrum& sun, const std::vector<KiderSample>& samples) {
    const std::vector<double> nm = KiderWavelengths();
    std::vector<double> r(nm.size(), 0.0);
    size_t n = 0;
    for (const KiderSample& s : samples) {
        if (s.suspect) continue;
        ++n;
        for (size_t i = 0; i < nm.size(); ++i) r[i] += s.spectrum[i];
    }
    std::vector<bool> gas(nm.size(), false);
    for (size_t i = 0; i < nm.size(); ++i) {
        r[i] = std::log(r[i] / static_cast<double>(n) / sun.At(nm[i]));
        for (double g : {689.0, 724.25, 759.5, 818.25})
            gas[i] = gas[i] || std::abs(nm[i] - g) < 1e-6;
    }
    double sum = 0.0;
    int count = 0;
    for (size_t i = 1; i + 1 < nm.size(); ++i) {
        if (gas[i - 1] || gas[i] || gas[i + 1]) continue;
        const double d = r[i] - 0.5 * (r[i - 1] + r[i + 1]);
        sum += d * d;
        ++count;
    }
    return std::sqrt(sum / count);
}

// The measured Kider samples are the 1-nm spectrum interpolated at 360 + 11.75 i nm,
// seen through the spectroradiometer's bandpass: the kider-2013 sun must be the
// G-173 spectrum at that bandpass (a 7 nm FWHM Gaussian), not clear-sky-models'
// means over the 11.75 nm bins starting at each wavelength (half a bin off, and
// 29 % too bright at 395.25 nm, where the Ca II H and K lines fall outside the bin).
TEST(Spectral, KiderSunMatchesTheInstrumentBandpass) {
    const std::vector<KiderSample> samples = ReadKiderCsv(
        (std::filesystem::path(ATMOS_SOURCE_DIR) / "tests/data/kider-2013/kider_ref.csv").string());
    const SpectralAtmosphere preset = LoadSpectralAtmosphere("kider-2013");
    const SpectralAtmosphere csm = LoadSpectralAtmosphere(
        "kider-2013", {R"(solar_irradiance={"table": "astm-g173-etr-11.75nm"})"});
    const double preset_roughness = KiderSunRoughness(preset.solar_irradiance, samples);
    const double csm_roughness = KiderSunRoughness(csm.solar_irradiance, samples);
    // Measured with this commit (2 captures): 1.6 % against 6.5 % with the bins.
    EXPECT_LT(preset_roughness, 0.02);
    EXPECT_GT(csm_roughness, 0.05);
    // The table is the G-173 ETR convolved with the Gaussian (scripts/solar_resolution.py).
    const SpectralAtmosphere raw =
        LoadSpectralAtmosphere("kider-2013", {R"(solar_irradiance={"table": "astm-g173-etr"})"});
    const double sigma = 7.0 / (2.0 * std::sqrt(2.0 * std::log(2.0)));
    for (double l : {371.75, 395.25, 430.5, 548.0, 656.0, 759.0}) {
        double sum = 0.0, weight = 0.0;
        for (double x = l - 5.0 * sigma; x <= l + 5.0 * sigma; x += 0.05) {
            const double w = std::exp(-0.5 * (x - l) * (x - l) / (sigma * sigma));
            sum += w * raw.solar_irradiance.At(x);
            weight += w;
        }
        EXPECT_NEAR(preset.solar_irradiance.At(l), sum / weight, 2e-3 * sum / weight) << l;
    }
}

TEST(Spectral, WavelengthListsAndLabels) {
    const std::vector<double> k = ParseWavelengths("360:818.25:40");
    ASSERT_EQ(k.size(), 40u);
    EXPECT_EQ(k, KiderWavelengths());
    EXPECT_EQ(WavelengthLabel(k[1]), "371.75");
    EXPECT_EQ(WavelengthLabel(k[0]), "360");
    EXPECT_EQ(ParseWavelengths("440,550,680"), (std::vector<double>{440, 550, 680}));
    const std::vector<double> w = WavelengthWeights(k);
    EXPECT_DOUBLE_EQ(w[0], 11.75);
    EXPECT_DOUBLE_EQ(w[39], 11.75);
    EXPECT_EQ(WavelengthWeights({400, 410, 430}), (std::vector<double>{10, 15, 20}));
    for (const char* bad : {"", "400:300:3", "360:830", "360:830:0", "100:200:2", "500,400", "a,b",
                            "360:830:2.5", "1:2:3:4"}) {
        EXPECT_THROW(ParseWavelengths(bad), Error) << bad;
    }
    EXPECT_EQ(SpectralExrChannelName(371.75), "S0.371,75nm");
    EXPECT_EQ(SpectralExrChannelName(550), "S0.550nm");
}

}  // namespace
}  // namespace atmos
