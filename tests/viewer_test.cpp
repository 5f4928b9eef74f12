// The engine path equals the library (issue 20): `atmos viewer` bakes
// bruneton, hillaire, atmosphere-plus and hosek-wilkie and writes the WebGL2 page; headless
// Chromium (Debian's `chromium`, WebGL2 on SwiftShader) renders the 12 views of each from the baked
// float32 tables with shaders/NAME.glsl into a float framebuffer, the page
// puts the pixels in the DOM (read back with --dump-dom), and each must match
// `atmos render --load` of the same view from the same tables: mean HDR-FLIP
// <= 0.01; so must a free view given as the page's URL state (issue 35 item 5)
// and `atmos render --camera --sun` of it. The page directory holds one copy
// of each table (tables.f32), the state round-trips through the URL's hash, and
// the benchmark mode prints a median per model and per GPU precomputation.
// Tables computed on the GPU (issue 35 item 3): the page runs a bake's
// "gpu_precompute" passes (hillaire: shaders/hillaire_precompute.glsl) and
// its tables must equal the CPU bake's within the float precision stated in
// docs/gpu.md, and its renders from them the page's renders from the CPU
// tables (FLIP <= 0.01); with the atmosphere's sliders and planet preset in
// the URL state, those of `atmos viewer --atmosphere --set` of that atmosphere.
// Skipped, with one line, where Chromium cannot start or has no WebGL2.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "atmos/atmosphere.h"
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

// The value of attribute `name` in the tag that starts at `tag` (&amp; as &).
std::string Attribute(const std::string& html, size_t tag, const std::string& name) {
    const size_t end = html.find('>', tag);
    const size_t at = html.find(" " + name + "=\"", tag);
    if (at == std::string::npos || at > end) return "";
    const size_t begin = at + name.size() + 3;
    std::string value = html.substr(begin, html.find('"', begin) - begin);
    for (size_t amp = value.find("&amp;"); amp != std::string::npos;
         amp = value.find("&amp;", amp + 1)) {
        value.erase(amp + 1, 4);
    }
    return value;
}

// Runs headless Chromium on `url`, the DOM into `dom`; `extra`: more flags.
int RunChromium(const std::string& chromium, const fs::path& dir, const std::string& url,
                const fs::path& dom, const std::string& extra = "") {
    return System("timeout 120 " + chromium +
                  " --headless --no-sandbox --use-angle=swiftshader --enable-unsafe-swiftshader"
                  " --allow-file-access-from-files"
                  " --disable-quic --no-first-run --disable-background-networking"
                  " --disable-component-update --disable-sync --user-data-dir=" +
                  (dir / "profile").string() + extra + " --dump-dom '" + url + "' > " +
                  dom.string() + " 2> " + (dir / "chromium.log").string());
}

// Every regular file under `dir` with its size.
std::map<std::string, uintmax_t> FileSizes(const fs::path& dir) {
    std::map<std::string, uintmax_t> sizes;
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
        if (e.is_regular_file()) sizes[fs::relative(e.path(), dir).string()] = e.file_size();
    }
    return sizes;
}

// The view the test gives the page as its URL state: a free camera 1.5 km up,
// looking 20 degrees down (the lit ground fills the lower part), and a sun of
// its own; `atmos render --camera/--sun` of the same view.
constexpr const char* kState =
    "m=bruneton&m2=hillaire&split=1&pos=0.35&view=&alt=1500&az=200&el=-20&fov=70&sun_az=120&"
    "sun_el=25&exp=1.5&disc=0&atm=&ray=1&mie=1&oz=1&alb=-1";
constexpr const char* kStateCamera =
    " --camera altitude=1500,azimuth=200,elevation=-20,fov=70 --sun elevation=25,azimuth=120";

struct BrowserImage {
    std::string model, view;
    double ms = 0.0;
    atmos::Image image;
};

