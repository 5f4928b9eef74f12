#include "io/raw_tables.h"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <ostream>

#include "atmos/error.h"
#include "io/image_formats.h"
#include "io/output_path.h"

namespace atmos {

uint16_t FloatToHalf(float x) {
    if (!std::isfinite(x)) {
        if (std::isnan(x)) return 0;
        x = x > 0.0f ? 65504.0f : -65504.0f;
    }
    uint32_t bits;
    std::memcpy(&bits, &x, 4);
    const uint16_t sign = static_cast<uint16_t>((bits >> 16) & 0x8000u);
    const uint32_t abs_bits = bits & 0x7fffffffu;
    float a;
    std::memcpy(&a, &abs_bits, 4);
    if (a >= 65520.0f) return static_cast<uint16_t>(sign | 0x7bffu);  // rounds past the max
    if (a < 5.9604645e-8f * 0.5f) return sign;                        // below half the smallest
    const int exponent = static_cast<int>(abs_bits >> 23) - 127;
    if (exponent < -14) {
        // Subnormal: value = m * 2^-24, m in [0, 1024); round to nearest even.
        const double m = static_cast<double>(a) * 16777216.0;
        double r = std::nearbyint(m);  // default rounding mode: to nearest even
        return static_cast<uint16_t>(sign | static_cast<uint16_t>(r));
    }
    // Normal: keep 10 mantissa bits, round to nearest even on the 13 dropped.
    uint32_t mantissa = abs_bits & 0x7fffffu;
    uint32_t e = static_cast<uint32_t>(exponent + 15);
    uint32_t h = (e << 10) | (mantissa >> 13);
    const uint32_t rest = mantissa & 0x1fffu;
    if (rest > 0x1000u || (rest == 0x1000u && (h & 1u))) ++h;  // may carry into the exponent
    return static_cast<uint16_t>(sign | h);
}

float HalfToFloat(uint16_t h) {
    const float sign = (h & 0x8000u) ? -1.0f : 1.0f;
    const int e = (h >> 10) & 0x1f;
    const int m = h & 0x3ff;
    if (e == 0) return sign * std::ldexp(static_cast<float>(m), -24);
    if (e == 31) return sign * 65504.0f;  // never written
    return sign * std::ldexp(static_cast<float>(1024 + m), e - 25);
}

namespace {

constexpr size_t kAlign = 256;

size_t AlignUp(size_t n) { return (n + kAlign - 1) / kAlign * kAlign; }

// Through a temporary file and one rename (io/output_path.h): a failed write
// never leaves a truncated table file.
void WriteFile(const std::string& path, const std::vector<unsigned char>& bytes) {
    WriteThroughTemporary(path, [&](const std::string& temporary) {
        detail::WriteFileBytes(temporary, bytes);  // each write and the close checked
    });
}

void PutLe(std::vector<unsigned char>* out, size_t at, uint32_t v, int bytes) {
    for (int i = 0; i < bytes; ++i) (*out)[at + i] = static_cast<unsigned char>(v >> (8 * i));
}

}  // namespace

size_t RawTablesFloat32Bytes(const std::vector<RawTable>& tables) {
    size_t bytes = 0;
    for (const RawTable& t : tables) bytes = AlignUp(bytes) + 4 * t.table->size();
    return bytes;
}

nlohmann::ordered_json WriteRawTables(const std::string& directory,
                                      const std::vector<RawTable>& tables) {
    std::vector<unsigned char> f32, f16;
    nlohmann::ordered_json list = nlohmann::ordered_json::object();
    for (const RawTable& t : tables) {
        const Table& table = *t.table;
        const size_t n = table.size();
        const size_t o32 = AlignUp(f32.size()), o16 = AlignUp(f16.size());
        f32.resize(o32 + 4 * n, 0);
        f16.resize(o16 + 2 * n, 0);
        for (size_t i = 0; i < n; ++i) {
            uint32_t bits;
            std::memcpy(&bits, table.data() + i, 4);
            PutLe(&f32, o32 + 4 * i, bits, 4);
            PutLe(&f16, o16 + 2 * i, FloatToHalf(table.data()[i]), 2);
        }
        list[t.name] = {{"width", table.width()},
                        {"height", table.height()},
                        {"depth", table.depth()},
                        {"channels", table.channels()},
                        {"values", n},
                        {"float32_offset", o32},
                        {"float16_offset", o16}};
    }
    namespace fs = std::filesystem;
    WriteFile((fs::path(directory) / "tables.f32").string(), f32);
    WriteFile((fs::path(directory) / "tables.f16").string(), f16);
    nlohmann::ordered_json j;
    j["description"] =
        "every table in two blobs, little-endian: float32 and IEEE half (round to nearest even, "
        "clamped to 65504); a W x H x D table with C channels is W*H*D*C values, channel fastest, "
        "then x (u), y (v), z (layer): the order glTexImage2D/3D reads; offsets in bytes";
    j["float32"] = {{"file", "tables.f32"}, {"bytes", f32.size()}};
    j["float16"] = {{"file", "tables.f16"}, {"bytes", f16.size()}};
    j["tables"] = list;
    return j;
}

void WriteGlslAtmosphere(std::ostream& s, const AtmosphereParameters& a) {
    const std::ios_base::fmtflags flags = s.flags();
    const std::streamsize precision = s.precision(9);
    s << std::scientific;
    auto vec3 = [&](const char* name, const Vec3d& v) {
        s << "#define " << name << " vec3(" << v.x << ", " << v.y << ", " << v.z << ")\n";
    };
    s << "#define ATMOS_BOTTOM_RADIUS " << a.bottom_radius << "\n";
    s << "#define ATMOS_TOP_RADIUS " << a.top_radius << "\n";
    s << "#define ATMOS_MIE_PHASE_G " << a.mie_phase_g << "\n";
    if (a.mie_phase_kind != MiePhaseKind::kCornetteShanks) {
        // The phase function's kind (common.glsl atmos_MiePhase; atmosphere.h
        // MiePhaseKind); absent for Cornette-Shanks, so those constants are as before.
        s << "#define ATMOS_MIE_PHASE_KIND " << static_cast<int>(a.mie_phase_kind) << "\n";
    }
    if (a.mie_phase_kind == MiePhaseKind::kTabulated) {
        // The table as two constant arrays: the nodes' cosines and the normalised
        // values (1/sr), linear in nu between nodes as physics/phase.h TabulatedPhase.
        const MiePhaseTable& t = a.mie_phase_table;
        s << "#define ATMOS_MIE_PHASE_TABLE_COUNT " << t.count << "\n";
        for (int array = 0; array < 2; ++array) {
            s << "const float "
              << (array == 0 ? "atmos_MiePhaseTableMu" : "atmos_MiePhaseTableValue") << "["
              << t.count << "] = float[" << t.count << "](";
            for (int i = 0; i < t.count; ++i) {
                s << (i == 0 ? "" : ", ") << (array == 0 ? t.mu[i] : t.value[i] * t.scale);
            }
            s << ");\n";
        }
    }
    if (a.mie_phase_weight2 != 0.0) {
        // The second Cornette-Shanks lobe (common.glsl atmos_MiePhase); absent
        // for one lobe, so one-lobe constants are as before.
        s << "#define ATMOS_MIE_PHASE_G2 " << a.mie_phase_g2 << "\n";
        s << "#define ATMOS_MIE_PHASE_WEIGHT2 " << a.mie_phase_weight2 << "\n";
    }
    s << "#define ATMOS_SUN_ANGULAR_RADIUS " << a.sun_angular_radius << "\n";
    vec3("ATMOS_RAYLEIGH_SCATTERING", a.rayleigh_scattering);
    vec3("ATMOS_MIE_SCATTERING", a.mie_scattering);
    vec3("ATMOS_MIE_EXTINCTION", a.mie_extinction);
    vec3("ATMOS_ABSORPTION_EXTINCTION", a.absorption_extinction);
    vec3("ATMOS_GROUND_ALBEDO", a.ground_albedo);
    vec3("ATMOS_SOLAR_IRRADIANCE", a.solar_irradiance);
    auto profile = [&](const char* name, const DensityProfile& p) {
        s << "#define ATMOS_" << name << "_WIDTH0 " << p.layers[0].width << "\n";
        for (int i = 0; i < 2; ++i) {
            const DensityProfileLayer& l = p.layers[i];
            s << "#define ATMOS_" << name << "_LAYER" << i << " vec4(" << l.exp_term << ", "
              << l.exp_scale << ", " << l.linear_term << ", " << l.constant_term << ")\n";
        }
    };
    profile("RAYLEIGH", a.rayleigh_density);
    profile("MIE", a.mie_density);
    profile("ABSORPTION", a.absorption_density);
    s.flags(flags);
    s.precision(precision);
}

void BeginGlslConstants(std::ostream& s, const char* header, const AtmosphereParameters& a) {
    s << header;
    WriteGlslAtmosphere(s, a);
    s.precision(9);
    s << std::scientific;
}

nlohmann::ordered_json WriteGlslConstants(const std::string& directory, const std::string& stem,
                                          const std::string& text) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::path(directory) / "shaders";
    fs::create_directories(dir);
    const std::string constants = "shaders/" + stem + "_constants.glsl";
    const std::string path = (fs::path(directory) / constants).string();
    WriteFileAtomically(path, text);
    const std::string functions = "shaders/" + stem + ".glsl";
    nlohmann::ordered_json j;
    j["constants"] = constants;
    j["common"] = "shaders/common.glsl";
    j["functions"] = functions;
    j["order"] = {constants, "shaders/common.glsl", functions};
    return j;
}

}  // namespace atmos
