// Tests of the comparison harness: metric CSV layout, lines-of-code counter,
// render cache, validity flags, and the `flip` / `rmse` / `compare` / `loc` CLI.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "atmos/atmosphere.h"
#include "atmos/image.h"
#include "atmos/model.h"
#include "atmos/view.h"
#include "harness/compare.h"
#include "harness/loc.h"
#include "harness/render_cache.h"
#include "harness/shipped_references.h"
#include "harness/table_cache.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace atmos {
namespace {

using atmos_test::Slurp;
using CliRun = atmos_test::CommandOutcome;

fs::path TempDir(const std::string& name) {
    return atmos_test::FreshTestTmpDir("harness_" + name + "_" + std::to_string(getpid()));
}

// A shell command line, its stdout and stderr.
CliRun Shell(const std::string& command, const fs::path& dir) {
    return atmos_test::RunCapturing(command, dir / "stdout", dir / "stderr");
}

CliRun Atmos(const std::string& args, const fs::path& dir) {
    return Shell(std::string(ATMOS_CLI_PATH) + " " + args, dir);
}

// The last number printed on stdout.
double LastNumber(const std::string& text) {
    size_t end = text.find_last_of("0123456789");
    EXPECT_NE(end, std::string::npos);
    size_t begin = text.find_last_not_of("0123456789.e-+", end);
    return std::stod(text.substr(begin + 1, end - begin));
}

TEST(MetricCsv, LayoutLikeTheThesisAppendix) {
    const fs::path dir = TempDir("csv");
    const fs::path path = dir / "flip.csv";
    WriteMetricCsv(path.string(), "FLIP errors", {"ground-dawn", "space"}, {"a", "b", "c"},
                   {{0.5, 0.25, 0.75}, {0.125, std::nan(""), 0.0625}});
    EXPECT_EQ(Slurp(path),
              "FLIP errors,a,b,c,best\n"
              "ground-dawn,0.5,0.25,0.75,b\n"
              "space,0.125,,0.0625,c\n");
    EXPECT_EQ(BestIndex({std::nan(""), 3.0, 2.0}), 2);
    EXPECT_EQ(BestIndex({std::nan("")}), -1);
}

TEST(Loc, FixtureFileHasTheKnownCount) {
    const std::string fixture = DefaultSourceDir() + "/tests/data/loc_fixture.cpp";
    EXPECT_EQ(CountSignificantLinesInFile(fixture), 8);
    EXPECT_EQ(CountSignificantLines("}\n);\n  \n// x\n/* y */\nint a;\n#define Q 1\n"), 1);
    EXPECT_EQ(CountSignificantLines("/* open\nint hidden;\n*/ int shown;\n"), 1);
}

TEST(Loc, FindsAModelsOwnFiles) {
    const std::vector<std::string> files = ModelSourceFiles(DefaultSourceDir(), "naive");
    ASSERT_EQ(files.size(), 2u);
    EXPECT_EQ(files[0], "src/atmos/models/naive.cpp");
    EXPECT_EQ(files[1], "src/atmos/models/naive.h");
    const ModelLoc loc = CountModelLoc(DefaultSourceDir(), "naive");
    EXPECT_GT(loc.lines, 20);
    EXPECT_EQ(loc.thesis_lines, 118);  // Leenman's 2025 thesis section 12.4
    EXPECT_EQ(ThesisLoc("bruneton"), 832);
    EXPECT_EQ(ThesisLoc("no-such-model"), -1);
}

TEST(RenderCache, RoundTripAndKeying) {
    const fs::path dir = TempDir("cache");
    const RenderCache cache(dir.string());
    RenderKey key;
    key.model = "naive";
    key.options = ResolvedModelOptions("naive", {{"steps", "4"}});
    EXPECT_EQ(key.options.at("light-steps"), "8");  // defaults are part of the key
    key.atmosphere_json = AtmosphereToJson(LoadAtmosphere("earth", {}));
    key.view = "space";
    key.width = 3;
    key.height = 2;
    Image img(3, 2);
    img.Set(2, 1, Rgb(1.0f, 2.0f, 3.0f));
    Image loaded;
    double seconds = 0.0;
    EXPECT_FALSE(cache.Load(key, &loaded, &seconds));
    cache.Store(key, img, 1.5);
    ASSERT_TRUE(cache.Load(key, &loaded, &seconds));
    EXPECT_EQ(seconds, 1.5);
    EXPECT_EQ(loaded.Get(2, 1).z, 3.0f);
    RenderKey other = key;
    other.view = "ground-noon";
    EXPECT_FALSE(cache.Load(other, &loaded, &seconds));
    other = key;
    other.options["steps"] = "5";
    EXPECT_FALSE(cache.Load(other, &loaded, &seconds));
    other = key;
    other.atmosphere_json = AtmosphereToJson(LoadAtmosphere("earth", {"ground_albedo=0.3"}));
    EXPECT_FALSE(cache.Load(other, &loaded, &seconds));
    other = key;
    other.quantity = Quantity::kTransmittance;
    EXPECT_FALSE(cache.Load(other, &loaded, &seconds));
    EXPECT_FALSE(RenderCache("").Load(key, &loaded, &seconds));
    // An image another build stored (same key otherwise) is not reused: edit the
    // stored key text's build line as an older executable would have written it.
    const std::string id = CodeIdentity();
    EXPECT_EQ(id.size(), 16u);
    EXPECT_EQ(id, CodeIdentity());
    EXPECT_NE(RenderKeyText(key).find("build " + id + "\n"), std::string::npos);
    const fs::path meta = fs::path(cache.ImagePath(key)).replace_extension(".json");
    ASSERT_TRUE(fs::exists(meta)) << meta;
    std::string text;
    {
        std::ifstream in(meta);
        text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    const size_t at = text.find(id);
    ASSERT_NE(at, std::string::npos);
    text.replace(at, id.size(), std::string(16, '0'));
    {
        std::ofstream out(meta);
        out << text;
    }
    EXPECT_FALSE(cache.Load(key, &loaded, &seconds));
}

// An option naming a file (neural's weights, hosek-wilkie's coefficients):
// the file rewritten in place is a new key, so a refit into the same path is
// never answered with the old fit's cached image.
TEST(RenderCache, AnOptionsFileIsKeyedByItsContent) {
    const fs::path dir = TempDir("cache-file-option");
    const RenderCache cache(dir.string());
    const fs::path file = dir / "coefficients.json";
    {
        std::ofstream out(file);
        out << "first fit\n";
    }
    RenderKey key;
    key.model = "hosek-wilkie";
    key.options = {{"coefficients", file.string()}};
    key.atmosphere_json = AtmosphereToJson(LoadAtmosphere("earth", {}));
    key.view = "ground-noon";
    key.width = 2;
    key.height = 1;
    const std::string first = RenderKeyText(key);
    EXPECT_NE(first.find(" file-fnv1a="), std::string::npos) << first;
    Image img(2, 1);
    img.Set(1, 0, Rgb(1.0f, 2.0f, 3.0f));
    cache.Store(key, img, 0.5);
    Image loaded;
    double seconds = 0.0;
    ASSERT_TRUE(cache.Load(key, &loaded, &seconds));
    {
        std::ofstream out(file);
        out << "second fit\n";
    }
    EXPECT_NE(RenderKeyText(key), first);
    EXPECT_FALSE(cache.Load(key, &loaded, &seconds));
    // A value that is not a file is keyed by its text alone.
    key.options = {{"coefficients", (dir / "no-such-file.json").string()}};
    EXPECT_EQ(RenderKeyText(key).find(" file-fnv1a="), std::string::npos);
}

// Issue 22: a Monte Carlo render's variance travels with its image, and a
// model's precomputation record (seconds, table bytes) is kept per model.
TEST(RenderCache, KeepsTheVarianceAndThePrepareRecord) {
    const fs::path dir = TempDir("cache_prepare");
    const RenderCache cache(dir.string());
    RenderKey key;
    key.model = "reference";
    key.options = ResolvedModelOptions("reference", {});
    key.atmosphere_json = AtmosphereToJson(LoadAtmosphere("earth", {}));
    key.view = "space";
    key.width = 3;
    key.height = 2;
    key.monte_carlo = true;
    Image img(3, 2), variance(3, 2);
    variance.Set(1, 1, Rgb(0.25f, 0.5f, 0.75f));
    MonteCarloReport report;
    report.samples = 8;
    report.noise = 0.02;
    cache.Store(key, img, 2.0, &report, &variance);
    Image loaded, loaded_variance;
    double seconds = 0.0;
    ASSERT_TRUE(cache.Load(key, &loaded, &seconds, nullptr, &loaded_variance));
    ASSERT_EQ(loaded_variance.width(), 3);
    EXPECT_EQ(loaded_variance.Get(1, 1).y, 0.5f);
    // Stored without one: none comes back.
    RenderKey plain = key;
    plain.view = "ground-noon";
    cache.Store(plain, img, 2.0, &report);
    ASSERT_TRUE(cache.Load(plain, &loaded, &seconds, nullptr, &loaded_variance));
    EXPECT_EQ(loaded_variance.size(), 0u);

    double prepare = 0.0;
    int64_t bytes = 0;
    EXPECT_FALSE(cache.LoadPrepare(key, &prepare, &bytes));
    cache.StorePrepare(key, 12.5, 4096);
    ASSERT_TRUE(cache.LoadPrepare(plain, &prepare, &bytes));  // the view does not matter
    EXPECT_EQ(prepare, 12.5);
    EXPECT_EQ(bytes, 4096);
    RenderKey other = key;
    other.options["max-order"] = "2";
    EXPECT_FALSE(cache.LoadPrepare(other, &prepare, &bytes));
    fs::remove_all(dir);
}

TEST(Compare, ValidityFlags) {
    const AtmosphereParameters atm = LoadAtmosphere("earth", {});
    ModelCapabilities ground_only;
    ground_only.space_views = false;
    EXPECT_EQ(ValidityNote(ground_only, GetView("ground-noon", atm), atm), "");
    EXPECT_NE(ValidityNote(ground_only, GetView("plane-noon", atm), atm), "");
    EXPECT_NE(ValidityNote(ground_only, GetView("space", atm), atm), "");
    ModelCapabilities day_only;
    day_only.sun_below_horizon = false;
    EXPECT_NE(ValidityNote(day_only, GetView("ground-dawn", atm), atm), "");
    EXPECT_EQ(ValidityNote(day_only, GetView("ground-sunrise", atm), atm), "");
    EXPECT_EQ(CompareRowLabel("plane-noon", Quantity::kTransmittance), "plane");
    EXPECT_EQ(DefaultCompareViews(Quantity::kRadiance).size(), 12u);
    EXPECT_EQ(DefaultCompareViews(Quantity::kTransmittance).size(), 5u);
}

TEST(Cli, FlipAndRmseOfTwoImages) {
    const fs::path dir = TempDir("flipcli");
    Image a(40, 30), b(40, 30);
    for (int y = 0; y < 30; ++y) {
        for (int x = 0; x < 40; ++x) {
            a.Set(x, y, Rgb(0.1f * static_cast<float>(x % 7), 0.3f, 0.02f * static_cast<float>(y)));
            b.Set(x, y, a.Get(x, y) * (x < 20 ? 1.0f : 1.5f));
        }
    }
    WriteImage(a, (dir / "a.exr").string());
    WriteImage(b, (dir / "b.npy").string());
    WriteImage(a, (dir / "a.png").string());
    WriteImage(b, (dir / "b.png").string());
    CliRun same = Atmos("flip " + (dir / "a.exr").string() + " " + (dir / "a.exr").string(), dir);
    ASSERT_EQ(same.status, 0) << same.err;
    EXPECT_EQ(LastNumber(same.out), 0.0);
    EXPECT_NE(same.out.find("HDR-FLIP"), std::string::npos);
    CliRun diff = Atmos("flip " + (dir / "a.exr").string() + " " + (dir / "b.npy").string() +
                            " -o " + (dir / "map.png").string(),
                        dir);
    ASSERT_EQ(diff.status, 0) << diff.err;
    EXPECT_GT(LastNumber(diff.out), 0.01);
    EXPECT_EQ(ReadImage((dir / "map.png").string()).width(), 40);
    CliRun ldr = Atmos("flip " + (dir / "a.png").string() + " " + (dir / "b.png").string(), dir);
    ASSERT_EQ(ldr.status, 0) << ldr.err;
    EXPECT_NE(ldr.out.find("LDR-FLIP"), std::string::npos);
    EXPECT_GT(LastNumber(ldr.out), 0.0);
    CliRun rmse = Atmos("rmse " + (dir / "a.exr").string() + " " + (dir / "a.exr").string(), dir);
    ASSERT_EQ(rmse.status, 0) << rmse.err;
    EXPECT_EQ(LastNumber(rmse.out), 0.0);
    Image c(40, 31);
    WriteImage(c, (dir / "c.exr").string());
    CliRun bad = Atmos("flip " + (dir / "a.exr").string() + " " + (dir / "c.exr").string(), dir);
    EXPECT_EQ(bad.status, 2);
    EXPECT_NE(bad.err.find("same size"), std::string::npos);
    CliRun bad_tm = Atmos(
        "flip " + (dir / "a.exr").string() + " " + (dir / "a.exr").string() + " --tonemapper nope",
        dir);
    EXPECT_EQ(bad_tm.status, 2);
}

TEST(Cli, LocCountsTheFixture) {
    const fs::path dir = TempDir("loccli");
    CliRun r = Atmos("loc --file " + DefaultSourceDir() + "/tests/data/loc_fixture.cpp", dir);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(LastNumber(r.out), 8.0);
    CliRun m = Atmos("loc naive", dir);
    ASSERT_EQ(m.status, 0) << m.err;
    EXPECT_NE(m.out.find("naive.cpp"), std::string::npos);
}

TEST(Cli, CompareWritesTablesImagesAndUsesTheCache) {
    const fs::path dir = TempDir("compare");
    const std::string args =
        "compare --models empty,naive --views ground-noon,space --size 24x14 --reference "
        "naive:steps=24:light-steps=8 --cache " +
        (dir / "cache").string() + " -o " + (dir / "out").string();
    CliRun first = Atmos(args, dir);
    ASSERT_EQ(first.status, 0) << first.err;
    const std::string flip = Slurp(dir / "out" / "flip.csv");
    EXPECT_EQ(flip.substr(0, flip.find('\n')), "FLIP errors,empty,naive,best");
    EXPECT_NE(flip.find("\nground-noon,"), std::string::npos);
    EXPECT_NE(flip.find("\nspace,"), std::string::npos);
    EXPECT_EQ(Slurp(dir / "out" / "rmse.csv").substr(0, 28), "RMSE errors,empty,naive,best");
    for (const char* f : {"images/space/reference.png", "images/space/naive.exr",
                          "images/space/naive.npy", "errors/space/naive-flip.png",
                          "errors/space/empty-rmse.exr", "index.html", "times.csv"}) {
        EXPECT_TRUE(fs::exists(dir / "out" / f)) << f;
    }
    EXPECT_EQ(first.err.find("cached"), std::string::npos);
    CliRun second = Atmos(args, dir);
    ASSERT_EQ(second.status, 0) << second.err;
    EXPECT_NE(second.err.find("reference (naive) cached"), std::string::npos) << second.err;
    EXPECT_EQ(Slurp(dir / "out" / "flip.csv"), flip);  // same images -> same numbers
    CliRun bad = Atmos("compare --models nope -o " + (dir / "x").string(), dir);
    EXPECT_EQ(bad.status, 2);
    CliRun spp =
        Atmos("compare --reference naive --reference-spp 4 -o " + (dir / "x").string(), dir);
    EXPECT_EQ(spp.status, 2);
}

// A path-traced reference is two independent halves, averaged; their HDR-FLIP
// is the reference's noise, reported per view, and FLIPs at or below it are
// marked as unresolved.
TEST(Cli, CompareMeasuresTheReferencesNoise) {
    const fs::path dir = TempDir("compare-noise");
    const std::string args =
        "compare --models empty,naive --views space,ground-noon --size 32x18 --reference-spp 4 "
        "--cache " +
        (dir / "cache").string() + " -o " + (dir / "out").string();
    CliRun r = Atmos(args, dir);
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string noise_csv = Slurp(dir / "out" / "reference_noise.csv");
    std::istringstream noise(noise_csv);
    std::string line;
    std::getline(noise, line);
    EXPECT_EQ(line, "view,reference_noise_flip,half_spp,noise_target,source,provenance");
    std::map<std::string, double> floor;
    while (std::getline(noise, line)) {
        std::vector<std::string> f;
        std::istringstream fields(line);
        for (std::string x; std::getline(fields, x, ',');) f.push_back(x);
        ASSERT_EQ(f.size(), 5u) << line;  // the provenance (shipped only) is empty
        EXPECT_EQ(f[4], "rendered");
        floor[f[0]] = std::stod(f[1]);
        EXPECT_EQ(f[2], "2");  // two halves of 2 spp
        EXPECT_EQ(f[3], "0");  // --reference-spp alone: no noise target
    }
    ASSERT_EQ(floor.size(), 2u);
    for (const auto& [view, flip] : floor) {
        EXPECT_GT(flip, 0.0) << view;  // different seeds differ
        EXPECT_LT(flip, 1.0) << view;
    }
    // The white `empty` sky is far above the reference's noise.
    std::istringstream flips(Slurp(dir / "out" / "flip.csv"));
    std::getline(flips, line);
    EXPECT_EQ(line, "FLIP errors,empty,naive,best");
    while (std::getline(flips, line)) {
        const std::string view = line.substr(0, line.find(','));
        const double empty = std::stod(line.substr(line.find(',') + 1));
        EXPECT_GT(empty, floor.at(view)) << view;
    }
    EXPECT_NE(Slurp(dir / "out" / "index.html").find("reference noise</th>"), std::string::npos);
    // Both halves come from the cache on a second run: the same noise.
    CliRun again = Atmos(args, dir);
    ASSERT_EQ(again.status, 0) << again.err;
    EXPECT_NE(again.err.find("reference (reference) cached"), std::string::npos) << again.err;
    std::string cached_csv = Slurp(dir / "out" / "reference_noise.csv");
    for (size_t i = 0; (i = cached_csv.find(",cached,", i)) != std::string::npos;) {
        cached_csv.replace(i, 8, ",rendered,");  // the source column says where it came from
    }
    EXPECT_EQ(cached_csv, noise_csv);
}

// A noise target: each view's reference renders until the FLIP between its
// halves is at or below it (reached and reported per view), or stops at the
// --reference-spp cap (reported above the target).
TEST(Cli, CompareRendersTheReferenceToANoiseTarget) {
    const fs::path dir = TempDir("compare-noise-target");
    auto run = [&](const std::string& target, const std::string& cap) {
        const std::string args =
            "compare --models empty --views space,ground-noon --size 32x18 "
            "--reference-noise " +
            target + " --reference-spp " + cap + " --no-cache -o " + (dir / "out").string();
        CliRun r = Atmos(args, dir);
        EXPECT_EQ(r.status, 0) << r.err;
        std::istringstream noise(Slurp(dir / "out" / "reference_noise.csv"));
        std::string line;
        std::getline(noise, line);
        std::vector<std::vector<std::string>> rows;
        while (std::getline(noise, line)) {
            std::vector<std::string> f;
            std::istringstream fields(line);
            for (std::string x; std::getline(fields, x, ',');) f.push_back(x);
            rows.push_back(f);
        }
        return rows;
    };
    // Reachable: at or below the target, with more than the first pair of passes
    // somewhere (the first check is at 2 x 16 paths).
    for (const auto& f : run("0.2", "4096")) {
        ASSERT_EQ(f.size(), 5u);
        EXPECT_LE(std::stod(f[1]), 0.2) << f[0];
        EXPECT_GE(std::stoll(f[2]), 8) << f[0];
        EXPECT_EQ(std::stod(f[3]), 0.2);
    }
    // Unreachable within the cap: stops at the cap, above the target.
    for (const auto& f : run("0.0001", "16")) {
        ASSERT_EQ(f.size(), 5u);
        EXPECT_GT(std::stod(f[1]), 0.0001) << f[0];
        EXPECT_EQ(f[2], "8") << f[0];  // two halves of 8 paths
    }
}

// Variants of one model side by side: NAME:OPTION=VALUE specs. More view-ray
// steps bring naive closer to a 256-step naive reference.
TEST(Cli, CompareTakesModelVariants) {
    const fs::path dir = TempDir("compare-variants");
    const std::string out = (dir / "out").string();
    CliRun r = Atmos(
        "compare --models naive:steps=2,naive:steps=64:light-steps=16 --views ground-sunrise "
        "--size 24x14 --reference naive:steps=256:light-steps=64 --no-cache -o " +
            out,
        dir);
    ASSERT_EQ(r.status, 0) << r.err;
    std::istringstream flip(Slurp(dir / "out" / "flip.csv"));
    std::string header, row;
    std::getline(flip, header);
    std::getline(flip, row);
    EXPECT_EQ(header, "FLIP errors,naive:steps=2,naive:steps=64:light-steps=16,best");
    std::istringstream cells(row);
    std::string view, coarse, fine, best;
    std::getline(cells, view, ',');
    std::getline(cells, coarse, ',');
    std::getline(cells, fine, ',');
    std::getline(cells, best, ',');
    EXPECT_LT(std::stod(fine), std::stod(coarse));
    EXPECT_EQ(best, "naive:steps=64:light-steps=16");
    EXPECT_TRUE(fs::exists(dir / "out" / "images" / "ground-sunrise" / "naive_steps_2.png"));
    for (const char* bad :
         {"naive:steps", "naive:nope=3", "naive:steps=0", "naive:steps=2:steps=3", "naive,naive"}) {
        CliRun b = Atmos(std::string("compare --models ") + bad + " -o " + out, dir);
        EXPECT_EQ(b.status, 2) << bad;
        EXPECT_NE(b.err.find("error"), std::string::npos) << bad << ": " << b.err;
    }
}

// Shipped references (harness/shipped_references.h, issue 16 item 4).

// The fingerprint resolves what was rendered: default options spelled out or
// not are the same render; an atmosphere field, another view, an option and
// the size are not.
TEST(ShippedReferences, FingerprintIdentifiesTheRender) {
    const AtmosphereParameters earth = LoadAtmosphere("earth", {});
    const std::vector<View> views = {GetView("ground-noon", earth), GetView("ground-dawn", earth)};
    const ReferenceFingerprint a =
        MakeReferenceFingerprint("reference", {}, "earth", earth, 16, 9, views);
    const ReferenceFingerprint b = MakeReferenceFingerprint("reference", {{"estimator", "hybrid"}},
                                                            "earth", earth, 16, 9, views);
    EXPECT_EQ(a.model, b.model);
    EXPECT_NE(a.model.find(":estimator=hybrid"), std::string::npos) << a.model;
    EXPECT_EQ(a.atmosphere_hash, b.atmosphere_hash);
    EXPECT_NE(a.view_hashes.at("ground-noon"), a.view_hashes.at("ground-dawn"));
    const AtmosphereParameters albedo = LoadAtmosphere("earth", {"ground_albedo=0.31"});
    const ReferenceFingerprint c =
        MakeReferenceFingerprint("reference", {}, "earth", albedo, 16, 9, views);
    EXPECT_NE(a.atmosphere_hash, c.atmosphere_hash);
    const ReferenceFingerprint d =
        MakeReferenceFingerprint("reference", {{"max-order", "4"}}, "earth", earth, 16, 9, views);
    EXPECT_NE(a.model, d.model);
    // A view is its camera and sun: moving the sun changes its hash.
    View moved = views[0];
    moved.sun_direction = Normalize(moved.sun_direction + Vec3d{0.0, 1e-9, 0.0});
    EXPECT_NE(HashText(ViewFingerprintText(moved)), a.view_hashes.at("ground-noon"));
}

// The shipped references (data/references/*) are fingerprinted with the
// default reference's resolved options: a new option of the reference (or a
// changed default) must be recorded there, else `compare` silently re-renders
// every reference ("reference model options differ").
TEST(ShippedReferences, FingerprintsNameTheDefaultReference) {
    const AtmosphereParameters earth = LoadAtmosphere("earth", {});
    const ReferenceFingerprint run =
        MakeReferenceFingerprint("reference", {}, "earth", earth, 16, 9, {});
    int count = 0;
    for (const auto& entry :
         fs::directory_iterator(fs::path(ATMOS_SOURCE_DIR) / "data" / "references")) {
        if (!fs::exists(entry.path() / "provenance.json")) continue;
        const ShippedReferences shipped = ReadShippedReferences(entry.path().string());
        EXPECT_EQ(shipped.fingerprint.model, run.model) << entry.path();
        EXPECT_EQ(shipped.fingerprint.estimator_version, run.estimator_version) << entry.path();
        ++count;
    }
    EXPECT_GE(count, 2);
}

// The noise rule: a shipped image is used when its noise is at or below the
// target, or it has at least the run's paths per pixel (cap or fixed count).
TEST(ShippedReferences, UsedWhenAtLeastAsGoodAsTheRunsRender) {
    const AtmosphereParameters earth = LoadAtmosphere("earth", {});
    const ReferenceFingerprint run = MakeReferenceFingerprint("reference", {}, "earth", earth, 16,
                                                              9, {GetView("ground-noon", earth)});
    ShippedReferences shipped;
    shipped.fingerprint = run;
    shipped.views.push_back({"ground-noon", run.view_hashes.at("ground-noon"), 1024, 0.02, ""});
    EXPECT_EQ(ShippedMismatch(shipped, run, "ground-noon", 0.02, 512), "");
    EXPECT_EQ(ShippedMismatch(shipped, run, "ground-noon", 0.01, 1024), "");
    EXPECT_EQ(ShippedMismatch(shipped, run, "ground-noon", 0.0, 1024), "");  // a fixed count
    EXPECT_NE(ShippedMismatch(shipped, run, "ground-noon", 0.01, 2048).find("above the target"),
              std::string::npos);
    EXPECT_NE(ShippedMismatch(shipped, run, "ground-noon", 0.0, 2048), "");
    EXPECT_EQ(ShippedMismatch(shipped, run, "ground-dawn", 0.02, 512),
              "no shipped image of this view");
    ReferenceFingerprint other = run;
    other.estimator_version += 1;
    other.width = 32;
    EXPECT_EQ(ShippedMismatch(shipped, other, "ground-noon", 0.02, 512),
              "estimator version differs (shipped " + std::to_string(run.estimator_version) +
                  ", this build " + std::to_string(other.estimator_version) +
                  "); size differs (shipped 16x9)");
}

// A shipped set made by scripts/make_references.sh (ground-noon, 16x9, to a
// noise of 0.2: about a second); `resume`: the script skips it when run again.
fs::path MakeShippedSet(const fs::path& dir, bool resume = false) {
    const fs::path set = dir / "shipped";
    const std::string script = std::string("ATMOS=") + ATMOS_CLI_PATH + " " + ATMOS_SOURCE_DIR +
                               "/scripts/make_references.sh " + set.string() +
                               " 16x9 0.2 64 ground-noon";
    CliRun made = Shell(script, dir);
    EXPECT_EQ(made.status, 0) << made.err;
    EXPECT_NE(made.err.find("ground-noon: to render: no provenance"), std::string::npos)
        << made.err;
    if (!resume) return set;
    CliRun again = Shell(script, dir);
    EXPECT_EQ(again.status, 0) << again.err;
    EXPECT_NE(again.err.find("ground-noon: shipped reference kept"), std::string::npos)
        << again.err;
    EXPECT_EQ(again.err.find("to render"), std::string::npos) << again.err;
    return set;
}

// The reference_noise.csv rows (view -> fields).
std::map<std::string, std::vector<std::string>> NoiseRows(const fs::path& csv) {
    std::map<std::string, std::vector<std::string>> rows;
    std::istringstream in(Slurp(csv));
    std::string line;
    std::getline(in, line);
    EXPECT_EQ(line, "view,reference_noise_flip,half_spp,noise_target,source,provenance");
    while (std::getline(in, line)) {
        std::vector<std::string> f;
        std::istringstream fields(line);
        for (std::string x; std::getline(fields, x, ',');) f.push_back(x);
        if (!f.empty()) rows[f[0]] = f;
    }
    return rows;
}

// compare reads a matching shipped image instead of rendering the reference,
// and says so in stderr, reference_noise.csv and the report; its noise ranks.
TEST(Cli, CompareReadsAMatchingShippedReference) {
    const fs::path dir = TempDir("shipped-match");
    const fs::path set = MakeShippedSet(dir, true);
    std::ifstream in(set / "provenance.json");
    const nlohmann::json provenance = nlohmann::json::parse(in);
    const nlohmann::json& entry = provenance.at("views").at(0);
    CliRun r = Atmos(
        "compare --models empty --views ground-noon --size 16x9 --reference-noise "
        "0.2 --no-cache --shipped-references " +
            set.string() + " -o " + (dir / "out").string(),
        dir);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("reference (reference) shipped"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("reference (reference) rendered"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("not used"), std::string::npos) << r.err;
    const auto rows = NoiseRows(dir / "out" / "reference_noise.csv");
    ASSERT_EQ(rows.count("ground-noon"), 1u);
    const std::vector<std::string>& f = rows.at("ground-noon");
    ASSERT_EQ(f.size(), 6u);
    EXPECT_NEAR(std::stod(f[1]), entry.at("noise").get<double>(), 1e-9);
    EXPECT_EQ(std::stoll(f[2]), entry.at("paths_per_pixel").get<int64_t>() / 2);
    EXPECT_EQ(f[4], "shipped");
    EXPECT_NE(f[5].find("provenance.json"), std::string::npos);
    const Image shipped = ReadImage((set / "ground-noon.exr").string());
    const Image used =
        ReadImage((dir / "out" / "images" / "ground-noon" / "reference.exr").string());
    ASSERT_EQ(used.size(), shipped.size());
    for (size_t i = 0; i < used.size(); ++i) ASSERT_EQ(used.data()[i], shipped.data()[i]) << i;
    EXPECT_NE(Slurp(dir / "out" / "index.html").find("shipped: "), std::string::npos);
}

// A changed atmosphere, reference option, view or estimator version, and a
// damaged set: compare renders instead and names the cause in one line.
TEST(Cli, CompareRendersWhenTheShippedReferenceIsStale) {
    const fs::path dir = TempDir("shipped-stale");
    const fs::path set = MakeShippedSet(dir);
    const std::string provenance = Slurp(set / "provenance.json");
    auto run = [&](const std::string& extra) {
        CliRun r = Atmos(
            "compare --models empty --views ground-noon --size 16x9 "
            "--reference-noise 0.2 --reference-spp 64 --no-cache "
            "--shipped-references " +
                set.string() + " -o " + (dir / "out").string() + " " + extra,
            dir);
        EXPECT_EQ(r.status, 0) << r.err;
        EXPECT_NE(r.err.find("reference (reference) rendered"), std::string::npos) << r.err;
        EXPECT_EQ(NoiseRows(dir / "out" / "reference_noise.csv").at("ground-noon").at(4),
                  "rendered");
        return r.err;
    };
    auto expect_line = [](const std::string& err, const std::string& line) {
        EXPECT_NE(err.find(line + "\n"), std::string::npos) << err;
    };
    expect_line(run("--set rayleigh_scattering=6.38e-6,1.491e-5,3.641e-5"),
                "ground-noon: shipped reference not used: atmosphere differs (shipped earth)");
    EXPECT_NE(run("--reference reference:max-order=4")
                  .find("ground-noon: shipped reference not used: reference model options differ"),
              std::string::npos);
    nlohmann::json edited = nlohmann::json::parse(provenance);
    edited["views"][0]["view_hash"] = "fnv1a64:0000000000000000";
    edited["fingerprint"]["estimator_version"] = 0;
    std::ofstream(set / "provenance.json") << edited.dump(1);
    const std::string both = run("");
    EXPECT_NE(both.find("ground-noon: shipped reference not used: estimator version differs "
                        "(shipped 0, this build "),
              std::string::npos)
        << both;
    EXPECT_NE(both.find("); view differs\n"), std::string::npos) << both;
    // Damaged: a warning, and the run goes on.
    std::ofstream(set / "provenance.json") << provenance.substr(0, provenance.size() / 2);
    const std::string bad = run("");
    EXPECT_NE(bad.find("atmos: warning: shipped references not used: " +
                       (set / "provenance.json").string() + ": invalid JSON"),
              std::string::npos)
        << bad;
    std::ofstream(set / "provenance.json") << provenance;
    Image variance = ReadImage((set / "ground-noon.variance.exr").string());
    variance.data()[5] = std::nanf("");
    WriteImage(variance, (set / "ground-noon.variance.exr").string());
    expect_line(run(""), "ground-noon: shipped reference not used: " +
                             (set / "ground-noon.variance.exr").string() +
                             " holds a NaN, infinite or negative value");
    fs::remove(set / "ground-noon.variance.exr");
    expect_line(run(""), "ground-noon: shipped reference not used: " +
                             (set / "ground-noon.variance.exr").string() + " is missing");
    // Flags: a missing directory, both flags, transmittance.
    const std::string base =
        "compare --models empty --views ground-noon --size 16x9 -o " + (dir / "x").string() + " ";
    CliRun missing = Atmos(base + "--shipped-references " + (dir / "nope").string(), dir);
    EXPECT_EQ(missing.status, 2);
    EXPECT_NE(missing.err.find("is not a directory"), std::string::npos) << missing.err;
    EXPECT_EQ(Atmos(base + "--shipped-references " + set.string() + " --no-shipped-references", dir)
                  .status,
              2);
    EXPECT_EQ(
        Atmos(base + "--quantity transmittance --shipped-references " + set.string(), dir).status,
        2);
    // The recorder: a malformed entry is one error line.
    CliRun entry = Atmos("reference-provenance --views ground-noon --size 16x9 --record " +
                             (dir / "rec").string() +
                             " --entry '{\"view\":\"ground-noon\",\"paths_per_pixel\":0,"
                             "\"noise\":0.1}'",
                         dir);
    EXPECT_EQ(entry.status, 2);
    EXPECT_EQ(entry.err,
              "atmos: error: reference-provenance --record: the entry: paths_per_pixel must be "
              "positive and noise in [0, 1)\n");
}

// By default compare looks in data/references/WxH of the source tree when the
// reference renders to a noise target; a fixed --reference-spp uses shipped
// references only when named; --no-shipped-references never.
TEST(Cli, CompareLooksForShippedReferencesOfItsSize) {
    const fs::path dir = TempDir("shipped-default");
    const fs::path set = MakeShippedSet(dir);
    const fs::path tree = dir / "tree";
    fs::create_directories(tree / "data" / "references");
    fs::copy(set, tree / "data" / "references" / "16x9");
    fs::create_directory_symlink(fs::path(ATMOS_SOURCE_DIR) / "src", tree / "src");
    ::setenv("ATMOS_SOURCE_DIR", tree.c_str(), 1);
    auto source = [&](const std::string& extra) {
        CliRun r = Atmos("compare --models empty --views ground-noon --size 16x9 --no-cache -o " +
                             (dir / "out").string() + " " + extra,
                         dir);
        EXPECT_EQ(r.status, 0) << r.err;
        return NoiseRows(dir / "out" / "reference_noise.csv").at("ground-noon").at(4);
    };
    EXPECT_EQ(source("--reference-noise 0.2"), "shipped");
    EXPECT_EQ(source("--reference-noise 0.2 --no-shipped-references"), "rendered");
    EXPECT_EQ(source("--reference-spp 4"), "rendered");
    EXPECT_EQ(source("--reference-spp 4 --shipped-references " +
                     (tree / "data" / "references" / "16x9").string()),
              "shipped");
    ::unsetenv("ATMOS_SOURCE_DIR");
}

}  // namespace
}  // namespace atmos
