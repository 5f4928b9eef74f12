// atmos io: the engine shader stages of a bake (issue 35 item 1; docs/engine.md,
// "Vulkan, HLSL and Metal").
#pragma once

#include <string>

namespace atmos {

// From the WebGL2 GLSL a bake has just written to DIR/shaders/ (NAME_constants.glsl,
// common.glsl, NAME.glsl), writes complete Vulkan GLSL stages
// DIR/shaders/vulkan/NAME.vert, NAME.frag (and, for a shader that defines the
// per-frame passes atmos_SkyViewTexel / atmos_AerialPerspectiveTexel, the compute
// stages NAME_sky_view.comp and NAME_aerial_perspective.comp; for a bake whose
// JSON has "gpu_precompute", NAME_precompute.frag: all its passes, the pass
// chosen by specialization constant 0) with a uniform
// block and explicit bindings, their bindings as DIR/shaders/vulkan/NAME_bindings.json,
// and, with Debian's glslangValidator and spirv-cross on the PATH, their SPIR-V
// (DIR/shaders/spirv/*.spv), HLSL (DIR/shaders/hlsl/*.hlsl, shader model 5.0) and
// Metal (DIR/shaders/msl/*.metal). Without those tools the Vulkan GLSL is still
// written and one warning line says what is missing (unless `quiet`); a stage the
// tools refuse is an atmos::Error with their message.
void WriteEngineShaders(const std::string& dir, const std::string& model_name, bool quiet);

// Runs a shell command; returns its exit status (-1: it did not exit) and
// puts its stdout and stderr in *output.
int RunShellCommand(const std::string& command, std::string* output);

// Both glslangValidator and spirv-cross are on the PATH.
bool EngineShaderToolsFound();

}  // namespace atmos
