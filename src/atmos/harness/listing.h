// atmos: what `atmos list` prints about a model, from its declared
// capabilities and validity domain (atmos/model.h), never from its name.
#pragma once

#include <string>

#include "atmos/model.h"

namespace atmos {

// The capability lines under a model's entry (each "  " + 16 spaces + "   ...\n"):
// quantities, views, scattering, precomputed / Monte Carlo, validity notes and
// the validity domain.
std::string ModelCapabilitiesText(const ModelInfo& info);

// For a command line whose extra arguments CLI11 refused: when one is a model
// option written as a flag (`--orders 2`, the syntax before issue 14), the hint
// " (model options are part of the model: --model NAME:OPTION=VALUE; ...)";
// else "". `args` are the arguments after the program name.
std::string ModelOptionFlagHint(const std::vector<std::string>& args);

}  // namespace atmos
