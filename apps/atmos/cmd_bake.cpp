// atmos CLI: `atmos bake`: a model's precomputed tables as files for other
// engines (EXR, raw float32/float16, JSON) with the GLSL that reads them; and
// `atmos viewer`: those, for the models with shaders (bruneton, hillaire, hosek-wilkie,
// atmosphere-plus), in a WebGL2 page.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "atmos/model.h"
#include "base/parallel.h"
#include "cli_common.h"
#include "embedded_assets.h"
#include "io/bake_files.h"
#include "io/engine_shaders.h"
#include "io/output_path.h"
#include "io/rgba_tables.h"
#include "io/text_files.h"

namespace atmos::cli {

namespace {

namespace fs = std::filesystem;

void WriteText(const fs::path& path, const std::string& text) {
    WriteFileAtomically(path.string(), text);
}

// The GLSL files a bake's "gpu_precompute" lists (io/gpu_passes.h) that are
// engine assets (shaders/NAME_precompute.glsl): installed beside the others.
// The bake's JSON is the one with "gpu_precompute"; a model without passes has none.
void InstallPrecomputeShaders(const fs::path& into) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(into, ec)) {
        if (e.path().extension() != ".json") continue;
        const nlohmann::json j = nlohmann::json::parse(ReadWholeFile(e.path()), nullptr, false);
        if (!j.is_object() || !j.contains("gpu_precompute")) continue;
        for (const auto& file : j["gpu_precompute"]["shaders"]) {
            const std::string path = file.get<std::string>();
            if (fs::exists(into / path)) continue;  // written by the bake (constants, common)
            if (const char* text = FindAsset(path)) {
                fs::create_directories((into / path).parent_path());
                WriteText(into / path, text);
            }
        }
    }
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
    staged.Write([&](const std::string& staging) {
        const fs::path into(staging);
        model->Bake(into.string());
        if (const char* shader = FindAsset(ShaderAsset(spec.name))) {
            fs::create_directories(into / "shaders");
            WriteText(into / ShaderAsset(spec.name), shader);
            WriteText(into / kCommonShader, FindAsset(kCommonShader));
            InstallPrecomputeShaders(into);
            WriteEngineShaders(into.string(), spec.name, common.quiet);  // Vulkan, HLSL, Metal
        } else {
            InstallPrecomputeShaders(into);
        }
        InstallPrecomputeShaders(into);
    });
    staged.Commit();
    if (!common.quiet) {
        std::fprintf(stderr, "baked %s (precomputed in %.3f s) into %s\n", common.model.c_str(),
                     seconds, dir.c_str());
    }
    return spec.name;
}

// A command that bakes into an output directory: the common options and
// -o/--output (`bake` and `viewer`).
Command AddOutputCommand(CLI::App* root, const char* name, const char* description,
                         CommonOptions* common, std::string* output) {
    Command c;
    c.app = root->add_subcommand(name, description);
    // A model that bakes (the shared default, naive, has no tables).
    common->model = "bruneton";
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
    auto layout = std::make_shared<std::string>("rgb");
    c.app
        ->add_option("--layout", *layout,
                     "rgb: the 3-channel blobs (tables.f32/.f16, smallest, WebGL2); rgba: also "
                     "RGBA32F/RGBA16F blobs (tables_rgba.*) and KTX2 files (DIR/ktx2/)")
        ->check(CLI::IsMember({"rgb", "rgba"}))
        ->capture_default_str();
    CLI::Option* model_flag = c.app->get_option("--model");
    c.run = [common, output, layout, model_flag] {
        if (!common->load.empty() && model_flag->count() == 0) {
            common->model = BakedModelSpec(common->load);
        }
        const std::string name = BakeInto(*common, *output);
        if (*layout == "rgba") WriteRgbaTables(*output, name);
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
        ->add_option(
            "--models", *models,
            "models to bake, NAME[:OPTION=VALUE...] comma-separated (default: "
            "every model with a viewer shader: hillaire,bruneton,atmosphere-plus,hosek-wilkie); "
            "with --load DIR, one model read from DIR (default: the model of DIR's "
            "bake)")
        ->delimiter(',');
    CLI::Option* model_flag = c.app->get_option("--model");
    c.run = [common, output, models, model_flag] {
        std::vector<std::string> specs = *models;
        if (model_flag->count() > 0) {
            if (!specs.empty()) Fail("give --models or --model, not both");
            specs.push_back(common->model);  // --model: one model, as for bake
        }
        if (specs.empty() && !common->load.empty()) specs = {BakedModelSpec(common->load)};
        if (specs.empty()) specs = ShaderModels();
        if (!common->load.empty() && specs.size() != 1) {
            Fail("--load reads one model's tables: give one model in --models");
        }
        for (const std::string& spec : specs) {  // before any precomputation
            const std::string name = ParseModelSpec(spec).name;
            if (ShaderAsset(name).empty() || !FindAsset(ShaderAsset(name))) {
                std::string list;
                for (const std::string& m : ShaderModels()) list += (list.empty() ? "" : ", ") + m;
                Fail("model ", name, " has no shaders (",
                     ShaderAsset(name).empty() ? "none declared" : ShaderAsset(name),
                     "): the viewer shows ", list);
            }
        }
        const fs::path dir(*output);
        StagedDirectory::Check(dir.string());  // before any precomputation
        StagedDirectory staged(dir.string());  // one transaction, as bake
        staged.Write([&](const std::string& staging) {
            const fs::path into(staging);
            std::string list;
            for (const std::string& spec : specs) {
                CommonOptions one = *common;
                one.model = spec;
                const std::string name = ParseModelSpec(spec).name;
                BakeInto(one, (into / name).string());
                WriteViewerData(into / name, name);
                list += (list.empty() ? "" : ", ") + JsStringLiteral(name);
            }
            WriteText(into / "index.html", FindAsset("viewer/index.html"));
            WriteText(into / "viewer.js", FindAsset("viewer/viewer.js"));
            WriteText(into / "models.js", "var atmosViewerModels = [" + list + "];\n");
            WriteText(into / "presets.js", ViewerPresetsScript());
        });
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
