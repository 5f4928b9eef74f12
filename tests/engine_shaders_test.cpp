// Issue 35 item 1: `atmos bake` writes complete Vulkan stages from the one GLSL
// source, and their SPIR-V, HLSL and Metal translations (apps/atmos/bake_shaders.cpp).
// Every stage compiles here with glslangValidator -V on its own, its SPIR-V passes
// spirv-val, and every HLSL file compiles back to SPIR-V with glslang's HLSL front
// end (the round trip). Skipped when Debian's glslang-tools / spirv-cross are absent.
// A bake's GPU precomputation (its "gpu_precompute" passes: bruneton, hillaire)
// is one more fragment stage, and every pass also compiles as GLSL 3.30 and ES 3.00.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/engine_shaders.h"
#include "test_util.h"

namespace {

namespace fs = std::filesystem;
using atmos::RunShellCommand;
using atmos_test::Slurp;

fs::path TempDir() { return atmos_test::TestTmpDir("engine_shaders"); }

bool Have(const char* tool) {
    std::string out;
    return RunShellCommand(std::string("command -v ") + tool, &out) == 0;
}

struct BakeCase {
    const char* dir;
    const char* model;
    std::vector<std::string> stages;  // expected in shaders/vulkan/
};

TEST(EngineShaders, EveryStageCompilesAndTranslates) {
    if (!Have("glslangValidator") || !Have("spirv-cross") || !Have("spirv-val")) {
        GTEST_SKIP()
            << "glslang-tools / spirv-cross not installed (scripts/setup.sh installs them)";
    }
    const BakeCase cases[] = {
        {"bruneton",
         "bruneton:orders=1:scattering-r=4:scattering-mu=8:scattering-mu-s=4:scattering-nu=2",
         {"bruneton.vert", "bruneton.frag", "bruneton_precompute.frag"}},
        {"hillaire",
         "hillaire",
         {"hillaire.vert", "hillaire.frag", "hillaire_sky_view.comp",
          "hillaire_aerial_perspective.comp", "hillaire_precompute.frag"}},
        {"atmosphere_plus", "atmosphere-plus", {"atmosphere_plus.vert", "atmosphere_plus.frag"}},
        {"hosek_wilkie", "hosek-wilkie", {"hosek_wilkie.vert", "hosek_wilkie.frag"}},
    };
    for (const BakeCase& c : cases) {
        const fs::path dir = TempDir() / c.dir;
        fs::remove_all(dir);
        std::string out;
        ASSERT_EQ(RunShellCommand(std::string(ATMOS_CLI_PATH) + " bake -q --model " + c.model +
                                      " -o " + dir.string(),
                                  &out),
                  0)
            << out;
        const fs::path shaders = dir / "shaders";
        std::vector<std::string> found;
        for (const auto& e : fs::directory_iterator(shaders / "vulkan")) {
            if (e.path().extension() != ".json") found.push_back(e.path().filename().string());
        }
        EXPECT_EQ(found.size(), c.stages.size()) << c.dir;
        for (const std::string& stage : c.stages) {
            const fs::path source = shaders / "vulkan" / stage;
            ASSERT_TRUE(fs::exists(source)) << source;
            const std::string text = Slurp(source);
            EXPECT_EQ(text.rfind("#version 450\n", 0), 0u) << source;
            // No loose uniform outside a block (illegal in Vulkan GLSL).
            EXPECT_EQ(text.find("\nuniform vec"), std::string::npos) << source;
            EXPECT_EQ(text.find("\nuniform float"), std::string::npos) << source;
            // 1. The Vulkan GLSL compiles as it is.
            const fs::path spv = TempDir() / "check.spv";
            EXPECT_EQ(RunShellCommand("glslangValidator -V --target-env vulkan1.0 -o " +
                                          spv.string() + " " + source.string(),
                                      &out),
                      0)
                << source << ": " << out;
            EXPECT_EQ(RunShellCommand("spirv-val --target-env vulkan1.0 " + spv.string(), &out), 0)
                << source << ": " << out;
            // 2. The bake's SPIR-V, HLSL and Metal exist; the SPIR-V is valid.
            std::string stem = stage;
            const std::string kind = stem.substr(stem.rfind('.') + 1);
            stem[stem.rfind('.')] = '_';
            const fs::path baked_spv = shaders / "spirv" / (stem + ".spv");
            const fs::path hlsl = shaders / "hlsl" / (stem + ".hlsl");
            const fs::path metal = shaders / "msl" / (stem + ".metal");
            ASSERT_TRUE(fs::exists(baked_spv)) << baked_spv;
            ASSERT_TRUE(fs::exists(hlsl)) << hlsl;
            ASSERT_TRUE(fs::exists(metal)) << metal;
            EXPECT_EQ(
                RunShellCommand("spirv-val --target-env vulkan1.0 " + baked_spv.string(), &out), 0)
                << baked_spv << ": " << out;
            const std::string metal_text = Slurp(metal);
            const char* entry = kind == "vert"   ? "vertex "
                                : kind == "frag" ? "fragment "
                                                 : "kernel ";
            EXPECT_NE(metal_text.find("#include <metal_stdlib>"), std::string::npos) << metal;
            EXPECT_NE(metal_text.find(entry), std::string::npos) << metal;
            // 3. The HLSL round-trips: glslang's HLSL front end compiles it back to
            // valid SPIR-V.
            const fs::path back = TempDir() / "roundtrip.spv";
            EXPECT_EQ(RunShellCommand("glslangValidator -D -V -S " + kind + " -e main -o " +
                                          back.string() + " " + hlsl.string(),
                                      &out),
                      0)
                << hlsl << ": " << out;
            EXPECT_EQ(RunShellCommand("spirv-val --target-env vulkan1.0 " + back.string(), &out), 0)
                << hlsl << ": " << out;
            const std::string hlsl_text = Slurp(hlsl);
            if (stage.find("_precompute.") != std::string::npos) {
                // Every pass of "gpu_precompute" in one stage, selected by
                // specialization constant 0 (HLSL: a define; Metal: a function constant).
                EXPECT_NE(hlsl_text.find("SPIRV_CROSS_CONSTANT_ID_0"), std::string::npos) << hlsl;
                EXPECT_NE(metal_text.find("[[function_constant(0)]]"), std::string::npos) << metal;
                EXPECT_NE(text.find("if (ATMOS_PASS == 0) atmos_pass_0();  // ATMOS_"),
                          std::string::npos)
                    << source;
            }
            if (kind != "vert") {  // the full-screen triangle reads no uniform
                EXPECT_NE(hlsl_text.find("cbuffer AtmosFrame : register(b0)"), std::string::npos)
                    << hlsl;
            }
        }
        // The bindings: the frame block at 0, every sampler of the stage at its own binding.
        const std::string model_file = c.stages[0].substr(0, c.stages[0].find('.'));
        const std::string bindings = Slurp(shaders / "vulkan" / (model_file + "_bindings.json"));
        EXPECT_NE(bindings.find("\"binding\": 0, \"name\": \"AtmosFrame\""), std::string::npos);
        // hosek-wilkie has no tables: its constants are compiled into the shader.
        EXPECT_EQ(bindings.find("atmos_transmittance_texture") != std::string::npos,
                  std::string(c.model) != "hosek-wilkie")
            << bindings;
    }
}

// Issue 35 item 3: every pass of a bake's "gpu_precompute" (bruneton's
// precomputation, shaders/bruneton_precompute.glsl; hillaire's transmittance and
// multiple scattering, shaders/hillaire_precompute.glsl) compiles with glslang as
// GLSL 3.30 core and as GLSL ES 3.00 (WebGL2), in the order the schema gives:
// the #version line (and the ES precision lines), the pass's "#define ENTRY 1",
// then the listed files (io/gpu_passes.h). Both storage layouts of the Mie
// scattering, and orders 3 (15 entries) and 1 (6, ZERO among them): all 16;
// hillaire's 2.
TEST(EngineShaders, EveryPrecomputePassCompiles) {
    if (!Have("glslangValidator")) {
        GTEST_SKIP() << "glslang-tools not installed (scripts/setup.sh installs them)";
    }
    const std::string small = "scattering-r=4:scattering-mu=8:scattering-mu-s=4:scattering-nu=2";
    const struct {
        std::string spec, json;
        size_t entries;
    } cases[] = {
        {"bruneton:" + small + ":orders=3:mie-storage=separate", "bruneton.json", 15},
        {"bruneton:" + small + ":orders=1:mie-storage=combined", "bruneton.json", 6},
        {"hillaire", "hillaire.json", 2},
    };
    for (const auto& c : cases) {
        const std::string& options = c.spec;
        const fs::path dir = TempDir() / "gpu_precompute";
        fs::remove_all(dir);
        std::string out;
        ASSERT_EQ(RunShellCommand(std::string(ATMOS_CLI_PATH) + " bake -q --model " + c.spec +
                                      " -o " + dir.string(),
                                  &out),
                  0)
            << out;
        const nlohmann::json j = nlohmann::json::parse(Slurp(dir / c.json));
        ASSERT_TRUE(j.contains("gpu_precompute")) << options;
        std::string sources;
        for (const auto& file : j["gpu_precompute"]["shaders"]) {
            const fs::path path = dir / file.get<std::string>();
            ASSERT_TRUE(fs::exists(path)) << path;
            sources += Slurp(path) + "\n";
        }
        std::vector<std::string> entries;
        for (const auto& pass : j["gpu_precompute"]["passes"]) {
            const std::string entry = pass["entry"];
            if (std::find(entries.begin(), entries.end(), entry) == entries.end()) {
                entries.push_back(entry);
            }
            // Every input and the target are declared targets.
            ASSERT_TRUE(j["gpu_precompute"]["targets"].contains(pass["target"].get<std::string>()));
            for (const auto& [sampler, target] : pass["inputs"].items()) {
                EXPECT_NE(sources.find(" " + sampler + ";"), std::string::npos) << sampler;
                EXPECT_TRUE(j["gpu_precompute"]["targets"].contains(target.get<std::string>()));
            }
        }
        EXPECT_EQ(entries.size(), c.entries) << options;
        for (const std::string& entry : entries) {
            for (const std::string& version : {std::string("330 core"), std::string("300 es")}) {
                const std::string precision = version == "300 es"
                                                  ? "precision highp float;\nprecision highp "
                                                    "int;\nprecision highp sampler3D;\n"
                                                  : "";
                const fs::path frag = TempDir() / "pass.frag";
                {
                    std::ofstream f(frag);
                    f << "#version " << version << "\n"
                      << precision << "#define " << entry << " 1\n"
                      << sources;
                }
                EXPECT_EQ(RunShellCommand("glslangValidator " + frag.string(), &out), 0)
                    << entry << " (" << version << ", " << options << "): " << out;
            }
        }
    }
}

}  // namespace
