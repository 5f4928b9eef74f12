// atmos CLI: the spectral columns of `atmos sample --wavelengths` (sample_spectral.cpp).
#pragma once

#include <string>
#include <vector>

#include "atmos/model.h"
#include "cli_common.h"
#include "harness/spectral_run.h"

namespace atmos::cli {

// Prints the spectral CSV of `queries` (header L_<nm>..., X, Y, Z) to stdout.
int SampleSpectralCsv(const CommonOptions& common, const MonteCarloSettings& monte_carlo,
                      const std::string& wavelengths, const std::vector<SampleQuery>& queries,
                      BatchSeeds seeds = BatchSeeds::kSame);

}  // namespace atmos::cli