// The lines of the page's benchmark output (<pre id="atmos-bench">) in `html`:
// each model's median (ms) by name; `header`: the first line; `done`: its status.
// `precompute` (optional): the GPU precomputations' medians by model.
std::map<std::string, double> BenchMedians(const std::string& html, const std::string& size,
                                           const std::string& runs, const std::string& timer,
                                           std::string* header, std::string* done,
                                           std::map<std::string, double>* precompute = nullptr) {
    std::map<std::string, double> medians;
    const size_t bench_tag = html.find("id=\"atmos-bench\"");
    if (bench_tag == std::string::npos) return medians;
    *done = Attribute(html, html.rfind('<', bench_tag), "data-status");
    const size_t begin = html.find('>', bench_tag) + 1;
    std::stringstream lines(html.substr(begin, html.find('<', begin) - begin));
    std::string line;
    std::getline(lines, *header);
    std::printf("%s\n", header->c_str());
    while (std::getline(lines, line)) {
        std::printf("%s\n", line.c_str());
        const size_t m = line.find(" model="), med = line.find(" median_ms=");
        if (m == std::string::npos || med == std::string::npos) continue;
        if (line.rfind("atmos-bench-precompute ", 0) == 0) {
            EXPECT_NE(line.find(" runs=" + runs + " "), std::string::npos) << line;
            EXPECT_NE(line.find(" timer=" + timer), std::string::npos) << line;
            const std::string name = line.substr(m + 7, line.find(' ', m + 7) - m - 7);
            if (precompute) (*precompute)[name] = std::atof(line.c_str() + med + 11);
            continue;
        }
        EXPECT_NE(line.find(" size=" + size + " runs=" + runs + " "), std::string::npos) << line;
        EXPECT_NE(line.find(" timer=" + timer), std::string::npos) << line;
        const std::string name = line.substr(m + 7, line.find(' ', m + 7) - m - 7);
        medians[name] = std::atof(line.c_str() + med + 11);
    }
    return medians;
}

// The interactive page from the URL state kState with the benchmark mode
// (?bench=2, a small frame, finish-bracketed: synchronous, so --dump-dom sees
// it): the state comes back unchanged (parsed, shown, published to the hash),
// and each of the page's `model_count` models has a positive median. Then the
// GPU-timer path (asynchronous: --virtual-time-budget lets --dump-dom wait),
// where the browser has EXT_disjoint_timer_query_webgl2 (SwiftShader has).
// The models of the viewer in `page` whose bake lists GPU passes (asked of
// each bake's JSON).
size_t PrecomputeModelCount(const fs::path& page) {
    size_t n = 0;
    for (const auto& e : fs::directory_iterator(page)) {
        const fs::path json = e.path() / (e.path().filename().string() + ".json");
        if (!fs::exists(json)) continue;
        n += nlohmann::json::parse(Slurp(json)).contains("gpu_precompute") ? 1 : 0;
    }
    return n;
}

void ExpectStateAndBench(const std::string& chromium, const fs::path& dir, const fs::path& page,
                         size_t model_count) {
    const fs::path dom = dir / "bench.html";
    const std::string url =
        "file://" + (page / "index.html").string() + "?bench=2&size=192x108&timer=finish#" + kState;
    RunChromium(chromium, dir, url, dom);
    std::string html = Slurp(dom);
    const size_t status_tag = html.find("id=\"atmos-test\"");
    ASSERT_NE(status_tag, std::string::npos) << html.substr(0, 2000);
    const size_t open = html.rfind('<', status_tag);
    ASSERT_EQ(Attribute(html, open, "data-status"), "viewer")
        << Attribute(html, open, "data-error");
    EXPECT_EQ(Attribute(html, open, "data-state"), kState);
    EXPECT_EQ(Attribute(html, open, "data-hash"), std::string("#") + kState);
    std::string header, done;
    std::map<std::string, double> precompute;
    std::map<std::string, double> medians =
        BenchMedians(html, "192x108", "2", "finish", &header, &done, &precompute);
    EXPECT_EQ(done, "done");
    EXPECT_NE(header.find(" timer=finish"), std::string::npos) << header;
    EXPECT_EQ(medians.size(), model_count);
    for (const auto& [name, ms] : medians) EXPECT_GT(ms, 0.0) << name;
    // Each GPU precomputation too (item 4).
    EXPECT_GE(PrecomputeModelCount(page), 1u);
    EXPECT_EQ(precompute.size(), PrecomputeModelCount(page));
    for (const auto& [name, ms] : precompute) EXPECT_GT(ms, 0.0) << name;

    RunChromium(chromium, dir,
                "file://" + (page / "index.html").string() + "?bench=1&size=96x54#" + kState, dom,
                " --virtual-time-budget=300000");
    html = Slurp(dom);
    precompute.clear();
    medians = BenchMedians(html, "96x54", "1", "gpu-timer", &header, &done, &precompute);
    if (header.find(" timer=gpu-timer") == std::string::npos) {
        std::printf("no EXT_disjoint_timer_query_webgl2 here: GPU-timer path not run\n");
        return;
    }
    EXPECT_EQ(done, "done");
    EXPECT_EQ(medians.size(), model_count);
    for (const auto& [name, ms] : medians) EXPECT_GT(ms, 0.0) << name;
    EXPECT_EQ(precompute.size(), PrecomputeModelCount(page));
    for (const auto& [name, ms] : precompute) EXPECT_GT(ms, 0.0) << name;
}

