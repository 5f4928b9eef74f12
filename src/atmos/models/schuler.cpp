#include "models/schuler.h"

#include "models/transmittance_chapman.h"

namespace atmos {

ModelInfo SchulerModel::StaticInfo() {
    ModelInfo info;
    info.name = "schuler";
    info.title = "Naive integrator with Schuler's Chapman light depth";
    info.citation = "Schuler 2012 (GPU Pro 3); seed 003 sections 5.1 (Eq. 22-25), 11.2.7";
    info.summary =
        "single scattering, view ray by the midpoint rule, light optical depth by the "
        "Chapman approximation; no ozone";
    info.options = OptionRows().Specs();
    return info;
}

const OptionTable<SchulerOptions>& SchulerModel::OptionRows() {
    static const auto table =
        OptionTable<SchulerOptions>()
            .Integer("steps", &SchulerOptions::steps, 1, 1e5, "", "view-ray integration samples")
            .Choice("chapman-unit", &SchulerOptions::chapman_unit, ChapmanUnitChoices(),
                    kChapmanUnitHelp);
    return table;
}

SchulerModel::SchulerModel(const SchulerOptions& options) {
    evaluator_.steps = options.steps;
    evaluator_.chapman_unit = options.chapman_unit;
    Prepare(EarthAtmosphere());
}

void SchulerModel::Prepare(const AtmosphereParameters& atmosphere) {
    SetAtmosphere(atmosphere);
    evaluator_.m = MakeAnalyticMedia(atmosphere);
}

}  // namespace atmos
