// atmos io: the engine shader stages of a bake (bake_shaders.h): Vulkan GLSL
// from the one WebGL2 GLSL source, translated by glslang (SPIR-V) and
// SPIRV-Cross (HLSL, Metal).
#include "io/engine_shaders.h"

#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "atmos/error.h"
#include "io/output_path.h"
#include "io/text_files.h"

namespace atmos {

int RunShellCommand(const std::string& command, std::string* output) {
    output->clear();
    std::FILE* pipe = popen((command + " 2>&1").c_str(), "r");
    if (!pipe) return -1;
    char buffer[4096];
    size_t n;
    while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) output->append(buffer, n);
    const int status = pclose(pipe);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

namespace engine_shaders {

namespace fs = std::filesystem;

// The frame's uniform block (std140, set 0, binding 0), shared by every stage.
// hillaire's aerial-perspective camera (the WebGL2 source's loose atmos_ap_*
// uniforms, illegal in Vulkan) reads the same camera through macros.
constexpr const char* kFrameBlock = R"(layout(set = 0, binding = 0, std140) uniform AtmosFrame {
    vec4 atmos_frame_camera;   // xyz: camera, m from the planet's centre; w: sun irradiance scale
    vec4 atmos_frame_sun;      // xyz: unit direction to the sun; w: > 0.5 draws the sun's disc
    vec4 atmos_frame_forward;  // xyz: camera forward (unit); w: tan(vertical fov / 2)
    vec4 atmos_frame_right;    // xyz: camera right (unit); w: aspect, width / height
    vec4 atmos_frame_up;       // xyz: camera up (unit); w: unused
};
#define atmos_ap_forward atmos_frame_forward.xyz
#define atmos_ap_right atmos_frame_right.xyz
#define atmos_ap_up atmos_frame_up.xyz
#define atmos_ap_tan_half_fov_y atmos_frame_forward.w
#define atmos_ap_aspect atmos_frame_right.w
)";

constexpr const char* kVertexMain = R"(
// A full-screen triangle (draw 3 vertices, no vertex buffer); atmos_uv is (0, 0)
// at the image's top-left corner and (1, 1) at its bottom-right.
layout(location = 0) out vec2 atmos_uv;
void main() {
    vec2 p = vec2(float((gl_VertexIndex << 1) & 2), float(gl_VertexIndex & 2));
    atmos_uv = p;
    gl_Position = vec4(2.0 * p - 1.0, 0.0, 1.0);
}
)";

// What `atmos render` computes per pixel (a pinhole camera), linear radiance.
constexpr const char* kFragmentMain = R"(
layout(location = 0) in vec2 atmos_uv;
layout(location = 0) out vec4 atmos_radiance;
void main() {
    float tan_y = atmos_frame_forward.w;
    float x = (2.0 * atmos_uv.x - 1.0) * tan_y * atmos_frame_right.w;
    float y = (1.0 - 2.0 * atmos_uv.y) * tan_y;
    vec3 dir = normalize(atmos_frame_forward.xyz + atmos_frame_right.xyz * x +
                         atmos_frame_up.xyz * y);
    vec3 camera = atmos_frame_camera.xyz;
    vec3 sun = atmos_frame_sun.xyz;
    vec3 sky, ground, transmittance;
    bool hits_ground;
    atmos_Evaluate(camera, dir, sun, sky, ground, transmittance, hits_ground);
    vec3 irradiance = ATMOS_SOLAR_IRRADIANCE * atmos_frame_camera.w;
    vec3 radiance = (sky + ground) * irradiance;
    if (atmos_frame_sun.w > 0.5 && !hits_ground &&
        dot(dir, sun) >= cos(ATMOS_SUN_ANGULAR_RADIUS)) {
        radiance += irradiance * transmittance /
                    (ATMOS_PI * ATMOS_SUN_ANGULAR_RADIUS * ATMOS_SUN_ANGULAR_RADIUS);
    }
    atmos_radiance = vec4(max(radiance, vec3(0.0)), 1.0);
}
)";

// The sky-view table of the frame (the WebGL2 viewer's first pass): camera
// radius at least 1 m above the ground, the sun in the x-z plane at the
// camera's mu_s.
constexpr const char* kSkyViewMain = R"(
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
void main() {
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    if (texel.x >= int(ATMOS_SKY_VIEW_WIDTH) || texel.y >= int(ATMOS_SKY_VIEW_HEIGHT)) return;
    vec3 camera = atmos_frame_camera.xyz;
    float r = length(camera);
    float mu_s = clamp(dot(atmos_frame_sun.xyz, camera) / r, -1.0, 1.0);
    vec3 sun = vec3(sqrt(max(0.0, 1.0 - mu_s * mu_s)), 0.0, mu_s);
    vec3 L = atmos_SkyViewTexel(texel, max(r, ATMOS_BOTTOM_RADIUS + 1.0), sun);
    imageStore(atmos_sky_view_image, texel, vec4(L, 1.0));
}
)";

