// atmos io: a bake's table precomputation as GPU passes (issue 35 item 3;
// docs/engine.md, "Tables computed on the GPU").
//
// A model whose tables a GPU can compute lists, in its bake JSON's
// "gpu_precompute", the fragment-shader passes that compute them from the
// atmosphere's constants (NAME_constants.glsl). Hosts (the viewer, the
// reference OpenGL host examples/gl_host) run the list as it is: they ask the
// bake whether it has one, never the model's name.
//
// Schema ("gpu_precompute" in NAME.json):
//   "shaders": ["shaders/NAME_constants.glsl", "shaders/common.glsl",
//               "shaders/NAME_precompute.glsl"]  the order to concatenate them in,
//              after the #version line, the precision lines (ES) and the
//              pass's "#define ENTRY 1" line;
//   "targets": {NAME: {"width", "height", "depth", "channels" (4: RGBA32F)}}
//              every texture the passes write: the bake's tables (the same names
//              as "raw"."tables") and scratch textures;
//   "passes":  [{"name", "entry" (the #define that selects the pass's main()),
//               "target" (a "targets" name), "inputs" {sampler: target},
//               "uniforms" {name: int}, "blend": "replace" | "add"}]
// A pass draws one full-screen triangle per layer of its target (uniform int
// atmos_layer = z for a 3D target, 0 for a 2D one) into a float render target;
// its fragment shader writes `out vec4 atmos_out` (a table's RGB in .rgb; .a as
// the pass documents). "add" adds the result to the target's texels (blending
// with ONE, ONE, or a copy and add where float blending is missing). Inputs are
// sampled LINEAR, CLAMP_TO_EDGE. After the last pass each table target's first
// "channels" of the raw table (3 or 4) hold what the CPU bake wrote to "raw".
#pragma once

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace atmos {

struct GpuTarget {
    int width = 1, height = 1, depth = 1;
    int channels = 4;
};

struct GpuPass {
    std::string name;
    std::string entry;
    std::string target;
    std::map<std::string, std::string> inputs;  // sampler -> target
    std::map<std::string, int> uniforms;
    bool add = false;  // "blend": "add"
};

struct GpuPrecompute {
    std::vector<std::string> shaders;
    std::map<std::string, GpuTarget> targets;
    std::vector<GpuPass> passes;
};

inline nlohmann::ordered_json GpuPrecomputeJson(const GpuPrecompute& p) {
    nlohmann::ordered_json j;
    j["shaders"] = p.shaders;
    nlohmann::ordered_json targets = nlohmann::ordered_json::object();
    for (const auto& [name, t] : p.targets) {
        targets[name] = {
            {"width", t.width}, {"height", t.height}, {"depth", t.depth}, {"channels", t.channels}};
    }
    j["targets"] = targets;
    nlohmann::ordered_json passes = nlohmann::ordered_json::array();
    for (const GpuPass& pass : p.passes) {
        nlohmann::ordered_json inputs = nlohmann::ordered_json::object();
        for (const auto& [sampler, target] : pass.inputs) inputs[sampler] = target;
        nlohmann::ordered_json uniforms = nlohmann::ordered_json::object();
        for (const auto& [name, value] : pass.uniforms) uniforms[name] = value;
        passes.push_back({{"name", pass.name},
                          {"entry", pass.entry},
                          {"target", pass.target},
                          {"inputs", inputs},
                          {"uniforms", uniforms},
                          {"blend", pass.add ? "add" : "replace"}});
    }
    j["passes"] = passes;
    return j;
}

}  // namespace atmos
