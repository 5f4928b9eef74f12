// atmos CLI: `atmos list`.
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "atmos/atmosphere.h"
#include "atmos/error.h"
#include "atmos/image.h"
#include "atmos/model.h"
#include "atmos/view.h"
#include "base/parallel.h"
#include "cli_common.h"
#include "harness/gallery.h"
#include "harness/listing.h"

namespace fs = std::filesystem;

namespace atmos::cli {

namespace {

void PrintCapabilities(const ModelInfo& info) {
    std::printf("%s", ModelCapabilitiesText(info).c_str());  // harness/listing.h
}

// `atmos list NAME`: one model with its option table (its own defaults).
int CmdListModel(const std::string& name, bool markdown) {
    const ModelInfo& info = GetModelInfo(name);
    if (markdown) {
        std::printf("%s", OptionsMarkdown(info.options).c_str());
        return 0;
    }
    std::printf("%s: %s\n", info.name.c_str(), info.title.c_str());
    std::printf("  %s\n  source: %s\n", info.summary.c_str(), info.citation.c_str());
    PrintCapabilities(info);
    if (info.options.empty()) {
        std::printf("options: none\n");
        return 0;
    }
    std::printf("options (--model %s:OPTION=VALUE[:OPTION=VALUE...]):\n", info.name.c_str());
    for (const ModelOptionSpec& spec : info.options) {
        std::printf("  %-22s %s, default %s%s\n", spec.name.c_str(), spec.Describe().c_str(),
                    spec.default_value.empty() ? "(none)" : spec.default_value.c_str(),
                    spec.shapes_tables ? "; shapes the baked tables" : "");
        std::printf("  %-22s %s\n", "", spec.help.c_str());
    }
    return 0;
}

int CmdList(const std::string& name, bool markdown) {
    if (!name.empty()) return CmdListModel(name, markdown);
    if (markdown) Fail("list: --markdown needs a model name (atmos list NAME --markdown)");
    std::printf("models (`atmos list NAME` prints one model's options):\n");
    for (const ModelInfo& info : ListModels()) {
        std::printf("  %-16s %s\n", info.name.c_str(), info.title.c_str());
        std::printf("  %-16s   %s\n", "", info.summary.c_str());
        std::printf("  %-16s   source: %s\n", "", info.citation.c_str());
        PrintCapabilities(info);
        for (const ModelOptionSpec& spec : info.options) {
            std::printf("  %-16s   %s=%s: %s\n", "", spec.name.c_str(), spec.default_value.c_str(),
                        spec.help.c_str());
        }
    }
    std::printf("views:\n");
    for (const View& v : StandardViews(EarthAtmosphere())) {
        std::printf("  %-22s exposure %-3g %s\n", v.name.c_str(), static_cast<double>(v.exposure),
                    v.description.c_str());
    }
    std::printf("atmospheres:\n");
    for (const std::string& preset : AtmospherePresetNames()) std::printf("  %s\n", preset.c_str());
    return 0;
}

}  // namespace

Command AddListCommand(CLI::App* root) {
    Command c;
    auto name = std::make_shared<std::string>();
    auto markdown = std::make_shared<bool>(false);
    c.app = root->add_subcommand(
        "list", "list models, views and atmosphere presets; `list NAME`: one model's options");
    c.app->add_option("model", *name, "a model: print its options with their defaults and ranges");
    c.app->add_flag("--markdown", *markdown,
                    "with a model: its option table as Markdown (as in docs/models/NAME.md)");
    c.run = [name, markdown] { return CmdList(*name, *markdown); };
    return c;
}

}  // namespace atmos::cli
