// atmos io: the files of a bake that the viewer and `--load` read (bake_files.h).
#include "io/bake_files.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "atmos/model.h"
#include "io/output_path.h"
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

// The page's view of one baked model: MODEL/model.js (its JSON, constants and
// functions: common.glsl then the model's shader)
// and MODEL/tables_f32.js, MODEL/tables_f16.js (the raw blobs in base64):
// scripts, so that the page works from file:// where fetch() is refused.
void WriteViewerData(const fs::path& dir, const std::string& name) {
    const std::string json = ReadWholeFile(dir / (name + ".json"));
    const std::string functions =
        ReadWholeFile(dir / kCommonShader) + ReadWholeFile(dir / ShaderAsset(name));
    std::string file = name;
    for (char& c : file) {
        if (c == '-') c = '_';
    }
    const std::string constants = ReadWholeFile(dir / "shaders" / (file + "_constants.glsl"));
    WriteFileAtomically((dir / "model.js").string(),
                        "atmosViewerData.models[" + JsStringLiteral(name) + "] = {bake: " + json +
                            ", constants: " + JsStringLiteral(constants) +
                            ", functions: " + JsStringLiteral(functions) + "};\n");
    for (const char* format : {"f32", "f16"}) {
        const std::string blob = ReadWholeFile(dir / (std::string("tables.") + format));
        WriteFileAtomically((dir / (std::string("tables_") + format + ".js")).string(),
                            "atmosViewerData.tables[" + JsStringLiteral(name + "/" + format) +
                                "] = \"" + Base64Encode(blob) + "\";\n");
    }
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
