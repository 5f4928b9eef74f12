#include "models/transmittance_flat.h"

namespace atmos {

ModelInfo TransmittanceFlatModel::StaticInfo() {
    ModelInfo info;
    info.name = "transmittance-flat";
    info.title = "Flat / homogeneous-sphere transmittance";
    info.citation = "Leenman's 2025 thesis sections 10.2-10.5, 11.3.3 (Eq. 50, 53, 59, 60)";
    info.summary = "view-ray transmittance from the homogeneous-sphere optical depth + ozone shell";
    info.capabilities = TransmittanceCapabilities();
    return info;
}

}  // namespace atmos
