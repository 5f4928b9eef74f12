// atmos CLI: the Monte Carlo flags (see cli_monte_carlo.h).
#include "cli_monte_carlo.h"

#include "atmos/error.h"
#include "render/progressive.h"

namespace atmos::cli {

bool MonteCarloFlags::Given() const {
    return spp_flag->count() + seed_flag->count() + pass_flag->count() > 0;
}

MonteCarloSettings MonteCarloFlags::Checked() const {
    return MakeMonteCarloSettings(spp, seed, pass_spp);
}

MonteCarloSettings MonteCarloFlags::Settings(const ModelInfo& model) const {
    if (Given() && !model.capabilities.stochastic) {
        Fail("--spp, --seed and --pass-spp apply to Monte Carlo models only; model ", model.name,
             " is not one (`atmos list` marks them)");
    }
    return Checked();
}

void AddMonteCarloFlags(CLI::App* cmd, MonteCarloFlags* flags) {
    const char* group = "Monte Carlo models (e.g. reference)";
    flags->spp_flag =
        cmd->add_option("--spp", flags->spp, "paths per pixel (per query for sample), >= 1")
            ->capture_default_str()
            ->group(group);
    flags->seed_flag = cmd->add_option("--seed", flags->seed, "random seed in [0, 4294967295]")
                           ->capture_default_str()
                           ->group(group);
    flags->pass_flag =
        cmd->add_option("--pass-spp", flags->pass_spp,
                        "paths per pixel per pass (checkpoint and variance granularity); 0: "
                        "spp/8 in [1, 64]. Set it explicitly to extend a checkpointed render to "
                        "more spp with --resume")
            ->capture_default_str()
            ->group(group);
}

}  // namespace atmos::cli
