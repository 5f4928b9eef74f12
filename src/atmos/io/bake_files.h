// atmos io: the files of a bake that the viewer and `--load` read.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace atmos {

// The math and geometry every model's shader uses (GLSL has no #include: a
// program concatenates the constants, this, and the model's file).
inline constexpr const char* kCommonShader = "shaders/common.glsl";

// shaders/FILE.glsl of a model that declares one (ModelCapabilities::shader),
// or "" for one that does not.
std::string ShaderAsset(const std::string& model);

// The viewer's default list: every model with a shader, in registry order.
std::vector<std::string> ShaderModels();

// Thins the bake in `dir` to one copy of each table (tables.f32; its EXR
// files and tables.f16 are removed and its JSON says so) and writes the page's
// view of it: model.js (its JSON, constants and functions; the constants
// past the atmosphere's #defines, "modelConstants"; and the text of every
// other shader its GPU passes list, "sources": io/gpu_passes.h).
void WriteViewerData(const std::filesystem::path& dir, const std::string& name);

// The page's presets.js: every embedded atmosphere preset (AtmospherePresetNames)
// as its shaders' #defines (WriteGlslAtmosphere, computed here in C++), radii
// and ground albedo, for the viewer's planet-preset menu.
std::string ViewerPresetsScript();

// The model spec of the bake in `dir` (--load without --model): the JSON a
// model's Bake writes names the model ("model") and every option ("options").
// atmos::Error when `dir` holds no bake.
std::string BakedModelSpec(const std::string& dir);

}  // namespace atmos
