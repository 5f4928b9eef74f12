// atmos CLI: the Monte Carlo flags (see cli_monte_carlo.h).
#include "cli_monte_carlo.h"

#include "atmos/error.h"
#include "render/progressive.h"

namespace atmos::cli {

bool MonteCarloFlags::Given() const {
    return spp_flag->count() + seed_flag->count() + pass_flag->count() +
               (noise_flag ? noise_flag->count() : 0) >
           0;
}

MonteCarloSettings MonteCarloFlags::Checked() const {
    // With a noise target --spp is the cap; not given, it is 65536.
    const bool noise_given = noise_flag && noise_flag->count() > 0;
    const int64_t cap = noise_given && spp_flag->count() == 0 ? 65536 : spp;
    MonteCarloSettings mc = MakeMonteCarloSettings(cap, seed, pass_spp);
    if (noise_given) {
        if (!(noise > 0.0 && noise < 1.0)) Fail("--noise must be in (0, 1), got ", noise);
        mc.noise_target = noise;
    }
    return mc;
}

MonteCarloSettings MonteCarloFlags::Settings(const ModelInfo& model) const {
    if (Given() && !model.capabilities.stochastic) {
        Fail("--spp, --seed and --pass-spp apply to Monte Carlo models only; model ", model.name,
             " is not one (`atmos list` marks them)");
    }
    return Checked();
}

void AddMonteCarloFlags(CLI::App* cmd, MonteCarloFlags* flags, bool with_noise) {
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
    if (with_noise) {
        flags->noise_flag =
            cmd->add_option("--noise", flags->noise,
                            "render until the HDR-FLIP between the image's two halves (its even "
                            "and odd passes) is at or below this, in (0, 1); --spp is then the "
                            "cap (default 65536)")
                ->group(group);
    }
}

}  // namespace atmos::cli
