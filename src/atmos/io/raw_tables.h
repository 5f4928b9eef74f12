// atmos: baked tables in a raw layout an engine loads without an EXR library.
//
// `atmos bake` writes, beside the EXR files, every table of the bake into two
// blobs: DIR/tables.f32 (little-endian IEEE float32) and DIR/tables.f16
// (little-endian IEEE half, round to nearest even, clamped to +-65504). In both,
// a table of W x H x D texels with C channels is W*H*D*C consecutive values:
// channel fastest, then x (texture u), then y (v), then z (layer): exactly what
// glTexImage2D/3D reads for a GL_RGB/GL_RGBA texture of W x H (x D). Each
// table starts at a multiple of 256 bytes. The JSON under "raw" gives the files,
// byte sizes and, per table, its sizes and byte offsets in both blobs.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "base/texture.h"

namespace atmos {

struct RawTable {
    std::string name;
    const Table* table;
};

// The size in bytes of the tables.f32 that WriteRawTables writes for `tables`.
size_t RawTablesFloat32Bytes(const std::vector<RawTable>& tables);

// Writes DIR/tables.f32 and DIR/tables.f16; returns their description (the
// bake JSON's "raw"). Throws atmos::Error when a file cannot be written.
nlohmann::ordered_json WriteRawTables(const std::string& directory,
                                      const std::vector<RawTable>& tables);

// IEEE 754 binary16 bits of x: round to nearest even, +-65504 for larger
// magnitudes (no infinities), subnormals kept, NaN to 0.
uint16_t FloatToHalf(float x);

// The shaders' atmosphere #defines (shaders/common.glsl and every model's
// shader read them), in scientific notation with 9 digits: ATMOS_BOTTOM_RADIUS,
// ATMOS_TOP_RADIUS, ATMOS_MIE_PHASE_G, ATMOS_SUN_ANGULAR_RADIUS, the vec3s
// ATMOS_RAYLEIGH_SCATTERING, ATMOS_MIE_SCATTERING, ATMOS_MIE_EXTINCTION,
// ATMOS_ABSORPTION_EXTINCTION, ATMOS_GROUND_ALBEDO, ATMOS_SOLAR_IRRADIANCE, and
// the density profiles (ATMOS_RAYLEIGH_WIDTH0, ATMOS_RAYLEIGH_LAYER0/1 as
// vec4(exp_term, exp_scale, linear_term, constant_term), the same for MIE and
// ABSORPTION).
void WriteGlslAtmosphere(std::ostream& s, const AtmosphereParameters& a);
// A bake's constants file up to its model's own #defines: `header` (the
// comment lines), WriteGlslAtmosphere, and the stream left in scientific
// notation with 9 digits for the model's values.
void BeginGlslConstants(std::ostream& s, const char* header, const AtmosphereParameters& a);

// Writes DIR/shaders/STEM_constants.glsl (a bake's #defines, `text`) and
// returns the bake JSON's "shaders": the constants, shaders/common.glsl and
// shaders/STEM.glsl (installed by `atmos bake`), and "order", the order in
// which a program concatenates them. Throws atmos::Error when it cannot write.
nlohmann::ordered_json WriteGlslConstants(const std::string& directory, const std::string& stem,
                                          const std::string& text);
float HalfToFloat(uint16_t h);

}  // namespace atmos
