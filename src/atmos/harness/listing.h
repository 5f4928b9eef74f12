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

}  // namespace atmos
