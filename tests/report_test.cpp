// The HTML report in a real browser: headless Chromium (Debian's `chromium`,
// installed by scripts/setup.sh) loads a small generated report offline,
// every image must load (the page's inline script records the count in the
// DOM, read back with --dump-dom), and a screenshot is taken.
// Skipped (not failed) when no chromium is installed.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "atmos/image.h"
#include "chromium_util.h"

namespace fs = std::filesystem;

namespace {

using atmos::test::FindChromium;

std::string Slurp(const fs::path& p) {
    std::ifstream f(p);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

int System(const std::string& cmd) {
    const int raw = std::system(cmd.c_str());
    return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
}

TEST(Report, LoadsInHeadlessChromiumWithEveryImage) {
    const std::string chromium = FindChromium();
    if (chromium.empty()) GTEST_SKIP() << "chromium not installed (scripts/setup.sh installs it)";
    const char* env = std::getenv("ATMOS_TEST_TMP");
    fs::path dir = env ? fs::path(env) : fs::temp_directory_path() / "atmos_test";
    dir /= "report_" + std::to_string(getpid());
    fs::remove_all(dir);
    fs::create_directories(dir);

    // A small report: 2 views x (reference + 2 models x (image, FLIP map, error)) = 14 images.
    const fs::path report = dir / "report";
    const std::string compare =
        std::string(ATMOS_CLI_PATH) +
        " compare --models empty,naive --views ground-sunrise,space --size 32x18 --reference "
        "naive:steps=24 --no-cache --quiet -o " +
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
    ASSERT_EQ(System(browser("profile", "--window-size=1280,1600 --screenshot=" + shot.string() +
                                            " --dump-dom") +
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
    EXPECT_NE(html.find("FLIP errors"), std::string::npos);
    EXPECT_NE(html.find("<svg"), std::string::npos);

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

}  // namespace
