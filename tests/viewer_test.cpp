// The engine path equals the library (issue 20): `atmos viewer` bakes
// bruneton, hillaire, atmosphere-plus and hosek-wilkie and writes the WebGL2 page; headless
// Chromium (Debian's `chromium`, WebGL2 on SwiftShader) renders the 12 views of each from the baked
// float32 tables with shaders/NAME.glsl into a float framebuffer, the page
// puts the pixels in the DOM (read back with --dump-dom), and each must match
// `atmos render --load` of the same view from the same tables: mean HDR-FLIP
// <= 0.01. Skipped, with one line, where Chromium cannot start or has no WebGL2.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "atmos/image.h"
#include "chromium_util.h"
#include "metrics/flip.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace {

using atmos::test::FindChromium;

using atmos_test::Slurp;
using atmos_test::System;

std::string DecodeBase64(const std::string& text) {
    std::string out;
    unsigned v = 0;
    int bits = 0;
    for (const char c : text) {
        int d;
        if (c >= 'A' && c <= 'Z') {
            d = c - 'A';
        } else if (c >= 'a' && c <= 'z') {
            d = c - 'a' + 26;
        } else if (c >= '0' && c <= '9') {
            d = c - '0' + 52;
        } else if (c == '+') {
            d = 62;
        } else if (c == '/') {
            d = 63;
        } else {
            continue;  // '=', whitespace
        }
        v = (v << 6) | static_cast<unsigned>(d);
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            out += static_cast<char>((v >> bits) & 0xff);
        }
    }
    return out;
}

// The value of attribute `name` in the tag that starts at `tag`.
std::string Attribute(const std::string& html, size_t tag, const std::string& name) {
    const size_t end = html.find('>', tag);
    const size_t at = html.find(" " + name + "=\"", tag);
    if (at == std::string::npos || at > end) return "";
    const size_t begin = at + name.size() + 3;
    return html.substr(begin, html.find('"', begin) - begin);
}

struct BrowserImage {
    std::string model, view;
    double ms = 0.0;
    atmos::Image image;
};

