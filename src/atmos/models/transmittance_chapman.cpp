#include "models/transmittance_chapman.h"

namespace atmos {

ModelInfo TransmittanceChapmanModel::StaticInfo() {
    ModelInfo info;
    info.name = "transmittance-chapman";
    info.title = "Schuler 2012 Chapman-approximation transmittance";
    info.citation = "Schuler 2012 (GPU Pro 3); Leenman's 2025 thesis section 5.1 (Eq. 22-25)";
    info.summary = "view-ray transmittance from Schuler's Chapman approximation; no ozone";
    info.capabilities = TransmittanceCapabilities();
    info.options = OptionRows().Specs();
    return info;
}

std::vector<std::pair<std::string, double>> ChapmanUnitChoices() {
    return {{"seed", kChapmanSeedUnit}, {"half-height", kChapmanHalfHeightUnit}};
}

const char* const kChapmanUnitHelp =
    "length unit of the Chapman approximation: seed (scale height, Leenman's 2025 thesis Eq. 25) "
    "or "
    "half-height (H ln 2, Schuler's code)";

const OptionTable<TransmittanceChapmanOptions>& TransmittanceChapmanModel::OptionRows() {
    static const auto table = OptionTable<TransmittanceChapmanOptions>().Choice(
        "chapman-unit", &TransmittanceChapmanOptions::chapman_unit, ChapmanUnitChoices(),
        kChapmanUnitHelp);
    return table;
}

TransmittanceChapmanModel::TransmittanceChapmanModel(const TransmittanceChapmanOptions& options) {
    unit_ = options.chapman_unit;
    Prepare(EarthAtmosphere());
}

}  // namespace atmos
