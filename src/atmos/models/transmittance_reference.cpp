#include "models/transmittance_reference.h"

namespace atmos {

ModelInfo TransmittanceReferenceModel::StaticInfo() {
    ModelInfo info;
    info.name = "transmittance-reference";
    info.title = "Reference transmittance (Riemann sum, 128 steps)";
    info.citation = "seed 003 section 11.3.1";
    info.summary = "view-ray transmittance by a 128-step midpoint Riemann sum (all media)";
    info.capabilities = TransmittanceCapabilities();
    info.options = {
        {"steps", ModelOptionSpec::Type::kInteger, "128", "Riemann-sum steps", 1, 1e6, {}},
    };
    return info;
}

TransmittanceReferenceModel::TransmittanceReferenceModel(const ModelOptions& options) {
    steps_ = options.GetInt("steps");
    Prepare(EarthAtmosphere());
}

ReferenceTransmittanceOptics TransmittanceReferenceModel::MakeOptics(
    const AtmosphereParameters& atmosphere) const {
    ReferenceTransmittanceOptics o;
    o.atm = atmosphere;
    o.steps = steps_;
    return o;
}

}  // namespace atmos
