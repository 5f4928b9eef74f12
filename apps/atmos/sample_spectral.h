// atmos CLI: the spectral columns of `atmos sample --wavelengths` (sample_spectral.cpp).
#pragma once

#include <string>
#include <vector>

#include "atmos/model.h"
#include "cli_common.h"
#include "harness/spectral_run.h"

namespace atmos::cli {

// Writes the spectral CSV of `queries` (header L_<nm>..., X, Y, Z) to stdout, or
// to `output` (a file; "" or "-": stdout); `npy`: `output` gets a float32 array of
// shape (queries, wavelengths + 3), the L_<nm> values then X, Y, Z per row.
int SampleSpectralCsv(const CommonOptions& common, const MonteCarloSettings& monte_carlo,
                      const std::string& wavelengths, const std::vector<SampleQuery>& queries,
                      SpectralBatching batching = {}, const std::string& output = "",
                      bool npy = false);

}  // namespace atmos::cli
