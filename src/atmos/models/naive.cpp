#include "models/naive.h"

namespace atmos {

ModelInfo NaiveModel::StaticInfo() {
    ModelInfo info;
    info.name = "naive";
    info.title = "Naive single scattering (Nishita 93)";
    info.citation =
        "Nishita et al. 1993; Terrell 2016 (glsl-atmosphere); Leenman's 2025 thesis sections 3.2, "
        "5.1, 11.2.6";
    info.summary = "single scattering by nested numerical integration, Rayleigh + Mie + ozone";
    info.capabilities.multiple_scattering = false;
    info.options = OptionRows().Specs();
    info.thesis_name = "Naive";
    info.thesis_lines = 118;
    return info;
}

const OptionTable<NaiveOptions>& NaiveModel::OptionRows() {
    static const auto table =
        OptionTable<NaiveOptions>()
            .Integer("steps", &NaiveOptions::steps, 1, 1e5, "", "view-ray integration samples")
            .Integer("light-steps", &NaiveOptions::light_steps, 1, 1e5, "",
                     "light-ray integration samples");
    return table;
}

NaiveModel::NaiveModel(const NaiveOptions& options) {
    evaluator_.atm = EarthAtmosphere();
    evaluator_.steps = options.steps;
    evaluator_.light_steps = options.light_steps;
}

}  // namespace atmos
