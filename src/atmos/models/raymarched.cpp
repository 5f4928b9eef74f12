#include "models/raymarched.h"

namespace atmos {

ModelInfo RaymarchedModel::StaticInfo() {
    ModelInfo info;
    info.name = "raymarched";
    info.title = "Raymarched segments with the flat optical depth (Leenman's 2025 thesis s. 10.4)";
    info.citation = "Hillaire 2015; Leenman's 2025 thesis sections 10.2-10.5 (Eq. 50-59), 11.2.10";
    info.summary =
        "single scattering summed over a few closed-form segments (Eq. 55), flat optical "
        "depth, ozone shell";
    info.options = OptionRows().Specs();
    info.thesis_name = "Raymarched";
    info.thesis_lines = 74;
    return info;
}

const OptionTable<RaymarchedOptions>& RaymarchedModel::OptionRows() {
    static const auto table = OptionTable<RaymarchedOptions>().Integer(
        "steps", &RaymarchedOptions::steps, 1, 1e5, "", "view-ray segments");
    return table;
}

RaymarchedModel::RaymarchedModel(const RaymarchedOptions& options) {
    evaluator_.steps = options.steps;
    Prepare(EarthAtmosphere());
}

void RaymarchedModel::Prepare(const AtmosphereParameters& atmosphere) {
    SetAtmosphere(atmosphere);
    evaluator_.optics.m = MakeAnalyticMedia(atmosphere);
}

}  // namespace atmos
