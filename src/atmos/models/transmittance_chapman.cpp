#include "models/transmittance_chapman.h"

namespace atmos {

ModelInfo TransmittanceChapmanModel::StaticInfo() {
    ModelInfo info;
    info.name = "transmittance-chapman";
    info.title = "Schuler 2012 Chapman-approximation transmittance";
    info.citation = "Schuler 2012 (GPU Pro 3); seed 003 section 5.1 (Eq. 22-25)";
    info.summary = "view-ray transmittance from Schuler's Chapman approximation; no ozone";
    info.capabilities = TransmittanceCapabilities();
    info.options = {ChapmanUnitOption()};
    return info;
}

ModelOptionSpec ChapmanUnitOption() {
    return {"chapman-unit",
            ModelOptionSpec::Type::kChoice,
            "seed",
            "length unit of the Chapman approximation: seed (scale height, seed 003 Eq. 25) or "
            "half-height (H ln 2, Schuler's code)",
            0,
            0,
            {"seed", "half-height"}};
}

double ChapmanUnitFromOptions(const ModelOptions& options) {
    return options.GetText("chapman-unit") == "half-height" ? kChapmanHalfHeightUnit
                                                            : kChapmanSeedUnit;
}

TransmittanceChapmanModel::TransmittanceChapmanModel(const ModelOptions& options) {
    unit_ = ChapmanUnitFromOptions(options);
    Prepare(EarthAtmosphere());
}

}  // namespace atmos
