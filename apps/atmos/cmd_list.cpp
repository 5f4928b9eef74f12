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

namespace fs = std::filesystem;

namespace atmos::cli {

namespace {

int CmdList() {
    std::printf("models:\n");
    for (const ModelInfo& info : ListModels()) {
        const ModelCapabilities& c = info.capabilities;
        std::printf("  %-16s %s\n", info.name.c_str(), info.title.c_str());
        std::printf("  %-16s   %s\n", "", info.summary.c_str());
        std::printf("  %-16s   source: %s\n", "", info.citation.c_str());
        std::printf(
            "  %-16s   quantities: %s%s%s; space views: %s; sun below horizon: %s; "
            "multiple scattering: %s\n",
            "", c.radiance ? "radiance" : "", c.radiance && c.transmittance ? ", " : "",
            c.transmittance ? "transmittance" : "", c.space_views ? "yes" : "no",
            c.sun_below_horizon ? "yes" : "no", c.multiple_scattering ? "yes" : "no");
        if (c.stochastic) {
            std::printf("  %-16s   Monte Carlo: takes --spp, --seed, --pass-spp\n", "");
        }
        for (const ModelOptionSpec& spec : info.options) {
            std::printf("  %-16s   --%s (default %s): %s\n", "", spec.name.c_str(),
                        spec.default_value.c_str(), spec.help.c_str());
        }
    }
    std::printf("views:\n");
    for (const View& v : StandardViews(EarthAtmosphere())) {
        std::printf("  %-22s exposure %-3g %s\n", v.name.c_str(), static_cast<double>(v.exposure),
                    v.description.c_str());
    }
    std::printf("atmospheres:\n");
    for (const std::string& name : AtmospherePresetNames()) std::printf("  %s\n", name.c_str());
    return 0;
}

}  // namespace

Command AddListCommand(CLI::App* root) {
    Command c;
    c.app = root->add_subcommand("list", "list models, views and atmosphere presets");
    c.run = [] { return CmdList(); };
    return c;
}

}  // namespace atmos::cli
