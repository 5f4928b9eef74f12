// atmos CLI: `atmos loc`: significant lines of code per model (Leenman 2025, the
// thesis, section 11.7; rules in src/atmos/harness/loc.h), next to the thesis's counts.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "atmos/model.h"
#include "cli_common.h"
#include "harness/loc.h"

namespace fs = std::filesystem;

namespace atmos::cli {

namespace {

struct LocOptions {
    std::vector<std::string> models, files;
    std::string source = DefaultSourceDir();
};

int CmdLoc(const LocOptions& o) {
    if (!o.files.empty()) {
        int total = 0;
        for (const std::string& f : o.files) {
            const int n = CountSignificantLinesInFile(f);
            std::printf("%-50s %6d\n", f.c_str(), n);
            total += n;
        }
        std::printf("total %d\n", total);
        return 0;
    }
    if (!fs::is_directory(fs::path(o.source) / "src" / "atmos" / "models")) {
        Fail("no src/atmos/models under '", o.source, "' (give the repository with --source)");
    }
    std::vector<std::string> models = o.models;
    if (models.empty()) {
        for (const ModelInfo& info : ListModels()) models.push_back(info.name);
    }
    std::printf("%-20s %8s %8s  %s\n", "model", "lines", "thesis", "files");
    for (const std::string& m : models) {
        const ModelLoc loc = CountModelLoc(o.source, m);
        std::string files;
        for (const std::string& f : loc.files) files += (files.empty() ? "" : " ") + f;
        const std::string thesis = loc.thesis_lines >= 0 ? std::to_string(loc.thesis_lines) : "-";
        std::printf("%-20s %8d %8s  %s\n", m.c_str(), loc.lines, thesis.c_str(),
                    files.empty() ? "(no files)" : files.c_str());
    }
    return 0;
}

}  // namespace

Command AddLocCommand(CLI::App* root) {
    auto o = std::make_shared<LocOptions>();
    CLI::App* cmd = root->add_subcommand(
        "loc", "significant lines of code per model (thesis section 11.7 rules)");
    cmd->add_option("models", o->models, "models (default: all registered)");
    cmd->add_option("--file", o->files, "count these files instead (repeatable)")
        ->allow_extra_args(false);
    cmd->add_option("--source", o->source, "repository root holding src/atmos/models")
        ->capture_default_str();
    return {cmd, [o] { return CmdLoc(*o); }};
}

}  // namespace atmos::cli