// The aerial-perspective volume of the frame: one invocation per froxel
// column marches its slices in order (the segments and order of the C++
// HillaireAerialPerspectiveStage and of the viewer's per-slice passes).
constexpr const char* kAerialPerspectiveMain = R"(
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
void main() {
    ivec2 column = ivec2(gl_GlobalInvocationID.xy);
    if (column.x >= ATMOS_AP_SIZE || column.y >= ATMOS_AP_SIZE) return;
    vec3 L = vec3(0.0), T = vec3(1.0);
    for (int k = 0; k < ATMOS_AP_SIZE; ++k) {
        atmos_AerialPerspectiveStep(ivec3(column, k), atmos_frame_camera.xyz,
                                    atmos_frame_sun.xyz, L, T);
        imageStore(atmos_ap_scatter_image, ivec3(column, k), vec4(L, 1.0));
        imageStore(atmos_ap_transmittance_image, ivec3(column, k), vec4(T, 1.0));
    }
}
)";

struct Binding {
    int binding;
    std::string name;
    std::string type;  // "uniform block", "sampler2D", "image3D rgba32f", ...
};

struct Source {
    std::string text;  // constants + common + model, rewritten for Vulkan
    std::vector<Binding> bindings;
};

bool StartsWith(const std::string& s, const std::string& prefix) {
    return s.compare(0, prefix.size(), prefix) == 0;
}

// The model's GLSL for Vulkan: each `uniform [highp] samplerND NAME;` gets an
// explicit binding (1, 2, ... in the order of declaration; 0 is the frame's
// block); loose `uniform` values are dropped (the frame block's macros stand
// for them). Nothing else changes: the functions are the WebGL2 source's.
Source RewriteForVulkan(const std::string& text, int* next_binding, std::vector<Binding>* all) {
    Source out;
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) {
        if (StartsWith(line, "uniform ")) {
            std::istringstream words(line);
            std::string uniform, first, second, third;
            words >> uniform >> first >> second >> third;
            const bool highp = first == "highp";
            const std::string type = highp ? second : first;
            std::string name = highp ? third : second;
            if (!name.empty() && name.back() == ';') name.pop_back();
            if (StartsWith(type, "sampler")) {
                const int b = (*next_binding)++;
                all->push_back({b, name, type});
                out.text += "layout(set = 0, binding = " + std::to_string(b) + ") " + line + "\n";
            } else {
                out.text += "// " + line + " (in the AtmosFrame block)\n";
            }
            continue;
        }
        out.text += line + "\n";
    }
    return out;
}

// The GPU precomputation's passes (io/gpu_passes.h) as one Vulkan fragment
// stage: the WebGL2 source's helpers (everything before its "// ---- passes
// ----" line) once, then, per entry of the bake's pass list, its passes'
// section with that entry defined and its main() renamed atmos_pass_N; main()
// calls the pass that the specialization constant ATMOS_PASS (constant_id 0)
// selects. atmos_layer is a push constant; the samplers get bindings after the
// model's. Returns "" when the file has no passes section.
std::string PrecomputeStage(const std::string& text, const std::vector<std::string>& entries,
                            int* next_binding, std::vector<Binding>* all) {
    const size_t split = text.find("\n// ---- passes ----");
    if (split == std::string::npos) return "";
    std::string helpers = text.substr(0, split + 1);
    const std::string passes = text.substr(split + 1);
    const auto replace = [](std::string* s, const std::string& from, const std::string& to) {
        const size_t at = s->find(from);
        if (at != std::string::npos) s->replace(at, from.size(), to);
    };
    replace(&helpers, "\nuniform int atmos_layer;\n",
            "\nlayout(push_constant) uniform AtmosPass { int atmos_layer; };\n");
    replace(&helpers, "\nout vec4 atmos_out;\n", "\nlayout(location = 0) out vec4 atmos_out;\n");
    std::string out = "layout(constant_id = 0) const int ATMOS_PASS = 0;\n" +
                      RewriteForVulkan(helpers, next_binding, all).text;
    std::string calls;
    for (size_t i = 0; i < entries.size(); ++i) {
        const std::string fn = "atmos_pass_" + std::to_string(i);
        std::string body = passes;
        for (size_t at = body.find("void main()"); at != std::string::npos;
             at = body.find("void main()", at + 1)) {
            body.replace(at, 11, "void " + fn + "()");
        }
        out += "\n#define " + entries[i] + " 1\n" + body + "#undef " + entries[i] + "\n";
        calls += "    " + std::string(i ? "else " : "") + "if (ATMOS_PASS == " + std::to_string(i) +
                 ") " + fn + "();  // " + entries[i] + "\n";
    }
    return out + "\nvoid main() {\n" + calls + "}\n";
}

