#include "models/transmittance_erfc.h"

namespace atmos {

ModelInfo TransmittanceErfcModel::StaticInfo() {
    ModelInfo info;
    info.name = "transmittance-erfc";
    info.title = "Bruneton & Neyret 2008 erfc transmittance";
    info.citation =
        "Bruneton & Neyret 2008; Leenman's 2025 thesis section 5.1 (Eq. 26-30, Listing 3)";
    info.summary = "view-ray transmittance from the erfc optical-depth approximation; no ozone";
    info.capabilities = TransmittanceCapabilities();
    return info;
}

}  // namespace atmos
