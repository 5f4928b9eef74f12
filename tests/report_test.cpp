// The HTML report in a real browser: headless Chromium (Debian's `chromium`,
// installed by scripts/setup.sh) loads a small generated report offline,
// every image and plot must be present and load, with no script error or
// console error (the page's inline script records the counts in the DOM, read
// back with --dump-dom; chromium's console log is checked too), and a
// screenshot is taken. Skipped (not failed) when no chromium is installed.
// And the honest "best" marking (issue 22) on constructed tables: the
// ranking functions and the marks the report writes for them.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/image.h"
#include "atmos/view.h"
#include "chromium_util.h"
#include "harness/profiles.h"
#include "harness/ranking.h"
#include "harness/report.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace {

using atmos::test::FindChromium;

using atmos_test::Slurp;
using atmos_test::System;

TEST(Report, LoadsInHeadlessChromiumWithEveryImage) {
    const std::string chromium = FindChromium();
    if (chromium.empty()) GTEST_SKIP() << "chromium not installed (scripts/setup.sh installs it)";
    const fs::path dir = atmos_test::FreshTestTmpDir("report_" + std::to_string(getpid()));

    // A small report: 2 views x (reference + 2 models x (image, FLIP map, error)) = 14 images;
    // plots: accuracy against cost, render times, per view the colour bars and 2 profiles = 8.
    // The path-traced reference at a fixed 16 paths per pixel (two halves: its noise is
    // measured, so the ties and the profiles' noise band are drawn).
    const fs::path report = dir / "report";
    const std::string compare =
        std::string(ATMOS_CLI_PATH) +
        " compare --models empty,naive --views ground-sunrise,space --size 32x18 --reference "
        "reference --reference-spp 16 --no-cache --quiet -o " +
        report.string() + " > " + (dir / "compare.log").string() + " 2>&1";
    ASSERT_EQ(System(compare), 0) << Slurp(dir / "compare.log");

    auto browser = [&](const std::string& profile, const std::string& extra) {
        const fs::path user_data = dir / profile;  // a fresh profile
        fs::create_directories(user_data);
        return "timeout 60 " + chromium +
               " --headless --no-sandbox --disable-gpu --disable-quic --no-first-run"
               " --disable-background-networking --disable-component-update --disable-sync"
               " --user-data-dir=" +
               user_data.string() + " " + extra + " file://" + (report / "index.html").string();
    };
    // One run: the DOM after the load event (--dump-dom) and a screenshot.
    const fs::path dom = dir / "dom.html";
    const fs::path shot = dir / "report.png";
    ASSERT_EQ(System(browser("profile",
                             "--window-size=1280,1600 --enable-logging=stderr --v=0"
                             " --screenshot=" +
                                 shot.string() + " --dump-dom") +
                     " > " + dom.string() + " 2> " + (dir / "chromium.log").string()),
              0)
        << Slurp(dir / "chromium.log");
    const std::string html = Slurp(dom);
    // No std::regex: GCC 12 warns (maybe-uninitialized) inside <regex> under ASan.
    auto attribute = [&](const std::string& name) {
        const size_t tag = html.find("id=\"image-check\"");
        if (tag == std::string::npos) return std::string("missing");
        const size_t at = html.find(name + "=\"", tag);
        if (at == std::string::npos) return std::string("missing");
        const size_t begin = at + name.size() + 2;
        return html.substr(begin, html.find('"', begin) - begin);
    };
    ASSERT_NE(attribute("data-total"), "missing") << "the page's image check did not run";
    EXPECT_EQ(attribute("data-total"), "14");
    EXPECT_EQ(attribute("data-loaded"), attribute("data-total")) << "some images did not load";
    EXPECT_EQ(attribute("data-plots"), "8");
    EXPECT_EQ(attribute("data-errors"), "0") << "script errors in the page";
    EXPECT_NE(html.find("FLIP errors"), std::string::npos);
    auto count = [&](const std::string& needle) {
        int n = 0;
        for (size_t at = html.find(needle); at != std::string::npos;
             at = html.find(needle, at + 1)) {
            ++n;
        }
        return n;
    };
    EXPECT_EQ(count("data-plot=\"accuracy-cost\""), 1);
    EXPECT_EQ(count("data-plot=\"times\""), 1);
    EXPECT_EQ(count("data-plot=\"colour-bars\""), 2);
    EXPECT_EQ(count("data-plot=\"profile\""), 4);
    EXPECT_EQ(count("<polygon"), 4) << "a noise band per profile";
    EXPECT_NE(html.find("table class=\"summary\""), std::string::npos);
    // Chromium's own log of the page's console (--enable-logging): no error there either.
    const std::string log = Slurp(dir / "chromium.log");
    for (size_t at = log.find("CONSOLE"); at != std::string::npos;
         at = log.find("CONSOLE", at + 1)) {
        const size_t line = log.rfind('\n', at) + 1;
        ADD_FAILURE() << "console message: " << log.substr(line, log.find('\n', at) - line);
    }
    // The same data as CSV: a header and one line per model.
    const std::string csv = Slurp(report / "accuracy_cost.csv");
    EXPECT_EQ(csv.substr(0, csv.find('\n')),
              "model,mean_flip,worst_flip,worst_view,unresolved_views,frame_seconds,"
              "frame_seconds_1920x1080,prepare_seconds,table_bytes,lines_of_code,rank,pareto,"
              "validity");
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3);

    const atmos::Image image = atmos::ReadImage(shot.string());
    EXPECT_EQ(image.width(), 1280);
    EXPECT_EQ(image.height(), 1600);
    // Not blank: the page's dark background with lighter text and images.
    float lo = 1.0f, hi = 0.0f;
    for (size_t i = 0; i < image.size(); ++i) {
        lo = std::min(lo, image.data()[i]);
        hi = std::max(hi, image.data()[i]);
    }
    EXPECT_GT(hi - lo, 0.5f);
}

