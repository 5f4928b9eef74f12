// Any aerosol phase function (issue 32 item 4): Henyey-Greenstein and isotropic
// against their closed forms, a tabulated phase function's normalisation and its
// exact sampling (a histogram against the table), the JSON forms and their
// refusals, the reference with isotropic and Henyey-Greenstein phases against
// DISORT's test problems 1 and 3 (van de Hulst's tables), the table models with
// a tabulated Cornette-Shanks against the closed form, and a bake's shaders.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/model.h"
#include "base/rng.h"
#include "io/engine_shaders.h"
#include "models/reference.h"
#include "physics/phase.h"
#include "physics/sampling.h"
#include "render/render.h"
#include "studies/validate.h"
#include "test_util.h"

namespace atmos {
namespace {

namespace fs = std::filesystem;

// The AERONET table shipped in data/spectra (column 0: 442 nm).
AtmosphereParameters WithAeronetTable(int column = 0) {
    return LoadAtmosphere("earth", {"mie_phase={\"kind\": \"tabulated\", \"table\": "
                                    "\"aeronet-egbert-2013-05-27-phase\", \"column\": " +
                                    std::to_string(column) + "}"});
}

// The integral over the sphere of f(nu) by the midpoint rule in nu with n steps
// (independent of the table's own sums).
template <typename F>
double SphereIntegral(F f, int n) {
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
        const double nu = -1.0 + (i + 0.5) * (2.0 / n);
        sum += f(nu);
    }
    return 2.0 * kPi * sum * (2.0 / n);
}

// The chi-square quantile of `dof` degrees of freedom at upper tail z standard
// normal deviations (Wilson and Hilferty 1931).
double ChiSquareQuantile(int dof, double z) {
    const double k = dof;
    const double a = 2.0 / (9.0 * k);
    return k * std::pow(1.0 - a + z * std::sqrt(a), 3.0);
}

// Draws `count` cosines with `sample(xi)` and compares the histogram over the
// bins `edges` (decreasing cosines, 1 ... -1) with the probabilities of the
// density `pdf` (integrated per bin by Simpson's rule, independently of the
// sampler). Pearson's chi-square must stay below its quantile at z = 4.75
// (one-sided false-alarm rate 1e-6 for a random seed; the seed is fixed).
template <typename S, typename P>
void ExpectSamplesFollow(S sample, P pdf, const std::vector<double>& edges, int count,
                         const std::string& what) {
    const int bins = static_cast<int>(edges.size()) - 1;
    std::vector<double> expected(static_cast<size_t>(bins));
    double total = 0.0;
    for (int b = 0; b < bins; ++b) {
        const double hi = edges[static_cast<size_t>(b)], lo = edges[static_cast<size_t>(b) + 1];
        constexpr int kSteps = 200;  // even
        const double h = (hi - lo) / kSteps;
        double s = pdf(lo) + pdf(hi);
        for (int i = 1; i < kSteps; ++i) s += (i % 2 == 1 ? 4.0 : 2.0) * pdf(lo + i * h);
        expected[static_cast<size_t>(b)] = 2.0 * kPi * s * h / 3.0;
        total += expected[static_cast<size_t>(b)];
    }
    EXPECT_NEAR(total, 1.0, 1e-6) << what << ": the density integrates to 1";
    std::vector<int> observed(static_cast<size_t>(bins), 0);
    for (int i = 0; i < count; ++i) {
        Rng rng(12345, 7, static_cast<uint64_t>(i));
        const double mu = sample(rng.Uniform());
        ASSERT_TRUE(mu >= -1.0 && mu <= 1.0) << what << ": " << mu;
        // The bin b with edges[b] >= mu > edges[b + 1] (mu = -1 in the last).
        const auto it = std::upper_bound(edges.begin(), edges.end(), mu, std::greater<double>());
        const int b = std::clamp(static_cast<int>(it - edges.begin()) - 1, 0, bins - 1);
        ++observed[static_cast<size_t>(b)];
    }
    double chi2 = 0.0;
    int dof = -1;
    for (int b = 0; b < bins; ++b) {
        const double e = expected[static_cast<size_t>(b)] * count;
        if (e < 5.0) continue;  // Pearson's rule; such bins are few
        const double d = observed[static_cast<size_t>(b)] - e;
        chi2 += d * d / e;
        ++dof;
    }
    const double limit = ChiSquareQuantile(dof, 4.75);
    std::printf("%s: chi-square %.1f over %d degrees of freedom (limit %.1f)\n", what.c_str(), chi2,
                dof, limit);
    EXPECT_LT(chi2, limit) << what;
}

TEST(MiePhaseKinds, HenyeyGreensteinAndIsotropicFollowTheirClosedForms) {
    AtmosphereParameters a = EarthAtmosphere();
    a.mie_phase_kind = MiePhaseKind::kHenyeyGreenstein;
    for (double g : {-0.5, 0.0, 0.3, 0.76, 0.95}) {
        a.mie_phase_g = g;
        a.mie_phase_weight2 = 0.0;
        for (double nu = -1.0; nu <= 1.0; nu += 0.125) {
            // Henyey & Greenstein 1941: (1 - g^2) / (4 pi (1 + g^2 - 2 g nu)^(3/2)).
            const double want =
                (1.0 - g * g) / (4.0 * kPi * std::pow(1.0 + g * g - 2.0 * g * nu, 1.5));
            EXPECT_NEAR(MiePhase(a, nu), want, 1e-12 * want) << g << " " << nu;
            EXPECT_DOUBLE_EQ(MiePhaseSamplingPdf(a, nu), MiePhase(a, nu));
            EXPECT_EQ(MiePhaseOverSamplingPdf(a, nu), 1.0);
        }
        EXPECT_NEAR(SphereIntegral([&](double nu) { return MiePhase(a, nu); }, 400000), 1.0, 2e-5);
        // The mean cosine of HG(g) is g.
        EXPECT_NEAR(SphereIntegral([&](double nu) { return nu * MiePhase(a, nu); }, 400000), g,
                    2e-5);
    }
    // Two lobes: the mixture.
    a.mie_phase_g = 0.5;
    a.mie_phase_g2 = 0.9;
    a.mie_phase_weight2 = 0.25;
    for (double nu = -1.0; nu <= 1.0; nu += 0.25) {
        auto hg = [](double g, double x) {
            return (1.0 - g * g) / (4.0 * kPi * std::pow(1.0 + g * g - 2.0 * g * x, 1.5));
        };
        EXPECT_NEAR(MiePhase(a, nu), 0.75 * hg(0.5, nu) + 0.25 * hg(0.9, nu), 1e-12);
    }
    ExpectSamplesFollow([&](double xi) { return SampleMiePhaseCosine(a, xi); },
                        [&](double nu) { return MiePhase(a, nu); },
                        [] {
                            std::vector<double> e;
                            for (int i = 0; i <= 64; ++i) e.push_back(std::cos(kPi * i / 64.0));
                            return e;
                        }(),
                        200000, "two Henyey-Greenstein lobes");
    // Isotropic.
    a.mie_phase_kind = MiePhaseKind::kIsotropic;
    for (double nu = -1.0; nu <= 1.0; nu += 0.5) {
        EXPECT_DOUBLE_EQ(MiePhase(a, nu), 1.0 / (4.0 * kPi));
        EXPECT_EQ(MiePhaseOverSamplingPdf(a, nu), 1.0);
    }
    ExpectSamplesFollow([&](double xi) { return SampleMiePhaseCosine(a, xi); },
                        [&](double nu) { return MiePhase(a, nu); },
                        [] {
                            std::vector<double> e;
                            for (int i = 0; i <= 32; ++i) e.push_back(1.0 - i / 16.0);
                            return e;
                        }(),
                        100000, "isotropic");
}

TEST(MiePhaseKinds, TabulatedIsNormalisedAndItsMeanCosineIsG) {
    for (int column = 0; column < 4; ++column) {
        const AtmosphereParameters a = WithAeronetTable(column);
        ASSERT_EQ(a.mie_phase_kind, MiePhaseKind::kTabulated);
        const MiePhaseTable& t = a.mie_phase_table;
        EXPECT_EQ(t.count, 83);
        // The normalisation, by an independent quadrature of the phase function.
        EXPECT_NEAR(SphereIntegral([&](double nu) { return MiePhase(a, nu); }, 1000000), 1.0, 1e-6);
        const double g = SphereIntegral([&](double nu) { return nu * MiePhase(a, nu); }, 1000000);
        EXPECT_NEAR(t.mean_cosine, g, 1e-6);
        EXPECT_EQ(a.mie_phase_g, t.mean_cosine);
        // AERONET normalises to 4 pi; the renormalisation is small (0.4-0.7 %).
        EXPECT_NEAR(t.scale * 4.0 * kPi, 1.0, 0.01);
        // The table's nodes are interpolated exactly at the nodes.
        for (int i = 0; i < t.count; ++i) {
            const double nu = std::cos(t.angle_deg[i] * kPi / 180.0);
            EXPECT_NEAR(MiePhase(a, nu), t.scale * t.value[i], 1e-9 * t.scale * t.value[i]);
        }
        std::printf("AERONET column %d: g %.4f, 4 pi x scale %.5f\n", column, g,
                    t.scale * 4.0 * kPi);
    }
    // The AERONET 442 nm function at the nodes docs/harness.md quotes.
    const AtmosphereParameters a = WithAeronetTable(0);
    EXPECT_NEAR(4.0 * kPi * MiePhase(a, 1.0), 76.3527 * a.mie_phase_table.scale * 4.0 * kPi, 1e-9);
}

TEST(MiePhaseKinds, TabulatedSamplingFollowsTheTable) {
    const AtmosphereParameters a = WithAeronetTable(0);
    const MiePhaseTable& t = a.mie_phase_table;
    // Bins: each table interval cut in three (so the inversion inside an interval
    // is checked, not only the choice of the interval).
    std::vector<double> edges;
    for (int i = 0; i + 1 < t.count; ++i) {
        for (int k = 0; k < 3; ++k) edges.push_back(t.mu[i] + (t.mu[i + 1] - t.mu[i]) * k / 3.0);
    }
    edges.push_back(-1.0);
    ExpectSamplesFollow([&](double xi) { return SampleMiePhaseCosine(a, xi); },
                        [&](double nu) { return MiePhase(a, nu); }, edges, 400000,
                        "AERONET 442 nm table");
    // Exact sampling: the weight is 1 and the pdf the phase.
    for (double nu = -1.0; nu <= 1.0; nu += 0.1) {
        EXPECT_EQ(MiePhaseOverSamplingPdf(a, nu), 1.0);
        EXPECT_EQ(MiePhaseSamplingPdf(a, nu), MiePhase(a, nu));
    }
    // A two-node table (linear in nu over the sphere) with a steep slope, and a
    // uniform one.
    for (const std::string values : {"[3, 0.01]", "[0.2, 5]", "[1, 1]"}) {
        const AtmosphereParameters b = LoadAtmosphere(
            "earth", {"mie_phase={\"kind\": \"tabulated\", \"angles_deg\": [0, 180], "
                      "\"values\": " +
                      values + "}"});
        std::vector<double> e;
        for (int i = 0; i <= 40; ++i) e.push_back(1.0 - i / 20.0);
        ExpectSamplesFollow([&](double xi) { return SampleMiePhaseCosine(b, xi); },
                            [&](double nu) { return MiePhase(b, nu); }, e, 100000,
                            "two nodes " + values);
    }
}

TEST(MiePhaseKinds, JsonRoundTripIsExact) {
    const std::vector<std::vector<std::string>> sets = {
        {"mie_phase=henyey-greenstein"},
        {"mie_phase=henyey-greenstein", "mie_phase_g2=0.9", "mie_phase_weight2=0.2"},
        {"mie_phase=isotropic"},
        {"mie_phase={\"kind\": \"tabulated\", \"table\": \"aeronet-egbert-2013-05-27-phase\"}"},
        {"mie_phase={\"kind\": \"tabulated\", \"angles_deg\": [0, 0.3, 90, 180], \"values\": "
         "[10, 7.25, 0.1, 0.123456789012345]}"},
    };
    for (const std::vector<std::string>& set : sets) {
        const AtmosphereParameters a = LoadAtmosphere("earth", set);
        const std::string text = AtmosphereToJson(a);
        const AtmosphereParameters b = AtmosphereFromJson(text);
        EXPECT_EQ(AtmosphereToJson(b), text) << set[0];
        EXPECT_EQ(b.mie_phase_kind, a.mie_phase_kind);
        EXPECT_EQ(b.mie_phase_g, a.mie_phase_g);
        EXPECT_EQ(b.mie_phase_g2, a.mie_phase_g2);
        EXPECT_EQ(b.mie_phase_weight2, a.mie_phase_weight2);
        EXPECT_EQ(std::memcmp(&a.mie_phase_table, &b.mie_phase_table, sizeof(MiePhaseTable)), 0)
            << set[0];
        EXPECT_NE(text.find("\"mie_phase\""), std::string::npos);
    }
    // The default kind writes no "mie_phase" (existing atmospheres keep their text).
    for (const std::string& preset : AtmospherePresetNames()) {
        const AtmosphereParameters a = LoadAtmosphere(preset);
        if (a.mie_phase_kind != MiePhaseKind::kCornetteShanks) continue;
        EXPECT_EQ(AtmosphereToJson(a).find("mie_phase\""), std::string::npos) << preset;
    }
    // A tabulated atmosphere's lobe fields are not read: --set works on any preset.
    const AtmosphereParameters t = LoadAtmosphere(
        "kider-2013-aeronet",
        {"mie_phase={\"kind\": \"tabulated\", \"table\": \"aeronet-egbert-2013-05-27-phase\"}"});
    EXPECT_EQ(t.mie_phase_weight2, 0.0);
    EXPECT_EQ(t.mie_phase_g, t.mie_phase_table.mean_cosine);
}

TEST(MiePhaseKinds, FileFormReadsACsv) {
    const fs::path dir = atmos_test::FreshTestTmpDir("phase_file");
    const fs::path csv = dir / "phase.csv";
    {
        std::ofstream out(csv);
        out << "# a comment\ndeg,a,b\n0,4,40\n90,2,20\n180,1,10\n";
    }
    const AtmosphereParameters a = LoadAtmosphere(
        "earth", {"mie_phase={\"kind\": \"tabulated\", \"file\": \"" + csv.string() + "\"}"});
    const AtmosphereParameters b = LoadAtmosphere(
        "earth",
        {"mie_phase={\"kind\": \"tabulated\", \"file\": \"" + csv.string() + "\", \"column\": 1}"});
    ASSERT_EQ(a.mie_phase_table.count, 3);
    EXPECT_EQ(a.mie_phase_table.value[1], 2.0);
    EXPECT_EQ(b.mie_phase_table.value[1], 20.0);
    // The same shape: the same normalised phase function.
    EXPECT_NEAR(MiePhase(a, 0.3), MiePhase(b, 0.3), 1e-15);
}

TEST(MiePhaseKinds, BadTablesAreRefusedNamingTheField) {
    struct Bad {
        std::string set;
        std::string field;  // the message names it
    };
    const std::string t = "mie_phase={\"kind\": \"tabulated\", ";
    const Bad bad[] = {
        {t + "\"angles_deg\": [0, 90, 80, 180], \"values\": [1, 1, 1, 1]}",
         "mie_phase.angles_deg[2]"},
        {t + "\"angles_deg\": [1, 90, 180], \"values\": [1, 1, 1]}", "mie_phase.angles_deg[0]"},
        {t + "\"angles_deg\": [0, 90, 170], \"values\": [1, 1, 1]}", "mie_phase.angles_deg[2]"},
        {t + "\"angles_deg\": [0, 90, 190], \"values\": [1, 1, 1]}", "mie_phase.angles_deg[2]"},
        {t + "\"angles_deg\": [0, 90, 180], \"values\": [1, -1, 1]}", "mie_phase.values[1]"},
        {t + "\"angles_deg\": [0, 90, 180], \"values\": [1, 0, 1]}", "mie_phase.values[1]"},
        {t + "\"angles_deg\": [0, 90, 180], \"values\": [1, 1]}", "mie_phase"},
        {t + "\"angles_deg\": [0], \"values\": [1]}", "mie_phase"},
        {t + "\"angles_deg\": [0, 180], \"values\": [1, \"x\"]}", "mie_phase.values[1]"},
        {t + "\"values\": [1, 1]}", "mie_phase.angles_deg"},
        {t + "\"table\": \"no-such-table\"}", "mie_phase.table"},
        {t + "\"table\": \"aeronet-egbert-2013-05-27-phase\", \"column\": 9}", "mie_phase.table"},
        {t + "\"file\": \"/nonexistent/phase.csv\"}", "mie_phase.file"},
        {t + "\"angles_deg\": [0, 180], \"values\": [1, 1], \"colour\": 1}", "mie_phase.colour"},
        {"mie_phase=tabulated", "mie_phase"},
        {"mie_phase=rayleigh", "mie_phase"},
        {"mie_phase={\"kind\": \"isotropic\", \"values\": [1]}", "mie_phase.values"},
    };
    for (const Bad& b : bad) {
        try {
            (void)LoadAtmosphere("earth", {b.set});
            ADD_FAILURE() << "accepted: " << b.set;
        } catch (const Error& e) {
            const std::string message = e.what();
            EXPECT_NE(message.find("'" + b.field), std::string::npos) << b.set << " -> " << message;
            EXPECT_EQ(message.find('\n'), std::string::npos) << message;
        }
    }
    // More nodes than the capacity.
    std::string angles, values;
    for (int i = 0; i <= kMaxMiePhaseNodes; ++i) {
        angles += (i ? "," : "") + std::to_string(180.0 * i / kMaxMiePhaseNodes);
        values += std::string(i ? "," : "") + "1";
    }
    EXPECT_THROW((void)LoadAtmosphere("earth", {t + "\"angles_deg\": [" + angles +
                                                "], \"values\": [" + values + "]}"}),
                 Error);
}

// --- The table models with a tabulated Cornette-Shanks -------------------------

// Cornette-Shanks(0.8) tabulated at 256 nodes (denser towards 0 deg) gives the
// same sky as the closed form, within the table's interpolation error, in every
// model that has a Mie phase: the generic paths (bruneton's J sums, the analytic
// media, atmosphere-plus's scale) follow the tabulated kind.
TEST(MiePhaseKinds, TabulatedCornetteShanksMatchesTheClosedFormInTheModels) {
    const AtmosphereParameters cs = EarthAtmosphere();
    AtmosphereParameters tab = cs;
    MiePhaseTable& t = tab.mie_phase_table;
    t.count = kMaxMiePhaseNodes;
    for (int i = 0; i < t.count; ++i) {
        const double s = static_cast<double>(i) / (t.count - 1);
        t.angle_deg[i] = i == t.count - 1 ? 180.0 : 180.0 * s * s;  // denser near 0
        t.value[i] = CornetteShanksPhase(0.8, std::cos(t.angle_deg[i] * kPi / 180.0));
    }
    FinishMiePhaseTable(&t);
    tab.mie_phase_kind = MiePhaseKind::kTabulated;
    ValidateAtmosphere(tab);
    // 30 deg and more from the sun: the interpolation error is small there
    // (measured: at most 2e-5 relative; the tolerance is 0.2 %).
    std::vector<SampleQuery> queries(3);
    queries[0].altitude_m = 100.0, queries[0].mu = 0.5, queries[0].mu_s = 0.3;
    queries[0].azimuth_deg = 90.0;
    queries[1].altitude_m = 100.0, queries[1].mu = 0.1, queries[1].mu_s = 0.2;
    queries[1].azimuth_deg = 180.0;
    queries[2].altitude_m = 1000.0, queries[2].mu = 0.8, queries[2].mu_s = 0.05;
    queries[2].azimuth_deg = 60.0;
    // Small tables: the same code paths at a fraction of the precomputation.
    for (const char* name :
         {"naive", "flat", "oneil", "schuler", "raymarched",
          "bruneton:orders=3:scattering-r=8:scattering-mu=32:scattering-mu-s=8:scattering-nu=4",
          "hillaire", "atmosphere-plus"}) {
        std::unique_ptr<Model> a = CreateModel(ParseModelSpec(name));
        std::unique_ptr<Model> b = CreateModel(ParseModelSpec(name));
        a->Prepare(cs);
        b->Prepare(tab);
        const std::vector<SampleAnswer> ra = a->Sample(queries);
        const std::vector<SampleAnswer> rb = b->Sample(queries);
        for (size_t k = 0; k < queries.size(); ++k) {
            for (int c = 0; c < 3; ++c) {
                EXPECT_NEAR(rb[k].radiance[c], ra[k].radiance[c], 0.002f * ra[k].radiance[c])
                    << name << " query " << k << " channel " << c;
            }
            std::printf("%s query %zu: closed form %.5e, tabulated %.5e\n", name, k,
                        static_cast<double>(ra[k].radiance.y),
                        static_cast<double>(rb[k].radiance.y));
        }
    }
}

// The baked shaders follow the kind: `atmos bake` writes the kind and the table
// as constants, and every stage compiles (glslangValidator; skipped without it).
TEST(MiePhaseKinds, BakedShadersCompileForEveryKind) {
    std::string out;
    if (RunShellCommand("command -v glslangValidator", &out) != 0) {
        GTEST_SKIP() << "glslang-tools not installed (scripts/setup.sh installs them)";
    }
    const fs::path root = atmos_test::FreshTestTmpDir("phase_bake");
    const std::string kinds[] = {
        "henyey-greenstein", "isotropic",
        "'{\"kind\": \"tabulated\", \"table\": \"aeronet-egbert-2013-05-27-phase\"}'"};
    int k = 0;
    for (const std::string& kind : kinds) {
        const std::pair<const char*, const char*> models[] = {
            {"hillaire", "hillaire_constants.glsl"},
            {"atmosphere-plus", "atmosphere_plus_constants.glsl"},
            {"bruneton:orders=1:scattering-r=4:scattering-mu=8:scattering-mu-s=4:scattering-nu=2",
             "bruneton_constants.glsl"}};
        for (const auto& [model, constants_file] : models) {
            // The table (the most constants) in every model's shaders; the other
            // kinds in hillaire's (the shaders share common.glsl's atmos_MiePhase).
            if (k % 3 != 0 && kind.find("tabulated") == std::string::npos) {
                ++k;
                continue;
            }
            const fs::path dir = root / (std::to_string(k++));
            ASSERT_EQ(RunShellCommand(std::string(ATMOS_CLI_PATH) + " bake -q --model " + model +
                                          " --set mie_phase=" + kind + " -o " + dir.string(),
                                      &out),
                      0)
                << out;
            const std::string constants = atmos_test::Slurp(dir / "shaders" / constants_file);
            EXPECT_NE(constants.find("#define ATMOS_MIE_PHASE_KIND "), std::string::npos);
            int stages = 0;
            for (const auto& e : fs::directory_iterator(dir / "shaders" / "vulkan")) {
                const std::string ext = e.path().extension().string();
                if (ext != ".frag" && ext != ".comp") continue;
                ++stages;
                EXPECT_EQ(
                    RunShellCommand("glslangValidator -V --target-env vulkan1.0 -o " +
                                        (dir / "check.spv").string() + " " + e.path().string(),
                                    &out),
                    0)
                    << e.path() << ": " << out;
            }
            EXPECT_GT(stages, 0) << model;
        }
    }
}

// `validate` with a tabulated phase function: the AERONET preset runs through the
// study (in-process, the tests' excerpt of the Kider data), every value answered,
// finite and non-negative, and the table reaches the model: the values differ
// from those of one lobe with the table's mean cosine.
TEST(MiePhaseKinds, ValidateRunsWithATabulatedPhase) {
    auto run = [](const std::string& atmosphere, const std::vector<std::string>& sets) {
        ValidateConfig config;
        config.sets = sets;
        config.data_dir = (fs::path(ATMOS_SOURCE_DIR) / "tests" / "data" / "kider-2013").string();
        config.models = {"reference", "naive:steps=8:light-steps=4"};
        config.spp = 4;
        config.atmosphere = atmosphere;
        config.captures = {"12:45"};
        config = ResolveValidateConfig(config);
        return RunValidate(config, ReadValidateData(config));
    };
    // The comparison: one Cornette-Shanks lobe with the table's mean cosine (what a
    // model would see if the table were lost on the way and only its g kept).
    char g[64];
    std::snprintf(g, sizeof(g), "mie_phase_g=%.17g",
                  LoadAtmosphere("kider-2013-aeronet-tabulated").mie_phase_g);
    const ValidateResult tabulated = run("kider-2013-aeronet-tabulated", {});
    const ValidateResult lobes = run("kider-2013-aeronet", {g, "mie_phase_weight2=0"});
    ASSERT_EQ(tabulated.models.size(), 2u);
    for (size_t k = 0; k < tabulated.models.size(); ++k) {
        const ValidateModelResult& m = tabulated.models[k];
        ASSERT_EQ(m.values.size(), tabulated.samples.size() * tabulated.nm.size());
        ASSERT_EQ(m.values.size(), lobes.models[k].values.size());
        size_t differ = 0;
        for (size_t i = 0; i < m.values.size(); ++i) {
            EXPECT_TRUE(std::isfinite(m.values[i]) && m.values[i] >= 0.0) << m.model;
            if (m.values[i] != lobes.models[k].values[i]) ++differ;
        }
        EXPECT_GT(differ, m.values.size() / 2) << m.model;
        const ValidateErrorRow* all = m.Find("all", "all", "all");
        ASSERT_NE(all, nullptr);
        std::printf("%s: relative RMSE %.2f %% (one lobe, same g: %.2f %%)\n", m.model.c_str(),
                    100.0 * all->error.RelativeRmse(),
                    100.0 * lobes.models[k].Find("all", "all", "all")->error.RelativeRmse());
    }
}

}  // namespace
}  // namespace atmos
