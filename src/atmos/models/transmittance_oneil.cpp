#include "models/transmittance_oneil.h"

namespace atmos {

ModelInfo TransmittanceOneilModel::StaticInfo() {
    ModelInfo info;
    info.name = "transmittance-oneil";
    info.title = "O'Neil 2005 scale() transmittance";
    info.citation =
        "O'Neil 2005, GPU Gems 2 ch. 16; Raush's O'Neil slides (2018); Leenman's 2025 thesis Eq. "
        "17";
    info.summary = "view-ray transmittance from O'Neil's fitted scale() (refit per atmosphere)";
    info.capabilities = TransmittanceCapabilities();
    info.capabilities.precomputed = true;
    info.options = OptionRows().Specs();
    // The optical depth of `oneil` (its domain, measured there).
    info.domain = OneilModel::StaticInfo().domain;
    return info;
}

const OptionTable<TransmittanceOneilOptions>& TransmittanceOneilModel::OptionRows() {
    static const auto table = OptionTable<TransmittanceOneilOptions>().Choice(
        "fit", &TransmittanceOneilOptions::refit, {{"refit", true}, {"original", false}},
        "scale() constants: refit or original");
    return table;
}

TransmittanceOneilModel::TransmittanceOneilModel(const TransmittanceOneilOptions& options) {
    refit_ = options.refit;
    Prepare(EarthAtmosphere());
}

}  // namespace atmos
