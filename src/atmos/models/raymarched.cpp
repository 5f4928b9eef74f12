#include "models/raymarched.h"

namespace atmos {

ModelInfo RaymarchedModel::StaticInfo() {
    ModelInfo info;
    info.name = "raymarched";
    info.title = "Raymarched segments with the flat optical depth (seed 003 s. 10.4)";
    info.citation = "Hillaire 2015; seed 003 sections 10.2-10.5 (Eq. 50-59), 11.2.10";
    info.summary =
        "single scattering summed over a few closed-form segments (Eq. 55), flat optical "
        "depth, ozone shell";
    info.options = {
        {"steps", ModelOptionSpec::Type::kInteger, "5", "view-ray segments", 1, 1e5, {}},
    };
    return info;
}

RaymarchedModel::RaymarchedModel(const ModelOptions& options) {
    evaluator_.steps = options.GetInt("steps");
    Prepare(EarthAtmosphere());
}

void RaymarchedModel::Prepare(const AtmosphereParameters& atmosphere) {
    SetAtmosphere(atmosphere);
    evaluator_.optics.m = MakeAnalyticMedia(atmosphere);
}

}  // namespace atmos
