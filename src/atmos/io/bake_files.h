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

// The page's view of one baked model in `dir`: model.js (its JSON, constants
// and functions) and tables_f32.js, tables_f16.js (the raw blobs in base64).
void WriteViewerData(const std::filesystem::path& dir, const std::string& name);

// The model spec of the bake in `dir` (--load without --model): the JSON a
// model's Bake writes names the model ("model") and every option ("options").
// atmos::Error when `dir` holds no bake.
std::string BakedModelSpec(const std::string& dir);

}  // namespace atmos