// The rule of issue 22 on constructed values: a model is best only when its
// lead over the next exceeds the noise; within the noise the models tie.
TEST(Ranking, BestOnlyWhenTheLeadExceedsTheNoise) {
    using atmos::BestOfRow;
    using atmos::TiedRanks;
    // Lead 0.002 < noise 0.005: tied; the third is out.
    EXPECT_EQ(BestOfRow({0.010, 0.012, 0.030}, 0.005), (std::vector<int>{0, 1}));
    // Lead 0.010 > noise 0.005: one best, whatever the order of the columns.
    EXPECT_EQ(BestOfRow({0.030, 0.010, 0.020}, 0.005), (std::vector<int>{1}));
    // A lead exactly equal to the noise is not larger: a tie (binary-exact values).
    EXPECT_EQ(BestOfRow({0.5, 0.75}, 0.25), (std::vector<int>{0, 1}));
    // Noise not measured (< 0): only equal values tie.
    EXPECT_EQ(BestOfRow({0.02, 0.01, 0.01}, -1.0), (std::vector<int>{1, 2}));
    EXPECT_EQ(BestOfRow({0.02, 0.01, 0.0100001}, -1.0), (std::vector<int>{1}));
    // Everything within the noise: all tied.
    EXPECT_EQ(BestOfRow({0.004, 0.001, 0.003}, 0.01), (std::vector<int>{0, 1, 2}));
    EXPECT_TRUE(BestOfRow({NAN}, 0.01).empty());
    // Ranks: a group takes every value within the noise of its first; the
    // next rank skips the tied ones; non-finite values are unranked (0).
    EXPECT_EQ(TiedRanks({0.010, 0.012, 0.030}, 0.005), (std::vector<int>{1, 1, 3}));
    EXPECT_EQ(TiedRanks({0.018, 0.010, 0.014, NAN}, 0.005), (std::vector<int>{3, 1, 1, 0}));
    EXPECT_EQ(TiedRanks({0.3, 0.1, 0.2}, 0.0), (std::vector<int>{3, 1, 2}));
}

TEST(Ranking, ParetoFrontKeepsTheUndominatedPoints) {
    // (cost, error): b is dominated by a (slower and worse), d by c.
    const std::vector<double> cost = {1.0, 2.0, 0.5, 3.0, 10.0};
    const std::vector<double> error = {0.2, 0.3, 0.4, 0.1, 0.1};
    EXPECT_EQ(atmos::ParetoFront(cost, error), (std::vector<int>{2, 0, 3}));
}

// The classes the report's FLIP table gives the cells of a row (in column order).
std::vector<std::string> RowClasses(const std::string& html, const std::string& label) {
    const size_t table = html.find("<caption>FLIP errors");
    const size_t row = html.find("<tr><th>" + label + "</th>", table);
    std::vector<std::string> classes;
    if (table == std::string::npos || row == std::string::npos) return classes;
    const size_t end = html.find("</tr>", row);
    for (size_t at = html.find("<td", row); at < end; at = html.find("<td", at + 1)) {
        const size_t close = html.find('>', at);
        const size_t c = html.find("class=\"", at);
        classes.push_back(c < close ? html.substr(c + 7, html.find('"', c + 7) - c - 7) : "");
    }
    return classes;
}

