// The reference integration (issue 35 item 6, docs/engine.md): the OpenGL 3.3
// host examples/gl_host renders views of a bake headless through EGL (Mesa's
// llvmpipe here), and each must match `atmos render --load` of the same view
// from the same tables: mean HDR-FLIP <= 0.01. bruneton (small tables, separate
// and combined Mie), hillaire (its baked tables and the host's per-frame
// sky-view and aerial-perspective passes), atmosphere-plus (small tables) and
// hosek-wilkie (no tables), at four standard views and a free camera with
// float32 tables and one view with float16 tables. Skipped with the reason
// where the host was not built (no EGL/OpenGL at configure time) or EGL gives
// no OpenGL 3.3 context, and in sanitizer builds.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "atmos/image.h"
#include "metrics/flip.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace {

using atmos_test::Slurp;
using atmos_test::System;

#ifdef ATMOS_GL_HOST_PATH
constexpr const char* kHost = ATMOS_GL_HOST_PATH;
#else
constexpr const char* kHost = nullptr;
#endif

// Skips (with the reason) unless the host was built and EGL gives it a context.
#define SKIP_WITHOUT_GL_HOST(dir)                                                                  \
    do {                                                                                           \
        if (!kHost) {                                                                              \
            GTEST_SKIP() << "atmos_gl_host not built: EGL, libOpenGL or GL/glcorearb.h not "       \
                            "found at configure time (scripts/setup.sh installs them), or "        \
                            "ATMOS_GL_HOST=OFF";                                                   \
        }                                                                                          \
        const int info_rc =                                                                        \
            System(std::string(kHost) + " --info > " + ((dir) / "info.log").string() + " 2>&1");   \
        if (info_rc == 3) {                                                                        \
            GTEST_SKIP() << "EGL gives no OpenGL 3.3 context here: " << Slurp((dir) / "info.log"); \
        }                                                                                          \
        ASSERT_EQ(info_rc, 0) << Slurp((dir) / "info.log");                                        \
    } while (0)

struct Case {
    std::string view;    // a standard view, or "" for the free camera below
    std::string format;  // f32 or f16
};

// The free camera: 1 km up, looking east-north-east a little above the
// horizon, the sun low in the east (sun irradiance 1, not the views' 6).
constexpr const char* kCamera = "altitude=1000,azimuth=70,elevation=4,roll=5,fov=50";
constexpr const char* kSun = "elevation=8,azimuth=95";

void ExpectHostMatchesAtmosRender(const std::string& name, const std::string& spec) {
#if defined(__SANITIZE_ADDRESS__)
    GTEST_SKIP() << "not under sanitizers (Mesa's allocations; the Release suite has it)";
#endif
    const fs::path dir =
        atmos_test::FreshTestTmpDir("gl_host_" + name + "_" + std::to_string(getpid()));
    SKIP_WITHOUT_GL_HOST(dir);
    std::printf("%s", Slurp(dir / "info.log").c_str());
    const std::string cli = ATMOS_CLI_PATH;
    const fs::path bake = dir / "bake", log = dir / "log";
    ASSERT_EQ(System(cli + " bake -q --model " + spec + " -o " + bake.string() + " > " +
                     log.string() + " 2>&1"),
              0)
        << Slurp(log);
    const int width = 160, height = 90;
    const std::string size = std::to_string(width) + "x" + std::to_string(height);
    // Inside the atmosphere (hillaire's passes run), a dim dawn, outside it.
    const std::vector<Case> cases = {
        {"ground-sunrise", "f32"},       {"plane-dawn", "f32"}, {"orbit-noon", "f32"},
        {"planet-shadow-ground", "f32"}, {"", "f32"},           {"ground-noon", "f16"}};
    for (const Case& c : cases) {
        const std::string label = (c.view.empty() ? "free-camera" : c.view) + "-" + c.format;
        const std::string where = c.view.empty()
                                      ? std::string(" --camera ") + kCamera + " --sun " + kSun
                                      : " --view " + c.view;
        const fs::path ref = dir / (label + ".exr"), test = dir / (label + ".pfm");
        ASSERT_EQ(
            System(cli + " render -q --model " + spec + " --load " + bake.string() + where +
                   " --size " + size + " -o " + ref.string() + " > " + log.string() + " 2>&1"),
            0)
            << Slurp(log);
        ASSERT_EQ(System(std::string(kHost) + " " + bake.string() + where + " --size " + size +
                         " --format " + c.format + " -o " + test.string() + " > " + log.string() +
                         " 2>&1"),
                  0)
            << label << ": " << Slurp(log);
        const atmos::Image reference = atmos::ReadImage(ref.string());
        const atmos::Image image = atmos::ReadImage(test.string());
        ASSERT_EQ(image.width(), width);
        ASSERT_EQ(image.height(), height);
        const double flip = atmos::HdrFlip(reference, image).mean;
        std::printf("%-16s %-26s HDR-FLIP %.6f  %s", name.c_str(), label.c_str(), flip,
                    Slurp(log).c_str());
        EXPECT_LE(flip, 0.01) << name << " " << label;
    }
    fs::remove_all(dir);
}

TEST(GlHost, BrunetonMatchesAtmosRender) {
    ExpectHostMatchesAtmosRender(
        "bruneton", "bruneton:orders=2:scattering-r=16:scattering-mu=64:scattering-mu-s=16");
}

TEST(GlHost, BrunetonCombinedMieMatchesAtmosRender) {
    // One RGBA scattering table, the single Mie extrapolated from its alpha.
    ExpectHostMatchesAtmosRender("bruneton-combined",
                                 "bruneton:orders=2:scattering-r=16:scattering-mu=64:scattering-"
                                 "mu-s=16:mie-storage=combined");
}

TEST(GlHost, HillaireMatchesAtmosRender) { ExpectHostMatchesAtmosRender("hillaire", "hillaire"); }

TEST(GlHost, AtmospherePlusMatchesAtmosRender) {
    ExpectHostMatchesAtmosRender(
        "atmosphere-plus",
        "atmosphere-plus:orders=2:table-width=16:table-height=32:table-depth=16:"
        "transmittance-width=16:transmittance-height=64:gather-theta=6:gather-phi=12");
}

TEST(GlHost, HosekWilkieMatchesAtmosRender) {
    // No tables: constants only (an empty blob).
    ExpectHostMatchesAtmosRender("hosek-wilkie", "hosek-wilkie");
}

// Bad input: one `atmos_gl_host: error: ...` line, exit 2, nothing written
// (checked before any GL work, so it needs no context).
TEST(GlHost, BadInputIsOneErrorLineAndExit2) {
    if (!kHost) GTEST_SKIP() << "atmos_gl_host not built";
    const fs::path dir = atmos_test::FreshTestTmpDir("gl_host_bad_" + std::to_string(getpid()));
    const fs::path out = dir / "out.pfm";
    for (const std::string& args :
         {std::string(" ") + dir.string() + " --view ground-noon -o " + out.string(),
          std::string(" --view ground-noon -o ") + out.string(),
          std::string(" ") + dir.string() + " --view ground-noon --size 0x9 -o " + out.string(),
          std::string(" ") + dir.string() + " --view x --format f64 -o " + out.string()}) {
        const atmos_test::CommandOutcome r =
            atmos_test::RunCapturing(std::string(kHost) + args, dir / "o", dir / "e");
        EXPECT_EQ(r.status, 2) << args;
        EXPECT_EQ(r.err.rfind("atmos_gl_host: error: ", 0), 0u) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_FALSE(fs::exists(out)) << args;
    }
    fs::remove_all(dir);
}

}  // namespace
