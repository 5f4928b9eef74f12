// atmos io: the files of a bake that the viewer and `--load` read (bake_files.h).
#include "io/bake_files.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/model.h"
#include "io/output_path.h"
#include "io/raw_tables.h"
#include "io/text_files.h"

namespace atmos {

namespace fs = std::filesystem;

// shaders/FILE.glsl of a model that declares one (ModelCapabilities::shader),
// or "" for one that does not.
std::string ShaderAsset(const std::string& model) {
    const std::string& file = GetModelInfo(model).capabilities.shader;
    return file.empty() ? "" : "shaders/" + file + ".glsl";
}

// The viewer's default list: every model with a shader, in registry order.
std::vector<std::string> ShaderModels() {
    std::vector<std::string> names;
    for (const ModelInfo& info : ListModels()) {
        if (!info.capabilities.shader.empty()) names.push_back(info.name);
    }
    return names;
}

namespace {
// Every string of `j` naming an EXR table names the blob instead.
void PointTablesAtBlob(nlohmann::ordered_json* j) {
    if (j->is_string()) {
        const std::string v = j->get<std::string>();
        if (v.size() > 4 && v.compare(v.size() - 4, 4, ".exr") == 0) *j = "tables.f32";
    } else if (j->is_structured()) {
        for (auto& child : *j) PointTablesAtBlob(&child);
    }
}
}  // namespace

// One copy of each table (issue 35 item 5): the bake's EXR files and
// tables.f16 go (the page uploads the float32 blob as float16 textures when
// asked, and --load reads tables.f32 when the EXRs are absent: io/table_io.h);
// the JSON says so. Then the page's view of the model: MODEL/model.js (its
// JSON, constants and functions: common.glsl then the model's shader); the
// page loads MODEL/tables.f32 itself (XMLHttpRequest).
void WriteViewerData(const fs::path& dir, const std::string& name) {
    const fs::path json_path = dir / (name + ".json");
    nlohmann::ordered_json j = nlohmann::ordered_json::parse(ReadWholeFile(json_path));
    if (j.contains("raw") && j["raw"].is_object()) {
        j["raw"].erase("float16");
        if (j["raw"].contains("tables")) {
            for (auto& t : j["raw"]["tables"]) t.erase("float16_offset");
        }
    }
    PointTablesAtBlob(&j);
    j["viewer"] =
        "written by atmos viewer: the tables are in tables.f32 only (the EXR files and "
        "tables.f16 of a bake are left out; \"file\" names the blob)";
    WriteFileAtomically(json_path.string(), j.dump(2) + "\n");
    std::error_code ec;
    fs::remove(dir / "tables.f16", ec);
    std::vector<fs::path> exrs;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
        if (e.path().extension() == ".exr") exrs.push_back(e.path());
    }
    for (const fs::path& p : exrs) fs::remove(p, ec);
    const std::string functions =
        ReadWholeFile(dir / kCommonShader) + ReadWholeFile(dir / ShaderAsset(name));
    std::string file = name;
    for (char& c : file) {
        if (c == '-') c = '_';
    }
    const std::string constants_path = "shaders/" + file + "_constants.glsl";
    const std::string constants = ReadWholeFile(dir / constants_path);
    // The constants split where the atmosphere's #defines end (the page
    // regenerates them for another atmosphere: ViewerPresetsScript), and the
    // text of every other shader of the bake's GPU passes (io/gpu_passes.h).
    std::string model_constants = constants;
    if (j.contains("atmosphere")) {
        std::ostringstream atmosphere;
        WriteGlslAtmosphere(atmosphere, AtmosphereFromJson(j["atmosphere"].dump(), name));
        const size_t at = constants.find(atmosphere.str());
        if (at == std::string::npos) {
            Fail(json_path.string(), ": its constants do not hold its atmosphere's #defines");
        }
        model_constants = constants.substr(at + atmosphere.str().size());
    }
    std::string sources;
    if (j.contains("gpu_precompute") && j["gpu_precompute"].contains("shaders")) {
        for (const auto& path : j["gpu_precompute"]["shaders"]) {
            const std::string p = path.get<std::string>();
            if (p == constants_path) continue;  // the page writes its own
            sources += (sources.empty() ? "" : ", ") + JsStringLiteral(p) + ": " +
                       JsStringLiteral(ReadWholeFile(dir / p));
        }
    }
    WriteFileAtomically(
        (dir / "model.js").string(),
        "atmosViewerData.models[" + JsStringLiteral(name) + "] = {bake: " + j.dump() +
            ", constants: " + JsStringLiteral(constants) +
            ", constantsPath: " + JsStringLiteral(constants_path) +
            ", modelConstants: " + JsStringLiteral(model_constants) +
            ", functions: " + JsStringLiteral(functions) + ", sources: {" + sources + "}};\n");
}

std::string ViewerPresetsScript() {
    std::string out = "var atmosViewerPresets = {";
    bool first = true;
    for (const std::string& name : AtmospherePresetNames()) {
        const AtmosphereParameters a = LoadAtmosphere(name);
        std::ostringstream constants;
        WriteGlslAtmosphere(constants, a);
        nlohmann::ordered_json albedo = {a.ground_albedo[0], a.ground_albedo[1],
                                         a.ground_albedo[2]};
        out += std::string(first ? "" : ",") + "\n  " + JsStringLiteral(name) +
               ": {constants: " + JsStringLiteral(constants.str()) +
               ", bottom: " + nlohmann::ordered_json(a.bottom_radius).dump() +
               ", top: " + nlohmann::ordered_json(a.top_radius).dump() +
               ", albedo: " + albedo.dump() + "}";
        first = false;
    }
    return out + "\n};\n";
}

// The model spec of the bake in `dir` (--load without --model): the JSON a
// model's Bake writes names the model ("model") and every option ("options").
std::string BakedModelSpec(const std::string& dir) {
    std::vector<fs::path> jsons;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
        if (e.path().extension() == ".json") jsons.push_back(e.path());
    }
    std::sort(jsons.begin(), jsons.end());
    for (const fs::path& path : jsons) {
        std::ifstream in(path);
        nlohmann::json j;
        try {
            in >> j;
        } catch (const std::exception&) {
            continue;
        }
        if (!j.is_object() || !j.contains("model") || !j["model"].is_string()) continue;
        const std::string name = j["model"].get<std::string>();
        bool known = false;
        for (const ModelInfo& info : ListModels()) known = known || info.name == name;
        if (!known) continue;
        std::string spec = name;
        if (j.contains("options") && j["options"].is_object()) {
            for (const auto& [option, value] : j["options"].items()) {
                spec += ":" + option + "=" +
                        (value.is_string() ? value.get<std::string>() : value.dump());
            }
        }
        return spec;
    }
    Fail("--load ", dir, ": no bake here (a JSON naming its \"model\", written by atmos bake)");
}

}  // namespace atmos
