// atmos CLI: `atmos bake`: a model's precomputed tables as files for other engines.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "atmos/error.h"
#include "atmos/model.h"
#include "base/parallel.h"
#include "cli_common.h"
#include "io/output_path.h"

namespace atmos::cli {

Command AddBakeCommand(CLI::App* root) {
    auto common = std::make_shared<CommonOptions>();
    auto output = std::make_shared<std::string>();
    Command c;
    c.app = root->add_subcommand(
        "bake", "precompute a model's lookup tables and write them (EXR + JSON) to a directory");
    AddCommonOptions(c.app, common.get());
    c.app->add_option("-o,--output", *output, "output directory")->required();
    c.run = [common, output] {
        std::unique_ptr<Model> model = CreateModel(GivenModel(*common));
        if (!model->CanBake()) Fail("model ", common->model, " has no precomputed tables to bake");
        ThreadLimit limit(common->threads);
        const AtmosphereParameters atmosphere = LoadAtmosphere(common->atmosphere, common->sets);
        CheckOutputDirectory(*output);  // before the precomputation (io/output_path.h)
        const double seconds = PrepareModel(*common, atmosphere, model.get());
        std::filesystem::create_directories(*output);
        model->Bake(*output);
        if (!common->quiet) {
            std::fprintf(stderr, "baked %s (precomputed in %.3f s) into %s\n",
                         common->model.c_str(), seconds, output->c_str());
        }
        return 0;
    };
    return c;
}

}  // namespace atmos::cli
