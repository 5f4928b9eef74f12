// atmos studies: the checks every study and the CLI's model-running commands share.
#pragma once

#include "atmos/model.h"

namespace atmos {

// Fails (one clear line, exit 2) when the model does not produce the quantity
// (a transmittance model asked for radiance, preetham for transmittance).
void RequireQuantity(const ModelInfo& info, Quantity quantity);

}  // namespace atmos
