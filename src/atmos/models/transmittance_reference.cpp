#include "models/transmittance_reference.h"

namespace atmos {

ModelInfo TransmittanceReferenceModel::StaticInfo() {
    ModelInfo info;
    info.name = "transmittance-reference";
    info.title = "Reference transmittance (Riemann sum, 128 steps)";
    info.citation = "seed 003 section 11.3.1";
    info.summary = "view-ray transmittance by a 128-step midpoint Riemann sum (all media)";
    info.capabilities = TransmittanceCapabilities();
    info.options = OptionRows().Specs();
    return info;
}

const OptionTable<TransmittanceReferenceOptions>& TransmittanceReferenceModel::OptionRows() {
    static const auto table = OptionTable<TransmittanceReferenceOptions>().Integer(
        "steps", &TransmittanceReferenceOptions::steps, 1, 1e6, "", "Riemann-sum steps");
    return table;
}

TransmittanceReferenceModel::TransmittanceReferenceModel(
    const TransmittanceReferenceOptions& options) {
    steps_ = options.steps;
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