TEST(Report, MarksTheBestOnlyWhenItsLeadExceedsTheReferenceNoise) {
    const char* env = std::getenv("ATMOS_TEST_TMP");
    fs::path dir = env ? fs::path(env) : fs::temp_directory_path() / "atmos_test";
    dir /= "report_rule_" + std::to_string(getpid());
    fs::create_directories(dir);
    atmos::CompareConfig config;
    config.width = 32;
    config.height = 18;
    atmos::CompareResult r;
    r.models = {"empty", "naive", "preetham"};
    r.model_names = r.models;
    r.model_titles = r.models;
    r.prepare_seconds = {0.0, 0.0, 0.0};
    r.prepared = {false, false, false};
    r.table_bytes = {-1, -1, -1};
    auto add_row = [&](const std::string& view, double noise, std::vector<double> flips) {
        atmos::CompareRow row;
        row.view = row.label = view;
        row.reference_noise = noise;
        for (double v : flips) {
            atmos::CompareCell c;
            c.flip = v;
            c.rmse = v;  // RMSE noise unknown: strict lowest
            c.render_seconds = 0.01;
            c.within_noise = v <= noise;
            row.cells.push_back(c);
        }
        r.rows.push_back(row);
    };
    add_row("ground-noon", 0.005, {0.030, 0.010, 0.012});     // tie: naive, preetham
    add_row("ground-sunrise", 0.005, {0.030, 0.010, 0.020});  // naive best
    add_row("space", 0.020, {0.500, 0.010, 0.015});           // tie, both within the noise
    const fs::path page = dir / "index.html";
    atmos::WriteCompareReport(page.string(), config, r);
    const std::string html = Slurp(page);
    EXPECT_EQ(RowClasses(html, "ground-noon"),
              (std::vector<std::string>{"", "tie", "tie", "noise"}));
    EXPECT_EQ(RowClasses(html, "ground-sunrise"),
              (std::vector<std::string>{"", "best", "", "noise"}));
    EXPECT_EQ(RowClasses(html, "space"),
              (std::vector<std::string>{"", "tie noise", "tie noise", "noise"}));
    // The summary: mean FLIP 0.18667, 0.010, 0.01567 with mean noise 0.01: naive and
    // preetham tie at rank 1, empty is rank 3.
    const std::vector<atmos::CompareSummary> summary = atmos::SummarizeCompare(config, r);
    ASSERT_EQ(summary.size(), 3u);
    EXPECT_EQ(summary[0].rank, 3);
    EXPECT_EQ(summary[1].rank, 1);
    EXPECT_EQ(summary[2].rank, 1);
    EXPECT_EQ(summary[1].unresolved_views, 1);
    EXPECT_NEAR(summary[1].frame_seconds_1080p, 0.01 * 1920 * 1080 / (32 * 18), 1e-9);
    fs::remove_all(dir);
}

}  // namespace

namespace {

// The profile lines' geometry: the column holds the pixel whose ray is
// closest to the sun; the row is the last one above the ground sphere.
TEST(Profiles, ColumnThroughTheSunAndRowAboveTheHorizon) {
    const atmos::AtmosphereParameters atmosphere;
    const atmos::View view = atmos::GetView("ground-sunrise", atmosphere);
    const int w = 160, h = 90;
    const std::vector<atmos::ProfileLine> lines =
        atmos::ViewProfileLines(view, w, h, atmosphere.bottom_radius, atmosphere.top_radius);
    ASSERT_EQ(lines.size(), 2u);
    const atmos::ProfileLine& column = lines[0];
    const atmos::ProfileLine& row = lines[1];
    ASSERT_TRUE(column.vertical);
    ASSERT_FALSE(row.vertical);
    EXPECT_NE(column.title.find("through the sun"), std::string::npos) << column.title;
    // The pixel whose ray is nearest the sun is in `column` (or ties with one there: here
    // the sun is on the centre line between columns 79 and 80).
    double best = -2.0, best_in_column = -2.0;
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const double c = atmos::Dot(view.camera.RayDirection(x, y, w, h), view.sun_direction);
            best = std::max(best, c);
            if (x == column.index) best_in_column = std::max(best_in_column, c);
        }
    }
    EXPECT_NEAR(best_in_column, best, 1e-12);
    // The row sees above the horizon, the one below it the ground (camera on the ground:
    // elevation 0 within a few metres of altitude).
    const atmos::Vec3d up = view.camera.position / atmos::Length(view.camera.position);
    const double r = atmos::Length(view.camera.position);
    const double tangent = -std::sqrt(1.0 - std::pow(atmosphere.bottom_radius / r, 2));
    ASSERT_GT(row.index, 0);
    ASSERT_LT(row.index, h - 1);
    EXPECT_GT(atmos::Dot(view.camera.RayDirection(column.index, row.index, w, h), up), tangent);
    EXPECT_LE(atmos::Dot(view.camera.RayDirection(column.index, row.index + 1, w, h), up), tangent);
    EXPECT_EQ(column.marker, row.index);
    EXPECT_EQ(row.marker, column.index);
    EXPECT_EQ(column.angle_deg.size(), static_cast<size_t>(h));
    EXPECT_GT(column.angle_deg.front(), column.angle_deg.back());  // top row first
    // Luminance of a constant image is its Rec. 709 weighted sum.
    atmos::Image image(w, h);
    for (size_t i = 0; i < image.size(); i += 3) {
        image.data()[i] = 1.0f;
        image.data()[i + 1] = 2.0f;
        image.data()[i + 2] = 4.0f;
    }
    const std::vector<double> y = atmos::ProfileLuminance(image, row);
    ASSERT_EQ(y.size(), static_cast<size_t>(w));
    EXPECT_NEAR(y[7], 0.2126 + 2 * 0.7152 + 4 * 0.0722, 1e-12);
}

}  // namespace