// The comparison above for the earth atmosphere with the `--set` flags `sets`
// (empty, or ones that give it a second Mie lobe and a ground albedo);
// `state_and_bench`: also the URL state's round trip and the benchmark mode.
void ExpectBrowserMatchesAtmosRender(const std::string& sets, bool state_and_bench) {
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

    // One copy of each table (issue 35 item 5): per model tables.f32 only (no
    // EXR, float16 blob or base64 script), as large as its JSON says; every
    // other file is text (JSON, shaders, scripts), small beside the tables.
    uintmax_t table_bytes = 0, other_bytes = 0;
    for (const auto& [file, bytes] : FileSizes(page)) {
        const fs::path p(file);
        EXPECT_NE(p.extension(), ".exr") << file;
        EXPECT_NE(p.extension(), ".f16") << file;
        EXPECT_NE(p.extension(), ".ktx2") << file;
        EXPECT_EQ(p.filename().string().rfind("tables_", 0), std::string::npos) << file;
        if (p.filename() == "tables.f32") {
            table_bytes += bytes;
        } else {
            other_bytes += bytes;
        }
    }
    for (const auto& [name, spec] : models) {
        const std::string json = Slurp(page / name / (name + ".json"));
        const size_t at = json.find("\"float32\"");
        ASSERT_NE(at, std::string::npos) << name;
        const size_t b = json.find("\"bytes\":", at);
        EXPECT_EQ(std::strtoull(json.c_str() + b + 8, nullptr, 10),
                  fs::file_size(page / name / "tables.f32"))
            << name;
    }
    std::printf("viewer directory: tables.f32 %ju bytes, everything else %ju bytes\n", table_bytes,
                other_bytes);
    EXPECT_LT(other_bytes, 3u << 20);

    const int width = 320, height = 180;
    const fs::path dom = dir / "dom.html";
    const std::string url = "file://" + (page / "index.html").string() +
                            "?test=1&format=f32&size=" + std::to_string(width) + "x" +
                            std::to_string(height) + "#" + kState;
    const int rc = RunChromium(chromium, dir, url, dom);
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
    ASSERT_EQ(images.size(), 52u);  // 4 models x (12 views + the state's)

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
    for (const auto& [name, spec] : models) {
        ASSERT_EQ(System(cli + " render" + sets + " --model " + spec + " --load " +
                         (page / name).string() + kStateCamera + " --size " +
                         std::to_string(width) + "x" + std::to_string(height) + " --quiet -o " +
                         (renders / (spec + "-state.exr")).string() + " > " +
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
    if (state_and_bench) ExpectStateAndBench(chromium, dir, page, models.size());
    fs::remove_all(dir);
}

TEST(Viewer, WebGlRenderingOfTheBakedTablesMatchesAtmosRender) {
    ExpectBrowserMatchesAtmosRender("", true);
}

TEST(Viewer, WebGlRenderingMatchesAtmosRenderWithTwoMieLobesAndAGroundAlbedo) {
    // The shaders' second lobe (ATMOS_MIE_PHASE_G2, ATMOS_MIE_PHASE_WEIGHT2 in
    // the baked constants) against the library's MiePhase.
    // With a ground albedo: the lit ground (the state's free view looks down
    // at it) as `atmos render` shows it.
    ExpectBrowserMatchesAtmosRender(
        " --set mie_phase_g2=0.95 --set mie_phase_weight2=0.3 --set ground_albedo=0.3", false);
}

// ---- tables computed on the GPU (issue 35 item 3) ----

// The float precision of the GPU passes (float32 mirrors of the double CPU
// stages; docs/gpu.md "Tables computed on the GPU"): |GPU - CPU| <=
// rel |CPU| + abs max|CPU| for every texel of the table.
struct TableBound {
    double rel, abs;
};
// Transmittance: the optical depth tau to float rounding (relative ~1e-5 of
// tau), so T = exp(-tau) within 1e-5 tau relative: 5e-4 covers tau up to 50;
// below T = 1e-7 (tau > 16, black on screen) an absolute 1e-7.
// Multiple scattering: 2e-3 relative, plus 1e-4 of the table's largest value
// (the texels at the terminator, where the shadow test of a float sample
// point flips, hold values ~1e-9 of the largest).
const std::map<std::string, TableBound> kHillaireBounds = {{"transmittance", {5e-4, 1e-7}},
                                                           {"multiple_scattering", {2e-3, 1e-4}}};

struct PageTable {
    std::string model, table;
    int width = 0, height = 0, depth = 0, channels = 0;
    std::vector<float> values;
};

// The page's <pre class="atmos-table"> elements.
std::vector<PageTable> PageTables(const std::string& html) {
    std::vector<PageTable> tables;
    for (size_t at = html.find("<pre class=\"atmos-table\""); at != std::string::npos;
         at = html.find("<pre class=\"atmos-table\"", at + 1)) {
        PageTable t;
        t.model = Attribute(html, at, "data-model");
        t.table = Attribute(html, at, "data-table");
        t.width = std::atoi(Attribute(html, at, "data-width").c_str());
        t.height = std::atoi(Attribute(html, at, "data-height").c_str());
        t.depth = std::atoi(Attribute(html, at, "data-depth").c_str());
        t.channels = std::atoi(Attribute(html, at, "data-channels").c_str());
        const size_t begin = html.find('>', at) + 1;
        const std::string bytes = DecodeBase64(html.substr(begin, html.find('<', begin) - begin));
        t.values.resize(bytes.size() / 4);
        std::memcpy(t.values.data(), bytes.data(), t.values.size() * 4);
        tables.push_back(std::move(t));
    }
    return tables;
}

// The page's <pre class="atmos-image"> elements of `tables` ("gpu" or "baked").
std::vector<BrowserImage> PageImages(const std::string& html, const std::string& tables, int width,
                                     int height) {
    std::vector<BrowserImage> images;
    for (size_t at = html.find("<pre class=\"atmos-image\""); at != std::string::npos;
         at = html.find("<pre class=\"atmos-image\"", at + 1)) {
        if (Attribute(html, at, "data-tables") != tables) continue;
        BrowserImage b;
        b.model = Attribute(html, at, "data-model");
        b.view = Attribute(html, at, "data-view");
        const size_t begin = html.find('>', at) + 1;
        const std::string bytes = DecodeBase64(html.substr(begin, html.find('<', begin) - begin));
        if (bytes.size() != static_cast<size_t>(width) * height * 12) continue;
        b.image = atmos::Image(width, height);
        std::memcpy(b.image.data(), bytes.data(), bytes.size());
        images.push_back(std::move(b));
    }
    return images;
}

// Table `name` of the bake in `bake` (NAME.json "raw", tables.f32).
std::vector<float> BakedTable(const fs::path& bake, const std::string& model,
                              const std::string& name) {
    const nlohmann::json j = nlohmann::json::parse(Slurp(bake / (model + ".json")));
    const nlohmann::json& e = j["raw"]["tables"][name];
    const std::string blob = Slurp(bake / "tables.f32");
    std::vector<float> v(e["values"].get<size_t>());
    const size_t offset = e["float32_offset"].get<size_t>();
    if (offset + v.size() * 4 > blob.size()) return {};
    std::memcpy(v.data(), blob.data() + offset, v.size() * 4);
    return v;
}

// Loads `page` in test mode with the tables computed on the GPU for the URL
// state `hash`; "" (and a skip message in *skip) where Chromium cannot run.
std::string GpuTablesPage(const std::string& chromium, const fs::path& dir, const fs::path& page,
                          const std::string& hash, int width, int height, std::string* skip) {
    const fs::path dom = dir / "gpu.html";
    const int rc = RunChromium(chromium, dir,
                               "file://" + (page / "index.html").string() +
                                   "?test=1&format=f32&tables=gpu&size=" + std::to_string(width) +
                                   "x" + std::to_string(height) + "#" + hash,
                               dom);
    const std::string html = Slurp(dom);
    if (rc != 0 && html.empty()) {
        *skip = "chromium could not start: " + Slurp(dir / "chromium.log").substr(0, 300);
        return "";
    }
    const size_t tag = html.find("id=\"atmos-test\"");
    if (tag == std::string::npos) return html;
    const size_t open = html.rfind('<', tag);
    if (Attribute(html, open, "data-error").find("WebGL2 is not available") != std::string::npos) {
        *skip = "chromium has no WebGL2 here (SwiftShader missing)";
        return "";
    }
    EXPECT_EQ(Attribute(html, open, "data-status"), "ok")
        << "page error: " << Attribute(html, open, "data-error");
    return html;
}

// The page's GPU tables of `model` against the CPU bake in `bake`, within
// kHillaireBounds; prints the measured errors.
void ExpectTablesMatch(const std::string& html, const fs::path& bake, const std::string& model,
                       const std::string& label,
                       const std::map<std::string, TableBound>& bounds = kHillaireBounds) {
    const std::vector<PageTable> tables = PageTables(html);
    ASSERT_EQ(tables.size(), bounds.size());
    for (const PageTable& t : tables) {
        ASSERT_EQ(t.model, model);
        ASSERT_EQ(bounds.count(t.table), 1u) << t.table;
        const TableBound bound = bounds.at(t.table);
        const std::vector<float> cpu = BakedTable(bake, model, t.table);
        ASSERT_EQ(cpu.size(), t.values.size()) << t.table;
        ASSERT_EQ(cpu.size(), static_cast<size_t>(t.width) * t.height * t.depth * t.channels);
        double largest = 0.0;
        for (const float c : cpu) largest = std::max(largest, std::fabs(static_cast<double>(c)));
        double max_rel = 0.0, max_abs = 0.0;
        size_t bad = 0, worst = 0;
        for (size_t i = 0; i < cpu.size(); ++i) {
            const double c = cpu[i], g = t.values[i];
            const double err = std::fabs(g - c);
            if (!(err <= bound.rel * std::fabs(c) + bound.abs * largest)) {
                if (bad++ == 0) worst = i;
            }
            max_abs = std::max(max_abs, err / largest);
            if (std::fabs(c) > bound.abs * largest) max_rel = std::max(max_rel, err / std::fabs(c));
        }
        std::printf(
            "%s %s %s: max relative error %.3g (texels above %.0e of the largest), "
            "max error %.3g of the largest\n",
            label.c_str(), model.c_str(), t.table.c_str(), max_rel, bound.abs, max_abs);
        EXPECT_EQ(bad, 0u) << label << " " << t.table << ": " << bad << " values outside the "
                           << "bound, first at " << worst << ": GPU " << t.values[worst] << ", CPU "
                           << cpu[worst];
    }
}

// The page's renders from GPU tables (`gpu`) against the same views from the
// CPU tables (`cpu`: the baked tables through the same shaders): mean
// HDR-FLIP <= 0.01 each, the 12 views and the state's.
void ExpectRendersMatch(const std::vector<BrowserImage>& gpu, const std::vector<BrowserImage>& cpu,
                        const std::string& label) {
    EXPECT_EQ(gpu.size(), 13u);  // the 12 views and the state's
    EXPECT_EQ(cpu.size(), gpu.size());
    for (const BrowserImage& g : gpu) {
        for (const BrowserImage& c : cpu) {
            if (c.view != g.view) continue;
            const double flip = atmos::HdrFlip(c.image, g.image).mean;
            std::printf("%s %-22s GPU tables vs CPU tables: HDR-FLIP %.5f\n", label.c_str(),
                        g.view.c_str(), flip);
            EXPECT_LE(flip, 0.01) << label << " " << g.view;
        }
    }
}

// The free view of kState, with hillaire on the left.
constexpr const char* kHillaireView =
    "m=hillaire&m2=hillaire&split=0&pos=0.5&view=&alt=1500&az=200&el=-20&fov=70&sun_az=120&"
    "sun_el=25&exp=1.5&disc=0";

TEST(Viewer, GpuComputedHillaireTablesMatchTheCpuBake) {
#if defined(__SANITIZE_ADDRESS__)
    GTEST_SKIP() << "not under sanitizers (it runs the CLI and a browser)";
#endif
    const std::string chromium = FindChromium();
    if (chromium.empty()) GTEST_SKIP() << "chromium not installed (scripts/setup.sh installs it)";
    const fs::path dir = atmos_test::FreshTestTmpDir("viewer_gpu_" + std::to_string(getpid()));
    const fs::path page = dir / "page";
    const std::string cli = ATMOS_CLI_PATH;
    ASSERT_EQ(System(cli + " viewer --models hillaire -o " + page.string() + " --quiet > " +
                     (dir / "viewer.log").string() + " 2>&1"),
              0)
        << Slurp(dir / "viewer.log");
    ASSERT_TRUE(fs::exists(page / "hillaire/shaders/hillaire_precompute.glsl"));
    ASSERT_TRUE(fs::exists(page / "presets.js"));
    const int width = 160, height = 90;
    std::string skip;
    const std::string html =
        GpuTablesPage(chromium, dir, page, kHillaireView, width, height, &skip);
    if (!skip.empty()) GTEST_SKIP() << skip;
    ExpectTablesMatch(html, page / "hillaire", "hillaire", "earth");
    ExpectRendersMatch(PageImages(html, "gpu", width, height),
                       PageImages(html, "baked", width, height), "earth");
    fs::remove_all(dir);
}

// bruneton's precomputation in the viewer: the same generic pass runner over
// its 25 passes ("add" blending among them), small tables as
// GlHostPrecompute's. Half its texels agree to ~1e-6 (float rounding), but
// rays that graze the ground differ by up to 11 % (where the CPU's own
// quadrature is the noisier one; docs/engine.md "Tables computed on the
// GPU"), so the per-texel bound is loose: 25 % relative plus 1e-3 of the
// table's largest value; the renders hold them to FLIP 0.01.
TEST(Viewer, GpuComputedBrunetonTablesMatchTheCpuBake) {
#if defined(__SANITIZE_ADDRESS__)
    GTEST_SKIP() << "not under sanitizers (it runs the CLI and a browser)";
#endif
    const std::string chromium = FindChromium();
    if (chromium.empty()) GTEST_SKIP() << "chromium not installed (scripts/setup.sh installs it)";
    const fs::path dir = atmos_test::FreshTestTmpDir("viewer_gpu_b_" + std::to_string(getpid()));
    const fs::path page = dir / "page";
    const std::string cli = ATMOS_CLI_PATH;
    ASSERT_EQ(System(cli +
                     " viewer --models bruneton:scattering-r=16:scattering-mu=64:scattering-mu-s=16"
                     " -o " +
                     page.string() + " --quiet > " + (dir / "viewer.log").string() + " 2>&1"),
              0)
        << Slurp(dir / "viewer.log");
    const int width = 160, height = 90;
    std::string view = kHillaireView;
    for (const char* key : {"m=hillaire", "m2=hillaire"}) {
        const size_t at = view.find(key);
        view.replace(at, std::string(key).size(),
                     std::string(key).substr(0, key[1] == '2' ? 3 : 2) + "bruneton");
    }
    std::string skip;
    const std::string html = GpuTablesPage(chromium, dir, page, view, width, height, &skip);
    if (!skip.empty()) GTEST_SKIP() << skip;
    const TableBound loose = {0.25, 1e-3};
    ExpectTablesMatch(html, page / "bruneton", "bruneton", "earth",
                      {{"transmittance", loose},
                       {"irradiance", loose},
                       {"scattering", loose},
                       {"single_mie_scattering", loose}});
    ExpectRendersMatch(PageImages(html, "gpu", width, height),
                       PageImages(html, "baked", width, height), "earth");
    fs::remove_all(dir);
}

// A slider change or another planet: the page's GPU tables and renders for
// that atmosphere against the CPU bake of it (`atmos viewer --atmosphere
// --set`: its tables, and its renders from them), and different from the
// baked atmosphere's.
TEST(Viewer, AtmosphereSlidersRecomputeHillaireOnTheGpuAsTheCpuBakes) {
#if defined(__SANITIZE_ADDRESS__)
    GTEST_SKIP() << "not under sanitizers (it runs the CLI and a browser)";
#endif
    const std::string chromium = FindChromium();
    if (chromium.empty()) GTEST_SKIP() << "chromium not installed (scripts/setup.sh installs it)";
    const fs::path dir = atmos_test::FreshTestTmpDir("viewer_slider_" + std::to_string(getpid()));
    const fs::path page = dir / "page";
    const std::string cli = ATMOS_CLI_PATH;
    ASSERT_EQ(System(cli + " viewer --models hillaire -o " + page.string() + " --quiet > " +
                     (dir / "viewer.log").string() + " 2>&1"),
              0)
        << Slurp(dir / "viewer.log");
    const int width = 160, height = 90;
    // The `--set` of a field scaled by k (the preset's values, as the page's
    // constants hold them to 10 digits).
    auto scaled = [](const char* field, const atmos::Vec3d& v, double k) {
        char text[200];
        std::snprintf(text, sizeof text, " --set %s=%.9e,%.9e,%.9e", field, v.x * k, v.y * k,
                      v.z * k);
        return std::string(text);
    };
    const atmos::AtmosphereParameters earth = atmos::LoadAtmosphere("earth");
    const atmos::AtmosphereParameters mars = atmos::LoadAtmosphere("mars");
    struct Case {
        std::string label, hash, args;
    };
    const std::vector<Case> cases = {
        {"earth-sliders", "atm=earth&ray=2&mie=0.5&oz=3&alb=0.3",
         " --atmosphere earth" + scaled("rayleigh_scattering", earth.rayleigh_scattering, 2.0) +
             scaled("mie_scattering", earth.mie_scattering, 0.5) +
             scaled("mie_extinction", earth.mie_extinction, 0.5) +
             scaled("absorption_extinction", earth.absorption_extinction, 3.0) +
             " --set ground_albedo=0.3"},
        {"mars-mie", "atm=mars&ray=1&mie=2&oz=1&alb=-1",
         " --atmosphere mars" + scaled("mie_scattering", mars.mie_scattering, 2.0) +
             scaled("mie_extinction", mars.mie_extinction, 2.0)}};
    std::string skip;
    for (const Case& c : cases) {
        // The CPU bake of that atmosphere, as a viewer page: its tables and
        // its renders from them.
        const fs::path cpu_page = dir / ("cpu-" + c.label);
        ASSERT_EQ(System(cli + " viewer --models hillaire" + c.args + " -o " + cpu_page.string() +
                         " --quiet > " + (dir / "bake.log").string() + " 2>&1"),
                  0)
            << Slurp(dir / "bake.log");
        const std::string cpu_html =
            GpuTablesPage(chromium, dir, cpu_page, kHillaireView, width, height, &skip);
        if (!skip.empty()) GTEST_SKIP() << skip;
        // Its own GPU passes from its (rewritten) constants, too.
        ExpectTablesMatch(cpu_html, cpu_page / "hillaire", "hillaire", c.label + "-as-baked");
        const std::vector<BrowserImage> cpu = PageImages(cpu_html, "baked", width, height);
        // The default page with the sliders / preset in its URL state.
        const std::string html = GpuTablesPage(
            chromium, dir, page, std::string(kHillaireView) + "&" + c.hash, width, height, &skip);
        ASSERT_TRUE(skip.empty()) << skip;
        ExpectTablesMatch(html, cpu_page / "hillaire", "hillaire", c.label);
        const std::vector<BrowserImage> gpu = PageImages(html, "gpu", width, height);
        ExpectRendersMatch(gpu, cpu, c.label);
        // A different atmosphere: the state's view is far from the baked one's.
        for (const BrowserImage& g : gpu) {
            if (g.view != "state") continue;
            for (const BrowserImage& b : PageImages(html, "baked", width, height)) {
                if (b.view != "state") continue;
                const double flip = atmos::HdrFlip(b.image, g.image).mean;
                std::printf("%s state view vs the baked atmosphere's: HDR-FLIP %.4f\n",
                            c.label.c_str(), flip);
                EXPECT_GT(flip, 0.05) << c.label;
            }
        }
    }
    fs::remove_all(dir);
}

}  // namespace
