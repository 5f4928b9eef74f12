#include "models/transmittance_oneil.h"

namespace atmos {

ModelInfo TransmittanceOneilModel::StaticInfo() {
    ModelInfo info;
    info.name = "transmittance-oneil";
    info.title = "O'Neil 2005 scale() transmittance";
    info.citation = "O'Neil 2005, GPU Gems 2 ch. 16; seed 001; seed 003 Eq. 17";
    info.summary = "view-ray transmittance from O'Neil's fitted scale() (refit per atmosphere)";
    info.capabilities = TransmittanceCapabilities();
    info.capabilities.precomputed = true;
    info.options = {
        {"fit",
         ModelOptionSpec::Type::kChoice,
         "refit",
         "scale() constants: refit or original",
         0,
         0,
         {"refit", "original"}},
    };
    return info;
}

TransmittanceOneilModel::TransmittanceOneilModel(const ModelOptions& options) {
    refit_ = options.GetText("fit") == "refit";
    Prepare(EarthAtmosphere());
}

}  // namespace atmos