// The comparison above for the earth atmosphere with the `--set` flags `sets`
// (empty, or ones that give it a second Mie lobe).
void ExpectBrowserMatchesAtmosRender(const std::string& sets) {
#if defined(__SANITIZE_ADDRESS__)
    GTEST_SKIP()
        << "not under sanitizers (it runs the CLI and a browser; the Release suite has it)";
#endif
    const std::string chromium = FindChromium();
    if (chromium.empty()) GTEST_SKIP() << "chromium not installed (scripts/setup.sh installs it)";
    const fs::path dir = atmos_test::FreshTestTmpDir("viewer_" + std::to_string(getpid()));
    const fs::path page = dir / "page";
    const std::string cli = ATMOS_CLI_PATH;

    // Small tables and 2 orders keep the bake quick (the shaders read any
    // sizes: bruneton_constants.glsl); combined Mie storage exercises the
    // shader's extrapolated-Mie path (the default, separate, is in docs/manual.md's
    // measurements, docs/engine.md).
    const std::string bruneton =
        "bruneton:orders=2:scattering-r=16:scattering-mu=64:scattering-mu-s=16:mie-storage="
        "combined";
    // Hillaire: its baked tables, and per view the sky-view and aerial-
    // perspective passes of shaders/hillaire.glsl.
    // Atmosphere Plus: small tables, 2 orders and a coarse gather (the bake
    // takes a fraction of a second); the default horizon-centric mapping.
    const std::string aplus =
        "atmosphere-plus:orders=2:table-width=16:table-height=32:table-depth=16:"
        "transmittance-width=16:transmittance-height=64:gather-theta=6:gather-phi=12";
    const std::map<std::string, std::string> models = {{"bruneton", bruneton},
                                                       {"hillaire", "hillaire"},
                                                       {"atmosphere-plus", aplus},
                                                       {"hosek-wilkie", "hosek-wilkie"}};
    ASSERT_EQ(System(cli + " viewer" + sets + " --models " + bruneton + ",hillaire," + aplus +
                     ",hosek-wilkie -o " + page.string() + " --quiet > " +
                     (dir / "viewer.log").string() + " 2>&1"),
              0)
        << Slurp(dir / "viewer.log");
    for (const char* shader :
         {"bruneton/shaders/bruneton.glsl", "hillaire/shaders/hillaire.glsl",
          "atmosphere-plus/shaders/atmosphere_plus.glsl", "atmosphere-plus/shaders/common.glsl",
          "hosek-wilkie/shaders/hosek_wilkie.glsl"}) {
        ASSERT_TRUE(fs::exists(page / shader)) << shader;
    }

    const int width = 320, height = 180;
    const fs::path dom = dir / "dom.html";
    const std::string url = "file://" + (page / "index.html").string() +
                            "?test=1&format=f32&size=" + std::to_string(width) + "x" +
                            std::to_string(height);
    const int rc =
        System("timeout 120 " + chromium +
               " --headless --no-sandbox --use-angle=swiftshader --enable-unsafe-swiftshader"
               " --disable-quic --no-first-run --disable-background-networking"
               " --disable-component-update --disable-sync --user-data-dir=" +
               (dir / "profile").string() + " --dump-dom '" + url + "' > " + dom.string() + " 2> " +
               (dir / "chromium.log").string());
    const std::string html = Slurp(dom);
    if (rc != 0 && html.empty()) {
        GTEST_SKIP() << "chromium could not start (exit " << rc
                     << "): " << Slurp(dir / "chromium.log").substr(0, 300);
    }
    const size_t status_tag = html.find("id=\"atmos-test\"");
    ASSERT_NE(status_tag, std::string::npos) << "page did not load:\n" << html.substr(0, 2000);
    const size_t status_open = html.rfind('<', status_tag);
    const std::string status = Attribute(html, status_open, "data-status");
    if (status == "error" &&
        Attribute(html, status_open, "data-error").find("WebGL2 is not available") !=
            std::string::npos) {
        GTEST_SKIP() << "chromium has no WebGL2 here (SwiftShader missing)";
    }
    ASSERT_EQ(status, "ok") << "page error: " << Attribute(html, status_open, "data-error");

    std::vector<BrowserImage> images;
    for (size_t at = html.find("<pre class=\"atmos-image\""); at != std::string::npos;
         at = html.find("<pre class=\"atmos-image\"", at + 1)) {
        BrowserImage b;
        b.model = Attribute(html, at, "data-model");
        b.view = Attribute(html, at, "data-view");
        b.ms = std::atof(Attribute(html, at, "data-ms").c_str());
        ASSERT_EQ(Attribute(html, at, "data-width"), std::to_string(width));
        ASSERT_EQ(Attribute(html, at, "data-height"), std::to_string(height));
        const size_t begin = html.find('>', at) + 1;
        const std::string bytes = DecodeBase64(html.substr(begin, html.find('<', begin) - begin));
        ASSERT_EQ(bytes.size(), static_cast<size_t>(width) * height * 3 * 4) << b.view;
        b.image = atmos::Image(width, height);
        std::memcpy(b.image.data(), bytes.data(), bytes.size());
        images.push_back(std::move(b));
    }
    ASSERT_EQ(images.size(), 48u);  // 4 models x 12 views

    // The library from the same tables.
    const fs::path renders = dir / "render";
    for (const auto& [name, spec] : models) {
        ASSERT_EQ(System(cli + " render" + sets + " --model " + spec + " --load " +
                         (page / name).string() + " --view all --size " + std::to_string(width) +
                         "x" + std::to_string(height) + " --quiet -o " + renders.string() + " > " +
                         (dir / "render.log").string() + " 2>&1"),
                  0)
            << Slurp(dir / "render.log");
    }
    for (const BrowserImage& b : images) {
        ASSERT_EQ(models.count(b.model), 1u) << b.model;
        // `render --view all` names files MODEL-VIEW with MODEL as given.
        const atmos::Image reference =
            atmos::ReadImage((renders / (models.at(b.model) + "-" + b.view + ".exr")).string());
        const atmos::FlipResult flip = atmos::HdrFlip(reference, b.image);
        std::printf("%-15s %-22s HDR-FLIP %.5f  (browser %.0f ms)\n", b.model.c_str(),
                    b.view.c_str(), flip.mean, b.ms);
        EXPECT_LE(flip.mean, 0.01) << b.model << " " << b.view;
    }
    fs::remove_all(dir);
}

TEST(Viewer, WebGlRenderingOfTheBakedTablesMatchesAtmosRender) {
    ExpectBrowserMatchesAtmosRender("");
}

TEST(Viewer, WebGlRenderingMatchesAtmosRenderWithTwoMieLobes) {
    // The shaders' second lobe (ATMOS_MIE_PHASE_G2, ATMOS_MIE_PHASE_WEIGHT2 in
    // the baked constants) against the library's MiePhase.
    ExpectBrowserMatchesAtmosRender(" --set mie_phase_g2=0.95 --set mie_phase_weight2=0.3");
}

}  // namespace
