#include "models/transmittance_chapman.h"

namespace atmos {

ModelInfo TransmittanceChapmanModel::StaticInfo() {
    ModelInfo info;
    info.name = "transmittance-chapman";
    info.title = "Schuler 2012 Chapman-approximation transmittance";
    info.citation = "Schuler 2012 (GPU Pro 3); seed 003 section 5.1 (Eq. 22-25)";
    info.summary = "view-ray transmittance from Schuler's Chapman approximation; no ozone";
    info.capabilities = TransmittanceCapabilities();
    return info;
}

}  // namespace atmos
