#include "models/schuler.h"

#include "models/transmittance_chapman.h"

namespace atmos {

ModelInfo SchulerModel::StaticInfo() {
    ModelInfo info;
    info.name = "schuler";
    info.title = "Naive integrator with Schuler's Chapman light depth";
    info.citation =
        "Schuler 2012 (GPU Pro 3); Leenman's 2025 thesis sections 5.1 (Eq. 22-25), 11.2.7";
    info.summary =
        "single scattering, view ray by the midpoint rule, light optical depth by the "
        "Chapman approximation; no ozone";
    info.options = OptionRows().Specs();
    info.thesis_name = "Schuler";
    info.thesis_lines = 106;
    // Measured: the zenith transmittance from the ground against its own at
    // Earth (docs/models/schuler.md "Validity domain"): +1.8 % at 26.4 column
    // heights, +3.5 % at 35.1, T = 1 on the giant planet.
    info.domain.max_shell_heights = 25.0;
    info.domain.shell_heights_reason =
        "the view ray's midpoint steps span the whole shell and step over the air near the "
        "ground (zenith transmittance +3.5 % at 35 heights, 1 on a 1e9 m shell)";
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
