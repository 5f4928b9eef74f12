// atmos CLI: `--spp`, `--seed` and `--pass-spp`, the flags of `render` and
// `sample` that set a Monte Carlo model's estimate (render/progressive.h).
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>

#include "atmos/model.h"

namespace atmos::cli {

struct MonteCarloFlags {
    int64_t spp = 64;
    int64_t seed = 0;
    int64_t pass_spp = 0;
    double noise = 0.0;  // render: a noise target (0: off)
    CLI::Option* spp_flag = nullptr;
    CLI::Option* noise_flag = nullptr;
    CLI::Option* seed_flag = nullptr;
    CLI::Option* pass_flag = nullptr;

    bool Given() const;
    // The settings, one atmos::Error when a flag is out of its range.
    MonteCarloSettings Checked() const;
    // The settings for the chosen model: one atmos::Error when a flag is given
    // for a model that is not Monte Carlo, or is out of its range.
    MonteCarloSettings Settings(const ModelInfo& model) const;
};

// `with_noise`: also --noise (renders only).
void AddMonteCarloFlags(CLI::App* cmd, MonteCarloFlags* flags, bool with_noise = false);

}  // namespace atmos::cli
