// atmos studies: the shared checks (common.h).
#include "studies/common.h"

#include "atmos/error.h"

namespace atmos {

void RequireQuantity(const ModelInfo& info, Quantity quantity) {
    const bool produces = quantity == Quantity::kRadiance ? info.capabilities.radiance
                                                          : info.capabilities.transmittance;
    if (!produces) {
        Fail("model ", info.name, " does not produce ", QuantityName(quantity), " (it produces ",
             info.capabilities.radiance ? "radiance" : "transmittance", " only)");
    }
}

}  // namespace atmos
