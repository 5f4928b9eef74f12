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
    info.options = {
        {"steps",
         ModelOptionSpec::Type::kInteger,
         "16",
         "view-ray integration samples",
         1,
         1e5,
         {}},
        ChapmanUnitOption(),
    };
    return info;
}

SchulerModel::SchulerModel(const ModelOptions& options) {
    evaluator_.steps = options.GetInt("steps");
    evaluator_.chapman_unit = ChapmanUnitFromOptions(options);
    Prepare(EarthAtmosphere());
}

void SchulerModel::Prepare(const AtmosphereParameters& atmosphere) {
    SetAtmosphere(atmosphere);
    evaluator_.m = MakeAnalyticMedia(atmosphere);
}

}  // namespace atmos
