// The studies as a library (src/atmos/studies/, issue 30 item 1): each study's
// run in-process on small inputs, and each writer on a fixed, hand-made result.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "atmos/image.h"
#include "compare_test_util.h"
#include "studies/bench.h"
#include "studies/compare.h"
#include "studies/spectral_sample.h"
#include "studies/validate.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace atmos {
namespace {

using atmos_test::Slurp;

fs::path TestDir(const std::string& name) { return atmos_test::FreshTestTmpDir("studies_" + name); }

fs::path KiderTestData() { return fs::path(ATMOS_SOURCE_DIR) / "tests" / "data" / "kider-2013"; }

// --- validate ---------------------------------------------------------------

TEST(StudiesValidate, RunScoresEachModelAgainstTheMeasuredSky) {
    ValidateConfig config;
    config.data_dir = KiderTestData().string();
    config.models = {"flat", "naive:steps=8:light-steps=4"};
    config.captures = {"12:45"};
    config = ResolveValidateConfig(config);
    int calls = 0;
    const ValidateResult r =
        RunValidate(config, ReadValidateData(config), [&](const ValidateResult&) { ++calls; });
    EXPECT_EQ(calls, 2);               // once per model, no fit
    ASSERT_EQ(r.samples.size(), 80u);  // one capture, sample 0 excluded
    ASSERT_EQ(r.nm.size(), static_cast<size_t>(kKiderBins));
    ASSERT_EQ(r.models.size(), 2u);
    for (const ValidateModelResult& m : r.models) {
        ASSERT_EQ(m.values.size(), r.samples.size() * r.nm.size());
        // The pooled row over every value, recomputed here from the values and the
        // measurements: sqrt(mean squared difference) / mean measured.
        double squared = 0.0, measured = 0.0;
        for (size_t q = 0; q < r.samples.size(); ++q) {
            for (size_t i = 0; i < r.nm.size(); ++i) {
                const double d = m.values[q * r.nm.size() + i] - r.samples[q].spectrum[i];
                squared += d * d;
                measured += r.samples[q].spectrum[i];
            }
        }
        const double n = static_cast<double>(m.values.size());
        const ValidateErrorRow* all = m.Find("all", "all", "all");
        ASSERT_NE(all, nullptr);
        EXPECT_EQ(all->error.count, static_cast<long>(m.values.size()));
        EXPECT_NEAR(all->error.RelativeRmse(), std::sqrt(squared / n) / (measured / n), 1e-12);
        // The capture's own row equals the pooled one (one capture).
        const ValidateErrorRow* own = m.Find("12:45", "all", "all");
        ASSERT_NE(own, nullptr);
        EXPECT_DOUBLE_EQ(own->error.squared, all->error.squared);
        // One row per bin, last.
        EXPECT_EQ(m.rows.back().scope, "818.25nm");
    }
}

TEST(StudiesValidate, ResolveAndRunRejectBadInput) {
    ValidateConfig config;
    config.dataset = "other";
    EXPECT_THROW(ResolveValidateConfig(config), Error);
    config = ValidateConfig();
    config.models = {"no-such-model"};
    EXPECT_THROW(ResolveValidateConfig(config), Error);
    config = ValidateConfig();
    config.data_dir = KiderTestData().string();
    config.models = {"flat"};
    config.captures = {"23:59"};
    try {
        RunValidate(config, ReadValidateData(config));
        FAIL() << "no capture matched, yet no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("--captures '23:59'"), std::string::npos) << e.what();
    }
}

// A hand-made result: one model, one sample, two bins.
ValidateResult FixedValidateResult() {
    ValidateResult r;
    KiderSample s;
    s.capture = "09:30";
    s.sample = 3;
    r.samples = {s};
    r.nm = {360.0, 371.75};
    ValidateModelResult m;
    m.model = "flat";
    m.values = {0.5, 0.25};
    ValidateErrorRow row;
    row.capture = "all";
    row.scope = "all";
    row.region = "all";
    row.error.Add(0.5, 0.25);   // squared 0.0625
    row.error.Add(0.25, 0.25);  // measured 0.5, 2 values
    row.model_sum = 0.75;
    m.rows = {row};
    r.models = {m};
    return r;
}

TEST(StudiesValidate, ErrorsCsvWriter) {
    // abs RMSE sqrt(0.0625 / 2) = 0.1767767, relative / 0.25 = 70.711 %.
    EXPECT_EQ(ValidateErrorsCsv(FixedValidateResult()),
              "model,capture,scope,region,rel_rmse_percent,abs_rmse_1e-3,mean_model_1e-3,"
              "mean_measured_1e-3,values\n"
              "flat,all,all,all,70.711,176.7767,375.0000,250.0000,2\n");
}

TEST(StudiesValidate, ValuesCsvAndHtmlWriters) {
    const ValidateResult r = FixedValidateResult();
    EXPECT_EQ(ValidateValuesCsv(r),
              "model,capture,sample,L_360,L_371.75\n"
              "flat,09:30,3,5.000000e-01,2.500000e-01\n");
    ValidateModelResult m = r.models[0];
    m.rows.push_back(m.rows[0]);
    m.rows.back().scope = "360-720nm";
    const std::string summary = ValidateModelSummary(m, 1);
    EXPECT_EQ(summary.rfind("flat: relative RMSE 70.71 %, absolute 176.777 e-3", 0), 0u) << summary;
    // The HTML: one plot per capture, at three bins the measured line and each model's.
    ValidateResult full = r;
    full.nm.assign(kKiderBins, 500.0);
    full.models[0].values.assign(kKiderBins, 0.125);
    full.samples.push_back(full.samples[0]);
    full.models[0].values.resize(2 * kKiderBins, 0.125);
    const std::string html = ValidateHtml(full, "a <title>");
    EXPECT_NE(html.find("a &lt;title&gt;"), std::string::npos);
    EXPECT_EQ(html.find("a <title>"), std::string::npos);
    size_t plots = 0, lines = 0;
    for (size_t at = html.find("<svg"); at != std::string::npos; at = html.find("<svg", at + 1)) {
        ++plots;
    }
    for (size_t at = html.find("<polyline"); at != std::string::npos;
         at = html.find("<polyline", at + 1)) {
        ++lines;
    }
    EXPECT_EQ(plots, 1u);
    EXPECT_EQ(lines, 6u);
}

// --- compare ----------------------------------------------------------------

TEST(StudiesCompare, ResolveAppliesTheDefaultsAndThePolicy) {
    CompareRequest q;
    q.width = 8;
    q.height = 4;
    q.no_shipped = true;
    CompareConfig c = ResolveCompareConfig(q);
    // One default reference: the path tracer, to a noise target capped at 512 paths.
    EXPECT_EQ(c.reference_model, "reference");
    EXPECT_EQ(c.reference_model, CompareConfig().reference_model);
    EXPECT_DOUBLE_EQ(c.reference_monte_carlo.noise_target, kCompareReferenceNoise);
    EXPECT_EQ(c.reference_monte_carlo.spp, kCompareReferenceCap);
    EXPECT_EQ(c.output_dir, "out");
    EXPECT_EQ(c.cache_dir, "out/cache");
    // A fixed count alone: no noise target.
    q.reference_spp = 16;
    q.output_dir = "elsewhere";
    q.cuda = true;
    c = ResolveCompareConfig(q);
    EXPECT_DOUBLE_EQ(c.reference_monte_carlo.noise_target, 0.0);
    EXPECT_EQ(c.reference_monte_carlo.spp, 16);
    EXPECT_EQ(c.cache_dir, "elsewhere/cache/cuda");
    // A deterministic reference takes no Monte Carlo settings.
    q.reference = "naive:steps=8";
    EXPECT_THROW(ResolveCompareConfig(q), Error);
    q.reference_spp.reset();
    q.quantity = "transmittance";
    q.output_dir.clear();
    q.no_cache = true;
    c = ResolveCompareConfig(q);
    EXPECT_EQ(c.reference_model, "naive");
    EXPECT_EQ(c.reference_options.at("steps"), "8");
    EXPECT_EQ(c.output_dir, "out/transmittance");
    EXPECT_EQ(c.cache_dir, "");
    q.reference_noise = 2.0;
    EXPECT_THROW(ResolveCompareConfig(q), Error);
}

TEST(StudiesCompare, RunOnTinyImages) {
    // The first model is the reference itself.
    const CompareRequest q = TinyCompareRequest({"naive:steps=8", "empty"},
                                                {"ground-noon", "space"}, TestDir("compare"));
    const CompareConfig config = ResolveCompareConfig(q);
    const CompareResult r = RunCompare(config);
    ASSERT_EQ(r.models.size(), 2u);
    ASSERT_EQ(r.rows.size(), 2u);
    for (const CompareRow& row : r.rows) {
        ASSERT_EQ(row.cells.size(), 2u);
        EXPECT_EQ(row.cells[0].flip, 0.0) << row.view;  // the same images
        EXPECT_EQ(row.cells[0].rmse, 0.0) << row.view;
        EXPECT_GT(row.cells[1].rmse, 0.0) << row.view;  // constant white is not the sky
    }
    EXPECT_FALSE(r.reference_noise_table);  // a deterministic reference
    // The run writes nothing (issue 30 item 1): the images are in the result.
    EXPECT_TRUE(fs::is_empty(config.output_dir));
    for (const CompareRow& row : r.rows) {
        EXPECT_EQ(row.reference_image.width(), 8) << row.view;
        EXPECT_EQ(row.reference_image.height(), 4) << row.view;
        for (const CompareCell& c : row.cells) {
            EXPECT_EQ(c.image.size(), row.reference_image.size()) << row.view;
            EXPECT_EQ(c.flip_map.size(), 8u * 4u) << row.view;
        }
        // The reference is the first model: the same pixels.
        EXPECT_TRUE(std::equal(row.reference_image.data(),
                               row.reference_image.data() + row.reference_image.size(),
                               row.cells[0].image.data()))
            << row.view;
    }
    // The images come from their writer, the tables from theirs.
    WriteCompareImages(config, r);
    for (const char* file : {"images/space/reference.png", "images/space/reference.exr",
                             "images/ground-noon/empty.exr", "errors/space/empty-flip.png",
                             "errors/space/empty-rmse.exr", "errors/space/empty-rmse.png"}) {
        EXPECT_TRUE(fs::is_regular_file(fs::path(config.output_dir) / file)) << file;
    }
    EXPECT_FALSE(fs::exists(fs::path(config.output_dir) / "images/space/empty.npy"));  // !npy
    {
        // The written reference is the result's (EXR: float32).
        const Image read =
            ReadImage((fs::path(config.output_dir) / "images/ground-noon/reference.exr").string());
        const Image& kept = r.rows[0].reference_image;
        ASSERT_EQ(read.size(), kept.size());
        EXPECT_TRUE(std::equal(kept.data(), kept.data() + kept.size(), read.data()));
    }
    EXPECT_FALSE(fs::exists(fs::path(config.output_dir) / "flip.csv"));
    WriteCompareTables(config, r);
    const std::string flip = Slurp(fs::path(config.output_dir) / "flip.csv");
    EXPECT_EQ(flip.rfind("FLIP errors,naive:steps=8,empty,best\nground-noon,0,", 0), 0u) << flip;
}

TEST(StudiesCompare, MetricTableWriter) {
    const fs::path dir = TestDir("metric_csv");
    WriteMetricCsv((dir / "flip.csv").string(), "FLIP errors", {"ground", "space"}, {"a", "b"},
                   {{0.5, 0.25}, {0.125, 0.75}}, {0.3, -1.0});
    // ground: b is lowest but a lies within the row's noise (0.3) of it: a tie.
    EXPECT_EQ(Slurp(dir / "flip.csv"),
              "FLIP errors,a,b,best\nground,0.5,0.25,a b\nspace,0.125,0.75,a\n");
}

// --- bench ------------------------------------------------------------------

TEST(StudiesBench, ResolveListsTheModelsAndChecksTheFlags) {
    BenchConfig c;
    c.width = 4;
    c.height = 2;
    const BenchConfig resolved = ResolveBenchConfig(c);
    EXPECT_NE(std::find(resolved.models.begin(), resolved.models.end(), "flat"),
              resolved.models.end());
    for (const std::string& m : resolved.models) {
        EXPECT_FALSE(GetModelInfo(m).capabilities.stochastic) << m;  // Monte Carlo only by name
    }
    c.models = {"flat"};
    c.monte_carlo_given = true;
    EXPECT_THROW(ResolveBenchConfig(c), Error);
    c.monte_carlo_given = false;
    c.repeat = 0;
    EXPECT_THROW(ResolveBenchConfig(c), Error);
}

TEST(StudiesBench, RunTimesEachModelAndView) {
    BenchConfig c;
    c.models = {"flat", "empty"};
    c.views = {"ground-noon", "space"};
    c.width = 4;
    c.height = 2;
    c.repeat = 3;
    c.warmup = 0;
    std::vector<std::string> lines;
    const BenchResult r =
        RunBench(ResolveBenchConfig(c), [&](const std::string& line) { lines.push_back(line); });
    ASSERT_EQ(r.rows.size(), 4u);
    EXPECT_EQ(r.rows[1].model, "flat");
    EXPECT_EQ(r.rows[1].view, "space");
    for (const BenchRow& row : r.rows) {
        EXPECT_EQ(row.runs, 3);
        EXPECT_LE(row.render_min_s, row.render_median_s);
        EXPECT_LE(row.render_median_s, row.render_max_s);
        EXPECT_NEAR(row.megapixels_per_s, 8.0 / row.render_median_s / 1e6, 1e-9);
    }
    EXPECT_EQ(lines.front(), BenchHeaderText());
    EXPECT_NE(std::find(lines.begin(), lines.end(), BenchRowText(r.rows[3])), lines.end());
}

TEST(StudiesBench, Writers) {
    BenchResult r;
    BenchRow row;
    row.model = "flat";
    row.view = "space";
    row.width = 4;
    row.height = 2;
    row.threads = 2;
    row.prepare_s = 0.5;
    row.render_median_s = 0.25;
    row.render_min_s = 0.125;
    row.render_max_s = 1.0;
    row.runs = 3;
    row.megapixels_per_s = 3.2e-5;
    row.cpu = "a, cpu";
    row.compiler = "GCC";
    row.backend = "cpu";
    r.rows = {row};
    BenchStage s;
    s.model = "flat";
    s.view = "prepare";
    s.name = "render";
    s.backend = "cpu";
    s.items = 8;
    s.runs = 3;
    s.kernel_median_ms = 1.5;
    s.total_median_ms = 2.0;
    r.stages = {s};
    EXPECT_EQ(BenchCsv(r),
              "model,view,width,height,quantity,threads,prepare_s,render_median_s,render_min_s,"
              "render_max_s,repeat,megapixels_per_s,paths_per_s,cpu,compiler,backend\n"
              "flat,space,4,2,radiance,2,0.5,0.25,0.125,1,3,3.2e-05,0,\"a, cpu\",GCC,cpu\n");
    EXPECT_EQ(BenchStagesCsv(r),
              "model,view,stage,items,backend,runs,kernel_median_ms,total_median_ms,bytes_up,"
              "bytes_down\nflat,prepare,render,8,cpu,3,1.5,2,0,0\n");
    EXPECT_EQ(BenchRowText(row),
              "flat                 space                       500.000      250.000      "
              "125.000     1000.000      0.000\n");
}

// --- spectral sample ----------------------------------------------------------

TEST(StudiesSpectralSample, CsvAndArrayWriters) {
    SampleQuery q;
    q.altitude_m = 0.0;
    q.mu = 0.5;
    q.mu_s = 0.25;
    q.azimuth_deg = 10.0;
    const std::vector<double> nm = {500.0, 600.0};
    const std::vector<double> values = {0.5, 0.25};
    const std::string csv = SpectralSampleCsv(nm, {q}, values);
    EXPECT_EQ(
        csv.rfind("altitude_m,mu,mu_s,azimuth_deg,L_500,L_600,X,Y,Z\n0,0.5,0.25,10,0.5,0.25,", 0),
        0u)
        << csv;
    const std::vector<float> array = SpectralSampleArray(nm, 1, values);
    ASSERT_EQ(array.size(), 5u);
    EXPECT_EQ(array[0], 0.5f);
    // Y of the CSV (the 10th field) is the array's Y.
    std::vector<std::string> fields;
    std::stringstream line(csv.substr(csv.find('\n') + 1));
    std::string field;
    while (std::getline(line, field, ',')) fields.push_back(field);
    ASSERT_EQ(fields.size(), 9u);
    EXPECT_FLOAT_EQ(std::stof(fields[7]), array[3]);
    EXPECT_GT(array[3], 0.0f);
}

}  // namespace
}  // namespace atmos
