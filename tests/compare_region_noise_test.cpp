// The reference's FLIP noise per region when it renders to a noise target
// (issue 33 item 2): the halves' per-pixel FLIP map over the sky and the
// ground, the same from the render cache, in-process on tiny images.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "atmos/model.h"
#include "compare_test_util.h"
#include "harness/compare_regions.h"
#include "studies/compare.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace atmos {
namespace {

using atmos_test::Slurp;

// The path tracer to a noise target at an equirect view half sky, half ground
// (8x4 pixels), with the render cache in `dir`/cache.
CompareRequest NoiseTargetRequest(const fs::path& dir, const std::string& out) {
    std::ofstream(dir / "views.json")
        << R"({"sky-5deg": {"camera": "projection=equirect", "sun": "elevation=5,azimuth=90"}})";
    CompareRequest q =
        TinyCompareRequest({"naive:steps=8"}, {(dir / "views.json").string()}, dir / out);
    q.reference = "reference";
    q.reference_noise = 0.05;
    q.reference_spp = 64;
    q.no_cache = false;
    q.cache_dir = (dir / "cache").string();
    q.no_shipped = true;
    return q;
}

TEST(CompareRegionNoise, NoiseTargetFillsTheRegionsFromTheHalvesMap) {
    const fs::path dir = atmos_test::FreshTestTmpDir("region_noise");
    const CompareConfig config = ResolveCompareConfig(NoiseTargetRequest(dir, "first"));
    ASSERT_GT(config.reference_monte_carlo.noise_target, 0.0);
    const CompareResult first = RunCompare(config);
    ASSERT_EQ(first.rows.size(), 1u);
    const CompareRow& row = first.rows[0];
    EXPECT_FALSE(row.reference_cached);
    ASSERT_EQ(row.sky_pixels, 16);
    ASSERT_EQ(row.ground_pixels, 16);
    // Filled, finite, different over the two regions.
    EXPECT_GT(row.reference_noise, 0.0);
    EXPECT_TRUE(std::isfinite(row.reference_noise_sky));
    EXPECT_TRUE(std::isfinite(row.reference_noise_ground));
    EXPECT_GE(row.reference_noise_sky, 0.0);
    EXPECT_GE(row.reference_noise_ground, 0.0);
    EXPECT_NE(row.reference_noise_sky, row.reference_noise_ground);
    // The pixel-weighted regions are the whole image's noise.
    const double combined = (row.reference_noise_sky * row.sky_pixels +
                             row.reference_noise_ground * row.ground_pixels) /
                            static_cast<double>(row.sky_pixels + row.ground_pixels);
    EXPECT_NEAR(combined, row.reference_noise, 1e-6 * row.reference_noise);
    // The regions are RegionMean of the halves' map of the same render done here.
    ASSERT_EQ(config.custom_views.size(), 1u);
    const View& view = config.custom_views[0];
    std::unique_ptr<Model> model = CreateModel(config.reference_model, config.reference_options);
    model->Prepare(config.atmosphere);
    RenderRequest request;
    request.view = view;
    request.width = config.width;
    request.height = config.height;
    request.show_progress = false;
    request.monte_carlo = config.reference_monte_carlo;
    MonteCarloReport report;
    request.report = &report;
    Image image;
    model->Render(request, &image);
    EXPECT_EQ(report.noise, row.reference_noise);
    const RegionValues expected =
        RegionMean(report.noise_map,
                   RegionMask(view, config.width, config.height, config.atmosphere.bottom_radius));
    EXPECT_EQ(row.reference_noise_sky, expected.sky);
    EXPECT_EQ(row.reference_noise_ground, expected.ground);
    WriteCompareTables(config, first);

    // From the render cache: the same region values and tables.
    CompareConfig again = ResolveCompareConfig(NoiseTargetRequest(dir, "second"));
    const CompareResult second = RunCompare(again);
    ASSERT_EQ(second.rows.size(), 1u);
    EXPECT_TRUE(second.rows[0].reference_cached);
    EXPECT_EQ(second.rows[0].reference_noise, row.reference_noise);
    EXPECT_EQ(second.rows[0].reference_noise_sky, row.reference_noise_sky);
    EXPECT_EQ(second.rows[0].reference_noise_ground, row.reference_noise_ground);
    WriteCompareTables(again, second);
    for (const char* f : {"reference_noise_regions.csv", "flip_sky.csv", "flip_ground.csv",
                          "flip.csv", "rmse.csv"}) {
        EXPECT_EQ(Slurp(dir / "first" / f), Slurp(dir / "second" / f)) << f;
    }
    const std::string regions = Slurp(dir / "first" / "reference_noise_regions.csv");
    EXPECT_EQ(regions.find(",,"), std::string::npos) << regions;  // no empty cell

    // An entry without the map (written before atmos stored it) or with a
    // damaged one is a miss: rendered again, to the same values.
    for (const bool damaged : {false, true}) {
        int entries = 0;
        for (const fs::directory_entry& e : fs::directory_iterator(dir / "cache")) {
            const std::string name = e.path().filename().string();
            // The reference's entry (not its prepare record, not naive's).
            if (name.rfind("reference-", 0) != 0 || name.find("-prepare-") != std::string::npos)
                continue;
            if (damaged && e.path().extension() == ".bin") {
                std::fstream f(e.path(), std::ios::in | std::ios::out | std::ios::binary);
                f.seekg(4);
                const char c = static_cast<char>(f.get());
                f.seekp(4);
                f.put(static_cast<char>(c ^ 0x5a));
                ++entries;
            }
            if (!damaged && e.path().extension() == ".json") {
                nlohmann::json j = nlohmann::json::parse(Slurp(e.path()));
                ASSERT_TRUE(j.contains("noise_map"));
                j.erase("noise_map");
                std::ofstream(e.path()) << j.dump(1);
                ++entries;
            }
        }
        ASSERT_EQ(entries, 1) << damaged;
        const CompareResult third = RunCompare(again);
        EXPECT_FALSE(third.rows[0].reference_cached) << damaged;
        EXPECT_EQ(third.rows[0].reference_noise_sky, row.reference_noise_sky) << damaged;
        EXPECT_EQ(third.rows[0].reference_noise_ground, row.reference_noise_ground) << damaged;
        EXPECT_TRUE(RunCompare(again).rows[0].reference_cached) << damaged;  // stored again
    }
}

}  // namespace
}  // namespace atmos