std::string Quote(const fs::path& p) {
    std::string s = "'";
    for (char c : p.string()) {
        if (c == '\'') {
            s += "'\\''";
        } else {
            s += c;
        }
    }
    return s + "'";
}

bool ToolFound(const char* tool) {
    std::string out;
    return RunShellCommand(std::string("command -v ") + tool, &out) == 0;
}

std::string FirstLines(const std::string& text) {
    std::string out;
    std::istringstream in(text);
    std::string line;
    for (int i = 0; i < 6 && std::getline(in, line); ++i) out += (i ? " | " : "") + line;
    return out;
}

}  // namespace engine_shaders

bool EngineShaderToolsFound() {
    return engine_shaders::ToolFound("glslangValidator") &&
           engine_shaders::ToolFound("spirv-cross");
}

void WriteEngineShaders(const std::string& dir_text, const std::string& model_name, bool quiet) {
    using namespace engine_shaders;
    const fs::path dir(dir_text);
    std::string file = model_name;
    for (char& c : file) {
        if (c == '-') c = '_';
    }
    const fs::path shaders = dir / "shaders";
    const std::string constants = ReadWholeFile(shaders / (file + "_constants.glsl"));
    const std::string common = ReadWholeFile(shaders / "common.glsl");
    const std::string model = ReadWholeFile(shaders / (file + ".glsl"));

    std::vector<Binding> bindings = {{0, "AtmosFrame", "uniform block (std140)"}};
    int next_binding = 1;
    const Source body = RewriteForVulkan(model, &next_binding, &bindings);
    const std::string header =
        "#version 450\n"
        "// Generated by `atmos bake` from shaders/" +
        file +
        ".glsl (the WebGL2 source) for\n"
        "// Vulkan: set 0, binding 0 the AtmosFrame block, the tables at the bindings\n"
        "// below (" +
        file + "_bindings.json). Compiles with `glslangValidator -V`.\n";
    const std::string prelude =
        std::string(kFrameBlock) + "\n// ---- " + file + "_constants.glsl ----\n" + constants +
        "\n// ---- common.glsl ----\n" + common + "\n// ---- " + file + ".glsl ----\n" + body.text;

    struct Stage {
        std::string name;   // file name in vulkan/
        std::string stage;  // glslang -S
        std::string text;
    };
    std::vector<Stage> stages;
    stages.push_back({file + ".vert", "vert", header + kVertexMain});
    stages.push_back({file + ".frag", "frag", header + prelude + kFragmentMain});
    std::string bindings_json =
        "{\n  \"frame\": {\"set\": 0, \"binding\": 0, \"block\": \"AtmosFrame\"},\n";
    if (model.find("atmos_SkyViewTexel(") != std::string::npos &&
        model.find("atmos_AerialPerspectiveStep(") != std::string::npos) {
        // The per-frame tables: storage images written by the compute stages,
        // then sampled by the fragment stage at the samplers' bindings.
        const int sky_image = next_binding++;
        const int ap_scatter_image = next_binding++;
        const int ap_transmittance_image = next_binding++;
        bindings.push_back({sky_image, "atmos_sky_view_image", "image2D rgba32f (writeonly)"});
        bindings.push_back(
            {ap_scatter_image, "atmos_ap_scatter_image", "image3D rgba32f (writeonly)"});
        bindings.push_back({ap_transmittance_image, "atmos_ap_transmittance_image",
                            "image3D rgba32f (writeonly)"});
        const std::string sky_decl = "layout(set = 0, binding = " + std::to_string(sky_image) +
                                     ", rgba32f) uniform writeonly image2D atmos_sky_view_image;\n";
        const std::string ap_decl =
            "layout(set = 0, binding = " + std::to_string(ap_scatter_image) +
            ", rgba32f) uniform writeonly image3D atmos_ap_scatter_image;\n"
            "layout(set = 0, binding = " +
            std::to_string(ap_transmittance_image) +
            ", rgba32f) uniform writeonly image3D atmos_ap_transmittance_image;\n";
        stages.push_back(
            {file + "_sky_view.comp", "comp", header + prelude + sky_decl + kSkyViewMain});
        stages.push_back({file + "_aerial_perspective.comp", "comp",
                          header + prelude + ap_decl + kAerialPerspectiveMain});
    }
    // The bake's GPU precomputation ("gpu_precompute" of its JSON, whose files
    // `atmos bake` has installed): one fragment stage for all its passes.
    std::vector<std::string> entries;
    std::string precompute_file;
    for (const auto& e : fs::directory_iterator(dir)) {
        if (e.path().extension() != ".json") continue;
        const nlohmann::json j = nlohmann::json::parse(ReadWholeFile(e.path()), nullptr, false);
        if (!j.is_object() || !j.contains("gpu_precompute")) continue;
        for (const auto& pass : j["gpu_precompute"]["passes"]) {
            const std::string entry = pass["entry"];
            if (std::find(entries.begin(), entries.end(), entry) == entries.end()) {
                entries.push_back(entry);
            }
        }
        const auto& files = j["gpu_precompute"]["shaders"];
        if (!files.empty()) precompute_file = files.back().get<std::string>();
    }
    if (!entries.empty() && fs::exists(dir / precompute_file)) {
        const std::string stage = PrecomputeStage(ReadWholeFile(dir / precompute_file), entries,
                                                  &next_binding, &bindings);
        if (!stage.empty()) {
            stages.push_back({file + "_precompute.frag", "frag", header + prelude + stage});
            bindings_json += "  \"precompute\": {\"stage\": \"" + file +
                             "_precompute.frag\", \"specialization constant 0 (ATMOS_PASS)\": {";
            for (size_t i = 0; i < entries.size(); ++i) {
                bindings_json +=
                    std::string(i ? ", " : "") + "\"" + entries[i] + "\": " + std::to_string(i);
            }
            bindings_json += "}, \"push constant\": \"int atmos_layer\"},\n";
        }
    }
    bindings_json += "  \"bindings\": [\n";
    for (size_t i = 0; i < bindings.size(); ++i) {
        bindings_json += "    {\"set\": 0, \"binding\": " + std::to_string(bindings[i].binding) +
                         ", \"name\": \"" + bindings[i].name + "\", \"type\": \"" +
                         bindings[i].type + "\"}" + (i + 1 < bindings.size() ? "," : "") + "\n";
    }
    bindings_json += "  ],\n  \"stages\": [";
    for (size_t i = 0; i < stages.size(); ++i) {
        bindings_json += std::string(i ? ", " : "") + "\"" + stages[i].name + "\"";
    }
    bindings_json += "]\n}\n";

    const fs::path vulkan = shaders / "vulkan";
    fs::create_directories(vulkan);
    for (const Stage& s : stages) WriteFileAtomically((vulkan / s.name).string(), s.text);
    WriteFileAtomically((vulkan / (file + "_bindings.json")).string(), bindings_json);

    if (!EngineShaderToolsFound()) {
        if (!quiet) {
            std::fprintf(stderr,
                         "atmos: warning: glslangValidator or spirv-cross not found: wrote the "
                         "Vulkan GLSL (%s) but no SPIR-V, HLSL or Metal (Debian: apt-get install "
                         "glslang-tools spirv-cross)\n",
                         vulkan.string().c_str());
        }
        return;
    }
    const fs::path spirv = shaders / "spirv", hlsl = shaders / "hlsl", msl = shaders / "msl";
    fs::create_directories(spirv);
    fs::create_directories(hlsl);
    fs::create_directories(msl);
    for (const Stage& s : stages) {
        // "bruneton.frag" -> "bruneton_frag"
        std::string stem = s.name;
        stem[stem.rfind('.')] = '_';
        const fs::path spv = spirv / (stem + ".spv");
        std::string out;
        if (RunShellCommand("glslangValidator -V --target-env vulkan1.0 -S " + s.stage + " -o " +
                                Quote(spv) + " " + Quote(vulkan / s.name),
                            &out) != 0) {
            Fail("bake: glslangValidator -V refused ", (vulkan / s.name).string(), ": ",
                 FirstLines(out));
        }
        if (RunShellCommand("spirv-cross " + Quote(spv) + " --hlsl --shader-model 50 --output " +
                                Quote(hlsl / (stem + ".hlsl")),
                            &out) != 0) {
            Fail("bake: spirv-cross --hlsl failed on ", spv.string(), ": ", FirstLines(out));
        }
        if (RunShellCommand(
                "spirv-cross " + Quote(spv) + " --msl --output " + Quote(msl / (stem + ".metal")),
                &out) != 0) {
            Fail("bake: spirv-cross --msl failed on ", spv.string(), ": ", FirstLines(out));
        }
    }
}

}  // namespace atmos
