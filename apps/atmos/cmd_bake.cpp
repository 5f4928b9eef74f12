// atmos CLI: `atmos bake`: a model's precomputed tables as files for other
// engines (EXR, raw float32/float16, JSON) with the GLSL that reads them; and
// `atmos viewer`: those, for the models with shaders (bruneton, hillaire,
// atmosphere-plus), in a WebGL2 page.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "atmos/model.h"
#include "base/parallel.h"
#include "cli_common.h"
#include "embedded_assets.h"
#include "io/output_path.h"

namespace atmos::cli {

namespace {

namespace fs = std::filesystem;

// shaders/NAME.glsl for a model name ("atmosphere-plus" -> atmosphere_plus).
std::string ShaderAsset(const std::string& model) {
    std::string file = model;
    for (char& c : file) {
        if (c == '-') c = '_';
    }
    return "shaders/" + file + ".glsl";
}

// The math and geometry every model's shader uses (GLSL has no #include: a
// program concatenates the constants, this, and the model's file).
constexpr const char* kCommonShader = "shaders/common.glsl";

void WriteText(const fs::path& path, const std::string& text) {
    WriteFileAtomically(path.string(), text);
}

std::string ReadFile(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) Fail("cannot read '", path.string(), "'");
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// Precomputes (or --load's) `common`'s model and bakes it into `dir`, shaders
// included; returns the model's registered name.
std::string BakeInto(const CommonOptions& common, const std::string& dir) {
    const ModelSpec spec = GivenModel(common);
    std::unique_ptr<Model> model = CreateModel(spec);
    if (!model->CanBake()) Fail("model ", common.model, " has no precomputed tables to bake");
    ThreadLimit limit(common.threads);
    const AtmosphereParameters atmosphere = LoadAtmosphere(common.atmosphere, common.sets);
    StagedDirectory::Check(dir);  // before the precomputation (io/output_path.h)
    const double seconds = PrepareModel(common, atmosphere, model.get());
    // One transaction (io/output_path.h): a failed or interrupted bake leaves
    // the previous one intact, never a mix of two.
    StagedDirectory staged(dir);
    const fs::path into(staged.path());
    model->Bake(into.string());
    if (const char* shader = FindAsset(ShaderAsset(spec.name))) {
        fs::create_directories(into / "shaders");
        WriteText(into / ShaderAsset(spec.name), shader);
        WriteText(into / kCommonShader, FindAsset(kCommonShader));
    }
    staged.Commit();
    if (!common.quiet) {
        std::fprintf(stderr, "baked %s (precomputed in %.3f s) into %s\n", common.model.c_str(),
                     seconds, dir.c_str());
    }
    return spec.name;
}

// A JavaScript string literal of `text`.
std::string JsString(const std::string& text) {
    std::string out = "\"";
    for (const char c : text) {
        switch (c) {
            case '"':
                out += "\\\"";
                break;
            case '\\':
                out += "\\\\";
                break;
            case '\n':
                out += "\\n";
                break;
            case '\r':
                break;
            case '<':
                out += "\\x3c";
                break;  // no "</script>" in a script
            default:
                out += c;
        }
    }
    return out + "\"";
}

std::string Base64(const std::string& bytes) {
    static const char* kDigits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    size_t i = 0;
    for (; i + 2 < bytes.size(); i += 3) {
        const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) |
                           (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                           static_cast<unsigned char>(bytes[i + 2]);
        out += kDigits[(v >> 18) & 63];
        out += kDigits[(v >> 12) & 63];
        out += kDigits[(v >> 6) & 63];
        out += kDigits[v & 63];
    }
    if (i < bytes.size()) {
        unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
        if (i + 1 < bytes.size()) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
        out += kDigits[(v >> 18) & 63];
        out += kDigits[(v >> 12) & 63];
        out += i + 1 < bytes.size() ? kDigits[(v >> 6) & 63] : '=';
        out += '=';
    }
    return out;
}

// The page's view of one baked model: MODEL/model.js (its JSON, constants and
// functions: common.glsl then the model's shader)
// and MODEL/tables_f32.js, MODEL/tables_f16.js (the raw blobs in base64):
// scripts, so that the page works from file:// where fetch() is refused.
void WriteViewerData(const fs::path& dir, const std::string& name) {
    const std::string json = ReadFile(dir / (name + ".json"));
    const std::string functions = ReadFile(dir / kCommonShader) + ReadFile(dir / ShaderAsset(name));
    std::string file = name;
    for (char& c : file) {
        if (c == '-') c = '_';
    }
    const std::string constants = ReadFile(dir / "shaders" / (file + "_constants.glsl"));
    WriteText(dir / "model.js", "atmosViewerData.models[" + JsString(name) + "] = {bake: " + json +
                                    ", constants: " + JsString(constants) +
                                    ", functions: " + JsString(functions) + "};\n");
    for (const char* format : {"f32", "f16"}) {
        const std::string blob = ReadFile(dir / (std::string("tables.") + format));
        WriteText(dir / (std::string("tables_") + format + ".js"),
                  "atmosViewerData.tables[" + JsString(name + "/" + format) + "] = \"" +
                      Base64(blob) + "\";\n");
    }
}

// A command that bakes into an output directory: the common options and
// -o/--output (`bake` and `viewer`).
Command AddOutputCommand(CLI::App* root, const char* name, const char* description,
                         CommonOptions* common, std::string* output) {
    Command c;
    c.app = root->add_subcommand(name, description);
    AddCommonOptions(c.app, common);
    c.app->add_option("-o,--output", *output, "output directory")->required();
    return c;
}

}  // namespace

Command AddBakeCommand(CLI::App* root) {
    auto common = std::make_shared<CommonOptions>();
    auto output = std::make_shared<std::string>();
    Command c = AddOutputCommand(
        root, "bake",
        "precompute a model's lookup tables and write them (EXR, raw float32/float16, JSON) and "
        "the GLSL that reads them (DIR/shaders/) to a directory",
        common.get(), output.get());
    c.run = [common, output] {
        BakeInto(*common, *output);
        return 0;
    };
    return c;
}

Command AddViewerCommand(CLI::App* root) {
    auto common = std::make_shared<CommonOptions>();
    auto output = std::make_shared<std::string>();
    auto models = std::make_shared<std::vector<std::string>>();
    Command c = AddOutputCommand(
        root, "viewer",
        "bake the models with shaders and write a self-contained WebGL2 sky viewer (open "
        "DIR/index.html; no network)",
        common.get(), output.get());
    c.app
        ->add_option("--models", *models,
                     "models to bake, NAME[:OPTION=VALUE...] comma-separated (default: "
                     "bruneton,hillaire,atmosphere-plus); with --load DIR, one model read "
                     "from DIR")
        ->delimiter(',');
    CLI::Option* model_flag = c.app->get_option("--model");
    c.run = [common, output, models, model_flag] {
        std::vector<std::string> specs = *models;
        if (model_flag->count() > 0) {
            if (!specs.empty()) Fail("give --models or --model, not both");
            specs.push_back(common->model);  // --model: one model, as for bake
        }
        if (specs.empty()) specs = {"bruneton", "hillaire", "atmosphere-plus"};
        if (!common->load.empty() && specs.size() != 1) {
            Fail("--load reads one model's tables: give one model in --models");
        }
        for (const std::string& spec : specs) {  // before any precomputation
            const std::string name = ParseModelSpec(spec).name;
            if (!FindAsset(ShaderAsset(name))) {
                Fail("model ", name, " has no shaders (", ShaderAsset(name),
                     "): the viewer shows bruneton, hillaire and atmosphere-plus");
            }
        }
        const fs::path dir(*output);
        StagedDirectory::Check(dir.string());  // before any precomputation
        StagedDirectory staged(dir.string());  // one transaction, as bake
        const fs::path into(staged.path());
        std::string list;
        for (const std::string& spec : specs) {
            CommonOptions one = *common;
            one.model = spec;
            const std::string name = ParseModelSpec(spec).name;
            BakeInto(one, (into / name).string());
            WriteViewerData(into / name, name);
            list += (list.empty() ? "" : ", ") + JsString(name);
        }
        WriteText(into / "index.html", FindAsset("viewer/index.html"));
        WriteText(into / "viewer.js", FindAsset("viewer/viewer.js"));
        WriteText(into / "models.js", "var atmosViewerModels = [" + list + "];\n");
        staged.Commit();
        if (!common->quiet) {
            std::fprintf(stderr, "viewer: open %s\n",
                         (fs::absolute(dir) / "index.html").string().c_str());
        }
        return 0;
    };
    return c;
}

}  // namespace atmos::cli
